// Beams over tiles (--beams on, host/trace/walks/grid_beams.h): the primary rays start where their
// tile's beam stopped, and every hit id, depth and image bit is the per-pixel rays' own, pass by
// pass and in batches, at tile sizes that cut the image's last tiles short, in jittered sample
// frames, and with the looping kernels (the march in one pass); the rays do start later (fewer
// voxel steps), and the beam passes are counted.
#include <doctest/doctest.h>

#include <string>

#include "host/accel/grid.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/stream_tracer.h"
#include "tests/support/bits.h"

using test_support::same_bits;

namespace {

uint64_t shaded_in(const vgpu::FrameStats& s, const std::string& program) {
  const auto* p = s.find(program);
  return p ? p->counters.fragments_shaded : 0;
}

host::RenderResult render(const host::Scene& scene, const host::Grid& grid, host::RenderOptions opt,
                          bool beams) {
  opt.beams = beams;
  host::StreamTracer tracer(scene, grid, opt);
  return tracer.render(host::scene_camera(scene));
}

struct Setup {
  const char* scene;
  int width, height, tile, bounces, spp;
  bool masks, batches;
  bool looping = false;
};

}  // namespace

TEST_CASE("beams over tiles give the per-pixel rays' hit ids, depths and images bit for bit") {
  // 44x36 with 8x8 tiles (and 12x12, 5x5): the last column and row of tiles are cut short.
  const Setup setups[] = {
      {"classic", 44, 36, 8, 0, 1, true, true},
      {"classic", 44, 36, 8, 1, 1, false, false},
      {"bunny-low", 44, 36, 12, 0, 1, true, false},
      {"hop", 40, 40, 5, 0, 1, true, true},
      {"bunny-low", 32, 32, 8, 0, 4, false, true},
      // The looping kernels: the march in one pass of its own loop.
      {"classic", 44, 36, 8, 1, 1, true, false, true},
      {"hop", 40, 40, 5, 0, 1, true, false, true},
  };
  for (const Setup& s : setups) {
    CAPTURE(s.scene);
    CAPTURE(s.tile);
    CAPTURE(s.batches);
    CAPTURE(s.looping);
    const host::Scene scene = host::load_scene(host::resolve_scene(s.scene));
    host::RenderOptions opt;
    opt.width = s.width;
    opt.height = s.height;
    opt.profile = "gf6600";
    opt.threads = 2;
    opt.bounces = s.bounces;
    opt.shadows = s.bounces > 0;
    opt.spp = s.spp;
    opt.masks = s.masks;
    opt.batch_walk = s.batches;
    opt.looping = s.looping;
    opt.beam_tile = s.tile;
    const host::Grid grid =
        host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile(opt.profile)));
    const host::RenderResult off = render(scene, grid, opt, false);
    const host::RenderResult on = render(scene, grid, opt, true);
    CHECK(same_bits(off.hit_id, on.hit_id));
    CHECK(same_bits(off.depth, on.depth));
    CHECK(same_bits(off.rgb, on.rgb));
    CHECK(off.beam_passes == 0);
    CHECK(on.beam_passes > 0);
    if (s.looping) CHECK(on.beam_passes == uint64_t(s.spp));  // one march pass a trace
    const uint64_t tiles = uint64_t((s.width + s.tile - 1) / s.tile) *
                           uint64_t((s.height + s.tile - 1) / s.tile) * uint64_t(s.spp);
    CHECK(on.beam_tiles == tiles);
    CHECK(on.beam_tiles_missed < tiles);
    // Under masks a pass charges only the rays still walking: rays that start where their
    // beam stopped take fewer voxel steps.
    if (s.masks && !s.looping)
      CHECK(shaded_in(on.stats, "traversal") < shaded_in(off.stats, "traversal"));
  }
}

TEST_CASE("a tile whose beam passes beside the grid is counted as missed, its rays hit nothing") {
  const host::Scene scene = host::load_scene(host::resolve_scene("bunny-low"));
  host::RenderOptions opt;
  opt.width = opt.height = 32;
  opt.profile = "gf6600";
  opt.threads = 2;
  opt.bounces = 0;
  opt.shadows = false;
  const host::Grid grid =
      host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile(opt.profile)));
  const host::RenderResult off = render(scene, grid, opt, false);
  const host::RenderResult on = render(scene, grid, opt, true);
  CHECK(same_bits(off.hit_id, on.hit_id));
  CHECK(on.beam_tiles == 16);
  // The bunny fills the middle of the frame: the corner tiles see only the background.
  CHECK(on.beam_tiles_missed > 0);
  uint64_t missing_pixels = 0;
  for (float id : off.hit_id) missing_pixels += id < 0;
  CHECK(missing_pixels >= on.beam_tiles_missed * 64);
}
