// Kernel tests for glass's ray streams (issue 25): dividirRayos (Fresnel shares, total internal
// reflection), sumaPrefijos, contarRayos, compactarRayos, reunirHijos, copiarFilas and
// sombraVidrio, each run as one real pass on hand-made texels; expected values computed here.
#include <doctest/doctest.h>

#include <cmath>

#include "kernel_pass.h"

using kernels::kFar;
using kernels::kNone;
using ktest::texels;
using ktest::Texture;
using ktest::vec3s;

namespace {

constexpr float kEps = 0.01f;  // the lift of a surface point off its triangle, world units

// Two triangles in the plane z = 0, winding normal +z: 0 glass (t = 1, ior 1.5), 1 a mirror
// (a = 0.3, opaque); entry i at texel i of 2-wide textures.
struct Plane {
  Texture v0 = vec3s("vertices0", 2, 1, {{-4, -4, 0}, {-4, -4, 0}});
  Texture v1 = vec3s("vertices1", 2, 1, {{4, -4, 0}, {4, -4, 0}});
  Texture v2 = vec3s("vertices2", 2, 1, {{-4, 4, 0}, {-4, 4, 0}});
  Texture n0 = vec3s("normals0", 2, 1, {{0, 0, 1}, {0, 0, 1}});
  Texture n1 = vec3s("normals1", 2, 1, {{0, 0, 1}, {0, 0, 1}});
  Texture n2 = vec3s("normals2", 2, 1, {{0, 0, 1}, {0, 0, 1}});
  Texture glass = texels("glass", 2, 1, {{0, 1, 1.5f, 0}, {0.3f, 0, 1.5f, 0}});
};

// Exact unpolarised Fresnel reflectance, e = eta1 / eta2, in double.
double fresnel(double e, double cos_i) {
  const double s2 = e * e * (1 - cos_i * cos_i);
  if (s2 >= 1) return 1;
  const double ct = std::sqrt(1 - s2);
  const double rs = (e * cos_i - ct) / (e * cos_i + ct), rp = (cos_i - e * ct) / (cos_i + e * ct);
  return (rs * rs + rp * rp) / 2;
}

}  // namespace

TEST_CASE("split rays gives Fresnel's shares, total internal reflection past the critical angle") {
  const Plane pl;
  const double s40 = std::sin(40 * M_PI / 180), c40 = std::cos(40 * M_PI / 180);
  const double s45 = std::sqrt(0.5);
  // Rays from above enter (+z side, the winding's front); from below they leave.
  const Texture rays = texels("rays", 4, 2,
                              {{0, 0, -1, kFar},                      // entering, normal
                               {0, 0, 1, kFar},                       // leaving, normal
                               {float(s45), 0, float(s45), kFar},     // leaving at 45 deg
                               {float(s40), 0, float(c40), kFar},     // leaving at 40 deg
                               {0, 0, -1, kFar},                      // the mirror
                               {0, 0, -1, kFar},                      // missed
                               {0, 0, -1, kFar},                      // weight too small
                               {float(s40), 0, float(-c40), kFar}});  // entering at 40 deg
  const Texture surface = texels("surface", 4, 2,
                                 {{0, 0, kEps, 0},
                                  {0, 0, -kEps, 0},
                                  {0, 0, -kEps, 0},
                                  {0, 0, -kEps, 0},
                                  {0, 0, kEps, 1},
                                  {0, 0, 0, kNone},
                                  {0, 0, kEps, 0},
                                  {0, 0, kEps, 0}});
  const Texture weight = texels("result", 4, 2,
                                {{0, 0, 0, 0.5f},
                                 {0, 0, 0, 1},
                                 {0, 0, 0, 1},
                                 {0, 0, 0, 1},
                                 {0, 0, 0, 0.5f},
                                 {0, 0, 0, 1},
                                 {0, 0, 0, 0.001f},
                                 {0, 0, 0, 1}});
  kernels::SplitRays k;
  k.scene.width = 2;
  const Texture out = ktest::run(
      k, {&rays, &surface, &weight, &pl.glass, &pl.v0, &pl.v1, &pl.v2, &pl.n0, &pl.n1, &pl.n2}, 4,
      2);
  const double f0 = std::pow(0.5 / 2.5, 2);  // ((n - 1) / (n + 1))^2 = 0.04
  CHECK(f0 == doctest::Approx(0.04));
  CHECK_TEXEL_NEAR(out, 0, 0, 1e-5, glm::vec4(0.5 * f0, 0.5 * (1 - f0), 2, 0));
  CHECK_TEXEL_NEAR(out, 1, 0, 1e-5, glm::vec4(f0, 1 - f0, 2, 0));
  // Leaving glass of 1.5 the critical angle is asin(1 / 1.5) = 41.8 deg: 45 is past it.
  CHECK(std::asin(1 / 1.5) * 180 / M_PI == doctest::Approx(41.81).epsilon(1e-3));
  CHECK_TEXEL_NEAR(out, 2, 0, 1e-5, glm::vec4(1, 0, 1, 1));
  // The helper above pinned to known answers (tests/trace/test_optics.cpp works them by hand):
  // Brewster's angle for n = 1.5 reflects no p light, R = (25/169)/2 = 0.0740, and 45 degrees
  // from air gives 0.0502399; the s term alone would give 0.1479 and 0.0920.
  CHECK(fresnel(1 / 1.5, std::cos(std::atan(1.5))) == doctest::Approx(25.0 / 338).epsilon(1e-12));
  CHECK(fresnel(1 / 1.5, s45) == doctest::Approx(0.0502399).epsilon(1e-6));
  const double f40 = fresnel(1.5, c40);
  CHECK(f40 < 1);
  CHECK_TEXEL_NEAR(out, 3, 0, 1e-4, glm::vec4(f40, 1 - f40, 2, 0));
  CHECK_TEXEL_NEAR(out, 0, 1, 1e-6, glm::vec4(0.5f * 0.3f, 0, 1, 0));  // the paper's w a
  CHECK_TEXEL_NEAR(out, 1, 1, 1e-6, glm::vec4(0, 0, 0, 0));
  CHECK_TEXEL_NEAR(out, 2, 1, 1e-6, glm::vec4(0, 0, 0, 0));  // 0.00004 and 0.00096 < 1/512
  const double e40 = fresnel(1 / 1.5, c40);
  CHECK_TEXEL_NEAR(out, 3, 1, 1e-4, glm::vec4(e40, 1 - e40, 2, 0));
}

TEST_CASE("three scan passes give the inclusive prefix sums of eight counts across two rows") {
  const Texture split = texels("split", 4, 2,
                               {{0, 0, 1, 0},
                                {0, 0, 0, 0},
                                {0, 0, 2, 0},
                                {0, 0, 1, 0},
                                {0, 0, 0, 0},
                                {0, 0, 2, 0},
                                {0, 0, 2, 0},
                                {0, 0, 1, 0}});
  kernels::ScanStream k;
  k.width = 4;
  k.channel = 2;
  k.offset = 1;
  const Texture a = ktest::run(k, {&split}, 4, 2);
  const float one[8] = {1, 1, 2, 3, 1, 2, 4, 3};  // c_i + c_{i-1}
  for (int i = 0; i < 8; ++i) CHECK_TEXEL_NEAR(a, i % 4, i / 4, 1e-6, glm::vec4(one[i], 0, 0, 0));
  k.channel = 0;
  k.offset = 2;
  const Texture b = ktest::run(k, {&a}, 4, 2);
  k.offset = 4;
  const Texture c = ktest::run(k, {&b}, 4, 2);
  const float sums[8] = {1, 1, 3, 4, 4, 6, 8, 9};
  for (int i = 0; i < 8; ++i) CHECK_TEXEL_NEAR(c, i % 4, i / 4, 1e-6, glm::vec4(sums[i], 0, 0, 0));
}

TEST_CASE("the stream count counts a channel at or over its threshold in the rows it is given") {
  const Texture split = texels("split", 2, 4,
                               {{0.5f, 0, 0, 0},
                                {0, 0.1f, 0, 0},
                                {0.001f, 0.3f, 0, 1},
                                {0.2f, 0, 0, 0},
                                {0.9f, 0.9f, 0, 1},
                                {0, 0, 0, 0},
                                {1, 0, 0, 0},
                                {1, 0, 0, 0}});
  kernels::CountStream k;
  k.channel = 0;
  k.rows = 1;  // a 2x2 target: rows 1 and 2 of the stream
  uint64_t n = 0;
  const Texture out = ktest::run(k, {&split}, 2, 2, glm::vec4(0.0f), &n);
  CHECK(n == 2);  // 0.2 and 0.9; 0.001 is under 1/512
  k.channel = 3;
  k.threshold = 0.5f;
  k.rows = 0;
  const Texture out2 = ktest::run(k, {&split}, 2, 2, glm::vec4(0.0f), &n);
  CHECK(n == 1);
  CHECK_TEXEL_NEAR(out2, 0, 1, 1e-6, glm::vec4(1, 0, 0, 0));  // counted: written
  CHECK_TEXEL_NEAR(out2, 1, 1, 1e-6, glm::vec4(0, 0, 0, 0));  // discarded: kept
}

TEST_CASE("compaction gathers each spawned ray from its source by binary search") {
  const Plane pl;
  // Four sources on the glass: spawn counts 1 (reflected), 0, 2, 1 (refracted).
  const Texture split =
      texels("split", 4, 1, {{0.3f, 0, 1, 0}, {0, 0, 0, 0}, {0.1f, 0.5f, 2, 0}, {0, 0.7f, 1, 0}});
  const Texture scan =
      texels("scan", 4, 1, {{1, 0, 0, 0}, {1, 0, 0, 0}, {3, 0, 0, 0}, {4, 0, 0, 0}});
  const Texture rays = texels(
      "rays", 4, 1, {{0, 0, -1, kFar}, {0, 0, -1, kFar}, {0, 0, -1, kFar}, {0.6f, 0, -0.8f, kFar}});
  const Texture surface = texels(
      "surface", 4, 1, {{1, 0, kEps, 0}, {0, 0, kNone, kNone}, {2, 0, kEps, 0}, {3, 0, kEps, 0}});
  kernels::CompactStream k;
  k.scene.width = 2;
  k.width = 4;
  k.count = 4;
  k.sources = 4;
  k.steps = 2;
  k.offset = kEps;
  const std::vector<const Texture*> units{&scan,  &split, &rays,  &surface, &pl.glass, &pl.v0,
                                          &pl.v1, &pl.v2, &pl.n0, &pl.n1,   &pl.n2};
  k.part = 2;
  const Texture w = ktest::run(k, units, 4, 2);
  const float weights[4] = {0.3f, 0.1f, 0.5f, 0.7f};  // slots 0-3: sources 0, 2, 2, 3
  for (int j = 0; j < 4; ++j) CHECK_TEXEL_NEAR(w, j, 0, 1e-6, glm::vec4(0, 0, 0, weights[j]));
  for (int j = 4; j < 8; ++j) CHECK_TEXEL_NEAR(w, j - 4, 1, 1e-6, glm::vec4(0, 0, 0, 0));
  k.part = 1;
  const Texture d = ktest::run(k, units, 4, 2);
  CHECK_TEXEL_NEAR(d, 0, 0, 1e-6, glm::vec4(0, 0, 1, kFar));   // mirrored
  CHECK_TEXEL_NEAR(d, 1, 0, 1e-6, glm::vec4(0, 0, 1, kFar));   // mirrored
  CHECK_TEXEL_NEAR(d, 2, 0, 1e-6, glm::vec4(0, 0, -1, kFar));  // straight through
  // Snell, entering 1.5 at sin 0.6: sin 0.4, cos sqrt(0.84).
  CHECK_TEXEL_NEAR(d, 3, 0, 1e-5, glm::vec4(0.4f, 0, -std::sqrt(0.84f), kFar));
  for (int j = 4; j < 8; ++j) CHECK_TEXEL_NEAR(d, j - 4, 1, 1e-6, glm::vec4(0, 0, 0, kNone));
  k.part = 0;
  const Texture o = ktest::run(k, units, 4, 2);
  CHECK_TEXEL_NEAR(o, 0, 0, 1e-6, glm::vec4(1, 0, kEps, 0));
  CHECK_TEXEL_NEAR(o, 1, 0, 1e-6, glm::vec4(2, 0, kEps, 0));
  CHECK_TEXEL_NEAR(o, 2, 0, 1e-5, glm::vec4(2, 0, -kEps, 0));  // the far side
  CHECK_TEXEL_NEAR(o, 3, 0, 1e-5, glm::vec4(3, 0, -kEps, 0));
}

TEST_CASE("the children gather adds each ray's children's colours to its own") {
  const Texture colour = texels("colour", 4, 1,
                                {{0.1f, 0.2f, 0.3f, 0.5f},
                                 {0.4f, 0.5f, 0.6f, 0},
                                 {0.7f, 0.8f, 0.9f, 0},
                                 {0.01f, 0.02f, 0.03f, 0}});
  const Texture split =
      texels("split", 4, 1, {{0.3f, 0, 1, 0}, {0, 0, 0, 0}, {0.1f, 0.5f, 2, 0}, {0, 0.7f, 1, 0}});
  const Texture scan =
      texels("scan", 4, 1, {{1, 0, 0, 0}, {1, 0, 0, 0}, {3, 0, 0, 0}, {4, 0, 0, 0}});
  const Texture children =
      texels("children", 4, 1, {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {2, 2, 2, 0}});
  kernels::GatherChildren k;
  k.width = 4;
  const Texture out = ktest::run(k, {&colour, &scan, &split, &children}, 4, 1);
  CHECK_TEXEL_NEAR(out, 0, 0, 1e-6, glm::vec4(1.1f, 0.2f, 0.3f, 0.5f));
  CHECK_TEXEL_NEAR(out, 1, 0, 1e-6, glm::vec4(0.4f, 0.5f, 0.6f, 0));
  CHECK_TEXEL_NEAR(out, 2, 0, 1e-6, glm::vec4(0.7f, 1.8f, 1.9f, 0));
  CHECK_TEXEL_NEAR(out, 3, 0, 1e-6, glm::vec4(2.01f, 2.02f, 2.03f, 0));
}

TEST_CASE("row copies move a chunk of rows out of a tall texture and back") {
  const Texture tall = texels("tall", 2, 4,
                              {{0, 0, 0, 0},
                               {1, 0, 0, 0},
                               {2, 0, 0, 0},
                               {3, 0, 0, 0},
                               {4, 0, 0, 0},
                               {5, 0, 0, 0},
                               {6, 0, 0, 1},
                               {7, 0, 0, 1}});
  kernels::CopyRows k;
  k.rows = 2;
  const Texture out = ktest::run(k, {&tall}, 2, 2);
  for (int i = 0; i < 4; ++i)
    CHECK_TEXEL_NEAR(out, i % 2, i / 2, 1e-6, glm::vec4(4 + i, 0, 0, i >= 2 ? 1 : 0));
}

TEST_CASE("a shadow ray stopping on glass goes on with the light times t, and stops on the rest") {
  const Texture glass = texels("glass", 2, 1, {{0, 0.5f, 1.5f, 0}, {0.3f, 0, 1.5f, 0}});
  const Texture origins = texels(
      "shadow origins", 4, 1, {{0, 0, 0, 0.5f}, {1, 0, 0, 0.5f}, {2, 0, 0, 0.5f}, {3, 0, 0, 0.5f}});
  const Texture rays =
      texels("shadow rays", 4, 1, {{0, 0, 1, 10}, {0, 0, 1, 10}, {0, 0, 1, 10}, {0, 0, 1, kNone}});
  // Hits: glass at t = 2, the mirror (opaque) at t = 3, nothing, (no ray traced).
  const Texture hits = texels(
      "shadow hits", 4, 1, {{2, 0, 0, 0}, {3, 0, 0, 1}, {kFar, 0, 0, kNone}, {kFar, 0, 0, kNone}});
  kernels::ShadowGlass k;
  k.scene.width = 2;
  k.offset = kEps;
  k.first = false;
  k.part = 0;
  const std::vector<const Texture*> units{&origins, &rays, &hits, &glass};
  const Texture o = ktest::run(k, units, 4, 1);
  CHECK_TEXEL_NEAR(o, 0, 0, 1e-6, glm::vec4(0, 0, 2 + kEps, 0.25f));
  CHECK_TEXEL_NEAR(o, 1, 0, 1e-6, glm::vec4(1, 0, 0, 0));
  CHECK_TEXEL_NEAR(o, 2, 0, 1e-6, glm::vec4(2, 0, 0, 0.5f));
  CHECK_TEXEL_NEAR(o, 3, 0, 1e-6, glm::vec4(3, 0, 0, 0.5f));
  k.part = 1;
  const Texture d = ktest::run(k, units, 4, 1);
  CHECK_TEXEL_NEAR(d, 0, 0, 1e-6, glm::vec4(0, 0, 1, 10 - 2 - kEps));
  for (int i = 1; i < 4; ++i) CHECK_TEXEL_NEAR(d, i, 0, 1e-6, glm::vec4(0, 0, 1, kNone));
  // The first round starts from the surface record (w: its triangle), light 1.
  k.first = true;
  k.part = 0;
  CHECK_TEXEL_NEAR(ktest::run(k, units, 4, 1), 0, 0, 1e-6, glm::vec4(0, 0, 2 + kEps, 0.5f));
  // The 8th glass surface blocks the light; nothing goes on.
  k.first = false;
  k.last = true;
  CHECK_TEXEL_NEAR(ktest::run(k, units, 4, 1), 0, 0, 1e-6, glm::vec4(0, 0, 0, 0));
  k.part = 1;
  CHECK_TEXEL_NEAR(ktest::run(k, units, 4, 1), 0, 0, 1e-6, glm::vec4(0, 0, 1, kNone));
}
