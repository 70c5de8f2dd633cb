// Kernel tests for the object-space decision of adaptive sampling (kernels/cones.h):
// guardarConos, guardarReflejos and marcarConos, each run as one real pass on hand-made texels.
#include <doctest/doctest.h>

#include "kernel_pass.h"
#include "kernels/cones.h"

using ktest::texels;
using ktest::Texture;

namespace {

// Four triangles' materials in one row: triangle i has material 10 + i.
Texture materials() {
  return texels("triangle materials", 4, 1,
                {{10, 0, 0, 0}, {11, 0, 0, 0}, {12, 0, 0, 0}, {13, 0, 0, 0}});
}

}  // namespace

TEST_CASE("keep cones writes a candidate, the hit's material and distance, or a miss's -1 and 0") {
  // Three pixels: triangle 2 at t 7.5, triangle 0 at t 3.25, a miss (w -1, t far).
  const Texture isect = texels("intersection", 3, 1,
                               {{7.5f, 0.2f, 0.3f, 2}, {3.25f, 0.1f, 0.1f, 0}, {1e30f, 0, 0, -1}});
  const Texture mats = materials();
  kernels::KeepCones k;
  k.scene = {4.0f};
  const Texture out = ktest::run(k, {&isect, &mats}, 3, 1, glm::vec4(9.0f));
  CHECK_TEXEL(out, 0, 0, glm::vec4(1, 12, 7.5f, -1));
  CHECK_TEXEL(out, 1, 0, glm::vec4(1, 10, 3.25f, -1));
  CHECK_TEXEL(out, 2, 0, glm::vec4(1, -1, 0, -1));
}

TEST_CASE("keep reflected adds the reflected ray's material, -1 for a miss, and keeps the rest") {
  const Texture marks =
      texels("marks", 3, 1, {{1, 12, 7.5f, -1}, {0, 10, 3.25f, -1}, {1, -1, 0, -1}});
  // The reflected walk's hits: triangle 3, triangle 1, none (a miss or no reflected ray).
  const Texture isect =
      texels("intersection", 3, 1, {{2.0f, 0.5f, 0.25f, 3}, {9.0f, 0, 0, 1}, {1e30f, 0, 0, -1}});
  const Texture mats = materials();
  kernels::KeepReflected k;
  k.scene = {4.0f};
  const Texture out = ktest::run(k, {&marks, &isect, &mats}, 3, 1, glm::vec4(9.0f));
  CHECK_TEXEL(out, 0, 0, glm::vec4(1, 12, 7.5f, 13));
  CHECK_TEXEL(out, 1, 0, glm::vec4(0, 10, 3.25f, 11));
  CHECK_TEXEL(out, 2, 0, glm::vec4(1, -1, 0, -1));
}

TEST_CASE(
    "mark cones refines where a neighbour's surface, its reflected surface or the depth's bend "
    "across the cone differs, and keeps the rest") {
  // A 9 x 1 row, one colour everywhere (no colour bend), surface 5, spread 0.01 and 2 cone
  // widths: a pixel at t 10 marks where the depth's second difference exceeds 0.2.
  //  x:          0    1    2    3    4    5    6    7    8
  //  t:         10   10   10   10.1 10   10   10  10.15 10.3   (an even ramp from 6 on)
  //  reflected: -1   -1   -1   -1   -1   -1    4   -1   -1
  //  0-1: flat; 2, 3, 4: the bump at 3 bends by 0.1 at 2 and 4 and 0.2 at 3, within the
  //  limit (3's limit is 0.202); pixel 3 is no candidate any more (x 0) and keeps its 0 even so.
  //  5 and 7: their neighbour 6's reflected ray saw surface 4; 6 itself differs from both.
  //  8: its right neighbour is itself (the edge clamps): 10.15 + 10.3 - 20.6 = -0.15, kept.
  const float t[9] = {10, 10, 10, 10.1f, 10, 10, 10, 10.15f, 10.3f};
  std::vector<glm::vec4> marks, colour;
  for (int x = 0; x < 9; ++x) {
    marks.push_back({x == 3 ? 0 : 1, 5, t[x], x == 6 ? 4 : -1});
    colour.push_back({0.4f, 0.5f, 0.6f, 1});
  }
  const Texture m = texels("marks", 9, 1, marks), c = texels("colour", 9, 1, colour);
  kernels::MarkCones k;
  k.threshold = 0.1f;
  k.spread = 0.01f;
  k.depth_cones = 2.0f;
  const Texture out = ktest::run(k, {&m, &c}, 9, 1, glm::vec4(9.0f));
  const float marked[9] = {0, 0, 0, 0, 0, 1, 1, 1, 0};
  for (int x = 0; x < 9; ++x) {
    CAPTURE(x);
    CHECK_TEXEL(out, x, 0, glm::vec4(marked[x], 5, t[x], x == 6 ? 4 : -1));
  }
  // Narrower cones (0.4 widths: 0.04 at t 10): the bump's 0.1 at 2 and 4 and the clamped 0.15
  // at 8 now mark too.
  k.depth_cones = 0.4f;
  const Texture narrow = ktest::run(k, {&m, &c}, 9, 1, glm::vec4(9.0f));
  const float marked_narrow[9] = {0, 0, 1, 0, 1, 1, 1, 1, 1};
  for (int x = 0; x < 9; ++x) {
    CAPTURE(x);
    CHECK_TEXEL(narrow, x, 0, glm::vec4(marked_narrow[x], 5, t[x], x == 6 ? 4 : -1));
  }
  k.depth_cones = 2.0f;

  // A fold: a 1 x 5 column on one surface, t 10, 10, 10, 14, 14 (a nearer part of the same
  // mesh hides a farther one below row 2): rows 2 and 3 bend by 4, far above 0.2; rows 0, 1
  // and 4 by 0 (rows 0 and 4 clamp at the edge).
  const Texture my = texels(
      "marks", 1, 5, {{1, 5, 10, 2}, {1, 5, 10, 2}, {1, 5, 10, 2}, {1, 5, 14, 2}, {1, 5, 14, 2}});
  const Texture cy = texels("colour", 1, 5, std::vector<glm::vec4>(5, {0.4f, 0.5f, 0.6f, 1}));
  const Texture outy = ktest::run(k, {&my, &cy}, 1, 5, glm::vec4(9.0f));
  const float markedy[5] = {0, 0, 1, 1, 0};
  const float ty[5] = {10, 10, 10, 14, 14};
  for (int y = 0; y < 5; ++y) {
    CAPTURE(y);
    CHECK_TEXEL(outy, 0, y, glm::vec4(markedy[y], 5, ty[y], 2));
  }

  // A colour step still marks, as marcarPixeles (one surface, flat depth): blue 0, 0, 0.5, 0.5
  // bends at 1 and 2; a miss row (key -1, t 0) beside it is not a fold.
  const Texture mc =
      texels("marks", 4, 1, {{1, -1, 0, -1}, {1, -1, 0, -1}, {1, -1, 0, -1}, {1, -1, 0, -1}});
  const Texture cc = texels(
      "colour", 4, 1,
      {{0.3f, 0.3f, 0, 1}, {0.3f, 0.3f, 0, 1}, {0.3f, 0.3f, 0.5f, 1}, {0.3f, 0.3f, 0.5f, 1}});
  const Texture outc = ktest::run(k, {&mc, &cc}, 4, 1, glm::vec4(9.0f));
  const float markedc[4] = {0, 1, 1, 0};
  for (int x = 0; x < 4; ++x) CHECK_TEXEL(outc, x, 0, glm::vec4(markedc[x], -1, 0, -1));
}
