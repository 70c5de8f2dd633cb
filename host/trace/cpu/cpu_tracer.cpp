// The CPU reference tracer (see cpu_tracer.h): Whitted's recursion per pixel, in double
// precision, over the same uniform grid as the stream tracer.
#include "host/trace/cpu/cpu_tracer.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>
#include <thread>
#include <vector>

#include "host/common/parallel.h"
#include "host/trace/cpu/cpu_beams.h"
#include "host/trace/cpu/cpu_core.h"
#include "host/trace/cpu/optics.h"
#include "host/trace/sampling.h"
#include "host/trace/textures.h"
#include "kernels/kernels.h"

namespace host {

namespace {

using namespace cpu_core;

// --aa-criterion budget's score of pixel i (kernels/cone_budget.h, puntuarConos), in double: the
// largest colour step to a 4-neighbour with another surface key or reflected key (to any
// neighbour where the hit distances fold), or the colour's second difference.
double budget_score(const std::vector<glm::dvec3>& estimate, const std::vector<int>& key,
                    const std::vector<int>& reflected, bool folds, size_t i,
                    const std::array<size_t, 4>& n) {
  auto largest = [](glm::dvec3 v) { return std::max({v.x, v.y, v.z}); };
  double score = 0;
  for (int a = 0; a < 2; ++a)  // left + right, up + down
    score = std::max(score, largest(glm::abs(estimate[n[size_t(2 * a)]] +
                                             estimate[n[size_t(2 * a + 1)]] - 2.0 * estimate[i])));
  for (const size_t j : n)
    if (folds || key[j] != key[i] || reflected[j] != reflected[i])
      score = std::max(score, largest(glm::abs(estimate[j] - estimate[i])));
  return score;
}

// --aa adaptive as the stream tracer runs it (host/trace/stream/stream_tracer.cpp,
// render_adaptive): the centre ray, then levels of n x n samples where marcarPixeles' rule marks
// the pixel (a neighbour's surface key differs, or the colour's second difference exceeds the
// threshold), each level's samples replacing the pixel's earlier ones. With --aa-criterion
// budget each level refines the highest scores above the threshold within its share of the
// pixels that hit (the threshold found exactly, by sorting: the search's answer), and its kept
// levels add their new samples to the earlier ones.
void adaptive(const Tracer& tracer, const RenderOptions& opt, unsigned workers,
              std::vector<Counters>& counters, RenderResult& res) {
  const int W = opt.width, H = opt.height;
  // --aa-criterion object (kernels/cones.h, marcarConos): also where the centre rays' hit
  // distances (the depth AOV, 0 for a miss) on both sides of a hit bend by more than cone_depth
  // widths of the pixel's cone at its hit. As the kernel, in float.
  const bool cones = opt.aa_criterion != RenderOptions::AaCriterion::image;
  const bool budget = opt.aa_criterion == RenderOptions::AaCriterion::budget;
  const bool mirrors = cones && !tracer.ray_streams();  // the reflected surface keys
  const float width_per_t = tracer.pixel_spread() * opt.cone_depth;
  auto cone_folds = [width_per_t](const std::vector<float>& t, const std::vector<int>& k,
                                  size_t own, size_t a, size_t b) {
    return k[own] >= 0 && std::fabs(t[a] + t[b] - 2.0f * t[own]) > t[own] * width_per_t;
  };
  const size_t n = size_t(W) * size_t(H);
  std::vector<glm::dvec3> estimate(n);
  std::vector<int> key(n), samples(n, 1), reflected(n, -1);
  std::vector<uint8_t> candidate(n, 1), marked(n, 0);
  for_each_row(H, workers, [&](unsigned worker, int y) {
    for (int x = 0; x < W; ++x) {
      const size_t i = size_t(y) * size_t(W) + size_t(x);
      estimate[i] =
          tracer.centre(x, y, res, key[i], counters[worker], mirrors ? &reflected[i] : nullptr);
    }
  });
  const auto kept =
      budget ? kept_level_samples(opt.spp, opt.sample_seed) : std::vector<std::vector<glm::vec2>>{};
  const uint64_t hits =
      uint64_t(std::count_if(key.begin(), key.end(), [](int k) { return k >= 0; }));
  std::vector<double> score(n, 0.0);
  const std::vector<int> levels = adaptive_levels(opt.spp);
  for (size_t l = 0; l < levels.size(); ++l) {
    // The 4-neighbours, clamped at the image's edge as the texture units clamp.
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const size_t i = size_t(y) * size_t(W) + size_t(x);
        auto at = [&](int dx, int dy) {
          return size_t(std::clamp(y + dy, 0, H - 1)) * size_t(W) +
                 size_t(std::clamp(x + dx, 0, W - 1));
        };
        const std::array<size_t, 4> nb{at(-1, 0), at(1, 0), at(0, -1), at(0, 1)};
        const bool folds = cones && (cone_folds(res.depth, key, i, nb[0], nb[1]) ||
                                     cone_folds(res.depth, key, i, nb[2], nb[3]));
        if (budget) {
          const double sc = budget_score(estimate, key, reflected, folds, i, nb);
          score[i] = candidate[i] && sc > double(opt.threshold()) ? sc : 0.0;
          continue;
        }
        bool edge = folds;
        for (const size_t j : nb) edge = edge || key[j] != key[i] || reflected[j] != reflected[i];
        // The colour's second difference along x and along y.
        for (int a = 0; a < 2; ++a) {
          const glm::dvec3 bend = glm::abs(estimate[nb[size_t(2 * a)]] +
                                           estimate[nb[size_t(2 * a + 1)]] - 2.0 * estimate[i]);
          edge = edge || std::max({bend.x, bend.y, bend.z}) > double(opt.threshold());
        }
        marked[i] = candidate[i] && edge;
      }
    if (budget) {
      // The least threshold with at most the budget's hits scoring above it: the first hit's
      // score left out when the scored hits are ranked, highest first.
      const uint64_t allowed = budget_pixels(opt.aa_budget, l, hits);
      std::vector<double> ranked;
      for (size_t i = 0; i < n; ++i)
        if (key[i] >= 0 && score[i] > 0) ranked.push_back(score[i]);
      double t = 0;
      if (ranked.size() > allowed) {
        std::nth_element(ranked.begin(), ranked.begin() + std::ptrdiff_t(allowed), ranked.end(),
                         std::greater<>());
        t = ranked[allowed];
      }
      for (size_t i = 0; i < n; ++i) marked[i] = score[i] > t;
      res.budget_levels.push_back({float(std::max(t, double(opt.threshold()))), allowed, 0});
    }
    if (std::find(marked.begin(), marked.end(), 1) == marked.end()) break;
    const int m = levels[l] * levels[l];
    const bool keeps = l > 0 && l < kept.size();
    const std::vector<glm::vec2> offsets =
        adaptive_level_offsets(opt.spp, l, kept, opt.sample_seed);
    for_each_row(H, workers, [&](unsigned worker, int y) {
      for (int x = 0; x < W; ++x) {
        const size_t i = size_t(y) * size_t(W) + size_t(x);
        if (!marked[i]) continue;
        glm::dvec3 sum = keeps ? estimate[i] * double(samples[i]) : glm::dvec3(0.0);
        for (const glm::vec2 o : offsets) sum += tracer.sample(x, y, o, nullptr, counters[worker]);
        estimate[i] = sum / double(m);
        samples[i] = m;
      }
    });
    candidate = marked;
  }
  res.rays_per_pixel.resize(n);
  int most = 1;
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) res.rgb[i * 3 + size_t(c)] = float(estimate[i][c]);
    res.rays_per_pixel[i] = adaptive_rays(opt.spp, samples[i], kept.size());
    most = std::max(most, samples[i]);
  }
  res.samples = most;
}

// --aa undersample:K as the stream tracer runs it (render_undersampled): the lattice pixels,
// then the pixels whose blended lattice pixels' surface keys or colours disagree, the rest
// blended bilinearly from their cell's corners; AOVs of pixels never traced from the nearest
// corner.
void undersample(const Tracer& tracer, const RenderOptions& opt, unsigned workers,
                 std::vector<Counters>& counters, RenderResult& res) {
  const int W = opt.width, H = opt.height, K = opt.undersample;
  const size_t n = size_t(W) * size_t(H);
  std::vector<glm::dvec3> colour(n);
  std::vector<int> key(n, -1);
  std::vector<uint8_t> traced(n, 0);
  auto trace = [&](unsigned worker, int x, int y) {
    const size_t i = size_t(y) * size_t(W) + size_t(x);
    colour[i] = tracer.centre(x, y, res, key[i], counters[worker]);
    traced[i] = 1;
  };
  for_each_row(H, workers, [&](unsigned worker, int y) {
    for (int x = 0; x < W; ++x)
      if (on_lattice(x, y, K, W, H)) trace(worker, x, y);
  });
  for_each_row(H, workers, [&](unsigned worker, int y) {
    for (int x = 0; x < W; ++x) {
      if (on_lattice(x, y, K, W, H)) continue;
      const GapTest t = undersample_gap_test(colour, key, x, y, K, W, H);
      if (t.keys_differ || t.spread > double(opt.threshold())) trace(worker, x, y);
    }
  });
  res.rays_per_pixel.assign(n, 0);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const size_t i = size_t(y) * size_t(W) + size_t(x);
      glm::dvec3 c = colour[i];
      if (traced[i]) {
        res.rays_per_pixel[i] = 1;
      } else {
        c = undersample_fill(colour, x, y, K, W, H, double(opt.threshold()));
        const glm::ivec4 q = lattice_cell(x, y, K, W, H);
        const int nx = x - q.x <= q.y - x ? q.x : q.y, ny = y - q.z <= q.w - y ? q.z : q.w;
        const size_t j = size_t(ny) * size_t(W) + size_t(nx);
        res.depth[i] = res.depth[j];
        res.hit_id[i] = res.hit_id[j];
      }
      for (int ch = 0; ch < 3; ++ch) res.rgb[i * 3 + size_t(ch)] = float(c[ch]);
    }
  res.samples = 1;
}

}  // namespace

glm::dvec3 cpu_primary_dir(const Camera& camera, int W, int H, int x, int y) {
  return PrimaryRays(camera, W, H).dir(x, y);
}

RenderResult render_cpu(const Scene& scene, const Grid& grid, const Camera& camera,
                        const RenderOptions& options, CpuStats* stats) {
  return render_cpu(scene, GridAccel(grid), camera, options, stats);
}

RenderResult render_cpu(const Scene& scene, const Accel& accel, const Camera& camera,
                        const RenderOptions& options, CpuStats* stats) {
  const Grid* grid = accel.grid();
  const auto t0 = std::chrono::steady_clock::now();
  if (grid && grid->start.size() != grid->voxels() + 1)
    throw std::invalid_argument("render_cpu: the grid has no voxel lists (not built)");
  RenderResult res;
  const int W = std::max(options.width, 0), H = std::max(options.height, 0);
  res.width = W;
  res.height = H;
  const size_t pixels = size_t(W) * size_t(H);
  res.rgb.assign(pixels * 3, 0.0f);
  res.depth.assign(pixels, 0.0f);
  res.hit_id.assign(pixels, -1.0f);

  const Tracer tracer(scene, accel, camera, options);
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const unsigned workers = std::clamp<unsigned>(
      options.threads > 0 ? unsigned(options.threads) : cores, 1u, unsigned(std::max(H, 1)));
  std::vector<Counters> counters(workers);
  // Every pixel is independent, so the order in which rows are handed out does not matter.
  if (options.undersample > 0)
    undersample(tracer, options, workers, counters, res);
  else if (options.adaptive && options.spp > 1)
    adaptive(tracer, options, workers, counters, res);
  else
    for_each_row(H, workers, [&](unsigned worker, int y) {
      for (int x = 0; x < W; ++x) tracer.pixel(x, y, res, counters[worker]);
    });

  CpuStats total;
  for (const Counters& c : counters) {
    total.rays += c.rays;
    total.voxel_steps += c.voxel_steps;
    total.triangle_tests += c.triangle_tests;
    total.nodes_visited += c.nodes_visited;
    total.restarts += c.restarts;
    total.glass_shadow_crossings += c.glass_shadow_crossings;
    add_into(total.reflected, c.reflected);
    add_into(total.refracted, c.refracted);
    add_into(total.total_internal, c.total_internal);
    res.rays_traced += c.entered;
    res.iterations = std::max(res.iterations, c.iterations);
  }
  for (auto* kind : {&total.reflected, &total.refracted, &total.total_internal})
    kind->resize(size_t(std::max(res.iterations, 1)), 0);  // one entry per iteration run
  if (const std::optional<CpuBeamCounts> counts = tracer.beam_counts()) {
    const CpuBeamCounts& b = *counts;
    res.beam_tiles = total.beam_tiles = b.tiles;
    res.beam_tiles_missed = total.beam_tiles_missed = b.tiles_missed;
    res.beam_passes = total.beam_passes = b.passes;
    total.beam_steps = b.steps;
    res.beam_depth_sum = b.depth_sum;
    res.beam_depth_max = b.depth_max;
    res.beam_depths = b.depths;
  }
  if (stats) *stats = total;
  if (res.rays_per_pixel.empty()) res.samples = std::max(options.spp, 1);
  res.render_ms = ms_since(t0);
  return res;
}

}  // namespace host
