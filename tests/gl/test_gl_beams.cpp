// Beams over tiles (--beams on, host/trace/walks/grid_beams.h) on the GL device: the GL frame runs
// the emulator's passes (the beam march with its queries, the count of missed tiles, the beam
// entry), gets the same query counts, and gives the same hit ids, depths and image as the
// emulator's frame with beams on and as the GL frame with beams off (on llvmpipe bit for bit,
// tests/gl/gl_compare.h); through the grid and through the BVH (host/trace/walks/bvh_beams.h).
#include <doctest/doctest.h>

#include <string>

#include "host/accel/accel.h"
#include "host/accel/grid.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/stream_tracer.h"
#include "tests/gl/gl_compare.h"

namespace {

struct Frame {
  host::RenderResult result;
  std::string device;
};

Frame render(const host::Scene& scene, const host::Grid& grid, host::RenderOptions opt,
             const std::string& device, bool beams) {
  opt.device = device;
  opt.beams = beams;
  host::StreamTracer tracer(scene, grid, opt);
  return {tracer.render(host::scene_camera(scene)), tracer.device().description()};
}

Frame render(const host::Scene& scene, const host::Accel& accel, host::RenderOptions opt,
             const std::string& device, bool beams) {
  opt.device = device;
  opt.beams = beams;
  host::StreamTracer tracer(scene, accel, opt);
  return {tracer.render(host::scene_camera(scene)), tracer.device().description()};
}

uint64_t passes_of(const host::RenderResult& r, const std::string& program) {
  uint64_t n = 0;
  for (const auto& p : r.stats.passes) n += p.program == program;
  return n;
}

}  // namespace

TEST_CASE(
    "beams over tiles on the GL device give the emulator's beam queries, hit ids, depths "
    "and image, and the image of beams off") {
  struct Setup {
    const char* scene;
    int width, height, tile, bounces;
  };
  // 36x28 in 8x8 tiles: the last column and row of tiles are cut short; classic with one
  // bounce and its shadows, the bunny's primary rays alone.
  for (const Setup s : {Setup{"classic", 36, 28, 8, 1}, Setup{"bunny-low", 32, 32, 4, 0}}) {
    const std::string name = s.scene;
    CAPTURE(name);
    const host::Scene scene = host::load_scene(host::resolve_scene(s.scene));
    host::RenderOptions opt;
    opt.width = s.width;
    opt.height = s.height;
    opt.threads = 2;
    opt.bounces = s.bounces;
    opt.shadows = s.bounces > 0;
    opt.beam_tile = s.tile;
    opt.keep_pass_records = true;
    const host::Grid grid =
        host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile(opt.profile)));
    const Frame vgpu_on = render(scene, grid, opt, "vgpu", true);
    const Frame gl_on = render(scene, grid, opt, "gl", true);
    const Frame gl_off = render(scene, grid, opt, "gl", false);
    const host::RenderResult &a = vgpu_on.result, &b = gl_on.result;
    // The same passes in the same order, each query counting the same fragments: the beams
    // still marching after each march pass, the tiles missed, the rays walking after each step.
    REQUIRE(a.stats.passes.size() == b.stats.passes.size());
    for (size_t i = 0; i < a.stats.passes.size(); ++i) {
      CAPTURE(i);
      REQUIRE(a.stats.passes[i].program == b.stats.passes[i].program);
      CHECK(a.stats.passes[i].query_result == b.stats.passes[i].query_result);
    }
    CHECK(passes_of(b, "beam march") == b.beam_passes);
    CHECK(passes_of(b, "beam entry") == 1);
    CHECK(b.beam_passes == a.beam_passes);
    CHECK(b.beam_passes > 1);
    CHECK(b.beam_tiles == a.beam_tiles);
    CHECK(b.beam_tiles_missed == a.beam_tiles_missed);
    CHECK(b.beam_tiles_missed > 0);
    CHECK(b.beam_tiles_missed < b.beam_tiles);
    CHECK(gl_off.result.beam_passes == 0);
    gltest::check_same_frame(gl_on.device, "intersections", a.hit_id, b.hit_id, a.depth, b.depth,
                             a.rgb, b.rgb);
    // Beams on and off on the GL device: the same rays, the same hits, the same image.
    gltest::check_same_frame(gl_on.device, "intersections", gl_off.result.hit_id, b.hit_id,
                             gl_off.result.depth, b.depth, gl_off.result.rgb, b.rgb);
  }
}

TEST_CASE(
    "beams through the BVH on the GL device give the emulator's descent queries, hit ids, "
    "depths and image, and the image of beams off") {
  // bunny-low's primary rays at 32x24 in 8x8 tiles, and classic with one bounce and its shadows
  // at 24x24 in 6x6 tiles (the step ends each primary ray's walk at its tile's node).
  struct Setup {
    const char* scene;
    int width, height, tile, bounces;
  };
  for (const Setup s : {Setup{"bunny-low", 32, 24, 8, 0}, Setup{"classic", 24, 24, 6, 1}}) {
    const std::string name = s.scene;
    CAPTURE(name);
    const host::Scene scene = host::load_scene(host::resolve_scene(s.scene));
    host::RenderOptions opt;
    opt.width = s.width;
    opt.height = s.height;
    opt.threads = 2;
    opt.bounces = s.bounces;
    opt.shadows = s.bounces > 0;
    opt.beam_tile = s.tile;
    opt.keep_pass_records = true;
    const auto bvh = host::make_accel(
        host::AccelKind::bvh, scene,
        host::AccelParams{host::grid_spec_for({}, scene, vgpu::profile(opt.profile))});
    const Frame vgpu_on = render(scene, *bvh, opt, "vgpu", true);
    const Frame gl_on = render(scene, *bvh, opt, "gl", true);
    const Frame gl_off = render(scene, *bvh, opt, "gl", false);
    const host::RenderResult &a = vgpu_on.result, &b = gl_on.result;
    REQUIRE(a.stats.passes.size() == b.stats.passes.size());
    for (size_t i = 0; i < a.stats.passes.size(); ++i) {
      CAPTURE(i);
      REQUIRE(a.stats.passes[i].program == b.stats.passes[i].program);
      CHECK(a.stats.passes[i].query_result == b.stats.passes[i].query_result);
    }
    // One descent pass per tree level the beams went down, each followed by its count.
    CHECK(passes_of(b, "bvh beam descend") == b.beam_passes);
    CHECK(passes_of(b, "bvh beams descending") >= 1);
    CHECK(passes_of(b, "bvh beam enter") == 1);
    CHECK(b.beam_passes > 1);
    CHECK(b.beam_passes == a.beam_passes);
    CHECK(b.beam_tiles == a.beam_tiles);
    CHECK(b.beam_tiles_missed == a.beam_tiles_missed);
    CHECK(gl_off.result.beam_passes == 0);
    gltest::check_same_frame(gl_on.device, "intersections", a.hit_id, b.hit_id, a.depth, b.depth,
                             a.rgb, b.rgb);
    gltest::check_same_frame(gl_on.device, "intersections", gl_off.result.hit_id, b.hit_id,
                             gl_off.result.depth, b.depth, gl_off.result.rgb, b.rgb);
  }
}
