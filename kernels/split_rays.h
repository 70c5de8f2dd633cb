// dividirRayos (an extension: glass, issue 25): per ray of a stream level, the weights of the
// two rays its hit spawns (docs/studies/materials.md, "Glass: the model"): reflected w((1-t)a +
// tF), refracted w t(1-F); a ray lives if its weight is at least 1/512 (rayosReflejados' cut). The
// surface's own shading keeps w(1-t)(1-a) (the shader, through the colour texture's alpha).
// Output: x = reflected weight, y = refracted weight (0: not spawned), z = rays spawned (0-2),
// w = 1 where the reflected ray is a total internal reflection.
#pragma once

#include "kernels/glass.h"

namespace kernels {

struct SplitRays {
  static constexpr const char* name = "split rays";
  static constexpr const char* paper_name = "dividirRayos (extension)";
  static constexpr int outputs = 1;  // -> split
  enum Unit { kRays, kSurface, kWeight, kGlass, kV0, kV1, kV2, kN0, kN1, kN2 };
  static constexpr std::array<const char*, 10> units{
      "rays",      "surface",   "result",   "glass",    "vertices0",
      "vertices1", "vertices2", "normals0", "normals1", "normals2"};

  SceneUniforms scene;
  float min_weight = 1.0f / 512.0f;  // as in rayosReflejados

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> surf = f.fetch_own(kSurface);
    const F w = f.fetch_own(kWeight).w;
    const Vec3<F> d = f.fetch_own(kRays).xyz();
    const auto hit = surf.w >= F(0.0f);
    Vec4<F> out{F(0.0f), F(0.0f), F(0.0f), F(0.0f)};
    if (f.branch(hit)) {
      const Vec4<F> mat = fetch_id(f, kGlass, surf.w, scene.width);  // a, t, ior
      const Surface<F> s = surface_at(f, surf.w, surf.xyz(), d, kV0, kN0, scene);
      const Glass<L> g = glass_optics<L>(d, s, mat.z);
      const F a = mat.x, t = mat.y;
      const auto glassy = t > F(0.0f);
      // An opaque surface's reflected share is a itself, so its weight rounds as the paper's w a.
      const F wr = w * select(glassy, (F(1.0f) - t) * a + t * g.fresnel, a);
      const F wt = w * select(glassy, t * (F(1.0f) - g.fresnel), F(0.0f));
      const auto lr = hit && (wr >= F(min_weight));
      const auto lt = hit && (wt >= F(min_weight));
      const F one = F(1.0f), zero = F(0.0f);
      const Vec4<F> split{select(lr, wr, zero), select(lt, wt, zero),
                          select(lr, one, zero) + select(lt, one, zero),
                          select(lr && glassy && g.tir, one, zero)};
      out = select(hit, split, out);
    }
    f.out(0) = out;
  }
};

}  // namespace kernels
