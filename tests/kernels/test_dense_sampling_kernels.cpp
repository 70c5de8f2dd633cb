// Kernel tests for the sampling modes' dense streams (issue 35, kernels/compact_marks.h):
// compactarMarcados, generadorRayosDensos, acumularDensos and reunirMarcados, each run as one
// real pass on hand-made texels; expected values computed here.
#include <doctest/doctest.h>

#include <cmath>

#include "kernel_pass.h"

using kernels::kFar;
using kernels::kNone;
using ktest::texels;
using ktest::Texture;

namespace {

// A 4x2 image whose pixels 1, 2, 6 and 7 are marked: the marks, and their inclusive sums (what
// sumaPrefijos leaves).
Texture marks() {
  return texels("marks", 4, 2,
                {{0, 0, 0, 0},
                 {1, 0, 0, 0},
                 {1, 0, 0, 0},
                 {0, 0, 0, 0},
                 {0, 0, 0, 0},
                 {0, 0, 0, 0},
                 {1, 0, 0, 0},
                 {1, 0, 0, 0}});
}
Texture sums() {
  return texels("scan", 4, 2,
                {{0, 0, 0, 0},
                 {1, 0, 0, 0},
                 {2, 0, 0, 0},
                 {2, 0, 0, 0},
                 {2, 0, 0, 0},
                 {2, 0, 0, 0},
                 {3, 0, 0, 0},
                 {4, 0, 0, 0}});
}

}  // namespace

TEST_CASE(
    "the marks compaction finds each marked pixel's centre by binary search, none past the "
    "count") {
  const Texture scan = sums();
  kernels::CompactMarks k;
  k.width = 4;
  k.count = 4;
  k.sources = 8;
  k.steps = 3;
  const Texture out = ktest::run(k, {&scan}, 4, 2, glm::vec4(9.0f));
  // Slots 0-3: pixels 1, 2 (row 0), 6, 7 (row 1), as (x + 0.5, y + 0.5, 0, 1).
  CHECK_TEXEL_NEAR(out, 0, 0, 1e-6, glm::vec4(1.5f, 0.5f, 0, 1));
  CHECK_TEXEL_NEAR(out, 1, 0, 1e-6, glm::vec4(2.5f, 0.5f, 0, 1));
  CHECK_TEXEL_NEAR(out, 2, 0, 1e-6, glm::vec4(2.5f, 1.5f, 0, 1));
  CHECK_TEXEL_NEAR(out, 3, 0, 1e-6, glm::vec4(3.5f, 1.5f, 0, 1));
  for (int j = 4; j < 8; ++j) CHECK_TEXEL_NEAR(out, j - 4, 1, 1e-6, glm::vec4(0, 0, 0, 0));
}

TEST_CASE(
    "dense rays go through their pixel's sample position, sample-major, and slots past "
    "the count get none") {
  // Three packed pixels (centres), two samples each from the table's entry 1 on.
  const Texture pixels = texels(
      "pixels", 4, 2,
      {{1.5f, 0.5f, 0, 1}, {2.5f, 1.5f, 0, 1}, {0.5f, 3.5f, 0, 1}, {0, 0, 0, 0}, {}, {}, {}, {}});
  const Texture jitters = texels(
      "jitters", 4, 1, {{0.4f, 0.4f, 0, 0}, {-0.25f, 0.25f, 0, 0}, {0.125f, -0.375f, 0, 0}, {}});
  kernels::GenerateDenseRays k;
  k.width = k.height = 4;  // the image: a 90 degree field of view, square
  k.tan_half_fov = 1;
  k.aspect = 1;
  k.stream_width = 4;
  k.marked = 3;
  k.count = 6;
  k.first = 1;
  k.table_width = 4;
  const Texture out = ktest::run(k, {&pixels, &jitters}, 4, 2, glm::vec4(9.0f));
  const glm::vec2 centre[3] = {{1.5f, 0.5f}, {2.5f, 1.5f}, {0.5f, 3.5f}};
  const glm::vec2 jitter[4] = {{0.4f, 0.4f}, {-0.25f, 0.25f}, {0.125f, -0.375f}, {0, 0}};
  for (int s = 0; s < 8; ++s) {
    CAPTURE(s);
    const int k_sample = s / 3, j = s % 3;
    // The camera looks down -z, x right, y up: the ray through image point (px, py).
    const glm::vec2 p = centre[j] + jitter[1 + k_sample];
    const glm::vec3 d =
        glm::normalize(glm::vec3(2.0f * p.x / 4.0f - 1.0f, 1.0f - 2.0f * p.y / 4.0f, -1.0f));
    CHECK_TEXEL_NEAR(out, s % 4, s / 4, 1e-6, glm::vec4(d, s < 6 ? kFar : kNone));
  }
}

TEST_CASE(
    "dense accumulation adds each marked pixel's slot for sample k, and the others keep "
    "their sums") {
  const Texture mk = marks(), scan = sums();
  const Texture sum = texels("sum", 4, 2,
                             {{1, 1, 1, 1},
                              {0.5f, 0.5f, 0.5f, 1},
                              {0.25f, 0, 0, 1},
                              {2, 2, 2, 2},
                              {3, 3, 3, 3},
                              {4, 4, 4, 4},
                              {0, 0.5f, 0, 1},
                              {0, 0, 0.5f, 1}});
  // Sample 0 of the four packed pixels in slots 0-3, sample 1 in slots 4-7.
  const Texture dense = texels("dense", 4, 2,
                               {{0.1f, 0, 0, 1},
                                {0.2f, 0, 0, 1},
                                {0.3f, 0, 0, 1},
                                {0.4f, 0, 0, 1},
                                {0, 0.1f, 0, 1},
                                {0, 0.2f, 0, 1},
                                {0, 0.3f, 0, 1},
                                {0, 0.4f, 0, 1}});
  kernels::AccumulateDense k;
  k.width = 4;
  k.base = 4;  // sample 1
  const Texture out = ktest::run(k, {&sum, &mk, &scan, &dense}, 4, 2);
  CHECK_TEXEL_NEAR(out, 0, 0, 1e-6, glm::vec4(1, 1, 1, 1));  // unmarked: kept
  CHECK_TEXEL_NEAR(out, 1, 0, 1e-6, glm::vec4(0.5f, 0.6f, 0.5f, 2));
  CHECK_TEXEL_NEAR(out, 2, 0, 1e-6, glm::vec4(0.25f, 0.2f, 0, 2));
  CHECK_TEXEL_NEAR(out, 3, 0, 1e-6, glm::vec4(2, 2, 2, 2));
  CHECK_TEXEL_NEAR(out, 0, 1, 1e-6, glm::vec4(3, 3, 3, 3));
  CHECK_TEXEL_NEAR(out, 1, 1, 1e-6, glm::vec4(4, 4, 4, 4));
  CHECK_TEXEL_NEAR(out, 2, 1, 1e-6, glm::vec4(0, 0.8f, 0, 2));
  CHECK_TEXEL_NEAR(out, 3, 1, 1e-6, glm::vec4(0, 0.4f, 0.5f, 2));
  // A level's first sample replaces the marked pixels' sums.
  k.base = 0;
  k.restart = true;
  const Texture fresh = ktest::run(k, {&sum, &mk, &scan, &dense}, 4, 2);
  CHECK_TEXEL_NEAR(fresh, 0, 0, 1e-6, glm::vec4(1, 1, 1, 1));
  CHECK_TEXEL_NEAR(fresh, 1, 0, 1e-6, glm::vec4(0.1f, 0, 0, 1));
  CHECK_TEXEL_NEAR(fresh, 2, 0, 1e-6, glm::vec4(0.2f, 0, 0, 1));
  CHECK_TEXEL_NEAR(fresh, 3, 0, 1e-6, glm::vec4(2, 2, 2, 2));
  CHECK_TEXEL_NEAR(fresh, 2, 1, 1e-6, glm::vec4(0.3f, 0, 0, 1));
  CHECK_TEXEL_NEAR(fresh, 3, 1, 1e-6, glm::vec4(0.4f, 0, 0, 1));
}

TEST_CASE("the marked gather brings each marked pixel its slot's texel, the others the fallback") {
  const Texture mk = marks(), scan = sums();
  const Texture hits = texels("dense hits", 4, 2,
                              {{1, 0.1f, 0.2f, 7},
                               {2, 0.3f, 0.4f, 8},
                               {3, 0.5f, 0.6f, 9},
                               {4, 0.7f, 0.8f, kNone},
                               {5, 5, 5, 5},
                               {6, 6, 6, 6},
                               {7, 7, 7, 7},
                               {8, 8, 8, 8}});
  kernels::GatherMarked k;
  k.width = 4;
  k.fallback = {kFar, 0, 0, kNone};
  const Texture out = ktest::run(k, {&mk, &scan, &hits}, 4, 2);
  const glm::vec4 none(kFar, 0, 0, kNone);
  CHECK_TEXEL_NEAR(out, 0, 0, 1e-6, none);
  CHECK_TEXEL_NEAR(out, 1, 0, 1e-6, glm::vec4(1, 0.1f, 0.2f, 7));
  CHECK_TEXEL_NEAR(out, 2, 0, 1e-6, glm::vec4(2, 0.3f, 0.4f, 8));
  CHECK_TEXEL_NEAR(out, 3, 0, 1e-6, none);
  CHECK_TEXEL_NEAR(out, 0, 1, 1e-6, none);
  CHECK_TEXEL_NEAR(out, 1, 1, 1e-6, none);
  CHECK_TEXEL_NEAR(out, 2, 1, 1e-6, glm::vec4(3, 0.5f, 0.6f, 9));
  CHECK_TEXEL_NEAR(out, 3, 1, 1e-6, glm::vec4(4, 0.7f, 0.8f, kNone));
}
