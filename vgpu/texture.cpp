// Texture storage and the stencil mask.
#include "vgpu/texture.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <mutex>
#include <stdexcept>

namespace vgpu {

namespace {
std::atomic<uint64_t> g_storage{0}, g_peak_storage{0};

// The id sinks (Texture::subscribe). Allocated once and never freed, so that a texture destroyed
// during the program's exit still finds it; `count` keeps the lock off every texture's
// destruction while no device listens (the emulator alone).
struct Sinks {
  std::mutex lock;
  std::vector<Texture::IdSink*> sinks;
  std::atomic<size_t> count{0};
};
Sinks& sinks() {
  static Sinks* s = new Sinks;
  return *s;
}
}  // namespace

void Texture::subscribe(IdSink* sink) {
  Sinks& s = sinks();
  std::lock_guard<std::mutex> hold(s.lock);
  s.sinks.push_back(sink);
  s.count.store(s.sinks.size(), std::memory_order_release);
}

void Texture::unsubscribe(IdSink* sink) {
  Sinks& s = sinks();
  std::lock_guard<std::mutex> hold(s.lock);
  std::erase(s.sinks, sink);
  s.count.store(s.sinks.size(), std::memory_order_release);
}

// Called from the noexcept moves and the destructor: a lock or a sink that throws (a mutex's
// system_error, a sink's bad_alloc) ends the program there, as any failure in them would.
void Texture::retire(uint64_t uid) {
  Sinks& s = sinks();
  if (s.count.load(std::memory_order_acquire) == 0) return;
  std::lock_guard<std::mutex> hold(s.lock);
  for (IdSink* sink : s.sinks) sink->retired(uid);
}

Texture::~Texture() {
  retire(uid_);
}

void Texture::count_storage(size_t bytes, bool allocated) {
  if (!allocated) {
    g_storage.fetch_sub(bytes, std::memory_order_relaxed);
    return;
  }
  const uint64_t now = g_storage.fetch_add(bytes, std::memory_order_relaxed) + bytes;
  uint64_t peak = g_peak_storage.load(std::memory_order_relaxed);
  while (now > peak &&
         !g_peak_storage.compare_exchange_weak(peak, now, std::memory_order_relaxed)) {
  }
}

uint64_t Texture::storage_bytes() {
  return g_storage.load(std::memory_order_relaxed);
}

uint64_t Texture::peak_storage_bytes() {
  return g_peak_storage.load(std::memory_order_relaxed);
}

void Texture::reset_peak_storage() {
  g_peak_storage.store(g_storage.load(std::memory_order_relaxed), std::memory_order_relaxed);
}

uint64_t Texture::fresh_uid() {
  static std::atomic<uint64_t> next{1};
  return next.fetch_add(1, std::memory_order_relaxed);
}

Texture::Texture(const Texture& o)
    : name_(o.name_),
      width_(o.width_),
      height_(o.height_),
      channels_(o.channels_),
      format_(o.format_),
      data_(o.data_),
      uid_(fresh_uid()) {}

Texture::Texture(Texture&& o) noexcept
    : name_(std::move(o.name_)),
      width_(o.width_),
      height_(o.height_),
      channels_(o.channels_),
      format_(o.format_),
      data_(std::move(o.data_)),
      uid_(fresh_uid()) {
  retire(o.uid_);
  o.uid_ = fresh_uid();
}

Texture& Texture::operator=(const Texture& o) {
  if (this == &o) return *this;
  Texture t(o);
  return *this = std::move(t);
}

Texture& Texture::operator=(Texture&& o) noexcept {
  if (this == &o) return *this;
  name_ = std::move(o.name_);
  width_ = o.width_;
  height_ = o.height_;
  channels_ = o.channels_;
  format_ = o.format_;
  data_ = std::move(o.data_);
  retire(uid_);
  retire(o.uid_);
  uid_ = fresh_uid();
  o.uid_ = fresh_uid();
  return *this;
}

Texture::Texture(std::string name, int width, int height, int channels, Format format)
    : name_(std::move(name)),
      width_(width),
      height_(height),
      channels_(channels),
      format_(format),
      uid_(fresh_uid()) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("texture " + name_ + ": empty size");
  if (channels < 1 || channels > 4)
    throw std::invalid_argument("texture " + name_ + ": texels have 1 to 4 channels");
  data_.resize(size_t(width) * height * channels);  // zeros, untouched (ZeroedAllocator)
}

void Texture::fill(std::span<const float> texel) {
  ++version_;
  fill_rows(texel, 0, height_);
}

void Texture::fill_rows(std::span<const float> texel, int y0, int y1) {
  float v[4];
  for (int c = 0; c < channels_; ++c) v[c] = round_to(format_, texel[size_t(c)]);
  float* p = data_.data() + size_t(y0) * size_t(width_) * size_t(channels_);
  float* const end = data_.data() + size_t(y1) * size_t(width_) * size_t(channels_);
  if (channels_ == 1) {
    std::fill(p, end, v[0]);
    return;
  }
  for (; p != end; p += channels_)
    for (int c = 0; c < channels_; ++c) p[c] = v[c];
}

bool Texture::replace(std::span<const float> texels) {
  if (texels.size() != data_.size())
    throw std::invalid_argument("texture " + name_ + ": replace() needs " +
                                std::to_string(data_.size()) + " values, got " +
                                std::to_string(texels.size()));
  bool changed = false;
  for (size_t i = 0; i < data_.size(); ++i) {
    const float v = round_to(format_, texels[i]);
    // Bit patterns, so that -0 for 0 or a NaN payload counts as a change too.
    changed |= std::bit_cast<uint32_t>(v) != std::bit_cast<uint32_t>(data_[i]);
    data_[i] = v;
  }
  if (changed) ++version_;
  return changed;
}

uint64_t Stencil::count() const {
  return uint64_t(std::count_if(bits_.begin(), bits_.end(), [](uint8_t b) { return b != 0; }));
}

}  // namespace vgpu
