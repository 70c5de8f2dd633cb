// The dense streams of marked pixels (host/trace/stream/mark_streams.h): the scan, the
// compaction and the gather back, each pass counted by job.
#include "host/trace/stream/mark_streams.h"

#include <algorithm>
#include <bit>
#include <cstdio>

namespace host {

using vgpu::Format;
using vgpu::Texture;

namespace {

// ceil(log2(n)) for n >= 1: the scan's passes and the binary search's steps.
int ceil_log2(uint64_t n) {
  return n <= 1 ? 0 : int(std::bit_width(n - 1));
}

void add(const vgpu::PassRecord& rec, uint64_t& passes, uint64_t& bytes) {
  ++passes;
  bytes += rec.counters.bytes_read + rec.counters.bytes_written;
}

}  // namespace

std::string describe(const CompactStats& s) {
  auto mb = [](uint64_t b) { return double(b) / 1e6; };
  const double share = s.pixels ? 100.0 * double(s.slots) / double(s.pixels) : 0.0;
  char line[400];
  std::snprintf(line, sizeof line,
                "dense streams: %llu gated frames of %llu marked pixels (%llu packs), passes "
                "drawn over %.1f%% of the target; passes (MB) scan %llu (%.1f), compaction %llu "
                "(%.1f), gather %llu (%.1f)\n",
                static_cast<unsigned long long>(s.frames),
                static_cast<unsigned long long>(s.live_rays),
                static_cast<unsigned long long>(s.packs), share,
                static_cast<unsigned long long>(s.scan_passes), mb(s.scan_bytes),
                static_cast<unsigned long long>(s.compaction_passes), mb(s.compaction_bytes),
                static_cast<unsigned long long>(s.gather_passes), mb(s.gather_bytes));
  return line;
}

bool MarkStreams::fits(const vgpu::Profile& profile, const RenderOptions& opt) {
  // Slot indices are float texel addresses, and the generator divides them by the marked
  // pixels' count: exact where the finest arithmetic has a bit to spare.
  const Format f = profile.computes(Format::fp32);
  if (profile.computes(opt.formats.arithmetic(Group::rays)) != f ||
      profile.computes(opt.formats.arithmetic(Group::colour)) != f)
    return false;
  const int bits = f == Format::fp16 ? 10 : f == Format::fp24 ? 16 : 22;
  return uint64_t(opt.width) * uint64_t(opt.height) <= (uint64_t(1) << bits);
}

MarkStreams::MarkStreams(vgpu::Device& gpu, const RenderOptions& opt)
    : gpu_(gpu), W_(opt.width), H_(opt.height) {
  // The sums and the pixel centres are integers and halves: fp32 holds them exactly.
  scan_[0] = gpu.make_texture("marks scan A", W_, H_, 1, Format::fp32);
  scan_[1] = gpu.make_texture("marks scan B", W_, H_, 1, Format::fp32);
  pixels_ = gpu.make_texture("dense pixels", W_, H_, 4, Format::fp32);
  // The addresses need the finest arithmetic; the rays are generadorRayosMuestra's, in the rays
  // group's arithmetic to the same rounding.
  scanner_.set_precision(Format::fp32);
  compactor_.set_precision(Format::fp32);
  gatherer_.set_precision(Format::fp32);
  generate.set_precision(opt.formats.arithmetic(Group::rays));
  accumulator_.set_precision(opt.formats.arithmetic(Group::colour));
}

vgpu::Rect MarkStreams::rect() const {
  const uint64_t rows = std::max<uint64_t>(1, (count_ + uint64_t(W_) - 1) / uint64_t(W_));
  return {0, 0, W_, int(rows)};
}

void MarkStreams::set_samples(const std::vector<glm::vec2>& offsets) {
  // The table only grows (entries past this frame's are never read: generadorRayosDensos
  // reads entries first .. first + samples - 1): a frame's levels ask for different counts, and
  // a new texture at each would be a new texture on the device at each level. (A pass's
  // footprint counts a texture up to its size, so a level's grows by the unread entries, 16
  // bytes each: a few hundred bytes at most.)
  const int n = int(std::max<size_t>(offsets.size(), 1));
  if (jitters_.width() < n) jitters_ = gpu_.make_texture("sample jitters", n, 1, 4, Format::fp32);
  std::vector<float> texels(size_t(jitters_.width()) * 4, 0.0f);
  // generadorRayosMuestra adds (jitter - 0.5) to the pixel's centre: the same float here.
  for (size_t k = 0; k < offsets.size(); ++k) {
    texels[k * 4] = offsets[k].x - 0.5f;
    texels[k * 4 + 1] = offsets[k].y - 0.5f;
  }
  jitters_.replace(texels);
  gpu_.upload(jitters_);
}

int MarkStreams::samples_per_frame() const {
  return int(std::max<uint64_t>(1, uint64_t(W_) * uint64_t(H_) / std::max<uint64_t>(n_, 1)));
}

void MarkStreams::frame_begins(int k0, int k1) {
  count_ = n_ * uint64_t(k1 - k0);
  kernels::GenerateDenseRays& g = generate.kernel;
  g.stream_width = float(W_);
  g.marked = float(std::max<uint64_t>(n_, 1));
  g.count = float(count_);
  g.first = float(k0);
  g.table_width = float(jitters_.width());
  ++stats.frames;
  stats.live_rays += count_;
  stats.slots += rect().area();
  stats.pixels += uint64_t(W_) * uint64_t(H_) * uint64_t(k1 - k0);
}

void MarkStreams::accumulate(PassRunner& r, const Texture& sum, const Texture& marks,
                             const Texture& dense, int k, bool restart, Texture& out) {
  kernels::AccumulateDense& a = accumulator_.kernel;
  a.width = float(W_);
  a.base = float(uint64_t(k) * n_);
  a.restart = restart;
  add(r.pass(accumulator_, {&sum, &marks, &scan_.current(), &dense}, out), stats.gather_passes,
      stats.gather_bytes);
}

void MarkStreams::pack(PassRunner& r, const Texture& marks, uint64_t n) {
  n_ = n;
  stats.on = true;
  ++stats.packs;
  const uint64_t pixels = uint64_t(W_) * uint64_t(H_);
  // sumaPrefijos over the flags (marks x, 1 or 0): log2 of the pixels' count passes.
  kernels::ScanStream& s = scanner_.kernel;
  s.width = float(W_);
  s.channel = 0;
  const Texture* in = &marks;
  scan_.make_current(1);  // the first pass reads the marks and writes scan A
  for (int p = 0; p < std::max(1, ceil_log2(pixels)); ++p) {
    s.offset = float(uint64_t(1) << p);
    add(r.pass(scanner_, {in}, scan_.next()), stats.scan_passes, stats.scan_bytes);
    scan_.swap();
    in = &scan_.current();
  }
  // compactarMarcados over the rows the stream fills.
  kernels::CompactMarks& c = compactor_.kernel;
  c.width = float(W_);
  c.count = float(n);
  c.sources = float(pixels);
  c.steps = ceil_log2(pixels);
  count_ = n;
  r.rect = rect();
  add(r.pass(compactor_, {&scan_.current()}, pixels_), stats.compaction_passes,
      stats.compaction_bytes);
  r.rect.reset();
}

void MarkStreams::gather(PassRunner& r, const Texture& marks, const Texture& dense, Texture& out,
                         glm::vec4 fallback) {
  gatherer_.kernel.width = float(W_);
  gatherer_.kernel.fallback = fallback;
  add(r.pass(gatherer_, {&marks, &scan_.current(), &dense}, out), stats.gather_passes,
      stats.gather_bytes);
}

uint64_t MarkStreams::texture_bytes() const {
  return scan_[0].bytes() + scan_[1].bytes() + pixels_.bytes() + jitters_.bytes();
}

}  // namespace host
