// Sampling that saves time (issue 35, host/trace/stream/mark_streams.h): the sampling modes'
// gated frames traced as dense streams of their marked pixels give the gated frames' images, and
// draw fewer fragments and passes for it.
#include <doctest/doctest.h>

#include <memory>
#include <string>

#include "host/accel/accel.h"
#include "host/model/cost_model.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/mark_streams.h"
#include "host/trace/stream/stream_tracer.h"
#include "tests/support/bits.h"

using test_support::same_bits;

namespace {

// At 24x24 (32x24 for the sphere, whose level of 16 samples then fits in few frames), up to 16
// samples (mode 0, adaptive) or the K = 2 lattice and its gaps (mode 1); the CLI's defaults
// otherwise (two bounces, shadow rays).
host::RenderOptions options(int mode, bool compact, int width = 24) {
  host::RenderOptions opt;
  opt.width = width;
  opt.height = 24;
  opt.profile = "gf6600";
  opt.aa_threshold = 0.1f;
  opt.compact = compact;
  if (mode == 0) {
    opt.spp = 16;
    opt.adaptive = true;
    opt.aa_criterion = host::RenderOptions::AaCriterion::image;
  } else {
    opt.undersample = 2;
  }
  return opt;
}

struct Loaded {
  explicit Loaded(const char* name) : scene(host::load_scene(host::resolve_scene(name))) {}
  host::Scene scene;
  host::Camera camera = host::scene_camera(scene);
  host::AccelParams params{host::grid_spec_for({}, scene, vgpu::profile("gf6600"))};
};

}  // namespace

TEST_CASE(
    "dense streams give the gated frames' images, depths and hit ids bit for bit on every "
    "structure, pass by pass and in batches, at any thread count") {
  const Loaded s("bunny");
  for (const host::AccelKind kind : host::kAccelKinds) {
    const std::unique_ptr<host::Accel> accel = host::make_accel(kind, s.scene, s.params);
    CAPTURE(std::string(accel->name()));
    for (const int mode : {0, 1}) {
      CAPTURE(mode);
      const host::RenderResult gated =
          host::StreamTracer(s.scene, *accel, options(mode, false)).render(s.camera);
      CHECK_FALSE(gated.compact.on);
      for (const bool batches : {true, false}) {
        CAPTURE(batches);
        host::RenderOptions opt = options(mode, true);
        opt.batch_walk = batches;
        opt.threads = batches ? 3 : 1;
        const host::RenderResult dense = host::StreamTracer(s.scene, *accel, opt).render(s.camera);
        CHECK(same_bits(gated.rgb, dense.rgb));
        CHECK(same_bits(gated.depth, dense.depth));
        CHECK(same_bits(gated.hit_id, dense.hit_id));
        CHECK(gated.rays_per_pixel == dense.rays_per_pixel);
        // The frames traced only their marked pixels' rows: fewer fragments, the same rays.
        REQUIRE(dense.compact.on);
        CHECK(dense.compact.slots < dense.compact.pixels);
        CHECK(dense.stats.totals.fragments_shaded < gated.stats.totals.fragments_shaded);
        CHECK(dense.rays_traced == gated.rays_traced);
        CHECK(dense.batch_walk == batches);
      }
    }
  }
}

TEST_CASE(
    "a dense adaptive level traces several samples per frame: fewer passes and a lower modeled "
    "time than the gated frames, its work in the statistics") {
  const Loaded s("sphere");
  const std::unique_ptr<host::Accel> grid =
      host::make_accel(host::AccelKind::grid, s.scene, s.params);
  host::RenderOptions opt = options(0, false, 32);
  opt.keep_pass_records = true;  // the cost model prices each pass
  const host::RenderResult gated = host::StreamTracer(s.scene, *grid, opt).render(s.camera);
  opt.compact = true;
  const host::RenderResult dense = host::StreamTracer(s.scene, *grid, opt).render(s.camera);
  const host::CompactStats& c = dense.compact;
  // Two levels (4 and 16 samples), each packed once; a level's samples share frames.
  CHECK(c.packs == 2);
  CHECK(c.frames < 4 + 16);
  CHECK(c.scan_passes > 0);
  CHECK(c.compaction_passes == 2);
  CHECK(c.gather_passes == 4 + 16);  // one acumularDensos per sample, as acumularMuestras
  CHECK(c.live_rays > 0);
  CHECK(c.slots >= c.live_rays);
  CHECK(dense.stats.totals.passes < gated.stats.totals.passes);
  const vgpu::Profile& p = vgpu::profile("gf6600");
  CHECK(host::predict(dense.stats, p).total_ms < 0.5 * host::predict(gated.stats, p).total_ms);
  const nlohmann::ordered_json j = host::to_json(c);
  CHECK(j["frames"] == c.frames);
  CHECK(j["live_rays"] == c.live_rays);
  CHECK(j["scan"]["passes"] == c.scan_passes);
  CHECK(j["gather"]["bytes"] == c.gather_bytes);
  CHECK(host::describe(c).find("dense streams: ") == 0);
}
