// The sampling modes around the frame (StreamTracer::frame): --spp N sample frames, --aa
// adaptive and --aa undersample:K. Each runs whole frames, adds each frame's colours into a sum
// (accumulate_samples, acumularMuestras) and ends in the frame's last stage, the sampling
// resolve (resolve_samples: resolverMuestras, or rellenarHuecos), which leaves the pixels'
// colours in the current result texture.
#include <algorithm>
#include <cmath>
#include <vector>

#include "host/trace/sampling.h"
#include "host/trace/stream/mark_streams.h"
#include "host/trace/stream/stream_state.h"

namespace host {

using namespace kernels;
using vgpu::Texture;

void StreamTracer::accumulate_samples(const Texture* marks) {
  State& s = *s_;
  // acumularMuestras: the sum so far and the frame's colour (and, gated, the marks saying
  // which pixels the frame traced) into the other sum texture.
  if (marks)
    s.runner->pass(s.accumulate, {&s.sum.current(), &s.result.current(), marks}, s.sum.next());
  else
    s.runner->pass(s.accumulate, {&s.sum.current(), &s.result.current()}, s.sum.next());
  s.sum.swap();
}

void StreamTracer::accumulate_gated(const Texture* marks, bool restart) {
  State& s = *s_;
  if (!s.dense) {
    accumulate_samples(marks);
    return;
  }
  // The frame traced its marked pixels as a dense stream: acumularDensos gathers its colours.
  s.dense->accumulate(*s.runner, s.sum.current(), *marks, s.result.current(), 0, restart,
                      s.sum.next());
  s.sum.swap();
}

void StreamTracer::dense_level(const Camera& cam, RenderResult& res, int& iteration_number,
                               uint64_t marked, const std::vector<glm::vec2>& offsets,
                               bool restart) {
  State& s = *s_;
  MarkStreams& d = *s.dense;
  // The level's samples of every marked pixel, as few frames as the stream's W x H slots
  // allow: each frame traces a run of whole samples (sample-major), then adds each sample's
  // colours into the marked pixels' sums in the gated frames' order (acumularDensos).
  d.pack(*s.runner, s.marks.current(), marked);
  d.set_samples(offsets);
  const int n = int(offsets.size());
  const int per = d.samples_per_frame();
  for (int k0 = 0; k0 < n; k0 += per) {
    const int k1 = std::min(n, k0 + per);
    d.frame_begins(k0, k1);
    frame(cam, s.sample_generate, res, false, iteration_number, &s.marks.current());
    for (int k = k0; k < k1; ++k) {
      d.accumulate(*s.runner, s.sum.current(), s.marks.current(), s.result.current(), k - k0,
                   restart && k == 0, s.sum.next());
      s.sum.swap();
    }
  }
}

void StreamTracer::budget_marks(size_t level, uint64_t& hits, RenderResult& res) {
  State& s = *s_;
  PassRunner& r = *s.runner;
  r.pass(s.score_cones, {&s.marks.current(), &s.result.current()}, s.marks.next());
  s.marks.swap();
  auto above = [&](float t) {
    s.scored_hits.kernel.above = t;
    return r.count(s.scored_hits, s.marks.current(), nullptr, nullptr);
  };
  // Every pixel that hits (the scores are 0 or above the floor, so all exceed -1).
  uint64_t steps = 0;
  if (level == 0) hits = above(-1.0f), steps = 1;
  const uint64_t budget = budget_pixels(opt_.aa_budget, level, hits);
  const BudgetSearch found = budget_threshold(opt_.threshold(), budget, above);
  const float t = found.threshold;
  steps += found.counts;
  s.cut_scores.kernel.above = t;
  r.pass(s.cut_scores, {&s.marks.current()}, s.marks.next());
  s.marks.swap();
  res.budget_levels.push_back({t, budget, steps});
}

void StreamTracer::resolve_samples(const vgpu::Program& resolve) {
  State& s = *s_;
  s.runner->pass(resolve, {&s.sum.current()}, s.result.next());
  s.result.swap();
}

void StreamTracer::render_samples(const Camera& cam, RenderResult& res, int& iteration_number) {
  vgpu::Device& gpu = *gpu_;
  State& s = *s_;
  // Supersampling as a 2004 card would: one whole frame per sample, each through its own
  // sub-pixel offset (generadorRayosMuestra), added into a sum texture (acumularMuestras),
  // then one box-filter pass (resolverMuestras). No texture grows with the sample count.
  gpu.clear(s.sum.current(), {0, 0, 0, 0});
  for (int k = 0; k < opt_.spp; ++k) {
    const glm::vec2 j = sample_offset(opt_.spp, k, opt_.sample_seed);
    s.sample_generate.kernel.jitter_x = j.x;
    s.sample_generate.kernel.jitter_y = j.y;
    frame(cam, s.sample_generate, res, k == 0, iteration_number);
    if (k == 0) res.first_frame_passes = gpu.stats().totals.passes;
    accumulate_samples(nullptr);
  }
  resolve_samples(s.resolve);
  res.samples = opt_.spp;
}

void StreamTracer::render_adaptive(const Camera& cam, RenderResult& res, int& iteration_number) {
  vgpu::Device& gpu = *gpu_;
  State& s = *s_;
  PassRunner& r = *s.runner;
  // The centre frame, the paper's, keeping each pixel's surface key; its colour is every
  // pixel's first estimate (one sample).
  frame(cam, s.generate, res, true, iteration_number, nullptr, true);
  res.first_frame_passes = gpu.stats().totals.passes;
  gpu.clear(s.sum.current(), {0, 0, 0, 0});
  s.accumulate.kernel.gated = false;
  accumulate_samples(nullptr);
  const std::vector<int> levels = adaptive_levels(opt_.spp);
  // The budget's levels keep the samples before them where they fall one to a stratum.
  const auto kept = budget() ? kept_level_samples(opt_.spp, opt_.sample_seed)
                             : std::vector<std::vector<glm::vec2>>{};
  uint64_t hits = 0;
  for (size_t l = 0; l < levels.size(); ++l) {
    // marcarPixeles on the current estimate, then pixelesMarcados: how many get more samples.
    // (marcarConos instead with --aa-criterion object: kernels/cones.h; the budget's scores,
    // search and cut with --aa-criterion budget: kernels/cone_budget.h.)
    if (budget()) {
      budget_marks(l, hits, res);
    } else {
      r.pass(cones() ? static_cast<const vgpu::Program&>(s.mark_cones) : s.mark,
             {&s.marks.current(), &s.result.current()}, s.marks.next());
      s.marks.swap();
    }
    const uint64_t marked = r.count(s.marked, s.marks.current(), nullptr, nullptr);
    if (marked == 0) break;
    // The level's n x n samples, only in marked pixels, replacing their earlier ones; a kept
    // level's new samples, added to them.
    const bool keeps = l > 0 && l < kept.size();
    const std::vector<glm::vec2> offsets =
        adaptive_level_offsets(opt_.spp, l, kept, opt_.sample_seed);
    if (s.dense) {
      dense_level(cam, res, iteration_number, marked, offsets, !keeps);
      resolve_samples(s.resolve);
      continue;
    }
    s.sample_generate.kernel.gated = true;
    s.accumulate.kernel.gated = true;
    for (size_t k = 0; k < offsets.size(); ++k) {
      s.sample_generate.kernel.jitter_x = offsets[k].x;
      s.sample_generate.kernel.jitter_y = offsets[k].y;
      frame(cam, s.sample_generate, res, false, iteration_number, &s.marks.current());
      s.accumulate.kernel.restart = k == 0 && !keeps;
      accumulate_samples(&s.marks.current());
    }
    // The new estimate: the next level's marks read it, and after the last level it is the
    // image. (Where no pixel is marked at all, the centre frame's colour stays the image.)
    resolve_samples(s.resolve);
  }
  s.sample_generate.kernel.gated = false;
  s.accumulate.kernel.gated = false;
  // Each pixel's final sample count, for the rays-per-pixel statistics and map.
  Texture& sum = s.sum.current();
  gpu.download(sum);
  const int W = opt_.width, H = opt_.height;
  res.rays_per_pixel.resize(size_t(W) * size_t(H));
  int most = 1;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const int samples = int(sum.texel(x, y)[3]);
      most = std::max(most, samples);
      res.rays_per_pixel[size_t(y) * size_t(W) + size_t(x)] =
          adaptive_rays(opt_.spp, samples, kept.size());
    }
  res.samples = most;
}

void StreamTracer::render_undersampled(const Camera& cam, RenderResult& res,
                                       int& iteration_number) {
  vgpu::Device& gpu = *gpu_;
  State& s = *s_;
  PassRunner& r = *s.runner;
  const int W = opt_.width, H = opt_.height, K = opt_.undersample;
  // marcarReticula into marks A; the lattice frame through the lattice pixels' centres, keeping
  // their surface keys in marks B; their colours into the sum.
  r.pass(s.mark_lattice, {}, s.marks[0]);
  s.marks.make_current(1);  // guardarImpactos writes the lattice frame's keys into marks B
  s.sample_generate.kernel.jitter_x = s.sample_generate.kernel.jitter_y = 0.5f;
  s.sample_generate.kernel.gated = true;
  // The lattice along each axis: the host's loops over every pixel below read it per row and
  // column (on_lattice and lattice_cell per pixel cost about a millisecond at 256x256).
  const LatticeAxis ax = lattice_axis(W, K), ay = lattice_axis(H, K);
  if (s.dense) {
    // The lattice's pixels, counted here (the host knows where they are), as a dense stream.
    s.dense->pack(r, s.marks[0], ax.count * ay.count);
    s.dense->set_samples({glm::vec2(0.5f)});
    s.dense->frame_begins(0, 1);
  }
  frame(cam, s.sample_generate, res, true, iteration_number, &s.marks[0], true);
  res.first_frame_passes = gpu.stats().totals.passes;
  gpu.clear(s.sum.current(), {0, 0, 0, 0});
  s.accumulate.kernel.gated = true;
  s.accumulate.kernel.restart = false;
  accumulate_gated(&s.marks[0], false);
  // marcarHuecos into marks A (the lattice flags are done with), pixelesMarcados counts them;
  // the gaps' frame traces them.
  r.pass(s.mark_gaps, {&s.marks[1], &s.sum.current()}, s.marks[0]);
  std::vector<uint8_t> gap(size_t(W) * size_t(H), 0);
  if (const uint64_t gaps = r.count(s.marked, s.marks[0], nullptr, nullptr); gaps > 0) {
    if (s.dense) {
      s.dense->pack(r, s.marks[0], gaps);
      s.dense->frame_begins(0, 1);
    }
    const std::vector<float> depth = res.depth, hit_id = res.hit_id;
    frame(cam, s.sample_generate, res, true, iteration_number, &s.marks[0]);
    accumulate_gated(&s.marks[0], false);
    // The AOVs: the gaps' from this frame, the lattice's from the first.
    gpu.download(s.marks[0]);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const size_t i = size_t(y) * size_t(W) + size_t(x);
        gap[i] = s.marks[0].texel(x, y)[0] > 0.0f;
        if (!gap[i]) res.depth[i] = depth[i], res.hit_id[i] = hit_id[i];
      }
  }
  s.sample_generate.kernel.gated = false;
  s.accumulate.kernel.gated = false;
  // The resolve, rellenarHuecos: the traced pixels' colours, the rest blended from their
  // lattice cell.
  resolve_samples(s.fill);
  // The AOVs of a pixel never traced: its lattice cell's nearest corner's.
  res.rays_per_pixel.assign(gap.size(), 0);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const size_t i = size_t(y) * size_t(W) + size_t(x);
      if ((ax.on[size_t(x)] && ay.on[size_t(y)]) || gap[i]) {
        res.rays_per_pixel[i] = 1;
        continue;
      }
      const size_t j = size_t(ay.nearest[size_t(y)]) * size_t(W) + size_t(ax.nearest[size_t(x)]);
      res.depth[i] = res.depth[j];
      res.hit_id[i] = res.hit_id[j];
    }
  res.samples = 1;
}

}  // namespace host
