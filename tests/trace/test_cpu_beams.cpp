// Beams over tiles in the CPU tracer (--engine cpu --beams on, host/trace/cpu/cpu_beams.h): the
// beams are the emulator's (the same tiles, misses and passes), every hit id, depth and image bit
// is the per-pixel rays' own, the walks take fewer voxel steps (through the BVH: fewer nodes);
// and the 3D-DDA moved on where a beam stopped is in the state the walk itself reaches there, bit
// for bit.
#include <doctest/doctest.h>

#include <cmath>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "host/accel/accel.h"
#include "host/accel/grid.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/cpu/cpu_beams.h"
#include "host/trace/cpu/cpu_tracer.h"
#include "host/trace/stream/stream_tracer.h"
#include "tests/support/bits.h"

using test_support::same_bits;

TEST_CASE(
    "the CPU tracer's beams, through the grid, the two-level grid, the BVH and the kd-tree, give "
    "the per-pixel rays' hit ids, depths and images, fewer steps, and the emulator's beam "
    "counts") {
  struct Setup {
    const char* scene;
    int width, height, tile, bounces, spp;
  };
  // 36x28 in 8x8 tiles: the last tiles are cut short; classic with a bounce and shadows (only
  // primary rays start where their beam stopped); the bunny's primary rays in 4x4 tiles; and
  // four jittered samples a pixel (a beam map each). Over the two-level grid's coarse grid, the
  // sphere and the teapot in their place (classic's and the bunny's coarse cells next to the eye
  // hold triangles: their rays start where they enter).
  std::map<host::AccelKind, uint64_t> missed;
  const std::vector<Setup> scenes{
      {"classic", 36, 28, 8, 1, 1}, {"bunny-low", 32, 32, 4, 0, 1}, {"bunny-low", 16, 16, 4, 0, 4}};
  const std::vector<Setup> coarse{
      {"sphere", 36, 28, 8, 1, 1}, {"teapot", 32, 32, 4, 0, 1}, {"sphere", 16, 16, 4, 0, 4}};
  for (const host::AccelKind kind : host::kAccelKinds)
    for (const Setup& s : kind == host::AccelKind::grid2 ? coarse : scenes) {
      const std::string name = s.scene;
      CAPTURE(name);
      CAPTURE(s.spp);
      CAPTURE(int(kind));
      const host::Scene scene = host::load_scene(host::resolve_scene(s.scene));
      const host::Camera camera = host::scene_camera(scene);
      host::RenderOptions opt;
      opt.width = s.width;
      opt.height = s.height;
      opt.threads = 2;
      opt.bounces = s.bounces;
      opt.shadows = s.bounces > 0;
      opt.spp = s.spp;
      opt.beam_tile = s.tile;
      const auto accel = host::make_accel(
          kind, scene,
          host::AccelParams{host::grid_spec_for({}, scene, vgpu::profile(opt.profile))});
      host::CpuStats off_stats, on_stats;
      const host::RenderResult off = host::render_cpu(scene, *accel, camera, opt, &off_stats);
      opt.beams = true;
      const host::RenderResult on = host::render_cpu(scene, *accel, camera, opt, &on_stats);
      CHECK(same_bits(off.hit_id, on.hit_id));
      CHECK(same_bits(off.depth, on.depth));
      CHECK(same_bits(off.rgb, on.rgb));
      CHECK(on.rays_traced == off.rays_traced);
      CHECK(on_stats.triangle_tests == off_stats.triangle_tests);
      // The rays start later (the grids: fewer voxels or sub-cells stepped through) or lower in
      // the tree (the BVH and the kd-tree: fewer nodes visited).
      const bool grid = kind == host::AccelKind::grid || kind == host::AccelKind::grid2;
      if (grid)
        CHECK(on_stats.voxel_steps < off_stats.voxel_steps);
      else
        CHECK(on_stats.nodes_visited < off_stats.nodes_visited);
      CHECK(off_stats.beam_tiles == 0);
      // The emulator runs the same beams (the same kernel, the same floats).
      host::StreamTracer tracer(scene, *accel, opt);
      const host::RenderResult gpu = tracer.render(camera);
      const uint64_t tiles = uint64_t((s.width + s.tile - 1) / s.tile) *
                             uint64_t((s.height + s.tile - 1) / s.tile) * uint64_t(s.spp);
      CHECK(on_stats.beam_tiles == tiles);
      CHECK(gpu.beam_tiles == tiles);
      CHECK(on_stats.beam_tiles_missed == gpu.beam_tiles_missed);
      CHECK(on_stats.beam_passes == gpu.beam_passes);
      // Through a tree, the depths the tiles' beams reached, as the descent's queries count them.
      if (!grid) {
        CHECK(on.beam_depth_sum == gpu.beam_depth_sum);
        CHECK(on.beam_depth_max == gpu.beam_depth_max);
        CHECK(on.beam_depth_max > 0);
      }
      CHECK(on.beam_passes == gpu.beam_passes);
      CHECK(on_stats.beam_passes > 1);
      missed[kind] += on_stats.beam_tiles_missed;
      CHECK(on_stats.beam_steps > on_stats.beam_tiles);
    }
  // Whole tiles miss somewhere through each structure. Through the kd-tree only where a beam
  // misses the scene box (the leaves fill it): classic's room, filling the view, never does.
  for (const auto& [bound_kind, bound_n] : missed) {
    // Named copies: clang 14 cannot capture a structured binding (CAPTURE, INFO).
    const auto& kind = bound_kind;
    const auto& n = bound_n;
    CAPTURE(int(kind));
    CHECK(n > 0);
  }
}

namespace {

// One voxel of the CPU tracer's 3D-DDA: the voxel, the next boundary per axis, the entry.
struct DdaState {
  glm::ivec3 vox{0};
  glm::dvec3 t_next{0.0};
  double t_enter = 0;
};

// The CPU tracer's walk (host/trace/cpu/cpu_tracer.cpp, Tracer::trace) from the grid's entry,
// written out again: the state at every voxel it visits, and its set-up (step, delta).
std::vector<DdaState> walk(const host::Grid& g, const glm::dvec3& o, const glm::dvec3& d,
                           glm::ivec3& step, glm::dvec3& t_delta) {
  double tnear = 0.0, tfar = INFINITY;
  for (int a = 0; a < 3; ++a) {
    double t0 = (g.boundary(a, 0) - o[a]) / d[a], t1 = (g.boundary(a, g.res[a]) - o[a]) / d[a];
    if (t0 > t1) std::swap(t0, t1);
    tnear = std::max(tnear, t0);
    tfar = std::min(tfar, t1);
  }
  std::vector<DdaState> states;
  if (!(tnear <= tfar)) return states;
  DdaState s{g.voxel_of(o + d * tnear), glm::dvec3(INFINITY), tnear};
  for (int a = 0; a < 3; ++a) {
    step[a] = d[a] > 0.0 ? 1 : -1;
    s.t_next[a] = (g.boundary(a, s.vox[a] + (d[a] > 0.0 ? 1 : 0)) - o[a]) / d[a];
    t_delta[a] = double(g.cell[a]) / std::abs(d[a]);
  }
  for (;;) {
    states.push_back(s);
    const double t_exit = std::min({s.t_next.x, s.t_next.y, s.t_next.z});
    bool outside = false;
    for (int a = 0; a < 3; ++a) {
      if (s.t_next[a] != t_exit) continue;
      s.vox[a] += step[a];
      s.t_next[a] += t_delta[a];
      outside = outside || s.vox[a] < 0 || s.vox[a] >= g.res[a];
    }
    if (outside) return states;
    s.t_enter = t_exit;
  }
}

}  // namespace

TEST_CASE(
    "a 3D-DDA moved on to where a beam stopped is in the walk's own state there, bit for "
    "bit, or not moved") {
  host::Grid g;
  g.lo = {-1.3f, 0.2f, -4.0f};
  g.res = {9, 7, 11};
  g.cell = {0.37f, 0.61f, 0.29f};
  g.hi = g.lo + g.cell * glm::vec3(g.res);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int moved = 0, asked = 0;
  for (int ray = 0; ray < 200; ++ray) {
    // From outside the box towards a point inside it.
    const glm::dvec3 mid = (glm::dvec3(g.lo) + glm::dvec3(g.hi)) * 0.5;
    const glm::dvec3 o = mid + glm::normalize(glm::dvec3(u(rng), u(rng), u(rng))) * 9.0;
    const glm::dvec3 aim = mid + glm::dvec3(u(rng), u(rng), u(rng)) * 1.2;
    const glm::dvec3 d = glm::normalize(aim - o);
    glm::ivec3 step(0);
    glm::dvec3 t_delta(0.0);
    const std::vector<DdaState> states = walk(g, o, d, step, t_delta);
    REQUIRE(states.size() > 1);
    for (size_t k = 0; k < states.size(); ++k) {
      const glm::dvec3& next = states[k].t_next;
      const double t_exit = std::min({next.x, next.y, next.z});
      // A point in the middle of the ray's piece in voxel k.
      const double ts = 0.5 * (states[k].t_enter + t_exit);
      DdaState s = states[0];
      ++asked;
      if (!host::cpu_dda_skip(g, o, d, ts, s.vox, step, s.t_next, t_delta, s.t_enter)) {
        // Not moved: the walk's entry state, untouched.
        CHECK(s.vox == states[0].vox);
        CHECK(same_bits(s.t_next, states[0].t_next));
        CHECK(same_bits(s.t_enter, states[0].t_enter));
        continue;
      }
      ++moved;
      CAPTURE(ray);
      CAPTURE(k);
      CHECK(s.vox == states[k].vox);
      CHECK(same_bits(s.t_next, states[k].t_next));
      CHECK(same_bits(s.t_enter, states[k].t_enter));
    }
    // A point behind the entry moves nothing.
    DdaState s = states[0];
    CHECK_FALSE(host::cpu_dda_skip(g, o, d, states[0].t_enter * 0.5, s.vox, step, s.t_next, t_delta,
                                   s.t_enter));
  }
  // Only the entry voxel itself (nothing to skip) and pieces shorter than rounding stay put.
  CHECK(moved > asked * 8 / 10);
}
