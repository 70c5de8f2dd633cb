// The BVH walk's kernels (an extension: the paper names bounding volumes as future work). The
// hierarchy is laid out depth first with an escape index per node (host/accel/bvh.h), so a ray
// walks it without a stack, one node per pass (Thrane & Simonsen 2005): a box the ray enters
// sends it to the next node in the layout (the left child), a box it misses sends it to the
// node's escape. The walk mirrors the grid's (Sec. 2.2-2.3) pass for pass:
//   inicioBVH (extension)      every ray with a ray at the root     (initTraversal's place)
//   recorridoBVH (extension)   one node per pass                     (traversal's place)
//   cargarHoja (extension)     the first triangle of a leaf entered  (actualizarVoxel's place)
//   interseccionesBVH (ext.)   one triangle per pass, nearest kept   (intersecciones' place)
// with proximoTriangulo, rayosIntersectando and rayosEnGrilla as the grid has them. Traversal
// state (kernels/layout.h): x = next node to visit (nodes count: past the last one, the walk is
// over at the next step; -1: done), y = list position of a leaf just entered (-1: none),
// z = where the walk ends: 0 for the node count (the whole tree), else the escape of the node a
// beam over tiles started the ray at (kernels/bvh_beams.h): in the depth-first layout a node's
// subtree is the index range [node, escape), so the walk covers exactly that subtree.
// A hit does not end the walk early (the order is fixed, not front to back), but a box farther
// than the nearest hit so far is missed.
#pragma once

#include "kernels/common.h"
#include "kernels/lists.h"

namespace kernels {

// Uniforms of the BVH's textures: its lists' (list_width; t_slack is not read: a hit counts
// anywhere) and its nodes'.
struct BvhUniforms : ListUniforms {
  float node_width = 1;  // width of the two node textures, texels
  float nodes = 1;       // node count: a node index at or past it ends the walk
  // Whether traversal z may carry an earlier end (beams over tiles): off, the programs test the
  // node count alone, instruction for instruction as before beams.
  bool ends = false;
};

// Whether the ray o + t d, 0 <= t <= tfar, meets the box [lo, hi] (the slab test,
// kernels/lists.h, on a box fetched from the node textures).
template <class F>
inline auto ray_meets_box(const Vec3<F>& o, const Vec3<F>& d, const Vec3<F>& lo, const Vec3<F>& hi,
                          const F& tfar) {
  F tn, tf;
  ray_box_segment(o, d, lo, hi, tfar, tn, tf);
  return tn <= tf;
}

// One node of the stackless walk for the lanes where `walking` (others keep `trav`): the node
// trav.x tested against the nearest hit so far; the next node and the leaf entered, if any.
template <class L>
inline Vec4<typename L::F> bvh_step(const Fragments<L>& f, int unit_lo, int unit_hi,
                                    const Vec4<typename L::F>& trav, const Vec3<typename L::F>& o,
                                    const Vec3<typename L::F>& d, const typename L::F& tfar,
                                    const typename L::M& walking, const BvhUniforms& bvh) {
  using F = typename L::F;
  const Vec4<F> lo = fetch_id(f, unit_lo, trav.x, bvh.node_width);
  const Vec4<F> hi = fetch_id(f, unit_hi, trav.x, bvh.node_width);
  const auto meets = ray_meets_box(o, d, lo.xyz(), hi.xyz(), tfar);
  const auto leaf = hi.w >= F(0.0f);
  // Past the last node of the walk (the tree's, or the beam's subtree's): the walk is done.
  const F end = bvh.ends ? select(trav.z > F(0.0f), trav.z, F(bvh.nodes)) : F(bvh.nodes);
  const auto over = trav.x >= end;
  const F next = select(meets && !leaf, trav.x + F(1.0f), lo.w);
  const F entered = select(meets && leaf, hi.w, F(kNone));
  // An escape of -1 (after the last node) becomes the node count: the leaf entered now is still
  // tested, and the next step ends the walk.
  const F next_or_end = select(next < F(0.0f), F(bvh.nodes), next);
  const Vec4<F> stepped{next_or_end, entered, bvh.ends ? trav.z : F(0.0f), F(0.0f)};
  const Vec4<F> done{F(kNone), F(kNone), F(0.0f), F(0.0f)};
  return select(walking, select(over, done, stepped), trav);
}

struct BvhEnter {
  static constexpr const char* name = "bvh enter";
  static constexpr const char* paper_name = "inicioBVH (extension)";
  static constexpr int outputs = 1;  // -> traversal
  enum Unit { kRays };
  static constexpr std::array<const char*, 1> units{"rays"};

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> ray = f.fetch_own(kRays);
    const Vec4<F> root{F(0.0f), F(kNone), F(0.0f), F(0.0f)};
    const Vec4<F> none{F(kNone), F(kNone), F(0.0f), F(0.0f)};
    f.out(0) = select(ray.w >= F(0.0f), root, none);
  }
};

struct BvhStep {
  static constexpr const char* name = "bvh step";
  static constexpr const char* paper_name = "recorridoBVH (extension)";
  static constexpr int outputs = 1;  // -> traversal
  enum Unit { kOrigins, kRays, kTraversal, kIntersection, kNodesLo, kNodesHi };
  static constexpr std::array<const char*, 6> units{"origins",      "rays",     "traversal",
                                                    "intersection", "nodes_lo", "nodes_hi"};
  static constexpr std::array<int, 1> passthrough{kTraversal};  // done rays keep their state

  BvhUniforms bvh;

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
      next = bvh_step(f, kNodesLo, kNodesHi, trav, o, ray.xyz(), min(best.x, ray.w), walking, bvh);
    }
    f.out(0) = next;
  }
};

// cargarHoja: the first triangle of the leaf just entered (traversal y: its list start), for a
// ray with nothing left to test (voxel state w = -1).
struct BvhLoadLeaf {
  static constexpr const char* name = "bvh load leaf";
  static constexpr const char* paper_name = "cargarHoja (extension)";
  static constexpr int outputs = 1;  // -> voxel state
  enum Unit { kTraversal, kVoxelState, kLists };
  static constexpr std::array<const char*, 3> units{"traversal", "voxel_state", "bvh_lists"};
  static constexpr std::array<int, 1> passthrough{kVoxelState};

  BvhUniforms bvh;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> trav = f.fetch_own(kTraversal);
    const Vec4<F> vs = f.fetch_own(kVoxelState);
    const auto load = (trav.y >= F(0.0f)) && (vs.w < F(0.0f));
    Vec4<F> next = vs;
    if (f.branch(load)) next = load_list(f, kLists, trav.y, vs, load, bvh);
    f.out(0) = next;
  }
};

// interseccionesBVH: the BVH lists a triangle once, so a hit counts wherever it lies
// (nearest_hit_anywhere, kernels/lists.h), bounded only by the ray's tmax.
struct BvhIntersections {
  static constexpr const char* name = "bvh intersections";
  static constexpr const char* paper_name = "interseccionesBVH (extension)";
  static constexpr int outputs = 1;  // -> intersection
  enum Unit { kOrigins, kRays, kVoxelState, kIntersection, kV0, kV1, kV2 };
  static constexpr std::array<const char*, 7> units{
      "origins", "rays", "voxel_state", "intersection", "vertices0", "vertices1", "vertices2"};
  static constexpr std::array<int, 1> passthrough{kIntersection};

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
      next = nearest_hit_anywhere(f, kV0, o, ray, vs, best, testing, scene);
    }
    f.out(0) = next;
  }
};

// recorridoBVHIterativo (extension): the whole walk in one looping program for profiles with
// data-dependent loops (as kernels/looping_traversal.h for the grid). Each iteration tests the
// ray's next triangle if its leaf has one left (and moves on in the list), else visits one
// node (and loads the leaf it enters); `steps` iterations per pass.
struct BvhLooping {
  static constexpr const char* name = "bvh looping traversal";
  static constexpr const char* paper_name = "recorridoBVHIterativo (extension)";
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
    kNodesLo,
    kNodesHi,
    kLists
  };
  static constexpr std::array<const char*, 11> units{
      "origins",   "rays",      "traversal", "voxel_state", "intersection", "vertices0",
      "vertices1", "vertices2", "nodes_lo",  "nodes_hi",    "bvh_lists"};
  static constexpr std::array<int, 3> passthrough{kTraversal, kVoxelState, kIntersection};

  BvhUniforms bvh;
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
    f.loop(steps, (trav.x >= F(0.0f)) || (vs.w >= F(0.0f)), [&](const M& act) {
      const M testing = act && (vs.w >= F(0.0f));
      best = nearest_hit_anywhere(f, kV0, o, ray, vs, best, testing, scene);
      const F pos = vs.x + F(1.0f);
      const F tri = list_entry(f, kLists, pos, bvh);
      const M stepping = act && !testing;
      const Vec4<F> stepped =
          bvh_step(f, kNodesLo, kNodesHi, trav, o, ray.xyz(), min(best.x, ray.w), stepping, bvh);
      const M load = stepping && (stepped.y >= F(0.0f));
      const F first = list_entry(f, kLists, stepped.y, bvh);
      vs = select(testing, Vec4<F>{pos, F(0.0f), F(0.0f), tri},
                  select(load, Vec4<F>{stepped.y, F(0.0f), F(0.0f), first}, vs));
      trav = select(stepping, Vec4<F>{stepped.x, F(kNone), stepped.z, F(0.0f)}, trav);
      return (trav.x >= F(0.0f)) || (vs.w >= F(0.0f));
    });
    f.out(0) = trav;
    f.out(1) = vs;
    f.out(2) = best;
  }
};

}  // namespace kernels

namespace kernels {

// recorridoBVH + cargarHoja (--mrt on): one node, and the first triangle of the leaf it enters,
// in one pass with two targets (the leaf comes from the register, not the written texture).
struct BvhStepLoad {
  static constexpr const char* name = "bvh step + load leaf";
  static constexpr const char* paper_name = "recorridoBVH+cargarHoja (extension)";
  static constexpr int outputs = 2;  // -> traversal, voxel state
  enum Unit { kOrigins, kRays, kTraversal, kIntersection, kVoxelState, kNodesLo, kNodesHi, kLists };
  static constexpr std::array<const char*, 8> units{"origins",      "rays",        "traversal",
                                                    "intersection", "voxel_state", "nodes_lo",
                                                    "nodes_hi",     "bvh_lists"};
  static constexpr std::array<int, 2> passthrough{kTraversal, kVoxelState};

  BvhUniforms bvh;

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
      next = bvh_step(f, kNodesLo, kNodesHi, trav, o, ray.xyz(), min(best.x, ray.w), walking, bvh);
      const auto load = walking && (next.y >= F(0.0f)) && (vs.w < F(0.0f));
      nvs = load_list(f, kLists, next.y, vs, load, bvh);
    }
    f.out(0) = next;
    f.out(1) = nvs;
  }
};

// interseccionesBVH + proximoTriangulo (--mrt on): test the current triangle and move on.
struct BvhIntersectNext {
  static constexpr const char* name = "bvh intersections + next triangle";
  static constexpr const char* paper_name = "interseccionesBVH+proximoTriangulo (extension)";
  static constexpr int outputs = 2;  // -> intersection, voxel state
  enum Unit { kOrigins, kRays, kVoxelState, kIntersection, kV0, kV1, kV2, kLists };
  static constexpr std::array<const char*, 8> units{"origins",      "rays",      "voxel_state",
                                                    "intersection", "vertices0", "vertices1",
                                                    "vertices2",    "bvh_lists"};
  static constexpr std::array<int, 2> passthrough{kIntersection, kVoxelState};

  BvhUniforms bvh;
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
      next = nearest_hit_anywhere(f, kV0, o, ray, vs, best, testing, scene);
      nvs = load_list(f, kLists, vs.x + F(1.0f), vs, testing, bvh);
    }
    f.out(0) = next;
    f.out(1) = nvs;
  }
};

}  // namespace kernels
