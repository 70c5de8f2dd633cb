// Beams over tiles through the trees and the two-level grid (--beams on): through the BVH and the
// kd-tree (host/trace/walks/bvh_beams.h) each tile's beam descends to the first node it cannot
// narrow down and the pixels' rays walk only that node's subtree (through the kd-tree, they start
// and restart there); over the two-level grid's coarse grid (kernels/grid2_beams.h) the beams
// march and the rays start at the sub-cell their walk reaches there. Every hit id, depth and image
// bit is the per-pixel rays' own, pass by pass and in batches, multipass (one pass and fused) and
// looping, at a tile size that cuts the last tiles short, with shadow and reflected rays beside
// (they walk from the root, or from where they enter). The beam passes are counted, and the rays
// visit fewer nodes or take fewer steps.
#include <doctest/doctest.h>

#include <string>
#include <utility>

#include "host/accel/accel.h"
#include "host/trace/stream/stream_tracer.h"
#include "tests/support/bits.h"
#include "tests/support/structures.h"

using test_support::same_bits;

namespace {

uint64_t shaded_in(const vgpu::FrameStats& s, const std::string& program) {
  const auto* p = s.find(program);
  return p ? p->counters.fragments_shaded : 0;
}

// One setup: a structure over a bundled scene at 44x36, its tile size, how the walk runs, and
// whether secondary rays (a bounce and shadows) go beside the primary ones.
struct Setup {
  host::AccelKind kind;
  const char* scene;
  int tile;
  bool batches, looping, mrt, secondary;
};

// The frame of `s` under masks with beams off and on, checked the same bit for bit (hit ids,
// depths, image), its beam passes counted, and each tile counted (none missing more than all).
std::pair<host::RenderResult, host::RenderResult> render_off_on(const Setup& s) {
  CAPTURE(host::accel_name(s.kind));
  CAPTURE(s.scene);
  CAPTURE(s.tile);
  CAPTURE(s.batches);
  CAPTURE(s.looping);
  CAPTURE(s.mrt);
  const test_support::Structures st =
      test_support::bundled_structures(s.kind, s.scene, 44, 36, "gf6600");
  host::RenderOptions opt;
  opt.width = 44;
  opt.height = 36;
  opt.profile = "gf6600";
  opt.threads = 2;
  opt.bounces = s.secondary ? 1 : 0;
  opt.shadows = s.secondary;
  opt.masks = true;
  opt.batch_walk = s.batches;
  opt.looping = s.looping;
  opt.mrt = s.mrt;
  opt.beam_tile = s.tile;
  host::RenderResult off, on;
  {
    host::StreamTracer tracer(st.scene, st.accel(), opt);
    off = tracer.render(st.camera);
  }
  opt.beams = true;
  {
    host::StreamTracer tracer(st.scene, st.accel(), opt);
    on = tracer.render(st.camera);
  }
  CHECK(same_bits(off.hit_id, on.hit_id));
  CHECK(same_bits(off.depth, on.depth));
  CHECK(same_bits(off.rgb, on.rgb));
  CHECK(off.beam_passes == 0);
  CHECK(on.beam_passes > 0);
  const uint64_t tiles =
      uint64_t((44 + s.tile - 1) / s.tile) * uint64_t((36 + s.tile - 1) / s.tile);
  CHECK(on.beam_tiles == tiles);
  CHECK(on.beam_tiles_missed < tiles);
  return {off, on};
}

}  // namespace

TEST_CASE(
    "beams through the bvh and the kd-tree give the per-pixel rays' hit ids, depths and images bit "
    "for bit") {
  using host::AccelKind;
  const Setup setups[] = {{AccelKind::bvh, "classic", 8, true, false, false, false},
                          {AccelKind::bvh, "classic", 8, false, false, false, false},
                          {AccelKind::bvh, "bunny-low", 6, true, false, false, false},
                          {AccelKind::bvh, "bunny-low", 8, false, true, false, false},
                          {AccelKind::kdtree, "classic", 8, true, false, false, true},
                          {AccelKind::kdtree, "classic", 8, false, false, true, false},
                          {AccelKind::kdtree, "bunny-low", 6, true, false, false, false},
                          {AccelKind::kdtree, "bunny-low", 8, false, true, false, true}};
  for (const Setup& s : setups) {
    CAPTURE(host::accel_name(s.kind));
    CAPTURE(s.scene);
    const auto [off, on] = render_off_on(s);
    // A kd-tree's leaves fill the scene box, so through it a tile misses only where its beam
    // misses the box, which classic's room, filling the view, never does.
    if (s.kind == AccelKind::bvh || std::string(s.scene) != "classic")
      CHECK(on.beam_tiles_missed > 0);
    // Under masks a pass charges only the rays still walking: rays that start below the root,
    // or not at all, visit fewer nodes.
    const std::string step = s.kind == AccelKind::bvh ? "bvh step"
                             : s.mrt                  ? "kd step + load leaf"
                                                      : "kd step";
    if (!s.looping) CHECK(shaded_in(on.stats, step) < shaded_in(off.stats, step));
  }
}

TEST_CASE(
    "beams over the two-level grid's coarse grid give the per-pixel rays' hit ids, depths and "
    "images bit for bit") {
  using host::AccelKind;
  // Scenes whose beams cross empty coarse cells at this size (classic's beams stop where they
  // stand: its rays start where they enter, and its frame is checked too).
  const Setup setups[] = {{AccelKind::grid2, "sphere", 8, true, false, false, false},
                          {AccelKind::grid2, "sphere", 5, false, false, true, true},
                          {AccelKind::grid2, "teapot", 8, false, true, false, false},
                          {AccelKind::grid2, "teapot", 6, true, false, false, true},
                          {AccelKind::grid2, "classic", 8, false, false, false, true}};
  for (const Setup& s : setups) {
    CAPTURE(s.scene);
    CAPTURE(s.tile);
    const auto [off, on] = render_off_on(s);
    if (s.looping) CHECK(on.beam_passes == 1);  // the march in one pass
    // Under masks a pass charges only the rays still walking: rays that start past empty coarse
    // cells take fewer steps.
    const std::string step = s.mrt ? "grid2 step + load cell" : "grid2 step";
    if (s.looping) continue;
    if (std::string(s.scene) == "classic")
      CHECK(shaded_in(on.stats, step) == shaded_in(off.stats, step));
    else
      CHECK(shaded_in(on.stats, step) < shaded_in(off.stats, step));
  }
}
