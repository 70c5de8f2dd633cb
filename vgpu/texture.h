// A texture: a 2D array of 1-4 channel texels in video memory, in one storage format.
// Programs read textures only through texture units (nearest sampling, integer texRECT
// coordinates, clamped at the edges) and write them only as render targets.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <new>
#include <span>
#include <string>
#include <vector>

#include "vgpu/format.h"

namespace vgpu {

class Gpu;

class Texture {
 public:
  Texture() : uid_(fresh_uid()) {}
  // Allocates width x height texels of `channels` channels, all zero.
  Texture(std::string name, int width, int height, int channels, Format format = Format::fp32);
  // A copy or a moved-to texture is a new texture for the Gpu's copy tracking (see uid_).
  Texture(const Texture& o);
  Texture(Texture&& o) noexcept;
  Texture& operator=(const Texture& o);
  Texture& operator=(Texture&& o) noexcept;
  ~Texture();

  // Identity for devices that keep their own copy of a texture (the GL device's objects): the
  // same as the emulator's uid, new for a copy or a moved-to texture.
  uint64_t id() const { return uid_; }

  // A device that keeps an object of its own per id (the GL device's GL textures) subscribes to
  // learn which ids no longer name any texture: one destroyed, and both ids a move or an
  // assignment drops (the moved-from texture's and the assigned-to texture's old ones; ids are
  // never reused). retired() runs on the thread that dropped the id, under the subscribers'
  // lock: it may only note the id, and free its object at its own next call.
  class IdSink {
   public:
    virtual void retired(uint64_t id) = 0;

   protected:
    ~IdSink() = default;
  };
  static void subscribe(IdSink* sink);
  static void unsubscribe(IdSink* sink);

  // The emulator's texel storage, every texture of the process together: 4 bytes a channel
  // whatever the format (bytes() is the modeled card's), counted when allocated, alive now and
  // at most since the last reset_peak_storage() (the memory model's texture term,
  // host/report/memory_json.h).
  static uint64_t storage_bytes();
  static uint64_t peak_storage_bytes();
  static void reset_peak_storage();

  const std::string& name() const { return name_; }
  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  Format format() const { return format_; }
  int bytes_per_texel() const { return channels_ * bytes_per_channel(format_); }
  uint64_t bytes() const { return uint64_t(width_) * height_ * bytes_per_texel(); }

  // Host access (uploads and read-backs): texel (x, y) channel c. Stores round to the format.
  float get(int x, int y, int c = 0) const { return data_[index(x, y) + c]; }
  void set(int x, int y, int c, float v) {
    ++version_;
    data_[index(x, y) + c] = round_to(format_, v);
  }
  void fill(std::span<const float> texel);  // every texel = texel (channels() values)
  // Every texel at once (channels() floats per texel, row-major, data().size() in all), rounded
  // to the format; returns whether any stored value changed (what a host re-upload must send).
  bool replace(std::span<const float> texels);
  // Raw texel storage: channels() floats per texel, row-major, already rounded.
  std::span<const float> data() const { return data_; }
  const float* texel(int x, int y) const { return data_.data() + index(x, y); }
  float* texel_mut(int x, int y) {
    ++version_;
    return data_.data() + index(x, y);
  }
  size_t index(int x, int y) const { return (size_t(y) * width_ + x) * channels_; }

 private:
  friend class Gpu;
  static uint64_t fresh_uid();
  static void retire(uint64_t uid);  // tells the subscribers that uid names no texture now
  static void count_storage(size_t bytes, bool allocated);
  // Rows [y0, y1) only, each texel = texel, without a version step (Gpu::clear splits its rows
  // over the threads and steps the version once).
  void fill_rows(std::span<const float> texel, int y0, int y1);

  std::string name_;
  int width_ = 0, height_ = 0, channels_ = 0;
  Format format_ = Format::fp32;
  // Zero texels from calloc, which maps a large block's pages zero from the system and leaves
  // them untouched: a frame's forty 16 MB textures cost nothing at creation and are faulted in by
  // the first pass that writes them, on every thread, not by a serial memset (0.6 s at 1024x1024).
  template <class T>
  struct ZeroedAllocator {
    using value_type = T;
    ZeroedAllocator() = default;
    template <class U>
    ZeroedAllocator(const ZeroedAllocator<U>&) {}
    T* allocate(size_t n) {
      if (void* p = std::calloc(n, sizeof(T))) {
        count_storage(n * sizeof(T), true);
        return static_cast<T*>(p);
      }
      throw std::bad_alloc();
    }
    void deallocate(T* p, size_t n) {
      count_storage(n * sizeof(T), false);
      std::free(p);
    }
    template <class U>
    void construct(U*) {}  // value-initialised: calloc's zeros already are (data_ is
                           // resized once, from empty, in the constructor: never over old texels)
    template <class U, class... A>
    void construct(U* p, A&&... a) {
      ::new (static_cast<void*>(p)) U(std::forward<A>(a)...);
    }
    bool operator==(const ZeroedAllocator&) const { return true; }
  };
  std::vector<float, ZeroedAllocator<float>> data_;
  // Emulator bookkeeping, not modeled state: the Gpu skips copying texels it knows two textures
  // already share (gpu.cpp, PairRecord). uid_ is unique per texture object and content lineage
  // (copies and moves get a new one), version_ counts every host write access; the Gpu bumps it
  // once per clear or pass that writes the texture.
  uint64_t uid_ = 0, version_ = 0;
};

// An early-z / stencil style mask over a render target: one byte per pixel. A pass that tests
// it skips fragments whose value is 0 before shading (they are counted as masked, not shaded).
class Stencil {
 public:
  Stencil() = default;
  Stencil(int width, int height, uint8_t value = 1)
      : width_(width), height_(height), bits_(size_t(width) * height, value) {}
  int width() const { return width_; }
  int height() const { return height_; }
  uint8_t get(int x, int y) const { return bits_[size_t(y) * width_ + x]; }
  void set(int x, int y, uint8_t v) {
    ++version_;
    bits_[size_t(y) * width_ + x] = v;
  }
  void fill(uint8_t v) {
    ++version_;
    std::fill(bits_.begin(), bits_.end(), v);
  }
  const uint8_t* row(int y) const { return bits_.data() + size_t(y) * width_; }
  uint8_t* row_mut(int y) {
    ++version_;
    return bits_.data() + size_t(y) * width_;
  }
  uint64_t count() const;  // pixels with a non-zero value

 private:
  friend class Gpu;
  int width_ = 0, height_ = 0;
  std::vector<uint8_t> bits_;
  // Emulator bookkeeping, not modeled state: after a pass that wrote this mask, the Gpu lists its
  // non-zero pixels (indices y * width + x, ascending), so a later pass under it visits only
  // those. Valid while listed_version_ == version_; every host write access bumps version_.
  // Copies share the (immutable) list with the bits.
  uint64_t version_ = 0, listed_version_ = ~uint64_t(0);
  std::shared_ptr<const std::vector<uint32_t>> nonzero_;
};

}  // namespace vgpu
