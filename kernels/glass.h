// Whitted's glass at a hit (docs/studies/materials.md, "Glass: the model"): which side the ray
// meets, the exact unpolarised Fresnel reflectance with total internal reflection, the refracted
// direction. Lane code shared by dividirRayos (the shares of a ray's weight) and compactarRayos
// (the spawned rays), so both see the same numbers.
#pragma once

#include "kernels/common.h"

namespace kernels {

template <class L>
struct Glass {
  using F = typename L::F;
  F e;                // eta1 / eta2: 1 / ior entering, ior leaving
  F cos_i, cos_t;     // cosines of the incident and transmitted angles (cos_t 0 under TIR)
  typename L::M tir;  // total internal reflection: sin^2 theta_t >= 1
  F fresnel;          // reflected fraction of the light the surface transmits; 1 under TIR
  Vec3<F> refracted;  // unit refracted direction (meaningless under TIR)
};

// d: the unit incoming direction; s: the surface seen from d (its shading normal faces d);
// ior: the glass's index. The ray enters when it meets the front of the triangle's winding
// (dot(d, e1 x e2) < 0), and leaves otherwise.
template <class L>
inline Glass<L> glass_optics(const Vec3<typename L::F>& d, const Surface<typename L::F>& s,
                             const typename L::F& ior) {
  using F = typename L::F;
  Glass<L> g;
  const auto enters = dot(d, cross(s.e1, s.e2)) < F(0.0f);
  g.e = select(enters, F(1.0f) / ior, ior);
  g.cos_i = min(-dot(d, s.n), F(1.0f));
  const F sin2_t = g.e * g.e * (F(1.0f) - g.cos_i * g.cos_i);
  g.tir = sin2_t >= F(1.0f);
  g.cos_t = sqrt(max(F(1.0f) - sin2_t, F(0.0f)));
  const F ec_i = g.e * g.cos_i, ec_t = g.e * g.cos_t;
  // Under TIR both denominators may vanish together (grazing): the select drops that lane.
  const F rs = (ec_i - g.cos_t) / (ec_i + g.cos_t);
  const F rp = (g.cos_i - ec_t) / (g.cos_i + ec_t);
  g.fresnel = select(g.tir, F(1.0f), (rs * rs + rp * rp) * F(0.5f));
  g.refracted = normalize(d * g.e + s.n * (ec_i - g.cos_t));
  return g;
}

// The element index of the fragment at texel centre (x, y) of a stream texture `width` wide:
// element i at (i mod width, i div width), exact in fp32 below 2^24.
template <class F>
inline F stream_index(const F& x, const F& y, float width) {
  return (y - F(0.5f)) * F(width) + (x - F(0.5f));
}

// Stream reduction's gather (Horn, GPU Gems 2 ch. 36): the first entry i of an inclusive prefix
// sum (texture unit `scan`, `sources` entries, a stream `width` wide) whose sum passes j, found
// by a binary search of `steps` = ceil(log2(sources)) dependent fetches (a fixed count: no
// data-dependent loop, so the FX runs it). It is the element that output slot j gathers from.
template <class L>
inline typename L::F scan_search(const Fragments<L>& f, int scan, const typename L::F& j,
                                 float sources, int steps, float width) {
  using F = typename L::F;
  F lo = F(0.0f), hi = F(sources - 1.0f);
  for (int s = 0; s < steps; ++s) {
    const F mid = floor((lo + hi) * F(0.5f));
    const auto left = fetch_id(f, scan, mid, width).x > j;
    hi = select(left, mid, hi);
    lo = select(left, lo, mid + F(1.0f));
  }
  return min(lo, F(sources - 1.0f));
}

}  // namespace kernels
