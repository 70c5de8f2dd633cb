// shader: the colour of each ray's hit, one pass per light (paper Sec. 2.4), accumulated into the
// result with the paper's blend: the i-th surface adds  w_i (1 - a_i) C_i  where w_i is the
// product of the reflection coefficients met before it (result alpha) and a_i its own. The last
// light's pass sets the weight of the reflected ray, w_i a_i. Swappable lighting models:
//   diffuse:      kd (ambient + sum over lights of vis * max(n.l, 0))
//   phong:        + vis * ks * max(r.v, 0)^32
//   phong-atten:  the per-light terms divided by 1 + (dist / atten_dist)^2 (paper Fig. 3)
// With base-colour textures (texture.on), kd is the material's colour times the filtered texel
// (kernels/base_color.h), through five more units: 16 in all, fp30's every texture image unit.
#pragma once

#include "kernels/base_color.h"
#include "kernels/common.h"

namespace kernels {

enum class ShadingModel { diffuse = 0, phong = 1, phong_atten = 2 };

struct Shader {
  static constexpr const char* name = "shader";
  static constexpr const char* paper_name = "shader";
  static constexpr int outputs = 1;  // -> result
  enum Unit {
    kSurface,
    kRays,
    kResult,
    kShadow,
    kColors,
    kV0,
    kV1,
    kV2,
    kN0,
    kN1,
    kN2,
    kOrigins,  // the rays' origins, the uvs, the table and the atlas: textured scenes only
    kUv01,
    kUv2,
    kTable,
    kAtlas
  };
  static constexpr std::array<const char*, 16> units{
      "surface",   "rays",      "result",        "shadow_hits",  "colors",   "vertices0",
      "vertices1", "vertices2", "normals0",      "normals1",     "normals2", "origins",
      "uvs01",     "uvs2",      "texture_table", "texture_atlas"};

  SceneUniforms scene;
  TextureUniforms texture;
  ShadingModel model = ShadingModel::diffuse;
  glm::vec3 light{0.0f}, light_color{1.0f};  // world space; rgb x intensity
  bool first_light = true, last_light = true;
  bool shadows = false;  // kShadow holds this light's shadow-ray intersections
  // Scenes with glass (sombraVidrio): kShadow holds instead the shadow origins whose w is the
  // light's transmittance (0 blocked, 1 clear, the glass crossed's t multiplied).
  bool shadow_transmittance = false;
  glm::vec3 ambient{0.1f};
  glm::vec3 background{0.0f};
  float specular = 0.5f;     // ks
  float atten_dist = 10.0f;  // world units: distance at which a light falls to half

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> surf = f.fetch_own(kSurface);
    const Vec4<F> res = f.fetch_own(kResult);
    const Vec3<F> d = f.fetch_own(kRays).xyz();
    const F w = res.w;
    const auto hit = surf.w >= F(0.0f);
    Vec3<F> add = first_light ? splat<F>(background) * w : splat<F>(glm::vec3(0.0f));
    F weight = last_light ? F(0.0f) : w;
    if (f.branch(hit)) {
      const Vec4<F> mat = fetch_id(f, kColors, surf.w, scene.width);
      Vec3<F> kd = mat.xyz();
      const Surface<F> s = surface_at(f, surf.w, surf.xyz(), d, kV0, kN0, scene);
      if (texture.on) {
        typename L::M textured;
        const Vec3<F> origin = f.fetch_own(kOrigins).xyz();
        const Vec4<F> texel = base_color(f, texture, scene, surf.w, surf.xyz(), d, origin, s, kUv01,
                                         kUv2, kTable, kAtlas, textured);
        kd = select(textured, kd * texel.xyz(), kd);
      }
      const Vec3<F> to = splat<F>(light) - surf.xyz();
      const F dist = sqrt(dot(to, to));
      const Vec3<F> l = to * (F(1.0f) / dist);
      Vec3<F> lit = kd * max(dot(s.n, l), F(0.0f));
      if (model != ShadingModel::diffuse) {
        const Vec3<F> r = l - s.n * (F(2.0f) * dot(l, s.n));  // mirror of l, pointing away
        F c = max(dot(r, d), F(0.0f));                        // = max(r'.v, 0), v = -d
        for (int i = 0; i < 5; ++i) c = c * c;                // ^32, unrolled: no loop on fp30
        lit = lit + splat<F>(glm::vec3(1.0f)) * (F(specular) * c);
      }
      if (model == ShadingModel::phong_atten) {
        const F q = dist / F(atten_dist);
        lit = lit * (F(1.0f) / (F(1.0f) + q * q));
      }
      F vis = F(1.0f);
      if (shadows && shadow_transmittance)
        vis = f.fetch_own(kShadow).w;
      else if (shadows)
        vis = select(f.fetch_own(kShadow).w >= F(0.0f), F(0.0f), F(1.0f));
      Vec3<F> c = lit * splat<F>(light_color) * vis;
      if (first_light) c = c + kd * splat<F>(ambient);
      const F a = mat.w;
      const Vec3<F> surface_add = c * (w * (F(1.0f) - a));
      add = select(hit, surface_add, add);
      if (last_light) weight = select(hit, w * a, F(0.0f));
    }
    f.out(0) = {res.x + add.x, res.y + add.y, res.z + add.z, weight};
  }
};

}  // namespace kernels
