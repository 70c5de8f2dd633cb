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

nlohmann::ordered_json to_json(const CompactStats& s) {
  auto job = [](uint64_t passes, uint64_t bytes) {
    return nlohmann::ordered_json{{"passes", passes}, {"bytes", bytes}};
  };
  return {{"packs", s.packs},
          {"frames", s.frames},
          {"live_rays", s.live_rays},
          {"slots", s.slots},
          {"pixels", s.pixels},
          {"scan", job(s.scan_passes, s.scan_bytes)},
          {"compaction", job(s.compaction_passes, s.compaction_bytes)},
          {"gather", job(s.gather_passes, s.gather_bytes)}};
}

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

bool MarkStreams::fits(const vgpu::Profile& profile, int width, int height) {
  // Pixel indices are float texel addresses, computed in the finest arithmetic the card has.
  const Format f = profile.computes(Format::fp32);
  const int bits = f == Format::fp16 ? 11 : f == Format::fp24 ? 17 : 24;
  return uint64_t(width) * uint64_t(height) <= (uint64_t(1) << bits);
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
}

vgpu::Rect MarkStreams::rect() const {
  const uint64_t rows = std::max<uint64_t>(1, (n_ + uint64_t(W_) - 1) / uint64_t(W_));
  return {0, 0, W_, int(rows)};
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

void MarkStreams::frame_begins() {
  ++stats.frames;
  stats.live_rays += n_;
  stats.slots += rect().area();
  stats.pixels += uint64_t(W_) * uint64_t(H_);
}

uint64_t MarkStreams::texture_bytes() const {
  return scan_[0].bytes() + scan_[1].bytes() + pixels_.bytes();
}

}  // namespace host
