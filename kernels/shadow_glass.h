// sombraVidrio (an extension: glass, issue 25): a shadow ray that stopped on glass goes on
// (docs/studies/materials.md: no caustics, refraction does not bend it). Each glass surface crossed
// multiplies the light by its transmission t; an opaque one blocks it (t = 0); on the 8th glass
// surface (`last`) the light counts as blocked. One output per pass (fp30): `part` 0 writes the
// continued origin (just past the glass, along the ray) with the light's transmittance so far in
// w, what the shader reads; 1 the continued ray (the distance left to the light as tmax), or no
// ray (tmax -1) where it stopped for good.
#pragma once

#include "kernels/common.h"

namespace kernels {

struct ShadowGlass {
  static constexpr const char* name = "shadow through glass";
  static constexpr const char* paper_name = "sombraVidrio (extension)";
  static constexpr int outputs = 1;  // -> shadow origins (part 0) or shadow rays (part 1)
  enum Unit { kOrigins, kRays, kHits, kGlass };
  static constexpr std::array<const char*, 4> units{"shadow_origins", "shadow_rays", "shadow_hits",
                                                    "glass"};

  SceneUniforms scene;
  bool first = true;     // the origins are the surface record (w: triangle), transmittance 1
  bool last = false;     // the 8th glass surface: what would go on is blocked
  int part = 0;          // 0: origins and transmittance, 1: rays
  float offset = 1e-4f;  // world units past the glass surface

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> o = f.fetch_own(kOrigins), r = f.fetch_own(kRays), h = f.fetch_own(kHits);
    const F light = first ? F(1.0f) : o.w;
    const auto hit = (r.w >= F(0.0f)) && (h.w >= F(0.0f));
    const F t = fetch_id(f, kGlass, max(h.w, F(0.0f)), scene.width).y;
    const auto goes_on = hit && (t > F(0.0f));
    F through = select(hit, light * t, light);
    if (last) through = select(goes_on, F(0.0f), through);
    const F step = h.x + F(offset);
    if (part == 0) {
      const Vec3<F> p = o.xyz() + r.xyz() * step;
      const Vec3<F> at = last ? o.xyz() : select(goes_on, p, o.xyz());
      f.out(0) = {at.x, at.y, at.z, through};
    } else {
      const F tmax = last ? F(kNone) : select(goes_on, r.w - step, F(kNone));
      f.out(0) = {r.x, r.y, r.z, tmax};
    }
  }
};

}  // namespace kernels
