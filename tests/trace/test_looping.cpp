// The looping variant of the walk (--kernels looping, kernels/looping_traversal.h) against the
// paper's multipass pipeline: the same primary hit ids, depths and colours (shadow and
// reflected rays walk through it too) on every bundled scene and every stability case, for any
// step budget; statistics identical for any thread count and lane width; fewer passes.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "host/accel/grid.h"
#include "host/image/image_io.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/stream_tracer.h"
#include "stability_cases.h"
#include "tests/support/bits.h"
#include "tests/support/lane_widths.h"

using host::RenderOptions;
using host::RenderResult;

using test_support::same_bits;

namespace {

RenderResult render(const host::Scene& scene, const host::Grid& grid, const host::Camera& cam,
                    const RenderOptions& opt) {
  host::StreamTracer tracer(scene, grid, opt);
  return tracer.render(cam);
}

RenderOptions on_gf6600(int w, int h, bool looping, int steps = 64) {
  RenderOptions opt;
  opt.width = w;
  opt.height = h;
  opt.profile = "gf6600";
  opt.threads = 1;
  opt.looping = looping;
  opt.steps_per_pass = steps;
  return opt;
}

std::vector<std::string> bundled_scenes() {
  std::vector<std::string> v;
  for (const auto& e : std::filesystem::directory_iterator(VGPU_SCENES_DIR))
    if (e.path().extension() == ".gltf") v.push_back(e.path().string());
  std::sort(v.begin(), v.end());
  return v;
}

uint64_t passes_of(const RenderResult& r, const char* kernel) {
  const auto* p = r.stats.find(kernel);
  return p ? p->counters.passes : 0;
}

}  // namespace

TEST_CASE("looping kernels give the multipass hit ids, depths and colours on the bundled scenes" * doctest::test_suite("sweep")) {
  const auto scenes = bundled_scenes();
  REQUIRE(scenes.size() >= 8);
  for (const std::string& path : scenes) {
    CAPTURE(path);
    const host::Scene scene = host::load_scene(path, host::with_images());
    const host::Camera cam = host::scene_camera(scene);
    const host::Grid grid = host::build_grid(
        scene, host::grid_spec_for(host::GridSpec{}, scene, vgpu::profile("gf6600")));
    const RenderResult multi = render(scene, grid, cam, on_gf6600(64, 64, false));
    for (int steps : {7, 64}) {
      CAPTURE(steps);
      const RenderResult loop = render(scene, grid, cam, on_gf6600(64, 64, true, steps));
      CHECK(same_bits(multi.hit_id, loop.hit_id));
      CHECK(same_bits(multi.depth, loop.depth));
      CHECK(same_bits(multi.rgb, loop.rgb));
      CHECK(loop.rays_unfinished == 0);
      CHECK(loop.rays_traced == multi.rays_traced);
      CHECK(passes_of(loop, "looping traversal") > 0);
      CHECK(passes_of(loop, "intersections") == 0);
      CHECK(loop.stats.totals.passes < multi.stats.totals.passes);
    }
  }
}

TEST_CASE("looping kernels give the multipass hit ids on every stability case") {
  for (const stability::Case& c : stability::cases()) {
    CAPTURE(c.name);
    const host::Grid grid = stability::grid_of(c);
    RenderOptions opt = stability::options_of(c, vgpu::Format::fp32);
    opt.profile = "gf6600";
    const RenderResult multi = render(c.scene, grid, c.camera, opt);
    opt.looping = true;
    opt.steps_per_pass = 5;
    const RenderResult loop = render(c.scene, grid, c.camera, opt);
    CHECK(same_bits(multi.hit_id, loop.hit_id));
    CHECK(same_bits(multi.depth, loop.depth));
    CHECK(loop.rays_unfinished == 0);
    int wrong = 0;
    for (size_t i = 0; i < c.expected.size(); ++i)
      wrong += !stability::accepts(c, c.expected[i], int(std::lround(loop.hit_id[i])));
    CHECK(wrong == 0);
  }
}

TEST_CASE("looping statistics are bit-identical for 1 and 3 threads and 1, 4, 8 and 16 lanes") {
  const host::Scene scene = host::load_scene(VGPU_SCENES_DIR "/bunny-refl.gltf");
  const host::Grid grid = host::build_grid(scene, host::GridSpec{});
  // 72x64 = 4608 fragments: passes are split over threads from 4096 on.
  RenderOptions opt = on_gf6600(72, 64, true, 16);
  opt.keep_pass_records = true;
  opt.lanes = 1;
  const RenderResult ref = render(scene, grid, *scene.camera, opt);
  const auto* lp = ref.stats.find("looping traversal");
  REQUIRE(lp);
  CHECK(lp->counters.loop_lanes_idle > 0);
  CHECK(lp->counters.loop_lane_slots ==
        lp->counters.loop_iterations + lp->counters.loop_lanes_idle);
  for (auto [bound_threads, bound_lanes] : {std::pair{3, 8}, std::pair{1, 4}, std::pair{3, 16}}) {
    // Named copies: clang 14 cannot capture a structured binding (CAPTURE, INFO).
    const auto& threads = bound_threads;
    const auto& lanes = bound_lanes;
    if (!test_support::kernel_width_built(lanes)) continue;
    CAPTURE(threads);
    CAPTURE(lanes);
    opt.threads = threads;
    opt.lanes = lanes;
    const RenderResult r = render(scene, grid, *scene.camera, opt);
    CHECK(same_bits(ref.rgb, r.rgb));
    CHECK(r.stats.totals.same_counts(ref.stats.totals));
    REQUIRE(r.stats.passes.size() == ref.stats.passes.size());
    for (size_t i = 0; i < r.stats.passes.size(); ++i) {
      CHECK(r.stats.passes[i].counters.same_counts(ref.stats.passes[i].counters));
      CHECK(r.stats.passes[i].loop_active == ref.stats.passes[i].loop_active);
      CHECK(r.stats.passes[i].loop_idle == ref.stats.passes[i].loop_idle);
    }
  }
}

TEST_CASE("early-z masks and the host shortcut change no looping hit and no loop counter") {
  const host::Scene scene = host::load_scene(VGPU_SCENES_DIR "/sphere.gltf");
  const host::Grid grid = host::build_grid(scene, host::GridSpec{});
  RenderOptions opt = on_gf6600(40, 30, true, 8);
  const RenderResult plain = render(scene, grid, *scene.camera, opt);
  opt.host_shortcut = false;
  const RenderResult slow = render(scene, grid, *scene.camera, opt);
  CHECK(same_bits(plain.rgb, slow.rgb));
  CHECK(plain.stats.totals.same_counts(slow.stats.totals));
  opt.host_shortcut = true;
  opt.masks = true;
  const RenderResult masked = render(scene, grid, *scene.camera, opt);
  CHECK(same_bits(plain.hit_id, masked.hit_id));
  CHECK(same_bits(plain.rgb, masked.rgb));
  const auto* a = plain.stats.find("looping traversal");
  const auto* b = masked.stats.find("looping traversal");
  REQUIRE(a);
  REQUIRE(b);
  // Finished rays never iterate: masking them leaves the active iterations as they were, and
  // takes their idle lane slots out of the batches.
  CHECK(b->counters.loop_iterations == a->counters.loop_iterations);
  CHECK(b->counters.loop_lanes_idle < a->counters.loop_lanes_idle);
  CHECK(b->counters.fragments_masked > 0);
}

TEST_CASE("the looping walk is refused on the FX 5700 with the program's name") {
  const host::Scene scene = host::load_scene(VGPU_SCENES_DIR "/sphere.gltf");
  const host::Grid grid = host::build_grid(scene, host::GridSpec{});
  RenderOptions opt = on_gf6600(16, 16, true);
  opt.profile = "gf5700";
  host::StreamTracer tracer(scene, grid, opt);
  CHECK_THROWS_WITH_AS(tracer.render(*scene.camera),
                       doctest::Contains("program 'looping traversal' has a data-dependent loop"),
                       vgpu::Error);
}
