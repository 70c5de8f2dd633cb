// Lane helpers shared by the kernels: uniforms as lanes, id-to-texel addressing, the voxel exit
// parameter (shared by traversal and intersecciones so both see the same voxel bounds) and the
// ray-triangle test. Everything here is fragment-program code: lanes only, no memory but fetches.
#pragma once

#include "kernels/layout.h"
#include "vgpu/fragment.h"

namespace kernels {

using vgpu::Fragments;
using vgpu::Vec3;
using vgpu::Vec4;
// The lane vocabulary, visible by name in kernel code (ADL alone would miss the CFloat and
// Vec3 overloads, and plain C's select() would win).
using vgpu::abs;
using vgpu::cross;
using vgpu::dot;
using vgpu::floor;
using vgpu::max;
using vgpu::min;
using vgpu::normalize;
using vgpu::rsqrt;
using vgpu::select;
using vgpu::sqrt;

template <class F>
inline Vec3<F> splat(const glm::vec3& v) {
  return {F(v.x), F(v.y), F(v.z)};
}

// Texel coordinates (centre) of entry `id` of a texture `width` texels wide.
template <class F>
inline void id_to_texel(const F& id, float width, F& u, F& v) {
  const F row = floor((id + F(0.5f)) / F(width));
  u = id - row * F(width) + F(0.5f);
  v = row + F(0.5f);
}

template <class L>
inline Vec4<typename L::F> fetch_id(const Fragments<L>& f, int unit, const typename L::F& id,
                                    float width) {
  typename L::F u, v;
  id_to_texel(id, width, u, v);
  return f.fetch(unit, u, v);
}

// The texel of the fragment's tile in a texture of one texel per `tile` x `tile` pixels (beams
// over tiles, kernels/beams.h).
template <class L>
inline Vec4<typename L::F> fetch_tile(const Fragments<L>& f, int unit, float tile) {
  using F = typename L::F;
  return f.fetch(unit, floor(f.x / F(tile)) + F(0.5f), floor(f.y / F(tile)) + F(0.5f));
}

// Amanatides & Woo, recomputed from the voxel index each pass (no per-ray DDA increments to
// store): for each axis the parameter t at which the ray leaves voxel `vox` through that
// axis' next boundary; an axis the ray runs parallel to never ends the voxel.
template <class F>
inline Vec3<F> voxel_exits(const Vec3<F>& o, const Vec3<F>& d, const Vec3<F>& vox,
                           const GridUniforms& g) {
  auto axis = [&](const F& oa, const F& da, const F& va, float lo, float cell) {
    const F boundary = F(lo) + (va + select(da > F(0.0f), F(1.0f), F(0.0f))) * F(cell);
    return select(da == F(0.0f), F(kFar), (boundary - oa) / da);
  };
  return {axis(o.x, d.x, vox.x, g.lo.x, g.cell.x), axis(o.y, d.y, vox.y, g.lo.y, g.cell.y),
          axis(o.z, d.z, vox.z, g.lo.z, g.cell.z)};
}

template <class F>
inline F min3(const Vec3<F>& v) {
  return min(min(v.x, v.y), v.z);
}

inline constexpr float kEdgeEps = 1.0f / (1 << 20);

// Moller-Trumbore, two-sided. Returns t (kFar where the ray misses) and barycentrics u, v.
template <class F>
inline F intersect_triangle(const Vec3<F>& o, const Vec3<F>& d, const Vec3<F>& p0,
                            const Vec3<F>& p1, const Vec3<F>& p2, F& u, F& v) {
  const Vec3<F> e1 = p1 - p0, e2 = p2 - p0;
  const Vec3<F> p = cross(d, e2);
  const F det = dot(e1, p);
  const F inv = F(1.0f) / det;
  const Vec3<F> s = o - p0;
  u = dot(s, p) * inv;
  const Vec3<F> q = cross(s, e1);
  v = dot(d, q) * inv;
  const F t = dot(e2, q) * inv;
  // Edges are widened by kEdgeEps (in barycentric units) so that a ray through an edge shared
  // by two triangles cannot be refused by both through rounding (a crack): found by the
  // stability suite's octahedron case, where both faces computed u + v = 1 + 2^-23.
  const F lo = F(-kEdgeEps), hi = F(1.0f + kEdgeEps);
  const auto hit = (det != F(0.0f)) && (u >= lo) && (v >= lo) && (u + v <= hi) && (t > F(0.0f));
  return select(hit, t, F(kFar));
}

}  // namespace kernels

namespace kernels {

// The triangle `tri` seen at world point p: barycentric weights from its corners, the
// interpolated shading normal (unit) and the geometric normal (unit). Both normals face the
// side the incoming direction d comes from. The barycentric solve is kept for the texture
// coordinates and their derivatives (kernels/base_color.h).
template <class F>
struct Surface {
  Vec3<F> n;   // shading normal
  Vec3<F> ng;  // geometric normal
  F b1, b2;    // barycentric weights of corners 1 and 2 at p
  // The solve: edges e1 = p1 - p0, e2 = p2 - p0 (world space), their dot products and the
  // inverse determinant; a world-space step dp changes b1 by (d11 dp.e1 - d01 dp.e2) inv.
  Vec3<F> e1, e2;
  F d00, d01, d11, inv;
};

template <class L>
inline Surface<typename L::F> surface_at(const Fragments<L>& f, const typename L::F& tri,
                                         const Vec3<typename L::F>& p, const Vec3<typename L::F>& d,
                                         int unit_v0, int unit_n0, const SceneUniforms& scene) {
  using F = typename L::F;
  const Vec3<F> p0 = fetch_id(f, unit_v0, tri, scene.width).xyz();
  const Vec3<F> p1 = fetch_id(f, unit_v0 + 1, tri, scene.width).xyz();
  const Vec3<F> p2 = fetch_id(f, unit_v0 + 2, tri, scene.width).xyz();
  const Vec3<F> n0 = fetch_id(f, unit_n0, tri, scene.width).xyz();
  const Vec3<F> n1 = fetch_id(f, unit_n0 + 1, tri, scene.width).xyz();
  const Vec3<F> n2 = fetch_id(f, unit_n0 + 2, tri, scene.width).xyz();
  const Vec3<F> e1 = p1 - p0, e2 = p2 - p0, ep = p - p0;
  const F d00 = dot(e1, e1), d01 = dot(e1, e2), d11 = dot(e2, e2);
  const F d20 = dot(ep, e1), d21 = dot(ep, e2);
  const F inv = F(1.0f) / (d00 * d11 - d01 * d01);
  const F b1 = (d11 * d20 - d01 * d21) * inv, b2 = (d00 * d21 - d01 * d20) * inv;
  Vec3<F> n = normalize(n0 * (F(1.0f) - b1 - b2) + n1 * b1 + n2 * b2);
  Vec3<F> ng = normalize(cross(e1, e2));
  n = select(dot(n, d) > F(0.0f), -n, n);
  ng = select(dot(ng, d) > F(0.0f), -ng, ng);
  return {n, ng, b1, b2, e1, e2, d00, d01, d11, inv};
}

}  // namespace kernels
