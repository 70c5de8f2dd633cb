// Kernel test for beams over the two-level grid (kernels/grid2_beams.h): inicioHazGrilla2 starts
// each ray at the sub-cell the walk's own steps (recorridoGrilla2) reach in the coarse cell
// holding the ray's point at its tile's t, bit for bit, in every channel; where the tile missed,
// the ray is done; where the point lies before the box, the ray enters as inicioGrilla2 has it.
// Real passes on a hand-made structure, with one-pixel tiles so that each ray has its own t.
//
// The coarse grid: box [0, 4] x [0, 2] x [0, 1], unit cells, res 4x2x1 (cell x + 4y). Every cell
// is empty (a one-cell sub-grid) but cell 3, whose sub-grid is 2x2x1 (sub-cells of 0.5 x 0.5 x
// 1). Sub-cells: cells 0-2 -> 0-2, cell 3 -> 3-6 (x fastest), cells 4-7 -> 7-10.
#include <vector>

#include "kernel_pass.h"

namespace {

using kernels::kFar;
using kernels::kNone;
using ktest::texels;
using ktest::Texture;

kernels::Grid2Uniforms uniforms() {
  kernels::Grid2Uniforms u;
  u.lo = glm::vec3(0.0f);
  u.cell = glm::vec3(1.0f);
  u.res = glm::vec3(4, 2, 1);
  u.cell_width = 8;
  u.sub_width = 11;
  u.list_width = 3;
  return u;
}

struct Structure {
  Texture cells = texels("grid2 cells", 8, 1,
                         {{1, 1, 1, 0},
                          {1, 1, 1, 1},
                          {1, 1, 1, 2},
                          {2, 2, 1, 3},
                          {1, 1, 1, 7},
                          {1, 1, 1, 8},
                          {1, 1, 1, 9},
                          {1, 1, 1, 10}});
  Texture subs = texels("grid2 sub-cells", 11, 1,
                        {{0, 0, 0, 0},
                         {0, 1, 0, 0},
                         {0, 2, 0, 0},
                         {1, 3, 0, 0},
                         {1, 3, 0, 0},
                         {1, 3, 0, 0},
                         {1, 3, 0, 0},
                         {0, 4, 0, 0},
                         {0, 5, 0, 0},
                         {0, 6, 0, 0},
                         {0, 7, 0, 0}});
};

glm::vec3 unit(glm::vec3 v) {
  return v / std::sqrt(glm::dot(v, v));
}

}  // namespace

TEST_CASE(
    "grid2 beam entry starts a ray at the sub-cell the walk's steps reach where its tile's beam "
    "stopped, or where it enters") {
  const Structure st;
  const kernels::Grid2Uniforms u = uniforms();
  const glm::vec3 from_left(-1, 0.3f, 0.5f), from_right(5, 1.5f, 0.5f);
  // Per ray: origin, direction, its beam texel (x -1: stopped; y = t; z = 1: missed), and the
  // sub-cell the walk must stand in (-1: the entry state, -2: done).
  struct Case {
    glm::vec3 o, d;
    glm::vec4 beam;
    float sub;
  };
  const std::vector<Case> cases = {
      // Along +x through cells 0 and 1, stopped in cell 2 (x 2.5).
      {from_left, unit({1, 0.02f, 0}), {-1, 3.5f, 0, 3}, 2},
      // Stopped inside the crowded cell 3 (x 3.3, y 0.39): its sub-cell (0, 0), entered across
      // its x face from cell 2 (the step's first sub-cell along x, the point's along y).
      {from_left, unit({1, 0.02f, 0}), {-1, 4.3f, 0, 4}, 3},
      // Climbing: the ray crosses y = 1 at x = 1.8 and stops in cell 6 (x 2.5, y 1.18).
      {from_left, unit({1, 0.25f, 0}), {-1, 3.6f, 0, 3}, 9},
      // The whole tile missed: done, though the ray enters the box.
      {from_left, unit({1, 0.02f, 0}), {-1, 1e30f, 1, 2}, -2},
      // Stopped before the box (x -0.5): it enters as inicioGrilla2 has it.
      {from_left, unit({1, 0.02f, 0}), {-1, 0.5f, 0, 1}, -1},
      // Parallel to y and z (they cannot change): stopped in cell 1.
      {from_left, {1, 0, 0}, {-1, 2.5f, 0, 2}, 1},
      // No ray (tmax -1): done.
      {from_left, unit({1, 0.02f, 0}), {-1, 3.5f, 0, 3}, -2},
      // Along -x from the right, through cells 7 and 6 (entered at their last sub-cell along x),
      // stopped in cell 5 (x 1.4, y 1.43).
      {from_right, unit({-1, -0.02f, 0}), {-1, 3.6f, 0, 3}, 8},
      // Stopped in the cell where it enters: nothing to skip, the entry state.
      {from_left, unit({1, 0.02f, 0}), {-1, 1.5f, 0, 1}, -1},
  };
  const int n = int(cases.size());
  std::vector<glm::vec4> o, d, b;
  for (size_t i = 0; i < cases.size(); ++i) {
    o.emplace_back(cases[i].o, 0.0f);
    d.emplace_back(cases[i].d, i == 6 ? kNone : kFar);
    b.push_back(cases[i].beam);
  }
  const Texture origins = texels("origins", n, 1, o), rays = texels("rays", n, 1, d),
                beams = texels("beams", n, 1, b);
  kernels::Grid2BeamEntry k;
  k.beams.tile = 1;
  k.grid2 = u;
  const Texture out =
      ktest::run(k, {&origins, &rays, &beams, &st.cells, &st.subs}, n, 1, glm::vec4(7));
  // The references: inicioGrilla2, then recorridoGrilla2 with no hit until every ray is done.
  kernels::Grid2Enter enter;
  enter.grid2 = u;
  const Texture entered =
      ktest::run(enter, {&origins, &rays, &st.cells, &st.subs}, n, 1, glm::vec4(7));
  kernels::Grid2Step step;
  step.grid2 = u;
  const Texture no_hit =
      texels("intersection", n, 1, std::vector<glm::vec4>(size_t(n), {kFar, 0, 0, kNone}));
  std::vector<Texture> walk{entered};
  for (int i = 0; i < 12; ++i)
    walk.push_back(
        ktest::run(step, {&origins, &rays, &walk.back(), &no_hit, &st.cells, &st.subs}, n, 1));
  const glm::vec4 done(kNone, kNone, 0, 0);
  for (int i = 0; i < n; ++i) {
    CAPTURE(i);
    const Case& c = cases[size_t(i)];
    if (c.sub == -2) {
      CHECK_TEXEL(out, i, 0, done);
    } else if (c.sub == -1) {
      CHECK_TEXEL(out, i, 0, ktest::at(entered, i, 0));
      CHECK(ktest::at(entered, i, 0).x >= 0);
    } else {
      // The walk's first state in that sub-cell, every channel bit for bit, past the entry.
      const Texture* reached = nullptr;
      for (const Texture& s : walk)
        if (ktest::at(s, i, 0).x == c.sub) {
          reached = &s;
          break;
        }
      REQUIRE(reached != nullptr);
      CHECK(reached != &walk[0]);
      CHECK_TEXEL(out, i, 0, ktest::at(*reached, i, 0));
    }
  }
}
