// Beams over tiles through the BVH (an extension, issue 35; docs/studies/groups.md): the
// entry-point search of multi-level ray tracing (Reshetov et al. 2005). A tile's beam (its four
// corner pixels' primary rays, as kernels/beams.h computes them) descends the hierarchy from the
// root, one node per pass (rayosHazBVH): at an inner node, a child whose box lies wholly outside
// the beam's frustum is skipped, and the beam moves on to the other child; it stops at the first
// node where it can skip neither child (or at a leaf). Then every pixel's ray starts at its
// tile's node N (inicioHazBVH) and walks only N's subtree, the index range [N, escape(N)) of the
// depth-first layout, in the order the full walk would: every node outside it is missed by every
// ray of the tile, so the hit, its depth and the image are the per-pixel walk's own.
#pragma once

#include "kernels/beams.h"
#include "kernels/bvh.h"
#include "kernels/common.h"

namespace kernels {

// Whether the box [lo, hi] lies wholly outside the frustum of rays from `e` between the corner
// directions d00, d10, d11, d01 (in order around the beam), by `margin` world units: outside one
// of its four side planes, or behind the eye (the plane through it across the beam's axis). A
// side plane holds the eye and two neighbouring corner rays; its normal n = d_a x d_b is turned
// to face the axis. The box's corner farthest along n is centre + |n| . half size; if even that
// one lies behind the plane, so does the whole box. Conservative: a plane of two equal corners
// (a tile one pixel wide) has n = 0 and excludes nothing.
template <class F>
inline auto beam_skips_box(const Vec3<F>& e, const Vec3<F> (&d)[4], const Vec3<F>& axis,
                           const Vec3<F>& lo, const Vec3<F>& hi, const F& margin) {
  const Vec3<F> c = (lo + hi) * F(0.5f) - e;
  const Vec3<F> h = (hi - lo) * F(0.5f);
  auto behind = [&](const Vec3<F>& n) {
    const F reach = dot(n, c) + abs(n.x) * h.x + abs(n.y) * h.y + abs(n.z) * h.z;
    return reach + margin * sqrt(dot(n, n)) < F(0.0f);
  };
  auto skips = behind(axis);
  for (int i = 0; i < 4; ++i) {
    const Vec3<F> raw = cross(d[i], d[(i + 1) % 4]);
    const Vec3<F> n = select(dot(raw, axis) < F(0.0f), raw * F(-1.0f), raw);
    skips = skips || behind(n);
  }
  return skips;
}

// Uniforms of the descent: the primary rays' camera and the tile size (the grid's beams'; their
// grid part is not read), the world-space margin of the frustum test, and the BVH's.
struct BvhBeamUniforms {
  BeamUniforms beams;
  BvhUniforms bvh;
};

// A tile's beam: its corner pixels' primary rays (as the grid's beam march has them), the axis
// between them, the eye and the frustum test's margin.
template <class L>
struct TileBeam {
  using F = typename L::F;
  Vec3<F> d[4], axis, e;
  F margin;
  TileBeam(const Fragments<L>& f, const BeamUniforms& bu) {
    const Vec4<F> c = tile_corners(f, bu);
    d[0] = bu.camera.ray_through<L>(c.x, c.y).xyz();
    d[1] = bu.camera.ray_through<L>(c.z, c.y).xyz();
    d[2] = bu.camera.ray_through<L>(c.z, c.w).xyz();
    d[3] = bu.camera.ray_through<L>(c.x, c.w).xyz();
    axis = normalize(d[0] + d[1] + d[2] + d[3]);
    e = splat<F>(bu.eye);
    margin = F(bu.margin);
  }
};

// One level of a tile's descent: the beam texel b (node, end or 0 while descending, missed,
// depth) after the node b.x is looked at (rayosHazBVH's work; its looping form repeats it).
template <class L>
inline Vec4<typename L::F> bvh_beam_step(const Fragments<L>& f, int unit_lo, int unit_hi,
                                         const Vec4<typename L::F>& b, const TileBeam<L>& beam,
                                         const BvhUniforms& bvh) {
  using F = typename L::F;
  const F node = b.x;
  const Vec4<F> lo = fetch_id(f, unit_lo, node, bvh.node_width);
  const Vec4<F> hi = fetch_id(f, unit_hi, node, bvh.node_width);
  const F end = select(lo.w < F(0.0f), F(bvh.nodes), lo.w);
  // A leaf (or an empty one, written as an inner node: its subtree is itself) has no children:
  // its own texels stand in for them (and are not used).
  const auto leaf = (hi.w >= F(0.0f)) || (node + F(1.0f) >= end);
  const F left = select(leaf, node, node + F(1.0f));
  const Vec4<F> llo = fetch_id(f, unit_lo, left, bvh.node_width);
  const Vec4<F> lhi = fetch_id(f, unit_hi, left, bvh.node_width);
  // The right child follows the left child's subtree: the left child's escape.
  const F right = select(leaf, node, llo.w);
  const Vec4<F> rlo = fetch_id(f, unit_lo, right, bvh.node_width);
  const Vec4<F> rhi = fetch_id(f, unit_hi, right, bvh.node_width);
  const auto& d = beam.d;
  const auto self_out = beam_skips_box(beam.e, d, beam.axis, lo.xyz(), hi.xyz(), beam.margin);
  const auto left_out =
      beam_skips_box(beam.e, d, beam.axis, llo.xyz(), lhi.xyz(), beam.margin) && !leaf;
  const auto right_out =
      beam_skips_box(beam.e, d, beam.axis, rlo.xyz(), rhi.xyz(), beam.margin) && !leaf;
  const auto descending = b.y <= F(0.0f);
  // The whole tile misses: the node's box (the root's: a child's is tested before the beam
  // moves there), or both children's.
  const auto missed = descending && (self_out || (!leaf && left_out && right_out));
  const auto moves =
      descending && !missed && !leaf && ((left_out && !right_out) || (right_out && !left_out));
  const F next = select(left_out, right, left);
  const auto stops = descending && !moves;
  return {select(moves, next, node), select(stops, end, b.y), select(missed, F(1.0f), b.z),
          select(moves, b.w + F(1.0f), b.w)};
}

// rayosHazBVH: one node of a tile's descent. The beam texture (one texel per tile) holds x = the
// node the beam is at; y = 0 while it descends, then the end of its rays' walk (the node's
// escape, the node count for -1); z = 1 where the whole tile misses the tree; w = the depth of
// the node (steps taken).
struct BvhBeamDescend {
  static constexpr const char* name = "bvh beam descend";
  static constexpr const char* paper_name = "rayosHazBVH (extension)";
  static constexpr int outputs = 1;  // -> beams
  enum Unit { kBeams, kNodesLo, kNodesHi };
  static constexpr std::array<const char*, 3> units{"beams", "nodes_lo", "nodes_hi"};
  static constexpr std::array<int, 1> passthrough{kBeams};  // stopped beams keep their state

  BvhBeamUniforms u;

  template <class L>
  void operator()(Fragments<L>& f) const {
    const TileBeam<L> beam(f, u.beams);
    f.out(0) = bvh_beam_step(f, kNodesLo, kNodesHi, f.fetch_own(kBeams), beam, u.bvh);
  }
};

// rayosHazBVHIterativo: a tile's whole descent in one pass (--kernels looping): rayosHazBVH's
// step repeated while the beam descends, at most `levels` times (the tree's levels). The same
// texel as the passes leave, without a query per level.
struct BvhBeamDescendLooping {
  static constexpr const char* name = "bvh beam descent loop";
  static constexpr const char* paper_name = "rayosHazBVHIterativo (extension)";
  static constexpr int outputs = 1;  // -> beams
  enum Unit { kBeams, kNodesLo, kNodesHi };
  static constexpr std::array<const char*, 3> units{"beams", "nodes_lo", "nodes_hi"};
  static constexpr std::array<int, 1> passthrough{kBeams};

  BvhBeamUniforms u;
  int levels = 1;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    using M = typename L::M;
    const TileBeam<L> beam(f, u.beams);
    Vec4<F> b = f.fetch_own(kBeams);
    f.loop(levels, b.y <= F(0.0f), [&](const M& act) {
      b = select(act, bvh_beam_step(f, kNodesLo, kNodesHi, b, beam, u.bvh), b);
      return b.y <= F(0.0f);
    });
    f.out(0) = b;
  }
};

// inicioHazBVH: inicioBVH for a pixel whose tile's beam descended: its ray starts at the tile's
// node, the walk's end (traversal z) at that node's escape; where the whole tile misses, or there
// is no ray, the ray is done.
struct BvhBeamEnter {
  static constexpr const char* name = "bvh beam enter";
  static constexpr const char* paper_name = "inicioHazBVH (extension)";
  static constexpr int outputs = 1;  // -> traversal
  enum Unit { kRays, kBeams };
  static constexpr std::array<const char*, 2> units{"rays", "beams"};

  float tile = 8;  // pixels per tile side

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> ray = f.fetch_own(kRays);
    const Vec4<F> b = fetch_tile(f, kBeams, tile);
    const Vec4<F> start{b.x, F(kNone), b.y, F(0.0f)};
    const Vec4<F> none{F(kNone), F(kNone), F(0.0f), F(0.0f)};
    f.out(0) = select((ray.w >= F(0.0f)) && (b.z <= F(0.0f)), start, none);
  }
};

// rayosHazBVHDescendiendo: counts the tiles whose beam still descends (y = 0); the others are
// discarded, so an occlusion query counts these.
struct BvhBeamsDescending {
  static constexpr const char* name = "bvh beams descending";
  static constexpr const char* paper_name = "rayosHazBVHDescendiendo (extension)";
  static constexpr int outputs = 1;  // a dummy target: the count is what matters
  static constexpr bool idle_discards = true;
  enum Unit { kBeams };
  static constexpr std::array<const char*, 1> units{"beams"};

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> b = f.fetch_own(kBeams);
    f.discard(b.y > F(0.0f));
    f.out(0) = {F(1.0f), F(0.0f), F(0.0f), F(0.0f)};
  }
};

}  // namespace kernels
