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

// --- Addresses ---------------------------------------------------------------------------

// A place in a texture of entries (lists, nodes, sub-cells) as a ray's state holds it: linear,
// entry x at (x mod width, x div width) and y unused; or, where the structure is addressed by
// (x, y) (ListUniforms::xy), the texel's column x and row y, as a card addresses a texture. A
// float holds integers exactly to 2^24 and the linear decode is exact to 2^23 (id_to_texel), so
// past that only (x, y) reaches every entry; it costs a second channel per pointer.
template <class F>
struct Addr {
  F x, y;
};

// The texel at address a of a texture `width` texels wide.
template <class L>
inline Vec4<typename L::F> fetch_at(const Fragments<L>& f, int unit, const Addr<typename L::F>& a,
                                    float width, bool xy) {
  using F = typename L::F;
  if (!xy) return fetch_id(f, unit, a.x, width);
  return f.fetch(unit, a.x + F(0.5f), a.y + F(0.5f));
}

// The entry after a (a list's next entry, a node's left child): by (x, y), the next column, or
// the next row's first past the last column. Widths are powers of two (host/trace/passes.h).
template <class F>
inline Addr<F> addr_next(const Addr<F>& a, float width, bool xy) {
  const F nx = a.x + F(1.0f);
  if (!xy) return {nx, a.y};
  const auto wrap = nx >= F(width);
  return {select(wrap, F(0.0f), nx), select(wrap, a.y + F(1.0f), a.y)};
}

// The entry k >= 0 entries after a (k small: a sub-grid's sub-cells). Exact: the width is a power
// of two, so the quotient is.
template <class F>
inline Addr<F> addr_add(const Addr<F>& a, const F& k, float width, bool xy) {
  const F s = a.x + k;
  if (!xy) return {s, a.y};
  const F rows = floor(s / F(width));
  return {s - rows * F(width), a.y + rows};
}

// How many entries b lies after a (b at or after a, the difference small).
template <class F>
inline F addr_minus(const Addr<F>& b, const Addr<F>& a, float width, bool xy) {
  if (!xy) return b.x - a.x;
  return (b.y - a.y) * F(width) + (b.x - a.x);
}

// a where m, else b (linear: y is a's, never read).
template <class F>
inline Addr<F> addr_select(const auto& m, const Addr<F>& a, const Addr<F>& b, bool xy) {
  return {select(m, a.x, b.x), xy ? select(m, a.y, b.y) : a.y};
}

// The list position a voxel state holds (x, and y where addressed by (x, y); linear, y is a
// copy of x and never read).
template <class F>
inline Addr<F> list_pos(const Vec4<F>& vs, const ListUniforms& lists) {
  return {vs.x, lists.xy > 0.5f ? vs.y : vs.x};
}

// --- The list loads -----------------------------------------------------------------------

// Entry `pos` of the triangle lists: a triangle id, or -1 at the end of a list.
template <class L>
inline typename L::F list_entry(const Fragments<L>& f, int unit_lists, const typename L::F& pos,
                                const ListUniforms& lists) {
  return fetch_id(f, unit_lists, pos, lists.list_width).x;
}

// The same at an address (linear or (x, y), as the lists are).
template <class L>
inline typename L::F list_entry_at(const Fragments<L>& f, int unit_lists,
                                   const Addr<typename L::F>& pos, const ListUniforms& lists) {
  return fetch_at(f, unit_lists, pos, lists.list_width, lists.xy > 0.5f).x;
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

// The same at an address: by (x, y), the state holds the position in x and y.
template <class L>
inline Vec4<typename L::F> load_list_at(const Fragments<L>& f, int unit_lists,
                                        const Addr<typename L::F>& pos,
                                        const Vec4<typename L::F>& vs, const typename L::M& load,
                                        const ListUniforms& lists) {
  using F = typename L::F;
  if (lists.xy <= 0.5f) return load_list(f, unit_lists, pos.x, vs, load, lists);
  const F tri = list_entry_at(f, unit_lists, pos, lists);
  return select(load, Vec4<F>{pos.x, pos.y, F(0.0f), tri}, vs);
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

// The looping walk of a list structure addressed by (x, y) (KdLooping, Grid2Looping), within
// f.loop: one iteration either tests the next triangle of the list a ray stands in, or takes one
// step of the structure and, where the step reaches a leaf or cell, loads the first entry of its
// list. `step(stepping, list)` returns the next traversal state and leaves in `list` the list
// start of what it reached (read from the same texel the step fetched); `reached(next)` says where
// it reached one. The list position is (column, row) in vs.xy; vs.w the triangle to test.
template <class L, class Step, class Reached>
inline void walk_lists_by_xy(Fragments<L>& f, int steps, int unit_v0, int unit_lists,
                             const Vec3<typename L::F>& o, const Vec4<typename L::F>& ray,
                             Vec4<typename L::F>& trav, Vec4<typename L::F>& vs,
                             Vec4<typename L::F>& best, const ListUniforms& lists,
                             const SceneUniforms& scene, Step step, Reached reached) {
  using F = typename L::F;
  using M = typename L::M;
  f.loop(steps, trav.x >= F(0.0f), [&](const M& act) {
    const M testing = act && (vs.w >= F(0.0f));
    best =
        nearest_hit_in_segment(f, unit_v0, o, ray, trav, vs, best, testing, scene, lists.t_slack);
    const Addr<F> pos = addr_next(list_pos(vs, lists), lists.list_width, true);
    const F tri = list_entry_at(f, unit_lists, pos, lists);
    const M stepping = act && !testing;
    Addr<F> list{pos.x, pos.y};
    const Vec4<F> next = step(stepping, list);
    const M load = stepping && reached(next);  // reached in this step
    const F first = list_entry_at(f, unit_lists, list, lists);
    vs = select(testing, Vec4<F>{pos.x, pos.y, F(0.0f), tri},
                select(load, Vec4<F>{list.x, list.y, F(0.0f), first}, vs));
    trav = select(stepping, next, trav);
    return trav.x >= F(0.0f);
  });
}

}  // namespace kernels
