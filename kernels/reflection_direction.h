// direccionReflejo: the reflected direction r = d - 2 (d.n) n from the incoming direction and
// the interpolated normal at the hit. Rays the shader did not reflect (weight below the cut)
// get tmax = -1: no ray, every later kernel leaves them alone.
#pragma once

#include "kernels/common.h"

namespace kernels {

struct ReflectionDirection {
  static constexpr const char* name = "reflection direction";
  static constexpr const char* paper_name = "direccionReflejo";
  static constexpr int outputs = 1;  // -> rays
  enum Unit { kRays, kSurface, kResult, kV0, kV1, kV2, kN0, kN1, kN2 };
  static constexpr std::array<const char*, 9> units{"rays",      "surface",   "result",
                                                    "vertices0", "vertices1", "vertices2",
                                                    "normals0",  "normals1",  "normals2"};

  SceneUniforms scene;
  float min_weight = 1.0f / 512.0f;  // as in rayosReflejados

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> surf = f.fetch_own(kSurface);
    const Vec4<F> res = f.fetch_own(kResult);
    const Vec3<F> d = f.fetch_own(kRays).xyz();
    const auto reflected = (surf.w >= F(0.0f)) && (res.w >= F(min_weight));
    Vec4<F> next{F(0.0f), F(0.0f), F(0.0f), F(kNone)};
    if (f.branch(reflected)) {
      const Surface<F> s = surface_at(f, surf.w, surf.xyz(), d, kV0, kN0, scene);
      const Vec3<F> r = normalize(d - s.n * (F(2.0f) * dot(d, s.n)));
      next = select(reflected, Vec4<F>{r.x, r.y, r.z, F(kFar)}, next);
    }
    f.out(0) = next;
  }
};

}  // namespace kernels
