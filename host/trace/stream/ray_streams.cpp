// Glass's ray streams (host/trace/stream/ray_streams.h): the levels' textures, the compaction
// (scan, counts, gather), the chunk copies and the colour's way back, each pass counted by job.
#include "host/trace/stream/ray_streams.h"

#include <algorithm>
#include <bit>
#include <cstdio>

namespace host {

using vgpu::Rect;
using vgpu::Texture;

bool scene_has_glass(const Scene& scene) {
  for (uint32_t m : scene.material)
    if (m < scene.materials.size() && scene.materials[m].transmission > 0.0f) return true;
  return false;
}

float unshaded_share(const Material& m) {
  if (m.transmission <= 0.0f) return m.reflect;
  return float(1.0 - (1.0 - double(m.transmission)) * (1.0 - double(m.reflect)));
}

std::string describe(const StreamStats& s) {
  std::string out = "ray streams: level rays (chunks) -> reflected + refracted (TIR):";
  char line[200];
  for (size_t k = 0; k < s.levels.size(); ++k) {
    const StreamLevel& l = s.levels[k];
    std::snprintf(
        line, sizeof line, "%s %zu: %llu (%llu) -> %llu + %llu (%llu)", k ? ";" : "", k,
        static_cast<unsigned long long>(l.rays), static_cast<unsigned long long>(l.chunks),
        static_cast<unsigned long long>(l.reflected), static_cast<unsigned long long>(l.refracted),
        static_cast<unsigned long long>(l.total_internal));
    out += line;
  }
  auto mb = [](uint64_t b) { return double(b) / 1e6; };
  std::snprintf(line, sizeof line,
                "\nray streams: passes (MB) split %llu (%.1f), compaction %llu (%.1f), copies %llu "
                "(%.1f), gather %llu (%.1f), shadows through glass %llu (%.1f), %llu shadow rays "
                "continued\n",
                static_cast<unsigned long long>(s.split_passes), mb(s.split_bytes),
                static_cast<unsigned long long>(s.compaction_passes), mb(s.compaction_bytes),
                static_cast<unsigned long long>(s.copy_passes), mb(s.copy_bytes),
                static_cast<unsigned long long>(s.gather_passes), mb(s.gather_bytes),
                static_cast<unsigned long long>(s.shadow_passes), mb(s.shadow_bytes),
                static_cast<unsigned long long>(s.shadow_continued));
  return out + line;
}

namespace {

// ceil(log2(n)) for n >= 1: the passes of the scan and the binary search's steps.
int ceil_log2(uint64_t n) {
  return n <= 1 ? 0 : int(std::bit_width(n - 1));
}

}  // namespace

RayStreams::RayStreams(vgpu::Device& gpu, const RenderOptions& opt, bool glass)
    : gpu_(gpu), opt_(opt), W_(opt.width), H_(opt.height), glass_scene_(glass) {
  counter_ = gpu.make_texture("stream counter", W_, H_, 1, vgpu::Format::fp16);
  const Formats& fm = opt.formats;
  split.set_precision(fm.arithmetic(Group::colour));
  gatherer.set_precision(fm.arithmetic(Group::colour));
  compactor.set_precision(fm.arithmetic(Group::rays));
  shadow_glass.set_precision(fm.arithmetic(Group::rays));
}

void RayStreams::set_scene(const kernels::SceneUniforms& scene, float offset) {
  split.kernel.scene = scene;
  compactor.kernel.scene = scene;
  compactor.kernel.offset = offset;
  shadow_glass.kernel.scene = scene;
  shadow_glass.kernel.offset = offset;
}

RayStreams::Level& RayStreams::level(int k, uint64_t n) {
  const uint64_t wh = uint64_t(W_) * uint64_t(H_);
  // Element indices are float texel addresses, computed in the passes' arithmetic: exact below
  // 2^24 in fp32, 2^17 in fp24, 2^11 in fp16 (as NV3x's half could not address a long stream).
  const vgpu::Format f = gpu_.profile().computes(opt_.formats.finest());
  const int bits = f == vgpu::Format::fp16 ? 11 : f == vgpu::Format::fp24 ? 17 : 24;
  if (std::max(n, wh) > (uint64_t(1) << bits))
    throw vgpu::Error("ray streams: level " + std::to_string(k) + " has " +
                      std::to_string(std::max(n, wh)) + " elements; " +
                      std::string(vgpu::format_name(f)) +
                      " arithmetic holds their indices exactly only up to " +
                      std::to_string(uint64_t(1) << bits));
  while (levels_.size() <= size_t(k)) levels_.emplace_back();
  Level& L = levels_[size_t(k)];
  L.n = n;
  L.chunks = int((n + wh - 1) / wh);
  const int rows = L.chunks * H_;
  const Formats& fm = opt_.formats;
  const std::string lv = "level " + std::to_string(k) + " ";
  auto ensure = [&](Texture& t, const std::string& name, int channels, vgpu::Format f) {
    if (t.width() != W_ || t.height() != rows || t.channels() != channels || t.format() != f)
      t = gpu_.make_texture(lv + name, W_, rows, channels, f);
  };
  if (k > 0) {
    ensure(L.origins, "origins", 4, fm[Group::rays]);
    ensure(L.rays, "rays", 4, fm[Group::rays]);
    ensure(L.weight, "weights", 4, fm[Group::colour]);
    ensure(L.colour, "colour", 4, fm[Group::colour]);
    ensure(L.gathered, "gathered", 4, fm[Group::colour]);
  }
  ensure(L.surface, "surface", 4, fm[Group::rays]);
  ensure(L.split, "split", 4, fm[Group::colour]);
  // Counts and their sums are integers: fp32 holds them exactly.
  ensure(L.scan[0], "scan A", 1, vgpu::Format::fp32);
  ensure(L.scan[1], "scan B", 1, vgpu::Format::fp32);
  if (L.chunks > 1 && work_[0].width() != W_) {
    const char* names[7] = {"origins", "rays",     "weights", "surface",
                            "split",   "colour A", "colour B"};
    const Group groups[7] = {Group::rays,   Group::rays,   Group::colour, Group::rays,
                             Group::colour, Group::colour, Group::colour};
    for (int i = 0; i < 7; ++i)
      work_[i] = gpu_.make_texture(std::string("chunk ") + names[i], W_, H_, 4, fm[groups[i]]);
  }
  if (stats.levels.size() <= size_t(k)) stats.levels.resize(size_t(k) + 1);
  return L;
}

uint64_t RayStreams::texture_bytes() const {
  uint64_t b = glass_.bytes() + counter_.bytes();
  for (const Level& L : levels_)
    for (const Texture* t : {&L.origins, &L.rays, &L.weight, &L.surface, &L.split, &L.colour,
                             &L.gathered, &L.scan[0], &L.scan[1]})
      b += t->bytes();
  for (const Texture& t : work_) b += t.bytes();
  for (int i = 0; i < 2; ++i) b += shadow_origins_[i].bytes() + shadow_rays_[i].bytes();
  return b;
}

const vgpu::PassRecord& RayStreams::pass(PassRunner& r, const vgpu::Program& p,
                                         std::initializer_list<const Texture*> in, Texture& out,
                                         const Rect* rect, uint64_t& passes, uint64_t& bytes) {
  gpu_.use_program(p);
  gpu_.unbind_textures();
  int unit = 0;
  for (const Texture* t : in) gpu_.bind_texture(unit++, *t);
  gpu_.set_targets({&out});
  r.set_work(nullptr);
  if (opt_.observer) opt_.observer->pass_begin(nullptr);
  const vgpu::PassRecord& rec = rect ? gpu_.draw(*rect) : gpu_.draw();
  if (opt_.observer)
    opt_.observer->pass({p, rec, out, gpu_.branch_flags(), gpu_.stats(), gpu_.loop_iterations()});
  ++passes;
  bytes += rec.counters.bytes_read + rec.counters.bytes_written;
  return rec;
}

uint64_t RayStreams::count(PassRunner& r, const Texture& in, uint64_t n, int channel,
                           float threshold, uint64_t& passes, uint64_t& bytes) {
  const uint64_t wh = uint64_t(W_) * uint64_t(H_);
  uint64_t total = 0;
  counter.kernel.channel = channel;
  counter.kernel.threshold = threshold;
  for (uint64_t c = 0; c * wh < n; ++c) {
    const uint64_t left = n - c * wh;
    const int rows =
        int(std::min<uint64_t>(uint64_t(H_), (left + uint64_t(W_) - 1) / uint64_t(W_)));
    counter.kernel.rows = float(c * uint64_t(H_));
    const Rect rect{0, 0, W_, rows};
    if (gpu_.has_stencil()) gpu_.set_stencil_write(nullptr);
    gpu_.begin_query();
    pass(r, counter, {&in}, counter_, &rect, passes, bytes);
    const uint64_t m = gpu_.end_query();
    if (opt_.observer) opt_.observer->query(m, nullptr, gpu_.stats());
    total += m;
  }
  return total;
}

void RayStreams::copy_chunk(PassRunner& r, const Texture& from, Texture& to, int c, bool to_tall) {
  copier.kernel.rows = float(to_tall ? -c * H_ : c * H_);
  const Rect rect = to_tall ? Rect{0, c * H_, W_, c * H_ + H_} : Rect{0, 0, W_, H_};
  pass(r, copier, {&from}, to, &rect, stats.copy_passes, stats.copy_bytes);
}

uint64_t RayStreams::compact(PassRunner& r, int k, const Texture& rays,
                             const Texture* const (&statics)[6]) {
  const uint64_t n = levels_[size_t(k)].n;
  const Rect rect{0, 0, W_, int((n + uint64_t(W_) - 1) / uint64_t(W_))};
  {
    // sumaPrefijos: the inclusive sums of the spawn counts (split z), log2(n) passes.
    Level& L = levels_[size_t(k)];
    const int passes = std::max(1, ceil_log2(n));
    const Texture* in = &L.split;
    scan.kernel.width = float(W_);
    scan.kernel.channel = 2;
    L.scan.make_current(1);  // the first pass reads the split and writes scan A
    for (int p = 0; p < passes; ++p) {
      scan.kernel.offset = float(uint64_t(1) << p);
      pass(r, scan, {in}, L.scan.next(), &rect, stats.compaction_passes, stats.compaction_bytes);
      L.scan.swap();
      in = &L.scan.current();
      scan.kernel.channel = 0;
    }
  }
  // contarRayos: the rays spawned by kind; their sum is the next level's length.
  const Texture& split_tex = levels_[size_t(k)].split;
  const float cut = split.kernel.min_weight;
  const uint64_t reflected =
      count(r, split_tex, n, 0, cut, stats.compaction_passes, stats.compaction_bytes);
  const uint64_t refracted =
      count(r, split_tex, n, 1, cut, stats.compaction_passes, stats.compaction_bytes);
  const uint64_t tir =
      count(r, split_tex, n, 3, 0.5f, stats.compaction_passes, stats.compaction_bytes);
  StreamLevel& st = stats.levels[size_t(k)];
  st.reflected += reflected;
  st.refracted += refracted;
  st.total_internal += tir;
  const uint64_t next = reflected + refracted;
  if (next == 0) return 0;
  // compactarRayos: the next level's origins, rays and weights, over the rows it fills; the
  // rest of its last chunk holds no ray.
  Level& N = level(k + 1, next);
  const Level& L = levels_[size_t(k)];
  gpu_.clear(N.rays, {0.0f, 0.0f, 0.0f, kernels::kNone});
  kernels::CompactStream& c = compactor.kernel;
  c.width = float(W_);
  c.count = float(next);
  c.sources = float(n);
  c.steps = ceil_log2(n);
  const Rect out{0, 0, W_, int((next + uint64_t(W_) - 1) / uint64_t(W_))};
  Texture* targets[3] = {&N.origins, &N.rays, &N.weight};
  for (int part = 0; part < 3; ++part) {
    c.part = part;
    pass(r, compactor,
         {&L.scan.current(), &L.split, &rays, &L.surface, &glass_, statics[0], statics[1],
          statics[2], statics[3], statics[4], statics[5]},
         *targets[part], &out, stats.compaction_passes, stats.compaction_bytes);
  }
  return next;
}

void RayStreams::gather_back(PassRunner& r, int deepest, Texture& pixels) {
  levels_[size_t(deepest)].total = levels_[size_t(deepest)].shaded;
  gatherer.kernel.width = float(W_);
  for (int k = deepest - 1; k >= 0; --k) {
    Level& L = levels_[size_t(k)];
    Texture& out = k == 0 ? pixels : L.gathered;
    const Rect rect{0, 0, W_, int((L.n + uint64_t(W_) - 1) / uint64_t(W_))};
    pass(r, gatherer, {L.shaded, &L.scan.current(), &L.split, levels_[size_t(k + 1)].total}, out,
         &rect, stats.gather_passes, stats.gather_bytes);
    L.total = &out;
  }
}

}  // namespace host
