// --beams auto (host/trace/stream/accel_choice.h, choose_beams): beams where the primary trace
// with them is predicted cheaper, off elsewhere and wherever --beams on would be refused; the
// tile map the report draws (RenderResult::beam_map), laid out as the image's tiles; and the beam
// textures counted in the frame's texture bytes.
#include <doctest/doctest.h>

#include <algorithm>
#include <limits>
#include <memory>
#include <string>

#include "host/accel/accel.h"
#include "host/accel/grid.h"
#include "host/model/cost_model.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/accel_choice.h"
#include "host/trace/stream/stream_tracer.h"

namespace {

host::RenderOptions small(int w, int h) {
  host::RenderOptions opt;
  opt.width = w;
  opt.height = h;
  opt.profile = "gf6600";
  opt.threads = 2;
  return opt;
}

std::unique_ptr<host::Accel> built(const host::Scene& scene, host::AccelKind kind,
                                   const host::RenderOptions& opt) {
  const host::AccelParams params{host::grid_spec_for({}, scene, vgpu::profile(opt.profile))};
  return host::make_accel(kind, scene, params);
}

// A pass observer that looks at nothing: a frame followed by one keeps its tile map.
struct Blind final : host::PassObserver {
  void iteration(int) override {}
  void trace_begin(TraceKind) override {}
  void trace_end() override {}
  void pass_begin(const vgpu::Stencil*) override {}
  void pass(const Pass&) override {}
  void query(uint64_t, const vgpu::Stencil*, const vgpu::FrameStats&) override {}
};

}  // namespace

TEST_CASE(
    "beams auto keeps beams exactly where the primary trace with them is predicted cheaper, "
    "through the grid, the two-level grid, the BVH and the kd-tree") {
  // At 32x32 on gf6600: the low bunny's primary trace is 0.90x with beams, classic's 1.04x.
  bool chose_on = false, chose_off = false;
  for (const host::AccelKind kind : host::kAccelKinds)
    for (const char* name : {"bunny-low", "classic"}) {
      CAPTURE(name);
      CAPTURE(int(kind));
      const host::Scene scene = host::load_scene(host::resolve_scene(name));
      host::RenderOptions opt = small(32, 32);
      opt.bounces = 1;  // the choice prices the primary trace alone
      opt.shadows = true;
      const auto accel = built(scene, kind, opt);
      const host::Camera cam = host::scene_camera(scene);
      const host::BeamsChoice c = host::choose_beams(scene, *accel, opt, cam, "stream");
      // The same primary traces, rendered here at the frame's size and priced.
      host::RenderOptions primary = opt;
      primary.bounces = 0;
      primary.shadows = false;
      double ms[2];
      for (const bool on : {false, true}) {
        primary.beams = on;
        host::StreamTracer tracer(scene, *accel, primary);
        ms[on] = host::predict(tracer.render(cam).stats, vgpu::profile(opt.profile)).total_ms;
      }
      CHECK(c.probed);
      CHECK(c.probe_width == 32);
      CHECK(c.probe_height == 32);
      CHECK(c.off_ms == doctest::Approx(ms[0]).epsilon(1e-9));
      CHECK(c.on_ms == doctest::Approx(ms[1]).epsilon(1e-9));
      CHECK(c.probe_model_ms == doctest::Approx(ms[0] + ms[1]).epsilon(1e-9));
      CHECK(c.on == (ms[1] < (1.0 - host::kAutoBeamsMargin) * ms[0]));
      CHECK(c.why.rfind(c.on ? "on: " : "off: ", 0) == 0);
      if (kind == host::AccelKind::grid) (c.on ? chose_on : chose_off) = true;
    }
  // Both answers occur on the grid: a choice that is always on or always off fails here.
  CHECK(chose_on);
  CHECK(chose_off);
}

TEST_CASE(
    "beams auto is off without probes where beams on would be refused or on the cpu engine, and "
    "says why") {
  const host::Scene scene = host::load_scene(host::resolve_scene("bunny-low"));
  const host::Camera cam = host::scene_camera(scene);
  const host::RenderOptions opt = small(16, 16);
  auto check_off = [&](const host::Accel& accel, const host::RenderOptions& o,
                       std::string_view engine, const std::string& why) {
    const host::BeamsChoice c = host::choose_beams(scene, accel, o, cam, engine);
    CAPTURE(c.why);
    CHECK_FALSE(c.on);
    CHECK_FALSE(c.probed);
    CHECK(c.why.rfind("off: ", 0) == 0);
    CHECK(c.why.find(why) != std::string::npos);
  };
  const auto grid = built(scene, host::AccelKind::grid, opt);
  check_off(*grid, opt, "cpu", "cpu engine");
  host::RenderOptions half = opt;
  half.formats = host::Formats::all(vgpu::Format::fp16);
  check_off(*grid, half, "stream", "needs fp32 rays");
  host::RenderOptions dense = opt;
  dense.adaptive = true;
  dense.spp = 4;
  check_off(*grid, dense, "stream", "--compact off");
}

TEST_CASE("beams auto is off, saying why, where a structure addressed by (x, y) refuses beams") {
  // The kd-tree and the two-level grid by (x, y) (docs/studies/scale.md) refuse beams once
  // built: auto takes that refusal for its answer instead of failing the frame.
  const host::Scene scene = host::load_scene(host::resolve_scene("bunny-low"));
  const host::Camera cam = host::scene_camera(scene);
  host::RenderOptions opt = small(16, 16);
  opt.addressing = host::RenderOptions::Addressing::xy;
  for (const host::AccelKind kind : {host::AccelKind::kdtree, host::AccelKind::grid2}) {
    const auto accel = built(scene, kind, opt);
    const host::BeamsChoice c = host::choose_beams(scene, *accel, opt, cam, "stream");
    CAPTURE(c.why);
    CHECK_FALSE(c.on);
    CHECK_FALSE(c.probed);  // the refusal comes before any probe renders
    CHECK(c.why.rfind("off: ", 0) == 0);
    CHECK(c.why.find("addressed by (x, y); beams over tiles") != std::string::npos);
  }
}

TEST_CASE("the tile map holds each tile where the image has it, missed tiles without a hit") {
  // 48x32 in 8x8 tiles: 6 tiles across and 4 down, so a map read across its rows fails.
  const host::Scene scene = host::load_scene(host::resolve_scene("bunny-low"));
  host::RenderOptions opt = small(48, 32);
  opt.bounces = 0;
  opt.shadows = false;
  opt.beams = true;
  const auto accel = built(scene, host::AccelKind::grid, opt);
  const host::Camera cam = host::scene_camera(scene, float(opt.width) / float(opt.height));
  {
    host::StreamTracer tracer(scene, *accel, opt);
    CHECK(tracer.render(cam).beam_map.start.empty());  // no observer, no map
  }
  Blind blind;
  opt.observer = &blind;
  host::StreamTracer tracer(scene, *accel, opt);
  const host::RenderResult r = tracer.render(cam);
  const host::BeamMap& m = r.beam_map;
  REQUIRE(m.tiles_x == 6);
  REQUIRE(m.tiles_y == 4);
  CHECK(m.tile == 8);
  REQUIRE(m.start.size() == 24);
  REQUIRE(m.steps.size() == 24);
  REQUIRE(m.missed.size() == 24);
  uint64_t missed = 0, reached = 0;
  for (int ty = 0; ty < m.tiles_y; ++ty)
    for (int tx = 0; tx < m.tiles_x; ++tx) {
      CAPTURE(tx);
      CAPTURE(ty);
      const size_t i = size_t(ty) * size_t(m.tiles_x) + size_t(tx);
      // The tile's pixels: whether any hits, and the nearest hit.
      bool hit = false;
      float nearest = std::numeric_limits<float>::max();
      for (int y = ty * 8; y < ty * 8 + 8; ++y)
        for (int x = tx * 8; x < tx * 8 + 8; ++x) {
          const size_t p = size_t(y) * size_t(opt.width) + size_t(x);
          if (r.hit_id[p] < 0) continue;
          hit = true;
          nearest = std::min(nearest, r.depth[p]);
        }
      if (m.missed[i]) {
        ++missed;
        CHECK_FALSE(hit);  // a missed tile's rays hit nothing
      } else {
        CHECK(m.start[i] >= 0.0f);
        CHECK(m.start[i] <= nearest);  // every ray starts before its hit
        reached += m.start[i] > 0.0f;
      }
    }
  CHECK(missed == r.beam_tiles_missed);
  CHECK(missed > 0);
  CHECK(missed < 24);
  CHECK(reached > 0);  // some beams moved on from the eye
}

TEST_CASE(
    "through the bvh and the kd-tree, the tile map holds each tile's start node and depth, and "
    "the descent's queries give the depths' sum and deepest") {
  // 48x32 in 4x4 tiles: 12 across, 8 down.
  const host::Scene scene = host::load_scene(host::resolve_scene("bunny-low"));
  for (const host::AccelKind kind : {host::AccelKind::bvh, host::AccelKind::kdtree}) {
    CAPTURE(int(kind));
    host::RenderOptions opt = small(48, 32);
    opt.bounces = 0;
    opt.shadows = false;
    opt.beams = true;
    opt.beam_tile = 4;
    const auto accel = built(scene, kind, opt);
    const host::Camera cam = host::scene_camera(scene, float(opt.width) / float(opt.height));
    host::RenderResult plain;
    {
      host::StreamTracer tracer(scene, *accel, opt);
      plain = tracer.render(cam);
    }
    Blind blind;
    opt.observer = &blind;
    host::StreamTracer tracer(scene, *accel, opt);
    const host::RenderResult r = tracer.render(cam);
    const host::BeamMap& m = r.beam_map;
    CHECK(m.tree);
    REQUIRE(m.tiles_x == 12);
    REQUIRE(m.tiles_y == 8);
    REQUIRE(m.steps.size() == 96);
    const int nodes = kind == host::AccelKind::bvh ? int(accel->bvh()->nodes.size())
                                                   : int(accel->kd()->nodes.size());
    uint64_t sum = 0, deepest = 0, missed = 0;
    for (size_t i = 0; i < 96; ++i) {
      CAPTURE(i);
      CHECK(m.start[i] >= 0.0f);
      CHECK(m.start[i] < float(nodes));
      sum += uint64_t(m.steps[i]);
      deepest = std::max(deepest, uint64_t(m.steps[i]));
      missed += m.missed[i];
    }
    // The queries' sums are the map's own (with or without an observer), on every tile.
    CHECK(r.beam_depth_sum == sum);
    CHECK(r.beam_depth_max == deepest);
    CHECK(plain.beam_depth_sum == sum);
    CHECK(plain.beam_depth_max == deepest);
    CHECK(deepest > 1);
    CHECK(missed == r.beam_tiles_missed);
  }
}

TEST_CASE("the beam textures are counted in the frame's texture bytes") {
  const host::Scene scene = host::load_scene(host::resolve_scene("bunny-low"));
  host::RenderOptions opt = small(40, 24);  // 5x3 tiles of 8x8
  opt.bounces = 0;
  opt.shadows = false;
  const auto accel = built(scene, host::AccelKind::grid, opt);
  const host::StreamTracer off(scene, *accel, opt);
  opt.beams = true;
  const host::StreamTracer on(scene, *accel, opt);
  const uint64_t voxels = accel->grid()->voxels();
  // The beam distances (one fp32 channel per voxel), the beam pair (4 channels per tile each)
  // and the counting target (1 channel per tile).
  CHECK(on.texture_bytes() - off.texture_bytes() == voxels * 4 + 15 * (4 + 4 + 1) * 4);
}
