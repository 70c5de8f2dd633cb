// Kernel tests for everything after the hit: shader (three lighting models, ambient, shadows,
// several lights, the paper's blend over three bounces), inicioReflejo, direccionReflejo and
// the shadow-ray kernel, each run as real passes on hand-made texels.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <vector>

#include "kernel_pass.h"

using kernels::kFar;
using kernels::kNone;
using kernels::ShadingModel;
using ktest::texels;
using ktest::Texture;
using ktest::vec3s;

namespace {

struct Tri {
  glm::vec3 p[3];
  glm::vec3 n[3];
  glm::vec4 color;  // rgb, a = reflection coefficient
};

// The scene textures, two triangles per row.
struct SceneTextures {
  Texture v[3], n[3], colors;
  explicit SceneTextures(const std::vector<Tri>& tris) {
    const int w = 2, h = int(tris.size() + 1) / 2;
    std::vector<glm::vec3> pv[3], nv[3];
    std::vector<glm::vec4> cv;
    for (const Tri& t : tris) {
      for (int k = 0; k < 3; ++k) pv[k].push_back(t.p[k]), nv[k].push_back(t.n[k]);
      cv.push_back(t.color);
    }
    for (int k = 0; k < 3; ++k) {
      v[k] = vec3s("vertices" + std::to_string(k), w, h, pv[k]);
      n[k] = vec3s("normals" + std::to_string(k), w, h, nv[k]);
    }
    colors = texels("colors", w, h, cv);
  }
};

const glm::vec3 kUp(0, 1, 0);
// Triangle 0: horizontal at y = 0 with corners (0,0,0), (0,0,2), (2,0,0) (geometric normal +y),
// flat normals, kd = (0.8, 0.6, 0.4), a = 0.25.
// Triangle 1: the same corners, corner normals +y, +z, +x, kd = (0.2, 0.4, 0.6), a = 0.
// Triangle 2: tilted, in the plane x = y through (0,0,-1), (0,0,1), (1,1,0): geometric normal
// (-1, 1, 0)/sqrt 2.
const glm::vec3 kKd0(0.8f, 0.6f, 0.4f), kKd1(0.2f, 0.4f, 0.6f);
const std::vector<Tri> kTris = {
    {{{0, 0, 0}, {0, 0, 2}, {2, 0, 0}}, {kUp, kUp, kUp}, glm::vec4(kKd0, 0.25f)},
    {{{0, 0, 0}, {0, 0, 2}, {2, 0, 0}}, {kUp, {0, 0, 1}, {1, 0, 0}}, glm::vec4(kKd1, 0.0f)},
    {{{0, 0, -1}, {0, 0, 1}, {1, 1, 0}},
     {{-0.70710678f, 0.70710678f, 0},
      {-0.70710678f, 0.70710678f, 0},
      {-0.70710678f, 0.70710678f, 0}},
     glm::vec4(0.5f, 0.5f, 0.5f, 0.0f)},
};

// One shader pass over per-pixel surface, ray, result and shadow texels (one row).
Texture shade(const kernels::Shader& k, const SceneTextures& s, const std::vector<glm::vec4>& surf,
              const std::vector<glm::vec4>& rays, const std::vector<glm::vec4>& result,
              std::vector<glm::vec4> shadow = {}) {
  const int n = int(surf.size());
  shadow.resize(surf.size(), glm::vec4(kFar, 0, 0, kNone));
  const Texture ts = texels("surface", n, 1, surf), tr = texels("rays", n, 1, rays),
                tres = texels("result", n, 1, result), tsh = texels("shadow", n, 1, shadow);
  return ktest::run(
      k, {&ts, &tr, &tres, &tsh, &s.colors, &s.v[0], &s.v[1], &s.v[2], &s.n[0], &s.n[1], &s.n[2]},
      n, 1);
}

// The light of most shader cases: from the hit point (0.5, 0, 0.5) it lies at (3, 4, 0), distance
// 5, so l = (0.6, 0.8, 0) and n.l = 0.8 on the flat triangle.
kernels::Shader base_shader() {
  kernels::Shader k;
  k.scene.width = 2;
  k.model = ShadingModel::diffuse;
  k.light = {3.5f, 4, 0.5f};
  k.light_color = glm::vec3(1.0f);
  k.ambient = glm::vec3(0.0f);
  k.background = {0.5f, 0.25f, 1.0f};
  k.first_light = k.last_light = true;
  k.shadows = false;
  return k;
}

const glm::vec4 kHit0(0.5f, 0, 0.5f, 0), kHit1(0.5f, 0, 0.5f, 1), kMiss(0, 0, 0, kNone);
const glm::vec4 kDown(0, -1, 0, kFar);

}  // namespace

TEST_CASE("the diffuse shader adds kd n.l weighted by w (1 - a) and hands w a to the reflection") {
  const SceneTextures s(kTris);
  const Texture out = shade(base_shader(), s, {kHit0, kHit0, kMiss, kHit0, kHit1},
                            {kDown, kDown, kDown, {0, 1, 0, kFar}, kDown},
                            {{0, 0, 0, 1},
                             {0.1f, 0.2f, 0.3f, 0.5f},
                             {0.1f, 0.2f, 0.3f, 0.5f},
                             {0, 0, 0, 1},
                             {0, 0, 0, 1}});
  // kd * 0.8 * (1 - 0.25) = kd * 0.6; weight 1 * 0.25.
  CHECK_TEXEL_NEAR(out, 0, 0, 1e-6, glm::vec4(0.48f, 0.36f, 0.24f, 0.25f));
  // res + kd * 0.8 * 0.5 * 0.75; weight 0.5 * 0.25.
  CHECK_TEXEL_NEAR(out, 1, 0, 1e-6, glm::vec4(0.34f, 0.38f, 0.42f, 0.125f));
  // A miss adds background * w and ends the ray.
  CHECK_TEXEL_NEAR(out, 2, 0, 1e-6, glm::vec4(0.35f, 0.325f, 0.8f, 0));
  // Seen from below the normal faces down, away from the light: black, but it still reflects.
  CHECK_TEXEL_NEAR(out, 3, 0, 1e-6, glm::vec4(0, 0, 0, 0.25f));
  // Triangle 1 at barycentrics (0.5, 0.25, 0.25): n = normalize(0.25, 0.5, 0.25).
  const double nl = (0.25 * 0.6 + 0.5 * 0.8) / std::sqrt(0.375);
  CHECK_TEXEL_NEAR(out, 4, 0, 1e-6, glm::vec4(glm::dvec3(kKd1) * nl, 0.0));
}

TEST_CASE("the shader scales by the light colour, adds ambient once and drops shadowed light") {
  kernels::Shader k = base_shader();
  k.ambient = {0.1f, 0.2f, 0.3f};
  k.light_color = {0.5f, 1, 2};
  k.shadows = true;
  const SceneTextures s(kTris);
  const glm::vec4 one(0, 0, 0, 1);
  const Texture out = shade(k, s, {kHit0, kHit0, kHit0}, {kDown, kDown, kDown}, {one, one, one},
                            {{kFar, 0, 0, kNone}, {1.5f, 0, 0, 2}, {0.5f, 0, 0, 0}});
  // Lit: (kd * 0.8 * lc + kd * ambient) * 0.75.
  CHECK_TEXEL_NEAR(out, 0, 0, 1e-6, glm::vec4(0.3f, 0.45f, 0.57f, 0.25f));
  // Shadowed (a blocker found, triangle 2 or 0): ambient only.
  CHECK_TEXEL_NEAR(out, 1, 0, 1e-6, glm::vec4(0.06f, 0.09f, 0.09f, 0.25f));
  CHECK_TEXEL_NEAR(out, 2, 0, 1e-6, glm::vec4(0.06f, 0.09f, 0.09f, 0.25f));
}

TEST_CASE(
    "with several lights only the first pass adds ambient and background, only the last sets the "
    "weight") {
  const SceneTextures s(kTris);
  for (bool last : {false, true}) {
    CAPTURE(last);
    kernels::Shader k = base_shader();
    k.ambient = {0.1f, 0.2f, 0.3f};
    k.light_color = {0.5f, 1, 2};
    k.first_light = false;
    k.last_light = last;
    const Texture out = shade(k, s, {kHit0, kMiss}, {kDown, kDown},
                              {{0.1f, 0.1f, 0.1f, 1}, {0.1f, 0.1f, 0.1f, 0.5f}});
    // res + kd * 0.8 * lc * 0.75, no ambient.
    CHECK_TEXEL_NEAR(out, 0, 0, 1e-6, glm::vec4(0.34f, 0.46f, 0.58f, last ? 0.25f : 1.0f));
    CHECK_TEXEL_NEAR(out, 1, 0, 1e-6, glm::vec4(0.1f, 0.1f, 0.1f, last ? 0.0f : 0.5f));
  }
}

TEST_CASE("phong adds ks (r.v)^32 and phong-atten divides the light by 1 + (dist / atten_dist)^2") {
  const SceneTextures s(kTris);
  // l = (0.6, 0.8, 0) mirrored about +y: r = (0.6, -0.8, 0); the shader's r.v is r.d.
  const std::vector<glm::vec4> rays = {kDown, {0.6f, -0.8f, 0, kFar}, {-0.6f, -0.8f, 0, kFar}};
  const double rv[3] = {0.8, 1.0, -0.36 + 0.64};
  const glm::vec4 one(0, 0, 0, 1);
  for (ShadingModel model : {ShadingModel::phong, ShadingModel::phong_atten}) {
    CAPTURE(int(model));
    kernels::Shader k = base_shader();
    k.model = model;
    k.specular = 0.5f;
    k.atten_dist = 10;  // distance 5: factor 1 / (1 + 0.25) = 0.8
    k.ambient = model == ShadingModel::phong_atten ? glm::vec3(0.1f) : glm::vec3(0.0f);
    const Texture out = shade(k, s, {kHit0, kHit0, kHit0}, rays, {one, one, one});
    for (int x = 0; x < 3; ++x) {
      CAPTURE(x);
      const double spec = 0.5 * std::pow(std::max(rv[x], 0.0), 32);
      glm::dvec3 c = glm::dvec3(kKd0) * 0.8 + glm::dvec3(spec);
      if (model == ShadingModel::phong_atten) c = c * 0.8 + glm::dvec3(kKd0) * 0.1;
      // r.d = 1 in float is 1 within an ulp or two, and the ^32 multiplies that by 32.
      CHECK_TEXEL_NEAR(out, x, 0, 1e-5, glm::vec4(glm::vec3(c * 0.75), 0.25f));
    }
  }
}

TEST_CASE("three bounces of the shader blend C1(1-a1) + a1 C2(1-a2) + a1 a2 C3(1-a3)") {
  // Three horizontal triangles at heights 0, 1, 2 under a light straight above the hit points,
  // so n.l = 1: Ci = kd_i exactly (diffuse, ambient 0, white light).
  const glm::vec3 C[3] = {{0.9f, 0.5f, 0.1f}, {0.2f, 0.7f, 0.4f}, {0.3f, 0.3f, 0.9f}};
  const float a[3] = {0.5f, 0.25f, 0.0f};
  std::vector<Tri> tris;
  for (int i = 0; i < 3; ++i) {
    const float h = float(i);
    tris.push_back({{{0, h, 0}, {0, h, 2}, {2, h, 0}}, {kUp, kUp, kUp}, glm::vec4(C[i], a[i])});
  }
  const SceneTextures s(tris);
  kernels::Shader k = base_shader();
  k.light = {0.5f, 10, 0.5f};
  const glm::vec3 bg(0.25f, 0.5f, 0.75f);
  k.background = bg;
  vgpu::Gpu gpu(ktest::gf5700(), 1, 1);
  vgpu::KernelProgram<kernels::Shader> shader(k);
  vgpu::KernelProgram<kernels::ReflectedRays> reflected;
  // Pixel 0 meets triangles 0, 1, 2; pixel 1 meets triangle 0, then nothing.
  Texture result[2] = {texels("result A", 2, 1, {{0, 0, 0, 1}, {0, 0, 0, 1}}),
                       Texture("result B", 2, 1, 4)};
  const Texture rays = texels("rays", 2, 1, {kDown, kDown});
  const Texture shadow = texels("shadow", 2, 1, {{kFar, 0, 0, kNone}, {kFar, 0, 0, kNone}});
  Texture counter("counter", 2, 1, 4);
  const float weight_after[3] = {0.5f, 0.125f, 0.0f};
  const uint64_t reflected_after[3] = {2, 1, 0};
  int cur = 0;
  for (int i = 0; i < 3; ++i) {
    CAPTURE(i);
    const Texture surf =
        texels("surface", 2, 1, {{0.5f, float(i), 0.5f, float(i)}, i == 0 ? kHit0 : kMiss});
    ktest::draw(gpu, shader,
                {&surf, &rays, &result[cur], &shadow, &s.colors, &s.v[0], &s.v[1], &s.v[2], &s.n[0],
                 &s.n[1], &s.n[2]},
                result[cur ^ 1]);
    cur ^= 1;
    CHECK(result[cur].get(0, 0, 3) == weight_after[i]);
    uint64_t n = 0;
    ktest::draw(gpu, reflected, {&result[cur]}, counter, &n);
    CHECK(n == reflected_after[i]);
  }
  const glm::vec3 expected =
      C[0] * (1 - a[0]) + a[0] * C[1] * (1 - a[1]) + a[0] * a[1] * C[2] * (1 - a[2]);
  CHECK_TEXEL_NEAR(result[cur], 0, 0, 1e-6, glm::vec4(expected, 0.0f));
  CHECK_TEXEL_NEAR(result[cur], 1, 0, 1e-6, glm::vec4(C[0] * (1 - a[0]) + a[0] * bg, 0.0f));
}

TEST_CASE(
    "reflection origin lifts the hit point by offset along the geometric normal, towards the "
    "incoming side") {
  const SceneTextures s(kTris);
  kernels::ReflectionOrigin k;
  k.scene.width = 2;
  k.offset = 0.01f;
  const Texture origins = texels(
      "origins", 5, 1,
      {{0.5f, 3, 0.5f, 0}, {0.5f, -2, 0.5f, 0}, {2, 0, 0, 0}, {-2, 0.5f, 0, 0}, {1, 2, 3, 0}});
  const Texture rays =
      texels("rays", 5, 1, {kDown, {0, 1, 0, kFar}, {-1, 0, 0, kFar}, {1, 0, 0, kFar}, kDown});
  const Texture isect = texels("intersection", 5, 1,
                               {{3, 0.1f, 0.2f, 0},
                                {2, 0.1f, 0.2f, 0},
                                {2, 0.5f, 0, 2},
                                {2.5f, 0.1f, 0.2f, 2},
                                {kFar, 0, 0, kNone}});
  const Texture out = ktest::run(k, {&origins, &rays, &isect, &s.v[0], &s.v[1], &s.v[2]}, 5, 1);
  const float e = 0.01f / std::sqrt(2.0f);
  CHECK_TEXEL_NEAR(out, 0, 0, 1e-6, glm::vec4(0.5f, 0.01f, 0.5f, 0));   // from above: up
  CHECK_TEXEL_NEAR(out, 1, 0, 1e-6, glm::vec4(0.5f, -0.01f, 0.5f, 0));  // from below: down
  // The tilted triangle hit at (0, 0, 0) from +x: the normal flips to (1, -1, 0)/sqrt 2.
  CHECK_TEXEL_NEAR(out, 2, 0, 1e-6, glm::vec4(e, -e, 0, 2));
  // Hit at (0.5, 0.5, 0) from -x: the normal (-1, 1, 0)/sqrt 2 already faces the ray.
  CHECK_TEXEL_NEAR(out, 3, 0, 1e-6, glm::vec4(0.5f - e, 0.5f + e, 0, 2));
  CHECK_TEXEL(out, 4, 0, glm::vec4(0, 0, 0, kNone));  // no hit: no surface
}

TEST_CASE(
    "reflection direction mirrors the ray about the interpolated normal, for reflected rays only") {
  const SceneTextures s(kTris);
  kernels::ReflectionDirection k;
  k.scene.width = 2;
  k.min_weight = 1.0f / 512;
  const Texture rays =
      texels("rays", 7, 1,
             {{0.6f, -0.8f, 0, kFar}, kDown, {0.6f, 0.8f, 0, kFar}, kDown, kDown, kDown, kDown});
  const Texture surf =
      texels("surface", 7, 1, {kHit0, {1, 0, 0, 1}, kHit0, kMiss, kHit0, kHit0, kHit0});
  const Texture res = texels("result", 7, 1,
                             {{0, 0, 0, 0.5f},
                              {0, 0, 0, 1},
                              {0, 0, 0, 1},
                              {0, 0, 0, 1},
                              {0, 0, 0, 0},
                              {0, 0, 0, 1.0f / 1024},
                              {0, 0, 0, 1.0f / 512}});
  const Texture out = ktest::run(
      k, {&rays, &surf, &res, &s.v[0], &s.v[1], &s.v[2], &s.n[0], &s.n[1], &s.n[2]}, 7, 1);
  CHECK_TEXEL_NEAR(out, 0, 0, 1e-6, glm::vec4(0.6f, 0.8f, 0, kFar));
  // Triangle 1 at (1, 0, 0), halfway between corners 0 and 2: n = normalize(+y + +x), and
  // (0, -1, 0) mirrors to (1, 0, 0).
  CHECK_TEXEL_NEAR(out, 1, 0, 1e-6, glm::vec4(1, 0, 0, kFar));
  CHECK_TEXEL_NEAR(out, 2, 0, 1e-6, glm::vec4(0.6f, -0.8f, 0, kFar));  // from below
  const glm::vec4 no_ray(0, 0, 0, kNone);
  CHECK_TEXEL(out, 3, 0, no_ray);                               // missed
  CHECK_TEXEL(out, 4, 0, no_ray);                               // not reflective
  CHECK_TEXEL(out, 5, 0, no_ray);                               // weight under the cut
  CHECK_TEXEL_NEAR(out, 6, 0, 1e-6, glm::vec4(0, 1, 0, kFar));  // weight at the cut
}

TEST_CASE("shadow rays point from the hit point to the light with tmax the light's distance") {
  kernels::ShadowRays k;
  k.light = {1, 2, 3};
  k.min_weight = 1.0f / 512;
  const Texture surf = texels(
      "surface", 5, 1, {{1, 2, 0, 0}, {4, 6, 3, 5}, {1, 2, 0, kNone}, {1, 2, 0, 0}, {1, 2, 0, 0}});
  const Texture res =
      texels("result", 5, 1,
             {{0, 0, 0, 1}, {0, 0, 0, 0.25f}, {0, 0, 0, 1}, {0, 0, 0, 0}, {0, 0, 0, 1.0f / 1024}});
  const Texture out = ktest::run(k, {&surf, &res}, 5, 1);
  CHECK_TEXEL(out, 0, 0, glm::vec4(0, 0, 1, 3));
  CHECK_TEXEL_NEAR(out, 1, 0, 1e-6, glm::vec4(-0.6f, -0.8f, 0, 5));
  const glm::vec4 no_ray(0, 0, 0, kNone);
  CHECK_TEXEL(out, 2, 0, no_ray);  // no surface
  CHECK_TEXEL(out, 3, 0, no_ray);  // weight 0: nothing left to light
  CHECK_TEXEL(out, 4, 0, no_ray);  // weight under the cut
}
