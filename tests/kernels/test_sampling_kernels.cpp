// Kernel tests for the sampling modes' marks: marcarPixeles (adaptive supersampling) and
// marcarHuecos (undersampling), each run as one real pass on hand-made texels.
#include <doctest/doctest.h>

#include "kernel_pass.h"

using ktest::texels;
using ktest::Texture;

TEST_CASE(
    "mark pixels refines both sides of a colour step and a change of surface, not an even "
    "shade") {
  // A 7 x 1 row, threshold 0.1, every pixel a candidate on surface 5 but pixel 6 (surface 4):
  //  red:   0, 0.1, 0.2, 0.3, 0.8, 0.8, 0.8
  //  pixels 1-2 lie on an even ramp (neighbours differ by 0.1, the second difference is 0);
  //  3 and 4 take the step of 0.5 (second differences 0.4 and -0.5); 5 and 6 change surface;
  //  0 sees its clamped self and 0.1 (second difference 0.1, not above 0.1).
  const float red[7] = {0, 0.1f, 0.2f, 0.3f, 0.8f, 0.8f, 0.8f};
  std::vector<glm::vec4> marks, colour;
  for (int x = 0; x < 7; ++x) {
    marks.push_back({1, x == 6 ? 4 : 5, 0, 0});
    colour.push_back({red[x], 0.25f, 0.5f, 1});
  }
  // Pixel 2 is no candidate any more (x 0): it stays unmarked whatever its neighbours.
  marks[2].x = 0;
  const Texture m = texels("marks", 7, 1, marks), c = texels("colour", 7, 1, colour);
  kernels::MarkPixels k;
  k.threshold = 0.1f;
  const Texture out = ktest::run(k, {&m, &c}, 7, 1, glm::vec4(9.0f));
  const float marked[7] = {0, 0, 0, 1, 1, 1, 1};
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
