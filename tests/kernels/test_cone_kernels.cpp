// Kernel tests for the object-space decision of adaptive sampling (kernels/cones.h):
// guardarConos, guardarReflejos and marcarConos, and the budget's puntuarConos, pixelesPuntuados
// and cortarPuntajes (kernels/cone_budget.h), each run as one real pass on hand-made texels.
#include <doctest/doctest.h>

#include "kernel_pass.h"
#include "kernels/cone_budget.h"
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

TEST_CASE(
    "score cones scores a candidate by the largest colour step behind an edge its cone sees, or "
    "its colour's bend, and keeps scores above the threshold only") {
  // A 7 x 1 row at t 10 on surface 5 (spread 0.01, 2 cone widths: a fold needs a depth bend
  // over 0.2). Red steps 0 -> 0.3 between pixels 1 and 2; blue ramps evenly, 0.6 + 0.02 x (no
  // bend but at the clamped ends); pixels 4 to 6 see reflected surface 9; pixel 6 is no
  // candidate. Scores:
  //  0: the blue bend at the clamped edge, 0.6 + 0.62 - 1.2 = 0.02;  1, 2: the red bend 0.3;
  //  3, 4: the blue step across the reflected edge between them, 0.02 (their bends are 0);
  //  5: 0 (its neighbours see 9 too);  6: no candidate: 0, whatever it scores.
  // At threshold 0.05 only 1 and 2 keep theirs; at 0.01 all do.
  std::vector<glm::vec4> marks, colour;
  for (int x = 0; x < 7; ++x) {
    marks.push_back({x == 6 ? 0 : 1, 5, 10, x >= 4 ? 9 : -1});
    colour.push_back({x >= 2 ? 0.3f : 0.0f, 0.5f, 0.6f + 0.02f * float(x), 1});
  }
  const Texture m = texels("marks", 7, 1, marks), c = texels("colour", 7, 1, colour);
  kernels::ScoreCones k;
  k.threshold = 0.05f;
  k.spread = 0.01f;
  k.depth_cones = 2.0f;
  const Texture out = ktest::run(k, {&m, &c}, 7, 1, glm::vec4(9.0f));
  const float score[7] = {0, 0.3f, 0.3f, 0, 0, 0, 0};
  for (int x = 0; x < 7; ++x) {
    CAPTURE(x);
    CHECK_TEXEL_NEAR(out, x, 0, 1e-5f, glm::vec4(score[x], 5, 10, x >= 4 ? 9 : -1));
  }
  k.threshold = 0.01f;
  const Texture low = ktest::run(k, {&m, &c}, 7, 1, glm::vec4(9.0f));
  const float score_low[7] = {0.02f, 0.3f, 0.3f, 0.02f, 0.02f, 0, 0};
  for (int x = 0; x < 7; ++x) {
    CAPTURE(x);
    CHECK_TEXEL_NEAR(low, x, 0, 1e-5f, glm::vec4(score_low[x], 5, 10, x >= 4 ? 9 : -1));
  }
  k.threshold = 0.05f;

  // Another surface key: a 6 x 1 row, surfaces 5, 5, 5, 7, 7, 7, red ramping evenly 0.2 to 0.7
  // (bends of 0.1 only at the clamped ends): 2 and 3 score the step across their edge, 0.1.
  // With one colour everywhere the key edge scores nothing: its step is 0.
  std::vector<glm::vec4> mkv, ckv;
  for (int x = 0; x < 6; ++x) {
    mkv.push_back({1, x < 3 ? 5.0f : 7.0f, 10, -1});
    ckv.push_back({0.2f + 0.1f * float(x), 0.5f, 0.5f, 1});
  }
  const Texture mk = texels("marks", 6, 1, mkv), ck = texels("colour", 6, 1, ckv);
  const Texture outk = ktest::run(k, {&mk, &ck}, 6, 1, glm::vec4(9.0f));
  const float scorek[6] = {0.1f, 0, 0.1f, 0.1f, 0, 0.1f};
  for (int x = 0; x < 6; ++x) {
    CAPTURE(x);
    CHECK_TEXEL_NEAR(outk, x, 0, 1e-5f, glm::vec4(scorek[x], x < 3 ? 5 : 7, 10, -1));
  }
  const Texture same = texels("colour", 6, 1, std::vector<glm::vec4>(6, {0.2f, 0.5f, 0.5f, 1}));
  const Texture outs = ktest::run(k, {&mk, &same}, 6, 1, glm::vec4(9.0f));
  for (int x = 0; x < 6; ++x) CHECK_TEXEL(outs, x, 0, glm::vec4(0, x < 3 ? 5 : 7, 10, -1));

  // A fold: a 1 x 4 column on one surface, t 10, 10, 14, 14, green 0.5, 0.5, 0.58, 0.66 (an
  // even ramp from row 1 on: row 2's bend is 0). Rows 1 and 2 fold (depth bends of 4 and -4),
  // so their largest step counts, 0.08; row 3 bends by 0.58 + 0.66 - 1.32 (the edge clamps):
  // 0.08; row 0 scores 0. At one depth (no fold) row 2 scores nothing: its bend is 0.
  const std::vector<glm::vec4> cfold{
      {0.1f, 0.5f, 0.1f, 1}, {0.1f, 0.5f, 0.1f, 1}, {0.1f, 0.58f, 0.1f, 1}, {0.1f, 0.66f, 0.1f, 1}};
  const Texture cf = texels("colour", 1, 4, cfold);
  const Texture mf =
      texels("marks", 1, 4, {{1, 5, 10, -1}, {1, 5, 10, -1}, {1, 5, 14, -1}, {1, 5, 14, -1}});
  const Texture mflat = texels("marks", 1, 4, std::vector<glm::vec4>(4, {1, 5, 10, -1}));
  const Texture outf = ktest::run(k, {&mf, &cf}, 1, 4, glm::vec4(9.0f));
  const Texture outflat = ktest::run(k, {&mflat, &cf}, 1, 4, glm::vec4(9.0f));
  const float scoref[4] = {0, 0.08f, 0.08f, 0.08f}, scoreflat[4] = {0, 0.08f, 0, 0.08f};
  const float tf[4] = {10, 10, 14, 14};
  for (int y = 0; y < 4; ++y) {
    CAPTURE(y);
    CHECK_TEXEL_NEAR(outf, 0, y, 1e-5f, glm::vec4(scoref[y], 5, tf[y], -1));
    CHECK_TEXEL_NEAR(outflat, 0, y, 1e-5f, glm::vec4(scoreflat[y], 5, 10, -1));
  }
}

TEST_CASE("scored hits counts the pixels that hit whose score exceeds the value, and no others") {
  // Scores 0, 0.3, 0.2, 0.5 (a miss), 0.7, 0.2; keys 5, 5, 5, -1, 6, 5.
  const Texture m = texels("marks", 6, 1,
                           {{0, 5, 10, -1},
                            {0.3f, 5, 10, -1},
                            {0.2f, 5, 10, -1},
                            {0.5f, -1, 0, -1},
                            {0.7f, 6, 10, -1},
                            {0.2f, 5, 10, -1}});
  kernels::ScoredHits k;
  for (const auto& case_ : std::vector<std::pair<float, uint64_t>>{
           {-1.0f, 5}, {0.0f, 4}, {0.2f, 2}, {0.3f, 1}, {0.7f, 0}}) {
    // Named copies: CAPTURE's lambda cannot capture a structured binding under clang 14.
    const float above = case_.first;
    const uint64_t expect = case_.second;
    CAPTURE(above);
    k.above = above;
    uint64_t count = 99;
    const Texture out = ktest::run(k, {&m}, 6, 1, glm::vec4(9.0f), &count);
    CHECK(count == expect);
    // The counted pixels write the dummy value, the rest keep the target's.
    for (int x = 0; x < 6; ++x) {
      const glm::vec4 t = ktest::at(m, x, 0);
      CAPTURE(x);
      const bool counted = t.x > above && t.y >= 0;
      CHECK_TEXEL(out, x, 0, counted ? glm::vec4(1, 0, 0, 0) : glm::vec4(9.0f));
    }
  }
}

TEST_CASE("cut scores marks the pixels scoring above the threshold and keeps the rest") {
  const Texture m = texels(
      "marks", 4, 1, {{0, 5, 10, -1}, {0.3f, 5, 11, 2}, {0.2f, -1, 0, -1}, {0.25f, 6, 12, 3}});
  kernels::CutScores k;
  k.above = 0.2f;
  const Texture out = ktest::run(k, {&m}, 4, 1, glm::vec4(9.0f));
  CHECK_TEXEL(out, 0, 0, glm::vec4(0, 5, 10, -1));
  CHECK_TEXEL(out, 1, 0, glm::vec4(1, 5, 11, 2));
  CHECK_TEXEL(out, 2, 0, glm::vec4(0, -1, 0, -1));
  CHECK_TEXEL(out, 3, 0, glm::vec4(1, 6, 12, 3));
}
