// Shadow rays (not one of the paper's 13 programs; its abstract names shadows): from each hit
// point towards one point light, tmax = the light's distance, so any hit before the light means
// shadow. They go through the same traversal and intersection kernels as every other ray.
#pragma once

#include "kernels/common.h"

namespace kernels {

struct ShadowRays {
  static constexpr const char* name = "shadow rays";
  static constexpr const char* paper_name = "rayosSombra (extension)";
  static constexpr int outputs = 1;  // -> rays (a separate shadow-ray texture)
  enum Unit { kSurface, kResult };
  static constexpr std::array<const char*, 2> units{"surface", "result"};

  glm::vec3 light{0.0f};  // world space
  float min_weight = 1.0f / 512.0f;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> surf = f.fetch_own(kSurface);
    const Vec4<F> res = f.fetch_own(kResult);
    const auto lit = (surf.w >= F(0.0f)) && (res.w >= F(min_weight));
    Vec4<F> next{F(0.0f), F(0.0f), F(0.0f), F(kNone)};
    if (f.branch(lit)) {
      const Vec3<F> to = splat<F>(light) - surf.xyz();
      const F dist = sqrt(dot(to, to));
      const Vec3<F> d = to * (F(1.0f) / dist);
      next = select(lit, Vec4<F>{d.x, d.y, d.z, dist}, next);
    }
    f.out(0) = next;
  }
};

}  // namespace kernels
