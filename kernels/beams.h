// Beams over tiles (an extension, issue 35; docs/studies/groups.md): a tile of T x T pixels is a
// beam bounded by its corner pixels' primary rays. Before the grid walk, passes of one fragment per
// tile march each beam from the eye through empty space (rayosHaz); then every pixel's ray starts
// where its tile's beam stopped (inicioHaz) instead of where it enters the grid. Only where the
// walk begins changes: the ray keeps its origin (the eye), so t, the hit and the depth are the
// per-pixel ray's own.
//
// The march: the host writes, per voxel, its chessboard distance k to the nearest voxel holding
// a triangle (beam_distances, host/trace/walks/grid_beams.h): every voxel fewer than k steps away
// along each axis is empty, so the cube of those voxels is an empty box, as is each half-space
// beyond a face of the grid box. A beam pass moves the beam on to where its first corner ray
// leaves the best of those boxes. The rays of the tile lie between its corner rays, so a box that
// holds the four corner rays' pieces holds the whole beam's piece (beam_march_step says how
// the sphere's bulge is kept inside). With --kernels looping, one pass marches every beam to
// its end (BeamMarchLooping).
#pragma once

#include "kernels/common.h"
#include "kernels/generate_rays.h"
#include "kernels/init_traversal.h"
#include "kernels/lists.h"

namespace kernels {

// What the beam passes and the beam entry share: the primary rays' camera (the ray generator's
// uniforms, and where in the pixel the frame's sample lies), the tile size and the grid.
struct BeamUniforms {
  GenerateRays camera;               // the primary rays' generator (its width and height: pixels)
  float offset_x = 0, offset_y = 0;  // sample position - pixel centre, pixels (jittered frames)
  glm::vec3 eye{0.0f};
  float tile = 8;  // pixels per tile side
  GridUniforms grid;
  float min_cell = 1;  // the grid's smallest cell side
  // The ray parameter past which the whole grid box lies behind every ray from the eye (the
  // distance from the eye to its farthest corner): a beam that gets there misses the grid.
  float far = 1;
  // World-space margin kept between a beam and anything it may not skip (rounding of the
  // pixels' rays, of the march, of the voxel faces), and the shortest step worth a pass.
  float margin = 1e-4f;
  float min_step = 0.5f;
};

// The sample positions of the corner pixels of the fragment's tile: x0, y0, x1, y1 (a tile at
// the image's edge may be cut short).
template <class L>
inline Vec4<typename L::F> tile_corners(const Fragments<L>& f, const BeamUniforms& u) {
  using F = typename L::F;
  const F x0 = (f.x - F(0.5f)) * F(u.tile) + F(0.5f + u.offset_x);
  const F y0 = (f.y - F(0.5f)) * F(u.tile) + F(0.5f + u.offset_y);
  return {x0, y0, min(x0 + F(u.tile - 1.0f), F(u.camera.width - 0.5f + u.offset_x)),
          min(y0 + F(u.tile - 1.0f), F(u.camera.height - 0.5f + u.offset_y))};
}

// A tile's beam (rayosHaz's view of it): the rays through the tile's corner pixels, their
// reciprocals (shared by every box), the beam's axis and cos(theta) from below, theta the widest
// angle between the axis and a corner. Computed once per tile (the looping march steps it many
// times).
template <class L>
struct MarchBeam {
  using F = typename L::F;
  Vec3<F> d[4], inv[4], axis, e;
  F cosw;
  MarchBeam(const Fragments<L>& f, const BeamUniforms& u) {
    const Vec4<F> c = tile_corners(f, u);
    d[0] = u.camera.ray_through<L>(c.x, c.y).xyz();
    d[1] = u.camera.ray_through<L>(c.z, c.y).xyz();
    d[2] = u.camera.ray_through<L>(c.x, c.w).xyz();
    d[3] = u.camera.ray_through<L>(c.z, c.w).xyz();
    axis = normalize(d[0] + d[1] + d[2] + d[3]);
    e = splat<F>(u.eye);
    for (int i = 0; i < 4; ++i)
      inv[i] = Vec3<F>{F(1.0f) / d[i].x, F(1.0f) / d[i].y, F(1.0f) / d[i].z};
    cosw = min(min(dot(axis, d[0]), dot(axis, d[1])), min(dot(axis, d[2]), dot(axis, d[3])));
  }
};

// One step of a tile's beam: its texel b (below) after the march from b.y (rayosHaz's work;
// the looping march repeats it).
//
// Two kinds of empty box: the cube of voxels around the axis point's voxel that its beam
// distance k says are empty, and each half-space beyond a face of the grid box. The beam moves
// on to where its first corner ray leaves the box (shrunk by the margin) if every corner ray is
// inside at t: the tile's rays between two parameters lie in the convex hull of the corner rays'
// points between those parameters, the later one divided by cos(theta) (the hull's flat faces
// cut the sphere of radius t).
template <class L>
inline Vec4<typename L::F> beam_march_step(const Fragments<L>& f, int unit_distances,
                                           const Vec4<typename L::F>& b, const MarchBeam<L>& m,
                                           const BeamUniforms& u) {
  using F = typename L::F;
  const GridUniforms& g = u.grid;
  const F t = b.y;
  const Vec3<F>& e = m.e;
  const Vec3<F> q = e + m.axis * t;
  auto cell_of = [&](const F& qa, float lo, float cell, float res) {
    return min(max(floor((qa - F(lo)) / F(cell)), F(0.0f)), F(res - 1.0f));
  };
  const Vec3<F> v{cell_of(q.x, g.lo.x, g.cell.x, g.res.x), cell_of(q.y, g.lo.y, g.cell.y, g.res.y),
                  cell_of(q.z, g.lo.z, g.cell.z, g.res.z)};
  const F k = f.fetch(unit_distances, v.x * F(g.res.y) + v.y + F(0.5f), v.z + F(0.5f)).x;
  const F mg = F(u.margin);
  const Vec3<F> cube_lo{F(g.lo.x) + (v.x - k + F(1.0f)) * F(g.cell.x) + mg,
                        F(g.lo.y) + (v.y - k + F(1.0f)) * F(g.cell.y) + mg,
                        F(g.lo.z) + (v.z - k + F(1.0f)) * F(g.cell.z) + mg};
  const Vec3<F> cube_hi{F(g.lo.x) + (v.x + k) * F(g.cell.x) - mg,
                        F(g.lo.y) + (v.y + k) * F(g.cell.y) - mg,
                        F(g.lo.z) + (v.z + k) * F(g.cell.z) - mg};
  // Per corner ray: where it leaves the cube, or -1 if it is not inside at t.
  auto axis_of = [](const Vec3<F>& v, int a) -> const F& {
    return a == 0 ? v.x : a == 1 ? v.y : v.z;
  };
  F cube = F(kFar);
  for (int i = 0; i < 4; ++i) {
    F tn = F(-kFar), tf = F(kFar);
    for (int a = 0; a < 3; ++a) {
      const F ea = axis_of(e, a), ia = axis_of(m.inv[i], a);
      const F t0 = (axis_of(cube_lo, a) - ea) * ia, t1 = (axis_of(cube_hi, a) - ea) * ia;
      tn = max(tn, min(t0, t1));
      tf = min(tf, max(t0, t1));
    }
    cube = min(cube, select((tn <= t) && (tf >= t), tf, F(-1.0f)));
  }
  F out = select(k >= F(1.0f), cube, F(-1.0f));
  // The half-spaces beyond each face of the grid box (by the margin): a corner is inside while
  // its coordinate stays beyond the face, for ever if it moves away from it.
  const glm::vec3 hi = g.lo + g.cell * g.res;
  for (int a = 0; a < 3; ++a)
    for (int side = 0; side < 2; ++side) {
      const float plane = side ? hi[a] + u.margin : g.lo[a] - u.margin;
      F leave = F(kFar);
      for (int i = 0; i < 4; ++i) {
        const F da = axis_of(m.d[i], a), ea = axis_of(e, a);
        const F now = ea + da * t;
        const auto inside = side ? now >= F(plane) : now <= F(plane);
        const auto towards = side ? da < F(0.0f) : da > F(0.0f);
        const F cross = (F(plane) - ea) * axis_of(m.inv[i], a);
        leave = min(leave, select(inside, select(towards, cross, F(kFar)), F(-1.0f)));
      }
      out = max(out, leave);
    }
  const F reach = out * m.cosw * F(0.9999f);
  const F s = reach - t;
  const auto marching = b.x >= F(0.0f);
  const auto moves = marching && (s >= F(u.min_step));
  const F t1 = select(moves, t + s, t);
  const auto missed = t1 >= F(u.far);
  const auto stops = marching && (!moves || missed);
  return {select(stops, F(-1.0f), b.x), t1, select(missed, F(1.0f), b.z),
          select(moves, b.w + F(1.0f), b.w)};
}

// rayosHaz: one step of a tile's beam. The beam texture (one texel per tile) holds x = 0 while the
// beam marches, -1 once it stopped; y = t, where all of the tile's rays may start (every point of
// them before it lies in empty space); z = 1 where the whole tile misses the grid; w = the steps
// it took.
struct BeamMarch {
  static constexpr const char* name = "beam march";
  static constexpr const char* paper_name = "rayosHaz (extension)";
  static constexpr int outputs = 1;  // -> beams
  enum Unit { kBeams, kDistances };
  static constexpr std::array<const char*, 2> units{"beams", "beam_distances"};
  static constexpr std::array<int, 1> passthrough{kBeams};  // stopped beams keep their state

  BeamUniforms beams;

  template <class L>
  void operator()(Fragments<L>& f) const {
    const Vec4<typename L::F> b = f.fetch_own(kBeams);
    f.out(0) = beam_march_step(f, kDistances, b, MarchBeam<L>(f, beams), beams);
  }
};

// rayosHazIterativo (--kernels looping): the whole march in one pass, rayosHaz's step repeated
// while the beam marches, at most `steps` times (the passes' own limit): the same texels as the
// passes, without a pass and a query per step.
struct BeamMarchLooping {
  static constexpr const char* name = "beam march loop";
  static constexpr const char* paper_name = "rayosHazIterativo (extension)";
  static constexpr int outputs = 1;  // -> beams
  enum Unit { kBeams, kDistances };
  static constexpr std::array<const char*, 2> units{"beams", "beam_distances"};
  static constexpr std::array<int, 1> passthrough{kBeams};

  BeamUniforms beams;
  int steps = 48;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    using M = typename L::M;
    const MarchBeam<L> m(f, beams);
    Vec4<F> b = f.fetch_own(kBeams);
    f.loop(steps, b.x >= F(0.0f), [&](const M& act) {
      b = select(act, beam_march_step(f, kDistances, b, m, beams), b);
      return b.x >= F(0.0f);
    });
    f.out(0) = b;
  }
};

// inicioHaz: initTraversal for a pixel whose tile's beam marched: where the ray enters the grid
// (grid_entry), moved on to the voxel holding the ray's point at its tile's t. The voxel and its
// entry parameter are exactly those the 3D-DDA would reach: the entry is the largest of the
// voxel's three entry faces' parameters, computed as traversal computes a face's. Where that
// could round another way than the walk (the point near a face, the entry near the grid's), the
// ray enters as initTraversal has it; where the whole tile misses, the ray is done.
struct BeamEntry {
  static constexpr const char* name = "beam entry";
  static constexpr const char* paper_name = "inicioHaz (extension)";
  static constexpr int outputs = 1;  // -> traversal
  enum Unit { kRays, kBeams };
  static constexpr std::array<const char*, 2> units{"rays", "beams"};

  BeamUniforms beams;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const BeamUniforms& u = beams;
    const GridUniforms& g = u.grid;
    const Vec4<F> ray = f.fetch_own(kRays);
    const Vec3<F> o = splat<F>(u.eye), d = ray.xyz();
    const Vec4<F> entry = grid_entry<L>(o, d, ray.w, g);
    const Vec4<F> b = fetch_tile(f, kBeams, u.tile);
    const F ts = b.y;
    // The voxel holding the ray's point at ts, and how deep inside it the point lies.
    const Vec3<F> p = o + d * ts;
    const Vec3<F> rel{(p.x - F(g.lo.x)) / F(g.cell.x), (p.y - F(g.lo.y)) / F(g.cell.y),
                      (p.z - F(g.lo.z)) / F(g.cell.z)};
    const Vec3<F> v{floor(rel.x), floor(rel.y), floor(rel.z)};
    const F m = F(1e-3f);
    auto deep = [&](const F& r, const F& va, float res) {
      const F fr = r - va;
      return (va >= F(0.0f)) && (va <= F(res - 1.0f)) && (fr >= m) && (fr <= F(1.0f) - m);
    };
    // Where the ray enters that voxel: the face it crosses last, computed as voxel_exits
    // computes the face where the previous voxel ends.
    auto face = [&](const F& oa, const F& da, const F& va, float lo, float cell) {
      const F boundary = F(lo) + (va + select(da > F(0.0f), F(0.0f), F(1.0f))) * F(cell);
      return select(da == F(0.0f), F(-kFar), (boundary - oa) / da);
    };
    const F te =
        max(max(face(o.x, d.x, v.x, g.lo.x, g.cell.x), face(o.y, d.y, v.y, g.lo.y, g.cell.y)),
            face(o.z, d.z, v.z, g.lo.z, g.cell.z));
    const auto entered = entry.x >= F(0.0f);
    const auto moved = entered && deep(rel.x, v.x, g.res.x) && deep(rel.y, v.y, g.res.y) &&
                       deep(rel.z, v.z, g.res.z) && (te > entry.w + F(u.margin)) && (te <= ts);
    const auto missed = b.z > F(0.0f);
    const Vec4<F> done{F(kNone), F(0.0f), F(0.0f), F(0.0f)};
    f.out(0) = select(missed, done, select(moved, Vec4<F>{v.x, v.y, v.z, te}, entry));
  }
};

// rayosHazPerdidos: counts the tiles whose whole beam misses the grid (z = 1); the others are
// discarded, so an occlusion query counts these.
struct BeamsMissed {
  static constexpr const char* name = "beams missed";
  static constexpr const char* paper_name = "rayosHazPerdidos (extension)";
  static constexpr int outputs = 1;  // a dummy target: the count is what matters
  static constexpr bool idle_discards = true;
  enum Unit { kBeams };
  static constexpr std::array<const char*, 1> units{"beams"};

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> b = f.fetch_own(kBeams);
    f.discard(b.z <= F(0.0f));
    f.out(0) = {F(1.0f), F(0.0f), F(0.0f), F(0.0f)};
  }
};

}  // namespace kernels
