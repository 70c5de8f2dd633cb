// inicioReflejo: the next ray of each pixel starts at the hit point. The point is lifted off the
// surface by `offset` along the geometric normal, towards the side the ray came from, so the
// new ray cannot hit its own triangle again through rounding ("acne"); offset is a fixed
// fraction of the scene size (see docs/architecture.md). Also the record the shader reads.
#pragma once

#include "kernels/common.h"

namespace kernels {

struct ReflectionOrigin {
  static constexpr const char* name = "reflection origin";
  static constexpr const char* paper_name = "inicioReflejo";
  static constexpr int outputs = 1;  // -> surface (next origins)
  enum Unit { kOrigins, kRays, kIntersection, kV0, kV1, kV2 };
  static constexpr std::array<const char*, 6> units{"origins",   "rays",      "intersection",
                                                    "vertices0", "vertices1", "vertices2"};

  SceneUniforms scene;
  float offset = 1e-4f;  // world units

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> hit = f.fetch_own(kIntersection);
    const Vec3<F> o = f.fetch_own(kOrigins).xyz(), d = f.fetch_own(kRays).xyz();
    const auto found = hit.w >= F(0.0f);
    Vec4<F> next{F(0.0f), F(0.0f), F(0.0f), F(kNone)};
    if (f.branch(found)) {
      const Vec3<F> p0 = fetch_id(f, kV0, hit.w, scene.width).xyz();
      const Vec3<F> p1 = fetch_id(f, kV1, hit.w, scene.width).xyz();
      const Vec3<F> p2 = fetch_id(f, kV2, hit.w, scene.width).xyz();
      Vec3<F> ng = normalize(cross(p1 - p0, p2 - p0));
      ng = select(dot(ng, d) > F(0.0f), -ng, ng);
      const Vec3<F> p = o + d * hit.x + ng * F(offset);
      next = select(found, Vec4<F>{p.x, p.y, p.z, hit.w}, next);
    }
    f.out(0) = next;
  }
};

}  // namespace kernels
