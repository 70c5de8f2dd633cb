// Beams over tiles (--beams on, host/trace/walks/grid_beams.h) on the GL device: the GL frame runs
// the emulator's passes (the beam march with its queries, the count of missed tiles, the beam
// entry), gets the same query counts, and gives the same hit ids, depths and image as the
// emulator's frame with beams on and as the GL frame with beams off (on llvmpipe bit for bit,
// tests/gl/gl_compare.h); through the grid, the two-level grid (kernels/grid2_beams.h), the BVH
// and the kd-tree (host/trace/walks/bvh_beams.h).
#include <doctest/doctest.h>

#include <string>
#include <vector>

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

struct Setup {
  const char* scene;
  int width, height, tile, bounces;
};

// The emulator's frame with beams and the GL frames with and without them, through `kind`: the
// same passes in the same order, each query counting the same fragments (the beams still
// marching or descending after each beam pass, the tiles missed, the rays walking after each
// step); `beam_pass` runs once per beam pass, `entry` once (the kd-tree's, inicioKd with the
// tile's node, once per trace as without beams); the same hit ids, depths and image.
void check_beams_on_gl(host::AccelKind kind, const std::vector<Setup>& setups,
                       const std::string& beam_pass, const std::string& entry) {
  uint64_t missed = 0;
  for (const Setup& s : setups) {
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
    const auto accel = host::make_accel(
        kind, scene, host::AccelParams{host::grid_spec_for({}, scene, vgpu::profile(opt.profile))});
    const Frame vgpu_on = render(scene, *accel, opt, "vgpu", true);
    const Frame gl_on = render(scene, *accel, opt, "gl", true);
    const Frame gl_off = render(scene, *accel, opt, "gl", false);
    const host::RenderResult &a = vgpu_on.result, &b = gl_on.result;
    REQUIRE(a.stats.passes.size() == b.stats.passes.size());
    for (size_t i = 0; i < a.stats.passes.size(); ++i) {
      CAPTURE(i);
      REQUIRE(a.stats.passes[i].program == b.stats.passes[i].program);
      CHECK(a.stats.passes[i].query_result == b.stats.passes[i].query_result);
    }
    CHECK(passes_of(b, beam_pass) == b.beam_passes);
    CHECK(passes_of(b, entry) ==
          (kind == host::AccelKind::kdtree ? passes_of(gl_off.result, entry) : 1));
    CHECK(b.beam_passes == a.beam_passes);
    CHECK(b.beam_passes > 1);
    CHECK(b.beam_tiles == a.beam_tiles);
    CHECK(b.beam_tiles_missed == a.beam_tiles_missed);
    missed += b.beam_tiles_missed;
    CHECK(b.beam_tiles_missed < b.beam_tiles);
    CHECK(gl_off.result.beam_passes == 0);
    gltest::check_same_frame(gl_on.device, "intersections", a.hit_id, b.hit_id, a.depth, b.depth,
                             a.rgb, b.rgb);
    // Beams on and off on the GL device: the same rays, the same hits, the same image.
    gltest::check_same_frame(gl_on.device, "intersections", gl_off.result.hit_id, b.hit_id,
                             gl_off.result.depth, b.depth, gl_off.result.rgb, b.rgb);
  }
  // Whole tiles miss in some setup (through the kd-tree only where a beam misses the scene box:
  // its leaves fill it).
  CHECK(missed > 0);
}

}  // namespace

TEST_CASE(
    "beams over tiles on the GL device give the emulator's beam queries, hit ids, depths "
    "and image, and the image of beams off") {
  // 36x28 in 8x8 tiles: the last column and row of tiles are cut short; classic with one
  // bounce and its shadows, the bunny's primary rays alone.
  check_beams_on_gl(host::AccelKind::grid, {{"classic", 36, 28, 8, 1}, {"bunny-low", 32, 32, 4, 0}},
                    "beam march", "beam entry");
}

TEST_CASE(
    "beams through the BVH on the GL device give the emulator's descent queries, hit ids, "
    "depths and image, and the image of beams off") {
  // bunny-low's primary rays at 32x24 in 8x8 tiles, and classic with one bounce and its shadows
  // at 24x24 in 6x6 tiles (the step ends each primary ray's walk at its tile's node).
  check_beams_on_gl(host::AccelKind::bvh, {{"bunny-low", 32, 24, 8, 0}, {"classic", 24, 24, 6, 1}},
                    "bvh beam descend", "bvh beam enter");
}

TEST_CASE(
    "beams through the kd-tree on the GL device give the emulator's descent queries, hit ids, "
    "depths and image, and the image of beams off") {
  // As the BVH's: the descent is the same kernel on the kd-tree's boxes; the primary rays start
  // and restart at their tile's node, the shadow and reflected rays at the root.
  check_beams_on_gl(host::AccelKind::kdtree,
                    {{"bunny-low", 36, 28, 6, 0}, {"classic", 24, 24, 6, 1}}, "bvh beam descend",
                    "kd enter");
}

TEST_CASE(
    "beams over the two-level grid on the GL device give the emulator's march queries, hit ids, "
    "depths and image, and the image of beams off") {
  // The beams march over the coarse grid; the sphere's primary rays at 36x28 in 8x8 tiles, and
  // the teapot with one bounce and its shadows at 32x24 in 6x6 tiles (only primary rays start
  // past empty coarse cells).
  check_beams_on_gl(host::AccelKind::grid2, {{"sphere", 36, 28, 8, 0}, {"teapot", 32, 24, 6, 1}},
                    "beam march", "grid2 beam entry");
}
