// Progress within a walk (RenderOptions::walk_progress, host/trace/passes.cpp): a walk pass by
// pass reports after each occlusion query the frame's passes so far, which query it was and what
// it counted; a walk in batches reports the share of its tiles walked,
// up to all of them, with a time left that shrinks to zero; a report never changes the frame.
#include <doctest/doctest.h>

#include <algorithm>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "host/accel/grid.h"
#include "host/image/image_io.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/stream_tracer.h"
#include "tests/support/bits.h"

namespace {

struct Bunny {
  host::Scene scene = host::load_scene(host::resolve_scene("bunny-refl"), host::with_images());
  host::Grid grid =
      host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile("gf5700")));
  host::Camera camera = host::scene_camera(scene, 1.0f);
};

host::RenderOptions options(bool batches) {
  host::RenderOptions opt;
  opt.width = opt.height = 64;
  opt.bounces = 1;
  opt.shadows = true;
  opt.threads = 2;
  opt.batch_walk = batches;
  opt.progress_every_ms = 0;  // every report
  opt.keep_pass_records = true;
  return opt;
}

}  // namespace

TEST_CASE("a walk pass by pass reports the passes so far, each query and the rays it counted") {
  const Bunny b;
  host::RenderOptions opt = options(false);
  std::vector<host::WalkProgress> seen;
  opt.walk_progress = [&](const host::WalkProgress& w) { seen.push_back(w); };
  host::StreamTracer tracer(b.scene, b.grid, opt);
  const host::RenderResult r = tracer.render(b.camera);
  CHECK_FALSE(r.batch_walk);
  // One report per counting pass, each after it: its result, and the passes up to it.
  std::vector<host::WalkProgress> queries;
  std::vector<std::string> names;
  uint64_t passes = 0;
  for (const vgpu::PassRecord& p : r.stats.passes) {
    ++passes;
    if (p.query_result >= 0) {
      names.push_back(p.program);
      host::WalkProgress q;
      q.passes = passes;
      q.rays_walking = p.query_result;
      queries.push_back(q);
    }
  }
  REQUIRE(queries.size() > 20);
  REQUIRE(seen.size() == queries.size());
  for (size_t i = 0; i < seen.size(); ++i) {
    CAPTURE(i);
    CHECK(seen[i].passes == queries[i].passes);
    CHECK(seen[i].rays_walking == queries[i].rays_walking);
    CHECK(std::string(seen[i].query) == names[i]);
    CHECK(seen[i].done == -1);
    // A count between walks (the reflected rays' count) names no walk.
    const std::string rays = seen[i].rays;
    CHECK((rays == "primary rays" || rays == "shadow rays" || rays == "reflected rays" ||
           rays == "rays"));
    CHECK(seen[i].left_ms == -1);
  }
  for (const char* walk : {"primary rays", "shadow rays", "reflected rays"})
    CHECK(std::any_of(seen.begin(), seen.end(),
                      [&](const auto& w) { return std::string(w.rays) == walk; }));
}

TEST_CASE("a walk in batches reports the share of its tiles walked, up to all, and the time left") {
  const Bunny b;
  host::RenderOptions opt = options(true);
  std::mutex mu;
  std::vector<host::WalkProgress> seen;
  opt.walk_progress = [&](const host::WalkProgress& w) {
    const std::lock_guard lk(mu);
    seen.push_back(w);
  };
  host::StreamTracer tracer(b.scene, b.grid, opt);
  const host::RenderResult r = tracer.render(b.camera);
  REQUIRE(r.batch_walk);
  // 64x64: four 32x32 tiles per walk. Reports arrive from both threads, never two at once; one
  // that finds another under way is skipped, so a walk reports between one and four times.
  std::vector<double> shares;
  for (const host::WalkProgress& w : seen)
    if (w.done >= 0) {
      CHECK(w.left_ms >= 0);
      shares.push_back(w.done);
    }
  REQUIRE(!shares.empty());
  for (double s : shares) CHECK(std::set<double>{0.25, 0.5, 0.75, 1.0}.count(s) == 1);
  // The last tile of a walk leaves nothing: a report of all four says no time is left.
  for (const host::WalkProgress& w : seen)
    if (w.done == 1.0) CHECK(w.left_ms == 0.0);
  // The replay's queries report rays, as a walk pass by pass does.
  CHECK(std::any_of(seen.begin(), seen.end(), [](const auto& w) { return w.rays_walking >= 0; }));
}

TEST_CASE("progress reports leave the frame and its statistics as they are") {
  const Bunny b;
  for (bool batches : {false, true}) {
    CAPTURE(batches);
    host::RenderOptions quiet = options(batches), told = quiet;
    int reports = 0;
    told.walk_progress = [&](const host::WalkProgress&) { ++reports; };
    const host::RenderResult a = host::StreamTracer(b.scene, b.grid, quiet).render(b.camera);
    const host::RenderResult c = host::StreamTracer(b.scene, b.grid, told).render(b.camera);
    CHECK(reports > 0);
    CHECK(test_support::same_bits(a.rgb, c.rgb));
    CHECK(a.stats.totals.same_counts(c.stats.totals));
  }
}

TEST_CASE("a clear split over the threads writes every texel, rounded, and counts one clear") {
  // 512x256: above the size a clear is split at (65,536 texels), with rows left over per block.
  for (int threads : {1, 3}) {
    CAPTURE(threads);
    vgpu::Gpu gpu(vgpu::profile("gf5700"), threads);
    for (int channels : {1, 3, 4}) {
      CAPTURE(channels);
      vgpu::Texture t = gpu.make_texture("t", 512, 257, channels, vgpu::Format::fp16);
      const std::vector<float> v = {0.1f, -2.5f, 3.0e5f, 7.0f};
      const uint64_t clears = gpu.stats().totals.clears;
      switch (channels) {
        case 1:
          gpu.clear(t, {v[0]});
          break;
        case 3:
          gpu.clear(t, {v[0], v[1], v[2]});
          break;
        default:
          gpu.clear(t, {v[0], v[1], v[2], v[3]});
      }
      CHECK(gpu.stats().totals.clears == clears + 1);
      size_t wrong = 0;
      for (int y = 0; y < t.height(); ++y)
        for (int x = 0; x < t.width(); ++x)
          for (int c = 0; c < channels; ++c)
            wrong += t.get(x, y, c) != vgpu::round_to(vgpu::Format::fp16, v[size_t(c)]);
      CHECK(wrong == 0);
    }
  }
}
