// Kernel tests for the sampling modes' marks: marcarPixeles (adaptive supersampling) and
// marcarHuecos (undersampling), each run as one real pass on hand-made texels.
#include <doctest/doctest.h>

#include "kernel_pass.h"

using ktest::texels;
using ktest::Texture;

TEST_CASE(
    "mark pixels refines both sides of a colour step and a change of surface, not an even "
    "ramp") {
  // A 7 x 1 row, threshold 0.1, on surface 5 but pixel 6 (surface 4); red:
  //  0.3, 0.3, 0.45, 0.6, 0.75, 0.25, 0.25
  //  0: flat (second difference 0); 1: the ramp starts (0.15); 2, 3: on the ramp (0: their
  //  neighbours differ by 0.15, more than the threshold, yet they keep one ray); 4: the step
  //  down (-0.65); 5: no candidate any more (x 0), so unmarked whatever its neighbours; 6: its
  //  neighbour hit surface 5.
  const float red[7] = {0.3f, 0.3f, 0.45f, 0.6f, 0.75f, 0.25f, 0.25f};
  std::vector<glm::vec4> marks, colour;
  for (int x = 0; x < 7; ++x) {
    marks.push_back({x == 5 ? 0 : 1, x == 6 ? 4 : 5, 0, 0});
    colour.push_back({red[x], 0.25f, 0.5f, 1});
  }
  const Texture m = texels("marks", 7, 1, marks), c = texels("colour", 7, 1, colour);
  kernels::MarkPixels k;
  k.threshold = 0.1f;
  const Texture out = ktest::run(k, {&m, &c}, 7, 1, glm::vec4(9.0f));
  const float marked[7] = {0, 1, 0, 0, 1, 0, 1};
  for (int x = 0; x < 7; ++x) CHECK_TEXEL(out, x, 0, glm::vec4(marked[x], x == 6 ? 4 : 5, 0, 0));

  // The same along y, in blue: a 1 x 4 column 0, 0, 0.5, 0.5 bends at rows 1 and 2.
  const Texture my =
      texels("marks", 1, 4, {{1, 5, 0, 0}, {1, 5, 0, 0}, {1, 5, 0, 0}, {1, 5, 0, 0}});
  const Texture cy = texels(
      "colour", 1, 4,
      {{0.3f, 0.3f, 0, 1}, {0.3f, 0.3f, 0, 1}, {0.3f, 0.3f, 0.5f, 1}, {0.3f, 0.3f, 0.5f, 1}});
  const Texture outy = ktest::run(k, {&my, &cy}, 1, 4, glm::vec4(9.0f));
  const float markedy[4] = {0, 1, 1, 0};
  for (int y = 0; y < 4; ++y) CHECK_TEXEL(outy, 0, y, glm::vec4(markedy[y], 5, 0, 0));
}

TEST_CASE("mark gaps traces a pixel only where the lattice pixels its fill blends disagree") {
  // A 3 x 3 image, K = 2: the lattice is the four corners. Keys (y): 1 on the top row, 2 on the
  // bottom row; every corner's colour the same (one sample each).
  const Texture keys = texels("keys", 3, 3,
                              {{1, 1, 0, 0},
                               {0, 0, 0, 0},
                               {1, 1, 0, 0},
                               {},
                               {},
                               {},
                               {1, 2, 0, 0},
                               {0, 0, 0, 0},
                               {1, 2, 0, 0}});
  const glm::vec4 grey(0.5f, 0.5f, 0.5f, 1.0f);
  const Texture sum = texels("sum", 3, 3, {grey, {}, grey, {}, {}, {}, grey, {}, grey});
  kernels::MarkGaps k;
  k.lattice = {2, 3, 3};
  k.threshold = 0.1f;
  const Texture out = ktest::run(k, {&keys, &sum}, 3, 3, glm::vec4(9.0f));
  // Traced: the left and right columns' middles (their two corners' keys differ) and the
  // centre (all four); not the top and bottom rows' middles (their two agree), nor the lattice.
  const float traced[9] = {0, 0, 0, 1, 1, 1, 0, 0, 0};
  for (int i = 0; i < 9; ++i) CHECK_TEXEL(out, i % 3, i / 3, glm::vec4(traced[i], 0, 0, 0));

  // One surface; the top right corner 0.3 redder: the top row's middle, the centre and the
  // right column's middle blend it.
  const Texture same =
      texels("same keys", 3, 3,
             {{1, 1, 0, 0}, {}, {1, 1, 0, 0}, {}, {}, {}, {1, 1, 0, 0}, {}, {1, 1, 0, 0}});
  const Texture red =
      texels("sum", 3, 3, {grey, {}, grey + glm::vec4(0.3f, 0, 0, 0), {}, {}, {}, grey, {}, grey});
  const Texture out2 = ktest::run(k, {&same, &red}, 3, 3, glm::vec4(9.0f));
  const float traced2[9] = {0, 1, 0, 0, 1, 1, 0, 0, 0};
  for (int i = 0; i < 9; ++i) CHECK_TEXEL(out2, i % 3, i / 3, glm::vec4(traced2[i], 0, 0, 0));
}
