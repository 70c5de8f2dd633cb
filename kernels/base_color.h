// The base-colour texel of a hit (glTF's baseColorTexture), for the shader: the hit's texture
// coordinates interpolated from its triangle's corners, then the texture unit's filter
// (vgpu/sampler.h) over that texture's mip chain in the atlas (kernels/layout.h).
//
// Level of detail from ray differentials (Igehy, "Tracing Ray Differentials", SIGGRAPH 1999),
// not from 2x2 fragment quads: in a stream tracer a fragment's neighbours in the quad are other
// pixels' rays, which after the first hit lie on other surfaces, in other iterations' mirrors, or
// nowhere; their differences (what DDX/DDY gave the 2004 hardware) would be garbage at every
// edge. A differential belongs to its own ray. The pixel's neighbouring rays differ in direction
// by `spread` along the camera's right and up; at the hit, t along the ray, the footprint steps
//   dP = t spread (R - (R.d) d),  projected along d onto the triangle's plane,
// and the coordinates' steps follow from the barycentric solve. Reflected rays restart the
// differential at the mirror (t is the segment's length, not the path's): their footprint is
// what a pixel's spread covers from the mirror on, sharper than Igehy's full transfer through a
// curved mirror. The larger of the two steps, in level-0 texels, is rho; lambda = log2(rho).
#pragma once

#include "kernels/common.h"
#include "vgpu/sampler.h"

namespace kernels {

// The filtered texel (linear rgb, alpha) at hit p of triangle `tri` (s: surface_at's solve there),
// for the ray from `origin` along unit d (world space); `textured` says where the triangle's
// material has a texture (elsewhere the texel is meaningless). Units: the corners' coordinates
// (uv01, uv2), the texture table and the atlas. Fetches: 2 + 2 + the filter's 1 or 4 texels;
// trilinear 2 + 4 + 8.
template <class L>
inline Vec4<typename L::F> base_color(const Fragments<L>& f, const TextureUniforms& tu,
                                      const SceneUniforms& scene, const typename L::F& tri,
                                      const Vec3<typename L::F>& p, const Vec3<typename L::F>& d,
                                      const Vec3<typename L::F>& origin,
                                      const Surface<typename L::F>& s, int unit_uv01, int unit_uv2,
                                      int unit_table, int unit_atlas, typename L::M& textured) {
  using F = typename L::F;
  using vgpu::MipLevel;
  const Vec4<F> uv01 = fetch_id(f, unit_uv01, tri, scene.width);
  const Vec4<F> uv2t = fetch_id(f, unit_uv2, tri, scene.width);
  textured = uv2t.z >= F(0.0f);
  const F row = uv2t.z + F(0.5f);  // the texture's row of the table (clamped to 0 if none)
  const F du1 = uv01.z - uv01.x, dv1 = uv01.w - uv01.y;
  const F du2 = uv2t.x - uv01.x, dv2 = uv2t.y - uv01.y;
  const F u = uv01.x + du1 * s.b1 + du2 * s.b2;
  const F v = uv01.y + dv1 * s.b1 + dv2 * s.b2;
  const Vec4<F> head = f.fetch(unit_table, F(0.5f), row);
  const Vec4<F> r0 = f.fetch(unit_table, F(1.5f), row);
  const MipLevel<F> level0{r0.x, r0.y, r0.z, r0.w};
  if (tu.filter == vgpu::Filter::nearest)
    return vgpu::sample_nearest(f, unit_atlas, level0, u, v, head.y, head.z);
  if (tu.filter == vgpu::Filter::bilinear)
    return vgpu::sample_bilinear(f, unit_atlas, level0, u, v, head.y, head.z);
  // The texture-space steps of the two neighbouring rays (in level-0 texels).
  const Vec3<F> to = p - origin;
  const F t = sqrt(dot(to, to));
  const F dn = dot(d, s.ng);
  auto step = [&](const glm::vec3& axis, F& du, F& dv) {
    const Vec3<F> a = splat<F>(axis);
    const Vec3<F> w = (a - d * dot(a, d)) * (t * F(tu.spread));
    const Vec3<F> dp = w - d * (dot(w, s.ng) / dn);
    const F q1 = dot(dp, s.e1), q2 = dot(dp, s.e2);
    const F db1 = (s.d11 * q1 - s.d01 * q2) * s.inv;
    const F db2 = (s.d00 * q2 - s.d01 * q1) * s.inv;
    du = (du1 * db1 + du2 * db2) * level0.w;
    dv = (dv1 * db1 + dv2 * db2) * level0.h;
  };
  F dux, dvx, duy, dvy;
  step(tu.right, dux, dvx);
  step(tu.up, duy, dvy);
  const F rho = sqrt(max(dux * dux + dvx * dvx, duy * duy + dvy * dvy));
  F level, frac;
  vgpu::level_of_detail(rho, head.x, level, frac);
  const F next = min(level + F(1.0f), head.x - F(1.0f));
  const Vec4<F> rf = f.fetch(unit_table, level + F(1.5f), row);
  const Vec4<F> rc = f.fetch(unit_table, next + F(1.5f), row);
  return vgpu::sample_trilinear(f, unit_atlas, MipLevel<F>{rf.x, rf.y, rf.z, rf.w},
                                MipLevel<F>{rc.x, rc.y, rc.z, rc.w}, frac, u, v, head.y, head.z);
}

}  // namespace kernels
