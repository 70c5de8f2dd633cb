// The kd-tree walk's kernels (an extension; host/accel/kdtree.h): kd-restart (Foley & Sugerman,
// Graphics Hardware 2005), one node per pass, steered by the same queries as the grid's walk:
//   inicioKd (extension)          the segment [tmin, tmax] where the ray is inside the scene box,
//                                 and the root                    (initTraversal's place)
//   recorridoKd (extension)       one node per pass: an inner node sends the ray to the child
//                                 its segment starts in (cutting tmax at the plane when it
//                                 reaches the other); a leaf just reached is handed to
//                                 cargarHojaKd; a leaf already tested ends the ray (a hit inside
//                                 it, or the segment reached the box's exit) or restarts it
//                                 from the root with tmin at the leaf's exit (traversal's place)
//   cargarHojaKd (extension)      the first triangle of the leaf reached (actualizarVoxel's)
//   interseccionesKd (extension)  one triangle per pass, a hit counting only inside the leaf's
//                                 segment, widened by t_slack (the grid's in-voxel rule)
// with proximoTriangulo, rayosIntersectando and rayosEnGrilla as the grid has them. Traversal
// state (kernels/layout.h): x = node (-1: done), y = list position of the leaf being tested
// (-1: none), z = tmin, w = tmax of the segment. Leaves are met front to back, so the first hit
// inside a leaf's segment is the nearest.
// Addressed by (x, y) (KdUniforms::xy, for trees past a float's linear reach): the state holds
// the node's column in x (plus the node texture's width once its leaf was reached: the flag
// linear y's list position gave) and its row in y; a node texel holds its right child's, or its
// leaf's list start's, column and row in z and w; cargarHojaKd reads the list start from the
// leaf's texel (one fetch more), and the looping kernel restarts at the root (push-down's node
// would need two channels the state has not got).
#pragma once

#include "kernels/common.h"
#include "kernels/lists.h"
#include "kernels/next_triangle.h"

namespace kernels {

// Uniforms of the kd-tree: its lists' (t_slack: the in-leaf rule's tolerance) and its nodes'.
struct KdUniforms : ListUniforms {
  glm::vec3 lo{0.0f}, hi{0.0f};  // the root's box
  float node_width = 1;          // width of the node texture, texels
};

// The segment entry of a ray with tmax ray_w: root and [tn, tf], or done.
template <class F>
inline Vec4<F> kd_entry(const Vec3<F>& o, const Vec3<F>& d, const F& ray_w, const KdUniforms& kd) {
  F tn, tf;
  ray_box_segment(o, d, kd.lo, kd.hi, ray_w, tn, tf);
  const auto enters = (tn <= tf) && (ray_w >= F(0.0f));
  return select(enters, Vec4<F>{F(0.0f), F(kNone), tn, tf},
                Vec4<F>{F(kNone), F(kNone), F(0.0f), F(0.0f)});
}

// The component of v along axis a (0, 1, 2), a given per lane.
template <class F>
inline F along(const Vec3<F>& v, const F& a) {
  return select(a < F(0.5f), v.x, select(a < F(1.5f), v.y, v.z));
}

// Whether the leaf a kd traversal state stands at was reached in an earlier step (its triangles
// loaded and tested since): linear, y holds its list position; by (x, y), x is past the width.
template <class F>
inline auto kd_reached(const Vec4<F>& trav, const KdUniforms& kd) {
  return kd.xy > 0.5f ? trav.x >= F(kd.node_width) : trav.y >= F(0.0f);
}

// The node a kd traversal state stands at (a walking one; linear: y unused).
template <class F>
inline Addr<F> kd_node(const Vec4<F>& trav, const KdUniforms& kd) {
  if (kd.xy <= 0.5f) return {trav.x, trav.x};
  return {trav.x - select(trav.x >= F(kd.node_width), F(kd.node_width), F(0.0f)), trav.y};
}

// One step of kd-restart for the lanes where `walking` (others keep trav): the node at
// kd_node(trav), fetched as (split, axis, right child, leaf list start), or by (x, y) (split,
// axis, then the right child's or the leaf's list start's column and row). A restart goes to
// the root, or to `*root` (beams over tiles, linear addresses only: the node the ray's tile's
// beam descended to, whose region holds the ray's whole segment, so every restart from the root
// would pass through it unchanged). `leaf_list`, where given, receives the fetched node's list
// start (a leaf's).
template <class L>
inline Vec4<typename L::F> kd_step(const Fragments<L>& f, int unit_nodes,
                                   const Vec4<typename L::F>& trav, const Vec4<typename L::F>& best,
                                   const Vec3<typename L::F>& o, const Vec3<typename L::F>& d,
                                   const typename L::F& ray_w, const typename L::M& walking,
                                   const KdUniforms& kd, const typename L::F* root = nullptr,
                                   Addr<typename L::F>* leaf_list = nullptr) {
  using F = typename L::F;
  const bool xy = kd.xy > 0.5f;
  const Addr<F> at = kd_node(trav, kd);
  const Vec4<F> node = fetch_at(f, unit_nodes, at, kd.node_width, xy);
  const auto leaf = node.y > F(2.5f);
  const auto tested = kd_reached(trav, kd);  // this leaf's triangles were tested in the last step
  if (leaf_list) *leaf_list = xy ? Addr<F>{node.z, node.w} : Addr<F>{node.w, node.w};
  // A leaf just reached: hand it to cargarHoja.
  const Vec4<F> reach = xy ? Vec4<F>{at.x + F(kd.node_width), at.y, trav.z, trav.w}
                           : Vec4<F>{trav.x, node.w, trav.z, trav.w};
  // A leaf tested: a hit inside it ends the ray, as does a segment that reached the box's exit
  // (or the ray's tmax); otherwise restart from the root past the leaf.
  F tn, tend;
  ray_box_segment(o, d, kd.lo, kd.hi, ray_w, tn, tend);
  const auto over = (best.w >= F(0.0f)) || (trav.w >= tend);
  const Vec4<F> done{F(kNone), F(kNone), F(0.0f), F(0.0f)};
  const Vec4<F> restart = xy ? Vec4<F>{F(0.0f), F(0.0f), trav.w, tend}
                             : Vec4<F>{root ? *root : F(0.0f), F(kNone), trav.w, tend};
  // An inner node: the child the segment starts in, cutting the segment at the plane when it
  // reaches the other child; the far child alone when the plane lies before tmin. A ray whose
  // origin lies on the plane (ts = 0, or -0) runs into the child its direction points to
  // (`below` breaks the tie by direction), which is then the near child and the only one.
  const F oa = along(o, node.y), da = along(d, node.y);
  const F ts = (node.x - oa) / da;
  const auto below = (oa < node.x) || ((oa == node.x) && (da <= F(0.0f)));
  const Addr<F> left = addr_next(at, kd.node_width, xy);
  const Addr<F> right = xy ? Addr<F>{node.z, node.w} : Addr<F>{node.z, node.z};
  const Addr<F> near = addr_select(below, left, right, xy),
                far = addr_select(below, right, left, xy);
  const auto near_only = (da == F(0.0f)) || (ts >= trav.w) || (ts <= F(0.0f));
  const auto far_only = !near_only && (ts <= trav.z);
  const Addr<F> child = addr_select(far_only, far, near, xy);
  const Vec4<F> inner{child.x, xy ? child.y : F(kNone), trav.z,
                      select(near_only || far_only, trav.w, ts)};
  const Vec4<F> at_leaf = select(tested, select(over, done, restart), reach);
  return select(walking, select(leaf, at_leaf, inner), trav);
}

// kd_step restarting at the node the beam texture (unit `unit_beams`) gives the fragment's tile
// where beam_tile > 0, else at the root without a fetch (the program without beams is the one
// before them): recorridoKd's step and its fused form's.
template <class L>
inline Vec4<typename L::F> kd_step_from_tile(const Fragments<L>& f, int unit_nodes, int unit_beams,
                                             float beam_tile, const Vec4<typename L::F>& trav,
                                             const Vec4<typename L::F>& best,
                                             const Vec3<typename L::F>& o,
                                             const Vec3<typename L::F>& d,
                                             const typename L::F& ray_w,
                                             const typename L::M& walking, const KdUniforms& kd) {
  if (beam_tile <= 0.0f) return kd_step(f, unit_nodes, trav, best, o, d, ray_w, walking, kd);
  const typename L::F root = fetch_tile(f, unit_beams, beam_tile).x;
  return kd_step(f, unit_nodes, trav, best, o, d, ray_w, walking, kd, &root);
}

// Beams over tiles through the kd-tree (--beams on, primary rays; host/trace/walks/kd_walk.cpp):
// the kernels below read the beam texture (one texel per tile, kernels::BvhBeamDescend's: x the
// node the tile's beam descended to, z 1 where the whole tile misses) where beam_tile > 0, the
// tile's side in pixels. Without beams (0) they never fetch it.

// inicioKd: the segment [tmin, tmax] inside the scene box and the root; with beams, the tile's
// node instead of the root (the segment is the same: the walk from the root would reach that
// node with it unchanged), and nothing for a tile that misses.
struct KdEnter {
  static constexpr const char* name = "kd enter";
  static constexpr const char* paper_name = "inicioKd (extension)";
  static constexpr int outputs = 1;  // -> traversal
  enum Unit { kOrigins, kRays, kBeams };
  static constexpr std::array<const char*, 3> units{"origins", "rays", "kd_beams"};

  KdUniforms kd;
  float beam_tile = 0;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> ray = f.fetch_own(kRays);
    Vec4<F> t = kd_entry(f.fetch_own(kOrigins).xyz(), ray.xyz(), ray.w, kd);
    if (kd.xy > 0.5f) t.y = F(0.0f);  // the root's row (a done ray's y is never read)
    if (beam_tile > 0.0f) {
      const Vec4<F> b = fetch_tile(f, kBeams, beam_tile);
      const auto starts = (t.x >= F(0.0f)) && (b.z <= F(0.0f));
      t = select(starts, Vec4<F>{b.x, t.y, t.z, t.w},
                 Vec4<F>{F(kNone), F(kNone), F(0.0f), F(0.0f)});
    }
    f.out(0) = t;
  }
};

struct KdStep {
  static constexpr const char* name = "kd step";
  static constexpr const char* paper_name = "recorridoKd (extension)";
  static constexpr int outputs = 1;  // -> traversal
  enum Unit { kOrigins, kRays, kTraversal, kIntersection, kNodes, kBeams };
  static constexpr std::array<const char*, 6> units{"origins",      "rays",     "traversal",
                                                    "intersection", "kd_nodes", "kd_beams"};
  static constexpr std::array<int, 1> passthrough{kTraversal};

  KdUniforms kd;
  float beam_tile = 0;  // > 0: restarts go to the tile's node

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
      next = kd_step_from_tile(f, kNodes, kBeams, beam_tile, trav, best, o, ray.xyz(), ray.w,
                               walking, kd);
    }
    f.out(0) = next;
  }
};

// cargarHojaKd: the first triangle of the leaf just reached (traversal y: its list start; by
// (x, y), read from the leaf's node texel, unit kNodes), for a ray with nothing left to test
// (voxel state w = -1).
struct KdLoadLeaf {
  static constexpr const char* name = "kd load leaf";
  static constexpr const char* paper_name = "cargarHojaKd (extension)";
  static constexpr int outputs = 1;  // -> voxel state
  enum Unit { kTraversal, kVoxelState, kLists, kNodes };
  static constexpr std::array<const char*, 4> units{"traversal", "voxel_state", "kd_lists",
                                                    "kd_nodes"};
  static constexpr std::array<int, 1> passthrough{kVoxelState};

  KdUniforms kd;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> trav = f.fetch_own(kTraversal);
    const Vec4<F> vs = f.fetch_own(kVoxelState);
    const auto load = kd_reached(trav, kd) && (vs.w < F(0.0f));
    Vec4<F> next = vs;
    if (f.branch(load)) {
      if (kd.xy > 0.5f) {
        const Vec4<F> leaf = fetch_at(f, kNodes, kd_node(trav, kd), kd.node_width, true);
        next = load_list_at(f, kLists, Addr<F>{leaf.z, leaf.w}, vs, load, kd);
      } else {
        next = load_list(f, kLists, trav.y, vs, load, kd);
      }
    }
    f.out(0) = next;
  }
};

// interseccionesKd: a hit counts only inside the leaf's segment trav.zw, widened by t_slack
// (nearest_hit_in_segment, kernels/lists.h: the grid's in-voxel rule).
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
      next = nearest_hit_in_segment(f, kV0, o, ray, trav, vs, best, testing, scene, kd.t_slack);
    }
    f.out(0) = next;
  }
};

// recorridoKd + cargarHojaKd (--mrt on): one node, and the first triangle of the leaf reached.
struct KdStepLoad {
  static constexpr const char* name = "kd step + load leaf";
  static constexpr const char* paper_name = "recorridoKd+cargarHojaKd (extension)";
  static constexpr int outputs = 2;  // -> traversal, voxel state
  enum Unit { kOrigins, kRays, kTraversal, kIntersection, kVoxelState, kNodes, kLists, kBeams };
  static constexpr std::array<const char*, 8> units{"origins",      "rays",        "traversal",
                                                    "intersection", "voxel_state", "kd_nodes",
                                                    "kd_lists",     "kd_beams"};
  static constexpr std::array<int, 2> passthrough{kTraversal, kVoxelState};

  KdUniforms kd;
  float beam_tile = 0;  // > 0: restarts go to the tile's node

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
      if (kd.xy > 0.5f) {
        // The step's node texel holds the list start of the leaf it reaches.
        Addr<F> list{trav.x, trav.x};
        next = kd_step(f, kNodes, trav, best, o, ray.xyz(), ray.w, walking, kd, nullptr, &list);
        const auto load = walking && kd_reached(next, kd) && (vs.w < F(0.0f));
        nvs = load_list_at(f, kLists, list, vs, load, kd);
      } else {
        next = kd_step_from_tile(f, kNodes, kBeams, beam_tile, trav, best, o, ray.xyz(), ray.w,
                                 walking, kd);
        const auto load = walking && (next.y >= F(0.0f)) && (vs.w < F(0.0f));
        nvs = load_list(f, kLists, next.y, vs, load, kd);
      }
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
      next = nearest_hit_in_segment(f, kV0, o, ray, trav, vs, best, testing, scene, kd.t_slack);
      nvs = next_in_list(f, kLists, vs, testing, kd);
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
// descent that has cut the segment since the last restart. With beams over tiles, the
// remembered node starts at the tile's node instead of the root (y 0, as the state is cleared).
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
    kLists,
    kBeams
  };
  static constexpr std::array<const char*, 11> units{
      "origins",   "rays",      "traversal", "voxel_state", "intersection", "vertices0",
      "vertices1", "vertices2", "kd_nodes",  "kd_lists",    "kd_beams"};
  static constexpr std::array<int, 3> passthrough{kTraversal, kVoxelState, kIntersection};

  KdUniforms kd;
  SceneUniforms scene;
  int steps = 32;
  float beam_tile = 0;  // > 0: push-down starts at the tile's node

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    using M = typename L::M;
    Vec4<F> trav = f.fetch_own(kTraversal);
    Vec4<F> vs = f.fetch_own(kVoxelState);
    Vec4<F> best = f.fetch_own(kIntersection);
    const Vec3<F> o = f.fetch_own(kOrigins).xyz();
    const Vec4<F> ray = f.fetch_own(kRays);
    if (kd.xy > 0.5f) {
      // By (x, y): no push-down (its node would need two more channels), every restart at the
      // root; the leaf's list start comes with the node texel the step fetched.
      walk_lists_by_xy(
          f, steps, kV0, kLists, o, ray, trav, vs, best, kd, scene,
          [&](const M& stepping, Addr<F>& list) {
            return kd_step(f, kNodes, trav, best, o, ray.xyz(), ray.w, stepping, kd, nullptr,
                           &list);
          },
          [&](const Vec4<F>& next) { return kd_reached(next, kd); });
      f.out(0) = trav;
      f.out(1) = vs;
      f.out(2) = best;
      return;
    }
    if (beam_tile > 0.0f) vs.y = select(vs.y == F(0.0f), fetch_tile(f, kBeams, beam_tile).x, vs.y);
    f.loop(steps, trav.x >= F(0.0f), [&](const M& act) {
      const M testing = act && (vs.w >= F(0.0f));
      best = nearest_hit_in_segment(f, kV0, o, ray, trav, vs, best, testing, scene, kd.t_slack);
      const F pos = vs.x + F(1.0f);
      const F tri = list_entry(f, kLists, pos, kd);
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
      const F first = list_entry(f, kLists, next.y, kd);
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
