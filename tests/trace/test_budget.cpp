// The budget criterion of adaptive sampling (--aa-criterion budget, kernels/cone_budget.h): the
// threshold search, the kept level's rays, and whole frames on the stream tracer against the CPU
// tracer, gated against dense streams, any thread count.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "host/accel/grid.h"
#include "host/image/image_io.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/cpu/cpu_tracer.h"
#include "host/trace/sampling.h"
#include "host/trace/stream/stream_tracer.h"

namespace {

// The threshold a ranking gives: the first score left out when the scores above the floor are
// taken highest first, `budget` of them; the floor when they all fit.
float ranked_threshold(std::vector<float> scores, float floor, uint64_t budget) {
  std::erase_if(scores, [floor](float s) { return !(s > floor); });
  if (scores.size() <= budget) return floor;
  std::sort(scores.begin(), scores.end(), std::greater<>());
  return scores[budget];
}

struct Frame {
  host::Scene scene;
  host::Grid grid;
  host::Camera camera;
  explicit Frame(const std::string& name)
      : scene(host::load_scene(host::resolve_scene(name), host::with_images())),
        grid(host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile("gf6600")))),
        camera(host::scene_camera(scene)) {}
};

host::RenderOptions budget_options(int size) {
  host::RenderOptions opt;
  opt.width = opt.height = size;
  opt.profile = "gf6600";
  opt.spp = 16;
  opt.adaptive = true;
  opt.aa_criterion = host::RenderOptions::AaCriterion::budget;
  opt.threads = 2;
  return opt;
}

// How many pixels that hit took at least `rays` rays.
uint64_t hits_with(const host::RenderResult& r, uint32_t rays) {
  uint64_t n = 0;
  for (size_t i = 0; i < r.rays_per_pixel.size(); ++i)
    n += r.rays_per_pixel[i] >= rays && r.hit_id[i] >= 0;
  return n;
}

}  // namespace

TEST_CASE("the budget's search ends on the exact threshold a ranking of the scores gives") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.5f);
  for (int round = 0; round < 40; ++round) {
    CAPTURE(round);
    // Scores with ties and zeros (pixels below the floor score 0), sometimes above 1.
    std::vector<float> scores(size_t(50 + round * 13));
    for (float& s : scores) s = u(rng) < 0.4f ? 0.0f : std::round(u(rng) * 64.0f) / 64.0f;
    if (round % 5 == 0) scores[0] = 9.5f;
    for (const float floor : {0.0f, 0.05f, 0.3f}) {
      for (const uint64_t budget : {uint64_t(0), uint64_t(1), uint64_t(scores.size() / 7),
                                    uint64_t(scores.size() / 2), uint64_t(scores.size())}) {
        CAPTURE(floor);
        CAPTURE(budget);
        uint64_t asked = 0;
        const host::BudgetSearch found =
            host::budget_threshold(floor, budget, [&](float t) -> uint64_t {
              ++asked;
              return uint64_t(
                  std::count_if(scores.begin(), scores.end(), [t](float s) { return s > t; }));
            });
        CHECK(found.threshold == ranked_threshold(scores, floor, budget));
        CHECK(found.counts == asked);
        CHECK(asked <= 40);  // about 26 halvings from the floor to 1, and the doublings above
      }
    }
  }
}

TEST_CASE("a kept level's pixels are charged only the samples it adds") {
  // spp 16: 1, then 1 + 4, then 1 + 4 + 12 (kept) or 1 + 4 + 16.
  CHECK(host::adaptive_rays(16, 1, 2) == 1);
  CHECK(host::adaptive_rays(16, 4, 2) == 5);
  CHECK(host::adaptive_rays(16, 16, 2) == 17);
  CHECK(host::adaptive_rays(16, 16, 0) == 21);
  CHECK(host::adaptive_rays(16, 16, 0) == host::adaptive_rays(16, 16));
  // spp 64: the 8 x 8 level adds 48 to the 16 kept; with only two kept levels it traces 64.
  CHECK(host::kept_level_samples(64, 1).size() == 3);
  CHECK(host::adaptive_rays(64, 64, 3) == 1 + 4 + 12 + 48);
  CHECK(host::adaptive_rays(64, 64, 2) == 1 + 4 + 12 + 64);
}

TEST_CASE(
    "a pixel's rays are those of its levels by the rule written out, for every sample count") {
  // The levels by the rule, written out here apart from host/trace/sampling.cpp: the sides
  // double from 2 while below the last (n, the spp's side), then n itself.
  auto levels_of = [](int spp) {
    int n = 1;
    while (n * n < spp) ++n;
    std::vector<int> levels;
    for (int side = 2; side < n; side *= 2) levels.push_back(side);
    if (n > 1) levels.push_back(n);
    return levels;
  };
  for (int side = 1; side <= 16; ++side) {
    const int spp = side * side;
    CAPTURE(spp);
    const std::vector<int> levels = levels_of(spp);
    CHECK(host::adaptive_levels(spp) == levels);
    for (size_t kept = 0; kept <= 5; ++kept)
      for (int samples = 0; samples <= spp + 1; ++samples) {
        CAPTURE(kept);
        CAPTURE(samples);
        uint32_t rays = 1;
        int before = 0;
        for (size_t l = 0; l < levels.size() && levels[l] * levels[l] <= samples; ++l) {
          const int m = levels[l] * levels[l];
          rays += uint32_t(l > 0 && l < kept ? m - before : m);
          before = m;
        }
        CHECK(host::adaptive_rays(spp, samples, kept) == rays);
        if (kept == 0) CHECK(host::adaptive_rays(spp, samples) == rays);
      }
  }
  // A few by hand: 1 (none), 9 (2, 3), 64 (2, 4, 8), 100 (2, 4, 8, 10).
  CHECK(host::adaptive_levels(1).empty());
  CHECK(host::adaptive_levels(9) == std::vector<int>{2, 3});
  CHECK(host::adaptive_levels(64) == std::vector<int>{2, 4, 8});
  CHECK(host::adaptive_levels(100) == std::vector<int>{2, 4, 8, 10});
}

TEST_CASE(
    "the budget criterion refines at most its share of the pixels that hit, and the stream "
    "tracer marks the CPU tracer's pixels") {
  const Frame f("bunny-refl");
  const host::RenderOptions opt = budget_options(24);
  host::StreamTracer tracer(f.scene, f.grid, opt);
  const host::RenderResult s = tracer.render(f.camera);
  const host::RenderResult c = host::render_cpu(f.scene, f.grid, f.camera, opt);
  REQUIRE(s.budget_levels.size() == 2);
  REQUIRE(c.budget_levels.size() == 2);
  const uint64_t hits = hits_with(s, 1);
  for (size_t l = 0; l < 2; ++l) {
    CAPTURE(l);
    const double share = opt.aa_budget[l];
    CHECK(s.budget_levels[l].budget == uint64_t(std::floor(share * double(hits))));
    CHECK(c.budget_levels[l].budget == s.budget_levels[l].budget);
    CHECK(s.budget_levels[l].threshold >= opt.threshold());
    // The CPU tracer ranks its double-precision scores; the card's search finds its floats'.
    CHECK(c.budget_levels[l].threshold ==
          doctest::Approx(s.budget_levels[l].threshold).epsilon(1e-3));
  }
  // Each level within its budget, and the budget spent (the scene has edges enough).
  CHECK(hits_with(s, 5) <= s.budget_levels[0].budget);
  CHECK(hits_with(s, 5) >= s.budget_levels[0].budget * 9 / 10);
  CHECK(hits_with(s, 17) <= s.budget_levels[1].budget);
  CHECK(hits_with(s, 17) > 0);
  // No pixel took the full 4 x 4 level's 21 rays: the kept level traces 12 new samples.
  CHECK(std::count(s.rays_per_pixel.begin(), s.rays_per_pixel.end(), 21u) == 0);
  // The same pixels refined, and the same colours where they were (the kept level's sums
  // continue the 2 x 2 level's on both).
  size_t same = 0, far = 0;
  for (size_t i = 0; i < s.rays_per_pixel.size(); ++i) {
    if (s.rays_per_pixel[i] != c.rays_per_pixel[i]) continue;
    ++same;
    for (int k = 0; k < 3; ++k) far += std::fabs(s.rgb[i * 3 + k] - c.rgb[i * 3 + k]) > 2e-3f;
  }
  CHECK(same >= s.rays_per_pixel.size() * 99 / 100);
  CHECK(far == 0);
}

TEST_CASE(
    "the budget criterion gives one image and one set of statistics gated or dense, at any "
    "thread count") {
  const Frame f("classic");
  host::RenderOptions opt = budget_options(24);
  opt.threads = 1;
  host::StreamTracer one(f.scene, f.grid, opt);
  const host::RenderResult a = one.render(f.camera);
  opt.threads = 3;
  host::StreamTracer three(f.scene, f.grid, opt);
  const host::RenderResult b = three.render(f.camera);
  CHECK(a.rgb == b.rgb);
  CHECK(a.rays_per_pixel == b.rays_per_pixel);
  CHECK(a.stats.totals.passes == b.stats.totals.passes);
  CHECK(a.stats.totals.fragments_launched == b.stats.totals.fragments_launched);
  opt.compact = false;
  host::StreamTracer gated(f.scene, f.grid, opt);
  const host::RenderResult g = gated.render(f.camera);
  CHECK(g.rgb == a.rgb);
  CHECK(g.rays_per_pixel == a.rays_per_pixel);
  REQUIRE(g.budget_levels.size() == a.budget_levels.size());
  for (size_t l = 0; l < a.budget_levels.size(); ++l) {
    CHECK(g.budget_levels[l].threshold == a.budget_levels[l].threshold);
    CHECK(g.budget_levels[l].steps == a.budget_levels[l].steps);
  }
  // Dense streams draw fewer fragments for the same rays.
  CHECK(a.stats.totals.fragments_launched < g.stats.totals.fragments_launched);
}
