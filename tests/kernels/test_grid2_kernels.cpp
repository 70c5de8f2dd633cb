// Kernel tests for the two-level grid walk (kernels/grid2.h): inicioGrilla2, recorridoGrilla2
// (step within a sub-grid, descend into a coarse cell's sub-grid, climb back out, tied axes,
// leave the box), cargarCelda, interseccionesGrilla2, the fused --mrt on forms and the looping
// kernel, each run as real passes on a hand-made structure. Expected values worked out by hand.
//
// The coarse grid: box [0, 4] x [0, 2] x [0, 2], cells of 2, res 2x1x1 (coarse-cell texture 1
// texel wide, so cell 1 sits on the second row):
//   cell 0 (x in [0, 2]): sub-grid 2x2x1 (sub-cells of 1 x 1 x 2), sub-cells 0..3, x fastest
//   cell 1 (x in [2, 4]): 1x1x1, sub-cell 4
// Sub-cell texel (list start, coarse cell), 3 wide: 0 (0,0,0): empty; 1 (1,0,0): list 1;
// 2 (0,1,0): empty; 3 (1,1,0): list 1; 4: list 3. Lists: -1 | 0 -1 | 1 -1 (4 wide).
// Triangle 0 lies in the plane x = 1.5, corners (1.5, 0, 0), (1.5, 2, 0), (1.5, 0, 4): the
// points with y / 2 + z / 4 <= 1; triangle 1 the same at x = 3. At a hit, u = y / 2, v = z / 4.
#include <array>
#include <iterator>
#include <vector>

#include "kernel_pass.h"

namespace {

using kernels::kFar;
using kernels::kNone;
using ktest::any_w_at_least;
using ktest::any_x_at_least;
using ktest::check_same;
using ktest::scalars;
using ktest::texels;
using ktest::Texture;
using ktest::vec3s;

kernels::Grid2Uniforms g2_uniforms(float t_slack = 0) {
  kernels::Grid2Uniforms u;
  u.lo = glm::vec3(0.0f);
  u.cell = glm::vec3(2.0f);
  u.res = glm::vec3(2, 1, 1);
  u.cell_width = 1;
  u.sub_width = 3;
  u.list_width = 4;
  u.t_slack = t_slack;
  return u;
}

struct Structure {
  Texture cells = texels("grid2 cells", 1, 2, {{2, 2, 1, 0}, {1, 1, 1, 4}});
  Texture subs = texels("grid2 sub-cells", 3, 2,
                        {{0, 0, 0, 0}, {1, 0, 0, 0}, {0, 0, 0, 0}, {1, 0, 0, 0}, {3, 1, 0, 0}});
  Texture lists = scalars("grid2 lists", 4, 2, {kNone, 0, kNone, 1, kNone});
  Texture v0 = vec3s("vertices0", 1, 2, {{1.5f, 0, 0}, {3, 0, 0}});
  Texture v1 = vec3s("vertices1", 1, 2, {{1.5f, 2, 0}, {3, 2, 0}});
  Texture v2 = vec3s("vertices2", 1, 2, {{1.5f, 0, 4}, {3, 0, 4}});
};

struct Rays {
  Texture origins, rays;
  int n;
  Rays(const std::vector<glm::vec3>& o, const std::vector<glm::vec4>& d) : n(int(o.size())) {
    std::vector<glm::vec4> o4;
    for (const glm::vec3& p : o) o4.emplace_back(p, 0.0f);
    origins = texels("origins", n, 1, o4);
    rays = texels("rays", n, 1, d);
  }
};

const float kD = 0.70710677f;  // 1 / sqrt 2, the diagonal ray's components
const glm::vec4 kNoHit(kFar, 0, 0, kNone);
const glm::vec4 kDone(kNone, kNone, 0, 0);

// The rays of the walk tests:
//   0: +x from (-1, 0.5, 1): enters sub-cell 0 at t = 1 (empty), steps to 1: triangle 0, t 2.5
//   1: +x from (-1, 1.5, 0.5): sub-cell 2 (empty), then 3: triangle 0 at t = 2.5
//   2: +x from (-1, 1.9, 1.9): sub-cells 2, 3 (triangle 0 missed: 0.95 + 0.475 > 1), climbs to
//      cell 1 (sub-cell 4, triangle 1 missed), leaves the box: no hit
//   3: -x from (2.5, 0.5, 1): starts in cell 1 (triangle 1 behind it), climbs back into cell
//      0's last sub-cell along x (1): triangle 0 at t = 1
//   4: +x from (-1, 5, 1): passes above the box: done at once
//   5: (1, 1, 0) / sqrt 2 from (0.5, 0.5, 0.5): leaves sub-cell 0 through its edge x = y = 1,
//      steps both axes at once to 3: triangle 0 at t = sqrt 2
//   6: +x from (2.5, 0.5, 1): starts in cell 1: triangle 1 at t = 0.5
Rays walk_rays() {
  return Rays({{-1, 0.5f, 1},
               {-1, 1.5f, 0.5f},
               {-1, 1.9f, 1.9f},
               {2.5f, 0.5f, 1},
               {-1, 5, 1},
               {0.5f, 0.5f, 0.5f},
               {2.5f, 0.5f, 1}},
              {{1, 0, 0, 100},
               {1, 0, 0, 100},
               {1, 0, 0, 100},
               {-1, 0, 0, 100},
               {1, 0, 0, 100},
               {kD, kD, 0, 100},
               {1, 0, 0, 100}});
}

// Entry states by hand (sub-cell, list start, t in, t out).
const std::array<glm::vec4, 7> kEntries = {glm::vec4(0, 0, 1, 2),
                                           glm::vec4(2, 0, 1, 2),
                                           glm::vec4(2, 0, 1, 2),
                                           glm::vec4(4, 3, 0, 0.5f),
                                           kDone,
                                           glm::vec4(0, 0, 0, 0.5f / kD),
                                           glm::vec4(4, 3, 0, 1.5f)};

const glm::vec4 kHit0(2.5f, 0.25f, 0.25f, 0), kHit1(2.5f, 0.75f, 0.125f, 0),
    kHit3(1, 0.25f, 0.25f, 0), kHit5(1.0f / kD, 0.75f, 0.125f, 0), kHit6(0.5f, 0.25f, 0.25f, 1);

void check_hits(const Texture& isect) {
  CHECK_TEXEL_NEAR(isect, 0, 0, 1e-6, kHit0);
  CHECK_TEXEL_NEAR(isect, 1, 0, 1e-6, kHit1);
  CHECK_TEXEL(isect, 2, 0, kNoHit);
  CHECK_TEXEL_NEAR(isect, 3, 0, 1e-6, kHit3);
  CHECK_TEXEL(isect, 4, 0, kNoHit);
  CHECK_TEXEL_NEAR(isect, 5, 0, 1e-6, kHit5);
  CHECK_TEXEL_NEAR(isect, 6, 0, 1e-6, kHit6);
}

Texture enter(const Structure& s, const Rays& r) {
  kernels::Grid2Enter k;
  k.grid2 = g2_uniforms();
  return ktest::run(k, {&r.origins, &r.rays, &s.cells, &s.subs}, r.n, 1, glm::vec4(7));
}

struct State {
  Texture trav, vs, isect;
  int steps = 0;
};

// The multipass sequence of host/trace/walks/grid2_walk.cpp: enter, load the entry sub-cell, then
// the sub-cell's triangles one per pass until no ray tests, a step (and load) until no ray
// walks. With fused, the --mrt on forms.
State multipass(const Structure& t, const Rays& r, bool fused) {
  const kernels::Grid2Uniforms u = g2_uniforms(0.001f);
  kernels::Grid2Step step;
  step.grid2 = u;
  kernels::Grid2LoadCell load;
  load.grid2.list_width = u.list_width;
  kernels::Grid2Intersections isect;
  isect.grid2.t_slack = u.t_slack;
  isect.scene.width = 1;
  kernels::NextTriangle next;
  next.lists.list_width = u.list_width;
  kernels::Grid2StepLoad step_load;
  step_load.grid2 = u;
  kernels::Grid2IntersectNext isect_next;
  isect_next.grid2.t_slack = u.t_slack;
  isect_next.grid2.list_width = u.list_width;
  isect_next.scene.width = 1;
  State s{enter(t, r),
          texels("cell state", r.n, 1, std::vector<glm::vec4>(size_t(r.n), {0, 0, 0, kNone})),
          texels("intersection", r.n, 1, std::vector<glm::vec4>(size_t(r.n), kNoHit))};
  s.vs = ktest::run(load, {&s.trav, &s.vs, &t.lists}, r.n, 1);
  while (any_x_at_least(s.trav, r.n, 0)) {
    for (int k = 0; any_w_at_least(s.vs, r.n, 0); ++k) {
      REQUIRE(k < 4);
      if (fused) {
        auto o = ktest::run_targets(
            isect_next,
            {&r.origins, &r.rays, &s.trav, &s.vs, &s.isect, &t.v0, &t.v1, &t.v2, &t.lists}, r.n, 1);
        s.isect = o[0];
        s.vs = o[1];
      } else {
        s.isect = ktest::run(
            isect, {&r.origins, &r.rays, &s.trav, &s.vs, &s.isect, &t.v0, &t.v1, &t.v2}, r.n, 1);
        s.vs = ktest::run(next, {&s.vs, &t.lists}, r.n, 1);
      }
    }
    REQUIRE(++s.steps < 20);
    if (fused) {
      auto o = ktest::run_targets(
          step_load, {&r.origins, &r.rays, &s.trav, &s.isect, &s.vs, &t.cells, &t.subs, &t.lists},
          r.n, 1);
      s.trav = o[0];
      s.vs = o[1];
    } else {
      s.trav =
          ktest::run(step, {&r.origins, &r.rays, &s.trav, &s.isect, &t.cells, &t.subs}, r.n, 1);
      s.vs = ktest::run(load, {&s.trav, &s.vs, &t.lists}, r.n, 1);
    }
  }
  return s;
}

}  // namespace

TEST_CASE("grid2 enter descends from the coarse cell of the entry point into its sub-cell") {
  const Structure s;
  const Rays r = walk_rays();
  const Texture out = enter(s, r);
  for (int i = 0; i < r.n; ++i) {
    CAPTURE(i);
    CHECK_TEXEL(out, i, 0, kEntries[size_t(i)]);
  }
}

TEST_CASE("grid2 step moves within a sub-grid, descends into the next cell, climbs and ends") {
  const Structure s;
  // Rays 0-6 of walk_rays from their entry states; ray 6 has a hit in its sub-cell; and ray 2
  // twice more: at sub-cell 3 (leaving cell 0's sub-grid along +x) and at sub-cell 4 (leaving
  // the box).
  Rays r({{-1, 0.5f, 1},
          {-1, 1.5f, 0.5f},
          {-1, 1.9f, 1.9f},
          {2.5f, 0.5f, 1},
          {-1, 5, 1},
          {0.5f, 0.5f, 0.5f},
          {2.5f, 0.5f, 1},
          {-1, 1.9f, 1.9f}},
         {{1, 0, 0, 100},
          {1, 0, 0, 100},
          {1, 0, 0, 100},
          {-1, 0, 0, 100},
          {1, 0, 0, 100},
          {kD, kD, 0, 100},
          {1, 0, 0, 100},
          {1, 0, 0, 100}});
  const Texture trav = texels("traversal", r.n, 1,
                              {kEntries[0],
                               kEntries[1],
                               {3, 1, 2, 3},
                               kEntries[3],
                               kDone,
                               kEntries[5],
                               kEntries[6],
                               {4, 3, 3, 5}});
  std::vector<glm::vec4> hits(size_t(r.n), kNoHit);
  hits[6] = kHit6;
  const Texture isect = texels("intersection", r.n, 1, hits);
  kernels::Grid2Step k;
  k.grid2 = g2_uniforms();
  const Texture out =
      ktest::run(k, {&r.origins, &r.rays, &trav, &isect, &s.cells, &s.subs}, r.n, 1);
  // 0: sub-cell 0 to 1 along +x (the x boundary 1 at t = 2, the next at 2: t = 3).
  CHECK_TEXEL(out, 0, 0, glm::vec4(1, 1, 2, 3));
  // 1: sub-cell 2 (x 0, y 1) to 3.
  CHECK_TEXEL(out, 1, 0, glm::vec4(3, 1, 2, 3));
  // 2 at sub-cell 3: x would reach 2, past cell 0's sub-grid: cell 1, its sub-cell 4 (x 2 to 4:
  // t 3 to 5).
  CHECK_TEXEL(out, 2, 0, glm::vec4(4, 3, 3, 5));
  // 3: -x out of cell 1 at x = 2 (t 0.5): cell 0, the last sub-cell along x (1), y 0.5 gives
  // row 0: sub-cell 1, to x = 1 at t = 1.5.
  CHECK_TEXEL(out, 3, 0, glm::vec4(1, 1, 0.5f, 1.5f));
  CHECK_TEXEL(out, 4, 0, kDone);  // done rays keep their state
  // 5: x and y tie at t = 0.5 / d: both step, to sub-cell 3, which it leaves at x = y = 2.
  CHECK_TEXEL(out, 5, 0, glm::vec4(3, 1, 0.5f / kD, 1.5f / kD));
  CHECK_TEXEL(out, 6, 0, kDone);  // a hit inside the sub-cell ends the walk
  CHECK_TEXEL(out, 7, 0, kDone);  // sub-cell 4 along +x leaves the box
}

TEST_CASE("grid2 step ends a ray whose next sub-cell begins past its tmax, less the slack") {
  // Ray 0 of walk_rays (+x from (-1, 0.5, 1), in sub-cell 0 from t = 1) leaves it at t = 2;
  // with the slack 0.5 a hit further on has t >= 1.5, so tmax 1.5 or less ends the walk there
  // (a shadow ray whose light lies before), a larger one steps into sub-cell 1 as before.
  const Structure s;
  Rays r({{-1, 0.5f, 1}, {-1, 0.5f, 1}, {-1, 0.5f, 1}, {-1, 0.5f, 1}},
         {{1, 0, 0, 1.5f}, {1, 0, 0, 1.2f}, {1, 0, 0, 1.6f}, {1, 0, 0, kFar}});
  const Texture trav = texels("traversal", r.n, 1, std::vector<glm::vec4>(4, kEntries[0]));
  const Texture isect = texels("intersection", r.n, 1, std::vector<glm::vec4>(4, kNoHit));
  kernels::Grid2Step k;
  k.grid2 = g2_uniforms(0.5f);
  const Texture out =
      ktest::run(k, {&r.origins, &r.rays, &trav, &isect, &s.cells, &s.subs}, r.n, 1);
  CHECK_TEXEL(out, 0, 0, kDone);
  CHECK_TEXEL(out, 1, 0, kDone);
  CHECK_TEXEL(out, 2, 0, glm::vec4(1, 1, 2, 3));
  CHECK_TEXEL(out, 3, 0, glm::vec4(1, 1, 2, 3));
}

TEST_CASE("grid2 load cell loads the first triangle of a sub-cell just entered") {
  const Structure s;
  const Texture trav = texels("traversal", 4, 1, {{1, 1, 2, 3}, {0, 0, 1, 2}, kDone, {4, 3, 0, 1}});
  const Texture vs = texels("cell state", 4, 1,
                            {{0, 0, 0, kNone}, {0, 0, 0, kNone}, {0, 0, 0, kNone}, {1, 0, 0, 0}});
  kernels::Grid2LoadCell k;
  k.grid2.list_width = 4;
  const Texture out = ktest::run(k, {&trav, &vs, &s.lists}, 4, 1);
  CHECK_TEXEL(out, 0, 0, glm::vec4(1, 0, 0, 0));      // list 1: triangle 0
  CHECK_TEXEL(out, 1, 0, glm::vec4(0, 0, 0, kNone));  // empty: the shared -1
  CHECK_TEXEL(out, 2, 0, glm::vec4(0, 0, 0, kNone));  // done: kept
  CHECK_TEXEL(out, 3, 0, glm::vec4(1, 0, 0, 0));      // still testing a list: kept
}

TEST_CASE("grid2 intersections keep a hit only inside the sub-cell's segment") {
  const Structure s;
  // Ray 0 of walk_rays meets triangle 0 at t = 2.5: inside [2, 3], outside [1, 2] and [3, 4].
  const Rays r({{-1, 0.5f, 1}, {-1, 0.5f, 1}, {-1, 0.5f, 1}},
               {{1, 0, 0, 100}, {1, 0, 0, 100}, {1, 0, 0, 100}});
  const Texture trav = texels("traversal", 3, 1, {{1, 1, 2, 3}, {0, 1, 1, 2}, {4, 1, 3, 4}});
  const Texture vs = texels("cell state", 3, 1, {{1, 0, 0, 0}, {1, 0, 0, 0}, {1, 0, 0, 0}});
  const Texture best = texels("intersection", 3, 1, {kNoHit, kNoHit, kNoHit});
  kernels::Grid2Intersections k;
  k.scene.width = 1;
  const Texture out =
      ktest::run(k, {&r.origins, &r.rays, &trav, &vs, &best, &s.v0, &s.v1, &s.v2}, 3, 1);
  CHECK_TEXEL_NEAR(out, 0, 0, 1e-6, kHit0);
  CHECK_TEXEL(out, 1, 0, kNoHit);
  CHECK_TEXEL(out, 2, 0, kNoHit);
}

TEST_CASE("the grid2 walk's single passes in sequence find each ray's hit") {
  const Structure t;
  const Rays r = walk_rays();
  const State s = multipass(t, r, false);
  check_hits(s.isect);
  for (int i = 0; i < r.n; ++i) CHECK_TEXEL(s.trav, i, 0, kDone);
  // Ray 2: sub-cells 2, 3, 4, then out of the box: 3 steps, the most of any ray.
  CHECK(s.steps == 3);
}

TEST_CASE("fused grid2 step + load and intersections + next triangle walk to the same state") {
  const Structure t;
  const Rays r = walk_rays();
  const State m = multipass(t, r, false), f = multipass(t, r, true);
  check_hits(f.isect);
  CHECK(f.steps == m.steps);
  check_same(f.trav, m.trav, r.n);
  check_same(f.vs, m.vs, r.n);
  check_same(f.isect, m.isect, r.n);
}

TEST_CASE("the grid2 looping kernel ends in the multipass walk's hits and traversal state") {
  const Structure t;
  const Rays r = walk_rays();
  const State m = multipass(t, r, false);
  // Entered and loaded, then one looping pass of enough iterations.
  kernels::Grid2LoadCell load;
  load.grid2.list_width = 4;
  const Texture trav = enter(t, r);
  const Texture vs0 =
      texels("cell state", r.n, 1, std::vector<glm::vec4>(size_t(r.n), {0, 0, 0, kNone}));
  const Texture vs = ktest::run(load, {&trav, &vs0, &t.lists}, r.n, 1);
  const Texture isect = texels("intersection", r.n, 1, std::vector<glm::vec4>(size_t(r.n), kNoHit));
  kernels::Grid2Looping k;
  k.grid2 = g2_uniforms(0.001f);
  k.scene.width = 1;
  k.steps = 32;
  const vgpu::KernelProgram<kernels::Grid2Looping> p(k);
  vgpu::Gpu gpu(vgpu::profile("gf6600"), 1, 1);
  Texture o_trav{"traversal out", r.n, 1, 4}, o_vs{"cell state out", r.n, 1, 4},
      o_isect{"intersection out", r.n, 1, 4};
  gpu.use_program(p);
  gpu.unbind_textures();
  const Texture* units[] = {&r.origins, &r.rays, &trav,    &vs,     &isect,  &t.v0,
                            &t.v1,      &t.v2,   &t.cells, &t.subs, &t.lists};
  for (int u = 0; u < 11; ++u) gpu.bind_texture(u, *units[u]);
  const std::vector<Texture> before = ktest::before_pass({&o_trav, &o_vs, &o_isect});
  gpu.set_targets({&o_trav, &o_vs, &o_isect});
  gpu.draw();
  if (ktest::gl_check()) {
    ktest::check_on_gl(p, {std::begin(units), std::end(units)}, before, {&o_trav, &o_vs, &o_isect},
                       nullptr);
  }
  check_same(o_isect, m.isect, r.n);
  check_same(o_trav, m.trav, r.n);
}
