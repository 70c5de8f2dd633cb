// Kernel tests for the sampling modes' marks: marcarPixeles (adaptive supersampling) and
// marcarHuecos and rellenarHuecos (undersampling), each run as one real pass on hand-made
// texels.
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

TEST_CASE(
    "fill gaps gives a gently curving shade back exactly, a ramp linearly, and a stripe or a "
    "step beyond the cell the straight blend") {
  // A 9 x 9 image, K = 2: lattice pixels at even x and y, each one sample (w = 1); gap texels
  // of the sum hold nothing (w = 0). Red: the quadratic 0.01 ((x/2)^2 + (y/2)^2), second
  // difference 0.02 along both axes (within the limit: threshold 0.1 / 2). Green: the ramp
  // 0.05 x + 0.02 y. Blue, along x only: 0.5 on lattice columns 0, 6 and 8, 0.2 on 2 and 4 (a
  // stripe two lattice steps wide: second difference 0.3 at both ends, past the limit).
  auto red = [](int x, int y) { return 0.01f * (float(x * x) / 4.0f + float(y * y) / 4.0f); };
  auto green = [](int x, int y) { return 0.05f * float(x) + 0.02f * float(y); };
  auto blue = [](int x) { return (x == 2 || x == 4) ? 0.2f : 0.5f; };
  std::vector<glm::vec4> sum(81, glm::vec4(0.0f));
  for (int y = 0; y < 9; y += 2)
    for (int x = 0; x < 9; x += 2) sum[size_t(y * 9 + x)] = {red(x, y), green(x, y), blue(x), 1};
  // One gap pixel was traced (two samples): it keeps its own mean.
  sum[size_t(5 * 9 + 5)] = {0.4f, 0.6f, 0.8f, 2};
  const Texture s = texels("sum", 9, 9, sum);
  kernels::FillGaps k;
  k.lattice = {2, 9, 9};
  k.threshold = 0.1f;
  const Texture out = ktest::run(k, {&s}, 9, 9, glm::vec4(9.0f));
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 9; ++x) {
      CAPTURE(x);
      CAPTURE(y);
      if (x == 5 && y == 5) {
        CHECK_TEXEL(out, x, y, glm::vec4(0.2f, 0.3f, 0.4f, 1));
        continue;
      }
      // The straight (bilinear) blend of the cell's corners, per channel.
      const int x0 = x / 2 * 2, y0 = y / 2 * 2, x1 = std::min(x0 + 2, 8), y1 = std::min(y0 + 2, 8);
      const float tx = float(x - x0) / 2.0f, ty = float(y - y0) / 2.0f;
      auto bilinear = [&](auto f) {
        const float top = f(x0, y0) + (f(x1, y0) - f(x0, y0)) * tx;
        const float bottom = f(x0, y1) + (f(x1, y1) - f(x0, y1)) * tx;
        return top + (bottom - top) * ty;
      };
      // Red: exact in the cells whose lattice neighbours one step out are in the image (x and y
      // in 2..6); elsewhere corrected along the axis that has them only.
      const bool along_x = x0 >= 2 && x1 <= 6, along_y = y0 >= 2 && y1 <= 6;
      float r = bilinear(red);
      if (along_x) r -= tx * (1 - tx) * 0.5f * 0.02f;
      if (along_y) r -= ty * (1 - ty) * 0.5f * 0.02f;
      const float b = bilinear([&](int px, int) { return blue(px); });
      CHECK_TEXEL_NEAR(out, x, y, 1e-5, glm::vec4(r, bilinear(green), b, 1));
      if (along_x && along_y) CHECK(ktest::at(out, x, y).x == doctest::Approx(red(x, y)));
    }
  // A 7 x 1 row, lattice columns 0, 2, 4, 6. Red 0, 0, 0, 0.04: a step beyond the cell 2..4
  // (second differences 0 at column 2 and 0.04 at 4, within the limit): the cell keeps the
  // straight blend (minmod of 0 and 0.04), where a cubic through the four would dip below 0.
  // Green 0, 0, 0.01, 0.04: second differences 0.01 and 0.02, the smaller corrects: at column 3
  // 0.005 - 0.01 / 8.
  const Texture row =
      texels("sum", 7, 1,
             {{0, 0, 0, 1}, {}, {0, 0, 0, 1}, {}, {0, 0.01f, 0, 1}, {}, {0.04f, 0.04f, 0, 1}});
  kernels::FillGaps kr;
  kr.lattice = {2, 7, 1};
  kr.threshold = 0.1f;
  const Texture out_row = ktest::run(kr, {&row}, 7, 1, glm::vec4(9.0f));
  CHECK_TEXEL_NEAR(out_row, 1, 0, 1e-6, glm::vec4(0, 0, 0, 1));  // no column -2: straight
  CHECK_TEXEL_NEAR(out_row, 3, 0, 1e-6, glm::vec4(0, 0.005f - 0.01f / 8.0f, 0, 1));
  CHECK_TEXEL_NEAR(out_row, 5, 0, 1e-6, glm::vec4(0.02f, 0.025f, 0, 1));  // no column 8
}
