// Sampling that saves time (issue 35, host/trace/stream/mark_streams.h): the sampling modes'
// gated frames traced as dense streams of their marked pixels give the gated frames' images, and
// draw fewer fragments and passes for it.
#include <doctest/doctest.h>

#include <algorithm>
#include <memory>
#include <string>

#include "host/accel/accel.h"
#include "host/model/cost_model.h"
#include "host/model/formats.h"
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
    "structure, pass by pass and in batches, at any thread count" * doctest::test_suite("sweep")) {
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
  CHECK(c.scan_bytes > 0);  // the report room writes these (tests/report/test_stats_parts_json.cpp)
  CHECK(c.compaction_bytes > 0);
  CHECK(c.gather_bytes > 0);
  CHECK(host::describe(c).find("dense streams: ") == 0);
}

namespace {

// One dense frame's fragments per pass: the whole rows its `live` slots fill, one row at least.
uint64_t rows_of(uint64_t live, int width) {
  return std::max<uint64_t>(1, (live + uint64_t(width) - 1) / uint64_t(width)) * uint64_t(width);
}

}  // namespace

TEST_CASE(
    "the dense streams' slots are the whole rows their frames' marked pixels fill, as the pixels' "
    "ray counts give them, for the lattice, the gaps and each adaptive level") {
  // Undersampling at 24x24, K = 2: the lattice is every second column and row and the last, 13
  // x 13 = 169 pixels, 7 rows and one pixel (8 rows); the gaps' frame traces the other pixels
  // with a ray. 169 is not a multiple of 24, so live rays and slots part.
  {
    const Loaded s("bunny");
    const std::unique_ptr<host::Accel> grid =
        host::make_accel(host::AccelKind::grid, s.scene, s.params);
    const host::RenderResult r =
        host::StreamTracer(s.scene, *grid, options(1, true)).render(s.camera);
    const host::CompactStats& c = r.compact;
    REQUIRE(c.on);
    const uint64_t traced =
        uint64_t(std::count(r.rays_per_pixel.begin(), r.rays_per_pixel.end(), 1u));
    REQUIRE(traced > 169);
    const uint64_t gaps = traced - 169;
    CHECK(c.packs == 2);
    CHECK(c.frames == 2);
    CHECK(c.live_rays == 169 + gaps);
    CHECK(c.slots == 8 * 24 + rows_of(gaps, 24));
    CHECK(c.pixels == 2 * 24 * 24);
  }
  // Adaptive, image criterion, 32x24 sphere: level 1 (4 samples) in the pixels that took 1 + 4
  // rays or more, level 2 (16) in those that took 1 + 4 + 16; each level's frames hold as many
  // whole samples of its n pixels as 32 x 24 slots take (768 / n), the last frame the rest.
  {
    const Loaded s("sphere");
    const std::unique_ptr<host::Accel> grid =
        host::make_accel(host::AccelKind::grid, s.scene, s.params);
    const int W = 32, H = 24;
    const host::RenderResult r =
        host::StreamTracer(s.scene, *grid, options(0, true, W)).render(s.camera);
    const host::CompactStats& c = r.compact;
    REQUIRE(c.on);
    const auto& rays = r.rays_per_pixel;
    const uint64_t level_pixels[2] = {
        uint64_t(std::count_if(rays.begin(), rays.end(), [](uint32_t n) { return n >= 5; })),
        uint64_t(std::count(rays.begin(), rays.end(), 21u))};
    const int level_samples[2] = {4, 16};
    uint64_t frames = 0, live = 0, slots = 0, pixels = 0;
    for (int l = 0; l < 2; ++l) {
      const uint64_t n = level_pixels[l];
      REQUIRE(n > 0);
      const int per = int(std::max<uint64_t>(1, uint64_t(W * H) / n));
      for (int k0 = 0; k0 < level_samples[l]; k0 += per) {
        const int k = std::min(level_samples[l], k0 + per) - k0;
        ++frames;
        live += n * uint64_t(k);
        slots += rows_of(n * uint64_t(k), W);
        pixels += uint64_t(W * H * k);
      }
    }
    CAPTURE(level_pixels[0]);
    CAPTURE(level_pixels[1]);
    CHECK(c.packs == 2);
    CHECK(c.frames == frames);
    CHECK(c.live_rays == live);
    CHECK(c.slots == slots);
    CHECK(c.pixels == pixels);
    CHECK(c.slots != c.live_rays);  // some frame's last row is not full
  }
}

TEST_CASE(
    "a dense stream fits where its slots are addressed exactly: up to 2^22 pixels in fp32, 2^16 "
    "in fp24, with the rays and the colour in the profile's finest arithmetic") {
  using host::MarkStreams;
  using vgpu::Format;
  auto sized = [](int w, int h) {
    host::RenderOptions opt;
    opt.width = w;
    opt.height = h;
    return opt;
  };
  const vgpu::Profile& fp32 = vgpu::profile("gf6600");
  const vgpu::Profile& fp24 = vgpu::profile("r300");
  REQUIRE(fp32.computes(Format::fp32) == Format::fp32);
  REQUIRE(fp24.computes(Format::fp32) == Format::fp24);
  CHECK(MarkStreams::fits(fp32, sized(2048, 2048)));  // 2^22
  CHECK_FALSE(MarkStreams::fits(fp32, sized(2049, 2048)));
  CHECK(MarkStreams::fits(fp32, sized(1, 1 << 22)));
  CHECK_FALSE(MarkStreams::fits(fp32, sized(1, (1 << 22) + 1)));
  CHECK(MarkStreams::fits(fp24, sized(256, 256)));  // 2^16
  CHECK_FALSE(MarkStreams::fits(fp24, sized(257, 256)));
  CHECK(MarkStreams::fits(fp24, sized(1 << 16, 1)));
  CHECK_FALSE(MarkStreams::fits(fp24, sized(4097, 16)));
  // The rays' or the colour's arithmetic below the finest the part has: the gated frames run.
  for (const host::Group g : {host::Group::rays, host::Group::colour, host::Group::traversal}) {
    CAPTURE(int(g));
    host::RenderOptions opt = sized(16, 16);
    opt.formats.set(g, Format::fp32, Format::fp16);
    REQUIRE(fp32.computes(Format::fp16) == Format::fp16);
    // (traversal's arithmetic does not address the stream)
    CHECK(MarkStreams::fits(fp32, opt) == (g == host::Group::traversal));
    // R300 computes fp16 in fp24, its finest: it fits.
    CHECK(MarkStreams::fits(fp24, opt));
  }
}
