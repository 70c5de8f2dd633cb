// The pieces every acceleration structure's walk shares, written once: each structure's kernels
// (the grid's, kernels/bvh.h, kernels/kdtree.h, kernels/grid2.h) include this header and say in
// their own file what they do with them.
//   - the ray-box slab test: where a ray is inside an axis-aligned box;
//   - the list loads: a structure keeps, per voxel (leaf, cell), a list of triangle ids closed
//     by -1 in one texture (kernels/layout.h); a ray holds its place in a list in its voxel
//     state (x = list position, w = triangle to test next, -1: none left);
//   - the triangle tests: the nearest hit so far, updated by one triangle, either anywhere along
//     the ray (a structure that lists each triangle once) or only inside the piece of the ray
//     the current voxel holds (a structure that lists a triangle in every voxel it touches: a
//     hit outside the voxel is found again in the voxel that holds it).
// The list uniforms (ListUniforms, kernels/layout.h) are what the list loads and the in-segment
// rule read. Everything here is fragment-program code: lanes only, no memory but fetches.
#pragma once

#include "kernels/common.h"

namespace kernels {

// --- The slab test ------------------------------------------------------------------------

// Clips the ray's parameter range [tn, tf] to the slab la <= o + t d <= ha of one axis (oa, da:
// the ray's origin and direction along it). An axis the ray runs parallel to keeps it inside
// the slab for every t, or outside for every t. The bounds are uniforms (float) or lanes (F).
template <class F, class B>
inline void clip_to_slab(const F& oa, const F& da, const B& la, const B& ha, F& tn, F& tf) {
  const F inv = F(1.0f) / da;
  const F t0 = (F(la) - oa) * inv, t1 = (F(ha) - oa) * inv;
  const auto parallel = da == F(0.0f);
  const auto inside = (oa >= F(la)) && (oa <= F(ha));
  tn = max(tn, select(parallel, select(inside, F(-kFar), F(kFar)), min(t0, t1)));
  tf = min(tf, select(parallel, select(inside, F(kFar), F(-kFar)), max(t0, t1)));
}

// Where the ray o + t d, 0 <= t <= tfar, is inside the box [lo, hi]: [tn, tf] (empty: tn > tf).
// The box's corners are uniforms (glm::vec3) or lanes (Vec3<F>, e.g. a fetched node).
template <class F, class V>
inline void ray_box_segment(const Vec3<F>& o, const Vec3<F>& d, const V& lo, const V& hi,
                            const F& tfar, F& tn, F& tf) {
  tn = F(0.0f);
  tf = tfar;
  clip_to_slab(o.x, d.x, lo.x, hi.x, tn, tf);
  clip_to_slab(o.y, d.y, lo.y, hi.y, tn, tf);
  clip_to_slab(o.z, d.z, lo.z, hi.z, tn, tf);
}

// --- The list loads -----------------------------------------------------------------------

// Entry `pos` of the triangle lists: a triangle id, or -1 at the end of a list.
template <class L>
inline typename L::F list_entry(const Fragments<L>& f, int unit_lists, const typename L::F& pos,
                                const ListUniforms& lists) {
  return fetch_id(f, unit_lists, pos, lists.list_width).x;
}

// The voxel state standing at list position `pos` (its triangle fetched), for the lanes where
// `load`; other lanes keep `vs`. Loading a voxel's first entry and moving on to the next
// entry (proximoTriangulo) are both this.
template <class L>
inline Vec4<typename L::F> load_list(const Fragments<L>& f, int unit_lists,
                                     const typename L::F& pos, const Vec4<typename L::F>& vs,
                                     const typename L::M& load, const ListUniforms& lists) {
  using F = typename L::F;
  const F tri = list_entry(f, unit_lists, pos, lists);
  return select(load, Vec4<F>{pos, F(0.0f), F(0.0f), tri}, vs);
}

// --- The triangle tests -------------------------------------------------------------------

// Triangle `tri` (its corners fetched from units unit_v0, unit_v0 + 1, unit_v0 + 2) against
// the ray o + t d: t (kFar on a miss) and the hit's barycentrics u, v.
template <class L>
inline typename L::F hit_triangle(const Fragments<L>& f, int unit_v0, const Vec3<typename L::F>& o,
                                  const Vec3<typename L::F>& d, const typename L::F& tri,
                                  const SceneUniforms& scene, typename L::F& u, typename L::F& v) {
  using F = typename L::F;
  const Vec3<F> p0 = fetch_id(f, unit_v0, tri, scene.width).xyz();
  const Vec3<F> p1 = fetch_id(f, unit_v0 + 1, tri, scene.width).xyz();
  const Vec3<F> p2 = fetch_id(f, unit_v0 + 2, tri, scene.width).xyz();
  return intersect_triangle(o, d, p0, p1, p2, u, v);
}

// Whether t lies in the ray's segment [tmin, tmax], widened by t_slack on both sides (so a hit
// on a face two voxels share is not lost to rounding in both).
template <class F>
inline auto in_segment(const F& t, const F& tmin, const F& tmax, float t_slack) {
  return (t >= tmin - F(t_slack)) && (t <= tmax + F(t_slack));
}

// Whether a walk can end before a cell that begins at t_enter: every hit in it or after it has
// t >= t_enter - t_slack (in_segment's lower bound), so with that at or past tmax none can pass
// t < tmax. The grids' steps end a shadow ray there (its tmax is the light's distance).
template <class F>
inline auto past_tmax(const F& t_enter, const F& tmax, float t_slack) {
  return t_enter - F(t_slack) >= tmax;
}

// The nearest of the hit so far (`best`: t, u, v, triangle) and triangle vs.w, for the lanes
// where `testing`, counting a hit only inside the segment seg.zw (widened by t_slack).
template <class L>
inline Vec4<typename L::F> nearest_hit_in_segment(
    const Fragments<L>& f, int unit_v0, const Vec3<typename L::F>& o,
    const Vec4<typename L::F>& ray, const Vec4<typename L::F>& seg, const Vec4<typename L::F>& vs,
    const Vec4<typename L::F>& best, const typename L::M& testing, const SceneUniforms& scene,
    float t_slack) {
  using F = typename L::F;
  F bu, bv;
  const F t = hit_triangle(f, unit_v0, o, ray.xyz(), vs.w, scene, bu, bv);
  const auto nearer =
      testing && in_segment(t, seg.z, seg.w, t_slack) && (t < best.x) && (t < ray.w);
  return select(nearer, Vec4<F>{t, bu, bv, vs.w}, best);
}

// The same with no bound but the ray's tmax: for a structure that lists each triangle once, a
// hit is valid wherever it lies.
template <class L>
inline Vec4<typename L::F> nearest_hit_anywhere(
    const Fragments<L>& f, int unit_v0, const Vec3<typename L::F>& o,
    const Vec4<typename L::F>& ray, const Vec4<typename L::F>& vs, const Vec4<typename L::F>& best,
    const typename L::M& testing, const SceneUniforms& scene) {
  using F = typename L::F;
  F bu, bv;
  const F t = hit_triangle(f, unit_v0, o, ray.xyz(), vs.w, scene, bu, bv);
  const auto nearer = testing && (t < best.x) && (t < ray.w);
  return select(nearer, Vec4<F>{t, bu, bv, vs.w}, best);
}

}  // namespace kernels
