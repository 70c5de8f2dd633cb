// The kd-tree walk's kernels (an extension; host/accel/kdtree.h): kd-restart (Foley & Sugerman,
// Graphics Hardware 2005), one node per pass, steered by the same queries as the grid's walk:
//   inicioKd (extension)          the segment [tmin, tmax] where the ray is inside the scene box,
//                                 and the root                    (initTraversal's place)
//   recorridoKd (extension)       one node per pass: an inner node sends the ray to the child
//                                 its segment starts in (cutting tmax at the plane when it
//                                 reaches the other); a leaf just reached is handed to
//                                 cargarHoja; a leaf already tested ends the ray (a hit inside
//                                 it, or the segment reached the box's exit) or restarts it
//                                 from the root with tmin at the leaf's exit (traversal's place)
//   cargarHojaKd (extension)      the first triangle of the leaf reached (actualizarVoxel's)
//   interseccionesKd (extension)  one triangle per pass, a hit counting only inside the leaf's
//                                 segment, widened by t_slack (the grid's in-voxel rule)
// with proximoTriangulo, rayosIntersectando and rayosEnGrilla as the grid has them. Traversal
// state (kernels/layout.h): x = node (-1: done), y = list position of the leaf being tested
// (-1: none), z = tmin, w = tmax of the segment. Leaves are met front to back, so the first hit
// inside a leaf's segment is the nearest.
#pragma once

#include "kernels/bvh.h"
#include "kernels/common.h"

namespace kernels {

struct KdUniforms {
  glm::vec3 lo{0.0f}, hi{0.0f};  // the root's box
  float node_width = 1;          // width of the node texture, texels
  float list_width = 1;          // width of the kd-tree's triangle-list texture, texels
  float t_slack = 0;             // the in-leaf rule's tolerance, world units along a unit ray
};

// Where the ray o + t d, 0 <= t <= tfar, is inside the box: [tn, tf] (empty: tn > tf).
template <class F>
inline void box_segment(const Vec3<F>& o, const Vec3<F>& d, const glm::vec3& lo,
                        const glm::vec3& hi, const F& tfar, F& tn, F& tf) {
  tn = F(0.0f);
  tf = tfar;
  auto slab = [&](const F& oa, const F& da, float la, float ha) {
    const F inv = F(1.0f) / da;
    const F t0 = (F(la) - oa) * inv, t1 = (F(ha) - oa) * inv;
    const auto parallel = da == F(0.0f);
    const auto inside = (oa >= F(la)) && (oa <= F(ha));
    tn = max(tn, select(parallel, select(inside, F(-kFar), F(kFar)), min(t0, t1)));
    tf = min(tf, select(parallel, select(inside, F(kFar), F(-kFar)), max(t0, t1)));
  };
  slab(o.x, d.x, lo.x, hi.x);
  slab(o.y, d.y, lo.y, hi.y);
  slab(o.z, d.z, lo.z, hi.z);
}

// The segment entry of a ray with tmax ray_w: root and [tn, tf], or done.
template <class F>
inline Vec4<F> kd_entry(const Vec3<F>& o, const Vec3<F>& d, const F& ray_w, const KdUniforms& kd) {
  F tn, tf;
  box_segment(o, d, kd.lo, kd.hi, ray_w, tn, tf);
  const auto enters = (tn <= tf) && (ray_w >= F(0.0f));
  return select(enters, Vec4<F>{F(0.0f), F(kNone), tn, tf},
                Vec4<F>{F(kNone), F(kNone), F(0.0f), F(0.0f)});
}

// The component of v along axis a (0, 1, 2), a given per lane.
template <class F>
inline F along(const Vec3<F>& v, const F& a) {
  return select(a < F(0.5f), v.x, select(a < F(1.5f), v.y, v.z));
}

// One step of kd-restart for the lanes where `walking` (others keep trav): the node trav.x,
// fetched as (split, axis, right child, leaf list start).
template <class L>
inline Vec4<typename L::F> kd_step(const Fragments<L>& f, int unit_nodes,
                                   const Vec4<typename L::F>& trav, const Vec4<typename L::F>& best,
                                   const Vec3<typename L::F>& o, const Vec3<typename L::F>& d,
                                   const typename L::F& ray_w, const typename L::M& walking,
                                   const KdUniforms& kd) {
  using F = typename L::F;
  const Vec4<F> node = fetch_id(f, unit_nodes, trav.x, kd.node_width);
  const auto leaf = node.y > F(2.5f);
  const auto tested = trav.y >= F(0.0f);  // this leaf's triangles were tested in the last step
  // A leaf just reached: hand it to cargarHoja.
  const Vec4<F> reach{trav.x, node.w, trav.z, trav.w};
  // A leaf tested: a hit inside it ends the ray, as does a segment that reached the box's exit
  // (or the ray's tmax); otherwise restart from the root past the leaf.
  F tn, tend;
  box_segment(o, d, kd.lo, kd.hi, ray_w, tn, tend);
  const auto over = (best.w >= F(0.0f)) || (trav.w >= tend);
  const Vec4<F> done{F(kNone), F(kNone), F(0.0f), F(0.0f)};
  const Vec4<F> restart{F(0.0f), F(kNone), trav.w, tend};
  // An inner node: the child the segment starts in, cutting the segment at the plane when it
  // reaches the other child; the far child alone when the plane lies before tmin. A ray whose
  // origin lies on the plane (ts = 0, or -0) runs into the child its direction points to
  // (`below` breaks the tie by direction), which is then the near child and the only one.
  const F oa = along(o, node.y), da = along(d, node.y);
  const F ts = (node.x - oa) / da;
  const auto below = (oa < node.x) || ((oa == node.x) && (da <= F(0.0f)));
  const F left = trav.x + F(1.0f), right = node.z;
  const F near = select(below, left, right), far = select(below, right, left);
  const auto near_only = (da == F(0.0f)) || (ts >= trav.w) || (ts <= F(0.0f));
  const auto far_only = !near_only && (ts <= trav.z);
  const Vec4<F> inner{select(far_only, far, near), F(kNone), trav.z,
                      select(near_only || far_only, trav.w, ts)};
  const Vec4<F> at_leaf = select(tested, select(over, done, restart), reach);
  return select(walking, select(leaf, at_leaf, inner), trav);
}

struct KdEnter {
  static constexpr const char* name = "kd enter";
  static constexpr const char* paper_name = "inicioKd (extension)";
  static constexpr int outputs = 1;  // -> traversal
  enum Unit { kOrigins, kRays };
  static constexpr std::array<const char*, 2> units{"origins", "rays"};

  KdUniforms kd;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> ray = f.fetch_own(kRays);
    f.out(0) = kd_entry(f.fetch_own(kOrigins).xyz(), ray.xyz(), ray.w, kd);
  }
};

struct KdStep {
  static constexpr const char* name = "kd step";
  static constexpr const char* paper_name = "recorridoKd (extension)";
  static constexpr int outputs = 1;  // -> traversal
  enum Unit { kOrigins, kRays, kTraversal, kIntersection, kNodes };
  static constexpr std::array<const char*, 5> units{"origins", "rays", "traversal", "intersection",
                                                    "kd_nodes"};
  static constexpr std::array<int, 1> passthrough{kTraversal};

  KdUniforms kd;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> trav = f.fetch_own(kTraversal);
    const auto walking = trav.x >= F(0.0f);
    Vec4<F> next = trav;
    if (f.branch(walking)) {
      const Vec4<F> ray = f.fetch_own(kRays);
      const Vec4<F> best = f.fetch_own(kIntersection);
      const Vec3<F> o = f.fetch_own(kOrigins).xyz();
      next = kd_step(f, kNodes, trav, best, o, ray.xyz(), ray.w, walking, kd);
    }
    f.out(0) = next;
  }
};

// cargarHojaKd: cargarHoja (kernels/bvh.h) over the kd-tree's lists.
struct KdLoadLeaf : BvhLoadLeaf {
  static constexpr const char* name = "kd load leaf";
  static constexpr const char* paper_name = "cargarHojaKd (extension)";
  static constexpr std::array<const char*, 3> units{"traversal", "voxel_state", "kd_lists"};
};

// The nearest of the hit so far and triangle vs.w inside the leaf's segment trav.zw (widened by
// t_slack), for the lanes where `testing`.
template <class L>
inline Vec4<typename L::F> nearest_hit_in_leaf(
    const Fragments<L>& f, int unit_v0, const Vec3<typename L::F>& o,
    const Vec4<typename L::F>& ray, const Vec4<typename L::F>& trav, const Vec4<typename L::F>& vs,
    const Vec4<typename L::F>& best, const typename L::M& testing, const SceneUniforms& scene,
    float t_slack) {
  using F = typename L::F;
  const Vec3<F> p0 = fetch_id(f, unit_v0, vs.w, scene.width).xyz();
  const Vec3<F> p1 = fetch_id(f, unit_v0 + 1, vs.w, scene.width).xyz();
  const Vec3<F> p2 = fetch_id(f, unit_v0 + 2, vs.w, scene.width).xyz();
  F bu, bv;
  const F t = intersect_triangle(o, ray.xyz(), p0, p1, p2, bu, bv);
  const auto in_leaf = (t >= trav.z - F(t_slack)) && (t <= trav.w + F(t_slack));
  const auto nearer = testing && in_leaf && (t < best.x) && (t < ray.w);
  return select(nearer, Vec4<F>{t, bu, bv, vs.w}, best);
}

struct KdIntersections {
  static constexpr const char* name = "kd intersections";
  static constexpr const char* paper_name = "interseccionesKd (extension)";
  static constexpr int outputs = 1;  // -> intersection
  enum Unit { kOrigins, kRays, kTraversal, kVoxelState, kIntersection, kV0, kV1, kV2 };
  static constexpr std::array<const char*, 8> units{"origins",     "rays",         "traversal",
                                                    "voxel_state", "intersection", "vertices0",
                                                    "vertices1",   "vertices2"};
  static constexpr std::array<int, 1> passthrough{kIntersection};

  KdUniforms kd;
  SceneUniforms scene;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> vs = f.fetch_own(kVoxelState);
    const Vec4<F> best = f.fetch_own(kIntersection);
    const auto testing = vs.w >= F(0.0f);
    Vec4<F> next = best;
    if (f.branch(testing)) {
      const Vec3<F> o = f.fetch_own(kOrigins).xyz();
      const Vec4<F> ray = f.fetch_own(kRays);
      const Vec4<F> trav = f.fetch_own(kTraversal);
      next = nearest_hit_in_leaf(f, kV0, o, ray, trav, vs, best, testing, scene, kd.t_slack);
    }
    f.out(0) = next;
  }
};

// recorridoKd + cargarHojaKd (--mrt on): one node, and the first triangle of the leaf reached.
struct KdStepLoad {
  static constexpr const char* name = "kd step + load leaf";
  static constexpr const char* paper_name = "recorridoKd+cargarHojaKd (extension)";
  static constexpr int outputs = 2;  // -> traversal, voxel state
  enum Unit { kOrigins, kRays, kTraversal, kIntersection, kVoxelState, kNodes, kLists };
  static constexpr std::array<const char*, 7> units{
      "origins", "rays", "traversal", "intersection", "voxel_state", "kd_nodes", "kd_lists"};
  static constexpr std::array<int, 2> passthrough{kTraversal, kVoxelState};

  KdUniforms kd;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> trav = f.fetch_own(kTraversal);
    const Vec4<F> vs = f.fetch_own(kVoxelState);
    const auto walking = trav.x >= F(0.0f);
    Vec4<F> next = trav, nvs = vs;
    if (f.branch(walking)) {
      const Vec4<F> ray = f.fetch_own(kRays);
      const Vec4<F> best = f.fetch_own(kIntersection);
      const Vec3<F> o = f.fetch_own(kOrigins).xyz();
      next = kd_step(f, kNodes, trav, best, o, ray.xyz(), ray.w, walking, kd);
      const auto load = walking && (next.y >= F(0.0f)) && (vs.w < F(0.0f));
      const F tri = fetch_id(f, kLists, next.y, kd.list_width).x;
      nvs = select(load, Vec4<F>{next.y, F(0.0f), F(0.0f), tri}, vs);
    }
    f.out(0) = next;
    f.out(1) = nvs;
  }
};

// interseccionesKd + proximoTriangulo (--mrt on).
struct KdIntersectNext {
  static constexpr const char* name = "kd intersections + next triangle";
  static constexpr const char* paper_name = "interseccionesKd+proximoTriangulo (extension)";
  static constexpr int outputs = 2;  // -> intersection, voxel state
  enum Unit { kOrigins, kRays, kTraversal, kVoxelState, kIntersection, kV0, kV1, kV2, kLists };
  static constexpr std::array<const char*, 9> units{"origins",     "rays",         "traversal",
                                                    "voxel_state", "intersection", "vertices0",
                                                    "vertices1",   "vertices2",    "kd_lists"};
  static constexpr std::array<int, 2> passthrough{kIntersection, kVoxelState};

  KdUniforms kd;
  SceneUniforms scene;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> vs = f.fetch_own(kVoxelState);
    const Vec4<F> best = f.fetch_own(kIntersection);
    const auto testing = vs.w >= F(0.0f);
    Vec4<F> next = best, nvs = vs;
    if (f.branch(testing)) {
      const Vec3<F> o = f.fetch_own(kOrigins).xyz();
      const Vec4<F> ray = f.fetch_own(kRays);
      const Vec4<F> trav = f.fetch_own(kTraversal);
      next = nearest_hit_in_leaf(f, kV0, o, ray, trav, vs, best, testing, scene, kd.t_slack);
      const F pos = vs.x + F(1.0f);
      const F tri = fetch_id(f, kLists, pos, kd.list_width).x;
      nvs = select(testing, Vec4<F>{pos, F(0.0f), F(0.0f), tri}, vs);
    }
    f.out(0) = next;
    f.out(1) = nvs;
  }
};

// recorridoKdIterativo (extension): kd-restart in one looping program, with push-down (Horn et
// al., I3D 2007): while the descent has met no plane that cuts the segment, the node reached is
// remembered (voxel state y), and a restart begins there instead of at the root, since every
// later segment lies inside it too. Each iteration tests the leaf's next triangle if one is
// left, else takes one kd-restart step (loading the leaf it reaches). Voxel state z = 1 marks a
// descent that has cut the segment since the last restart.
struct KdLooping {
  static constexpr const char* name = "kd looping traversal";
  static constexpr const char* paper_name = "recorridoKdIterativo (extension)";
  static constexpr int outputs = 3;  // -> traversal, voxel state, intersection
  enum Unit {
    kOrigins,
    kRays,
    kTraversal,
    kVoxelState,
    kIntersection,
    kV0,
    kV1,
    kV2,
    kNodes,
    kLists
  };
  static constexpr std::array<const char*, 10> units{
      "origins",   "rays",      "traversal", "voxel_state", "intersection",
      "vertices0", "vertices1", "vertices2", "kd_nodes",    "kd_lists"};
  static constexpr std::array<int, 3> passthrough{kTraversal, kVoxelState, kIntersection};

  KdUniforms kd;
  SceneUniforms scene;
  int steps = 32;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    using M = typename L::M;
    Vec4<F> trav = f.fetch_own(kTraversal);
    Vec4<F> vs = f.fetch_own(kVoxelState);
    Vec4<F> best = f.fetch_own(kIntersection);
    const Vec3<F> o = f.fetch_own(kOrigins).xyz();
    const Vec4<F> ray = f.fetch_own(kRays);
    f.loop(steps, trav.x >= F(0.0f), [&](const M& act) {
      const M testing = act && (vs.w >= F(0.0f));
      best = nearest_hit_in_leaf(f, kV0, o, ray, trav, vs, best, testing, scene, kd.t_slack);
      const F pos = vs.x + F(1.0f);
      const F tri = fetch_id(f, kLists, pos, kd.list_width).x;
      const M stepping = act && !testing;
      Vec4<F> next = kd_step(f, kNodes, trav, best, o, ray.xyz(), ray.w, stepping, kd);
      // Push-down: a restart goes to the remembered node; a descent that keeps the whole
      // segment in one child (tmax unchanged) and has not cut it yet moves the remembered node.
      const M restarted = stepping && (trav.y >= F(0.0f)) && (next.x == F(0.0f));
      const M descended = stepping && (trav.y < F(0.0f)) && (next.y < F(0.0f)) &&
                          (next.x >= F(0.0f)) && (next.x != trav.x);
      const M kept = descended && (next.w == trav.w) && (vs.z < F(0.5f));
      const M cut = descended && !(next.w == trav.w);
      next = select(restarted, Vec4<F>{vs.y, next.y, next.z, next.w}, next);
      const F pd = select(kept, next.x, vs.y);
      const F dirty = select(restarted, F(0.0f), select(cut, F(1.0f), vs.z));
      const M load = stepping && (next.y >= F(0.0f));
      const F first = fetch_id(f, kLists, next.y, kd.list_width).x;
      vs = select(testing, Vec4<F>{pos, vs.y, vs.z, tri},
                  select(load, Vec4<F>{next.y, pd, dirty, first},
                         select(stepping, Vec4<F>{vs.x, pd, dirty, vs.w}, vs)));
      trav = select(stepping, next, trav);
      return trav.x >= F(0.0f);
    });
    f.out(0) = trav;
    f.out(1) = vs;
    f.out(2) = best;
  }
};

}  // namespace kernels
