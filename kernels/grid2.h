// The two-level grid walk's kernels (an extension; host/accel/grid2.h): the paper's 3D-DDA on
// two levels, without a stack. The ray's state names one sub-cell; a step moves it to the next
// sub-cell of its coarse cell's sub-grid (descending by DDA), and where it leaves the sub-grid
// it steps the coarse grid and descends into the next coarse cell's sub-grid at the face it
// crossed (climbing back costs nothing: the coarse cell is read from the sub-cell's texel).
//   inicioGrilla2 (extension)          the coarse cell where the ray enters the box, then the
//                                      sub-cell of its sub-grid holding the entry point
//                                      (initTraversal's place)
//   recorridoGrilla2 (extension)       one sub-cell per pass: done at a hit inside the sub-cell,
//                                      else the next sub-cell (descend / step / climb)
//                                      (traversal's place)
//   cargarCelda (extension)            the first triangle of the sub-cell reached
//                                      (actualizarVoxel's place)
//   interseccionesGrilla2 (extension)  one triangle per pass, a hit counting only inside the
//                                      sub-cell's segment widened by t_slack (the in-voxel rule)
// with proximoTriangulo, rayosIntersectando and rayosEnGrilla as the grid has them. Traversal
// state (kernels/layout.h): x = sub-cell (-1: done), y = the sub-cell's list start, z, w = t
// where the ray enters and leaves the sub-cell.
// Addressed by (x, y) (Grid2Uniforms::xy, for grids past a float's linear reach): the state holds
// the sub-cell's column and row in x and y, and cargarCelda reads its list start from the
// sub-cell's texel (list start column, row, coarse cell); a coarse cell's record holds its
// sub-grid's resolution x + kGrid2ResPack y, z, and its first sub-cell's column and row.
#pragma once

#include "kernels/common.h"
#include "kernels/init_traversal.h"
#include "kernels/lists.h"
#include "kernels/next_triangle.h"

namespace kernels {

// Uniforms of the two-level grid: its lists' (t_slack: the in-cell rule's tolerance), its
// coarse grid's box and its two cell textures'.
struct Grid2Uniforms : ListUniforms {
  glm::vec3 lo{0.0f};    // coarse grid box minimum, world space
  glm::vec3 cell{1.0f};  // world size of one coarse cell
  glm::vec3 res{1.0f};   // coarse cells per axis, as floats
  float cell_width = 1;  // width of the coarse-cell texture, texels
  float sub_width = 1;   // width of the sub-cell texture, texels
};

// By (x, y), a coarse cell's record packs its sub-grid's x and y resolutions in one channel
// (x + kGrid2ResPack y; sub-grids stop at 128 cells per axis, host/accel/grid2.h).
inline constexpr float kGrid2ResPack = 1024.0f;

// Index `id` of an x-fastest rx × ry × rz array as (x, y, z); ids below 2^24 decode exactly
// (the + 1/2 keeps the quotient off the integer below).
template <class F>
inline Vec3<F> decode_index(const F& id, const F& rx, const F& ry) {
  const F q = floor((id + F(0.5f)) / rx);
  const F z = floor((q + F(0.5f)) / ry);
  return {id - q * rx, q - z * ry, z};
}

// The sub-grid of coarse cell `cc`: its resolution and first sub-cell from the coarse-cell
// texture (linear: xyz and w; by (x, y): packed, see kGrid2ResPack), its box minimum and its
// sub-cell size (world space).
template <class L>
struct SubGrid {
  using F = typename L::F;
  Vec3<F> res;
  Addr<F> first;
  Vec3<F> lo, size;
  SubGrid(const Fragments<L>& f, int unit_cells, const Vec3<F>& cc, const Grid2Uniforms& u)
      : SubGrid(
            cc,
            fetch_id(f, unit_cells, (cc.z * F(u.res.y) + cc.y) * F(u.res.x) + cc.x, u.cell_width),
            u, u.xy > 0.5f) {}
  // The sub-grid of coarse cell `cc` whose record is `record`, laid out linear or by (x, y) (no
  // fetch: the beam entry's empty cells, whose sub-grid is one cell, linear).
  SubGrid(const Vec3<F>& cc, const Vec4<F>& record, const Grid2Uniforms& u, bool xy = false) {
    if (xy) {
      const F ry = floor(record.x / F(kGrid2ResPack));
      res = {record.x - ry * F(kGrid2ResPack), ry, record.y};
      first = {record.z, record.w};
    } else {
      res = record.xyz();
      first = {record.w, record.w};
    }
    lo = {F(u.lo.x) + cc.x * F(u.cell.x), F(u.lo.y) + cc.y * F(u.cell.y),
          F(u.lo.z) + cc.z * F(u.cell.z)};
    size = {F(u.cell.x) / res.x, F(u.cell.y) / res.y, F(u.cell.z) / res.z};
  }
  // Per axis, the t where the ray leaves sub-cell s through that axis' next boundary (kFar
  // for an axis the ray runs parallel to): voxel_exits over the sub-grid.
  Vec3<F> exits(const Vec3<F>& o, const Vec3<F>& d, const Vec3<F>& s) const {
    auto axis = [&](const F& oa, const F& da, const F& sa, const F& la, const F& ca) {
      const F boundary = la + (sa + select(da > F(0.0f), F(1.0f), F(0.0f))) * ca;
      return select(da == F(0.0f), F(kFar), (boundary - oa) / da);
    };
    return {axis(o.x, d.x, s.x, lo.x, size.x), axis(o.y, d.y, s.y, lo.y, size.y),
            axis(o.z, d.z, s.z, lo.z, size.z)};
  }
};

// The state of a ray entering coarse cell `cc` at parameter t: per axis, the sub-cell `given`
// where from_point is 0 (clamped into the sub-grid: a huge value gives the last sub-cell), else
// the sub-cell holding the point o + t d (clamped). Linear, fetches the sub-cell's list start
// (state y); by (x, y), only where `list` is given (it receives it), else cargarCelda does.
template <class L>
inline Vec4<typename L::F> grid2_cell(const Fragments<L>& f, int unit_cells, int unit_subs,
                                      const Vec3<typename L::F>& o, const Vec3<typename L::F>& d,
                                      const Vec3<typename L::F>& cc, const typename L::F& t,
                                      const Vec3<typename L::F>& given,
                                      const Vec3<typename L::F>& from_point, const Grid2Uniforms& u,
                                      Addr<typename L::F>* list = nullptr) {
  using F = typename L::F;
  const SubGrid<L> sg(f, unit_cells, cc, u);
  const Vec3<F> p = o + d * t;  // world space
  auto sub = [&](const F& pa, const F& la, const F& ca, const F& ra, const F& ga, const F& fp) {
    const F v = select(fp > F(0.5f), floor((pa - la) / ca), ga);
    return min(max(v, F(0.0f)), ra - F(1.0f));
  };
  const Vec3<F> s{sub(p.x, sg.lo.x, sg.size.x, sg.res.x, given.x, from_point.x),
                  sub(p.y, sg.lo.y, sg.size.y, sg.res.y, given.y, from_point.y),
                  sub(p.z, sg.lo.z, sg.size.z, sg.res.z, given.z, from_point.z)};
  const bool xy = u.xy > 0.5f;
  const Addr<F> g = addr_add(sg.first, (s.z * sg.res.y + s.y) * sg.res.x + s.x, u.sub_width, xy);
  if (!xy) {
    const F start = fetch_id(f, unit_subs, g.x, u.sub_width).x;
    if (list) *list = {start, start};
    return {g.x, start, t, min3(sg.exits(o, d, s))};
  }
  if (list) {
    const Vec4<F> sub_texel = fetch_at(f, unit_subs, g, u.sub_width, true);
    *list = {sub_texel.x, sub_texel.y};
  }
  return {g.x, g.y, t, min3(sg.exits(o, d, s))};
}

inline constexpr float kGrid2Far = 1e6f;  // a sub-cell index past any sub-grid's last

// Entry of a ray with tmax ray_w: the coarse cell where it enters the box (initTraversal's
// grid_entry over the coarse grid), then the sub-cell holding the entry point; or done.
template <class L>
inline Vec4<typename L::F> grid2_entry(const Fragments<L>& f, int unit_cells, int unit_subs,
                                       const Vec3<typename L::F>& o, const Vec3<typename L::F>& d,
                                       const typename L::F& ray_w, const Grid2Uniforms& u) {
  using F = typename L::F;
  GridUniforms coarse;  // grid_entry reads the box alone
  coarse.lo = u.lo;
  coarse.cell = u.cell;
  coarse.res = u.res;
  const Vec4<F> e = grid_entry<L>(o, d, ray_w, coarse);
  const Vec3<F> zero{F(0.0f), F(0.0f), F(0.0f)}, one{F(1.0f), F(1.0f), F(1.0f)};
  const Vec3<F> cc = select(e.x >= F(0.0f), e.xyz(), zero);  // a done ray reads cell 0
  const Vec4<F> in = grid2_cell(f, unit_cells, unit_subs, o, d, cc, e.w, zero, one, u, nullptr);
  return select(e.x >= F(0.0f), in, Vec4<F>{F(kNone), F(kNone), F(0.0f), F(0.0f)});
}

// One step for the lanes where `walking` (others keep trav): done when a hit was found inside
// the sub-cell trav.x, the ray leaves the box or the next sub-cell begins past its tmax; else the
// next sub-cell along the ray. Every axis tied at the exit steps at once, as the grid's DDA; an
// axis that leaves the sub-grid steps the coarse grid, and the ray enters the next coarse cell's
// sub-grid on the face it crossed.
template <class L>
inline Vec4<typename L::F> grid2_step(const Fragments<L>& f, int unit_cells, int unit_subs,
                                      const Vec4<typename L::F>& trav,
                                      const Vec4<typename L::F>& best, const Vec3<typename L::F>& o,
                                      const Vec3<typename L::F>& d, const typename L::F& tmax,
                                      const typename L::M& walking, const Grid2Uniforms& u,
                                      Addr<typename L::F>* list = nullptr) {
  using F = typename L::F;
  const bool xy = u.xy > 0.5f;
  // Climb: the sub-cell's texel names its coarse cell.
  const Addr<F> at = xy ? Addr<F>{trav.x, trav.y} : Addr<F>{trav.x, trav.x};
  const Vec4<F> sub_texel = fetch_at(f, unit_subs, at, u.sub_width, xy);
  const F c = xy ? sub_texel.z : sub_texel.y;
  const Vec3<F> cc = decode_index(c, F(u.res.x), F(u.res.y));
  const SubGrid<L> sg(f, unit_cells, cc, u);
  const Vec3<F> s = decode_index(addr_minus(at, sg.first, u.sub_width, xy), sg.res.x, sg.res.y);
  const Vec3<F> exits = sg.exits(o, d, s);
  const F t_exit = min3(exits);
  // Per axis: the step (+-1 where tied at the exit, else 0), the sub-cell after it, and
  // whether that leaves the sub-grid.
  auto stepped = [&](const F& da, const F& ea) {
    return select(ea == t_exit, select(da > F(0.0f), F(1.0f), F(-1.0f)), F(0.0f));
  };
  const Vec3<F> st{stepped(d.x, exits.x), stepped(d.y, exits.y), stepped(d.z, exits.z)};
  const Vec3<F> ns = s + st;
  const auto lx = (ns.x < F(0.0f)) || (ns.x >= sg.res.x);
  const auto ly = (ns.y < F(0.0f)) || (ns.y >= sg.res.y);
  const auto lz = (ns.z < F(0.0f)) || (ns.z >= sg.res.z);
  const auto leaving = lx || ly || lz;
  // The coarse cell after the step (moved along the axes that leave the sub-grid).
  const Vec3<F> nc{cc.x + select(lx, st.x, F(0.0f)), cc.y + select(ly, st.y, F(0.0f)),
                   cc.z + select(lz, st.z, F(0.0f))};
  const auto outside = (nc.x < F(0.0f)) || (nc.y < F(0.0f)) || (nc.z < F(0.0f)) ||
                       (nc.x >= F(u.res.x)) || (nc.y >= F(u.res.y)) || (nc.z >= F(u.res.z));
  // Within the sub-grid: the stepped sub-cell. Into the next coarse cell: along a crossed axis
  // its first (or last) sub-cell, along the others the sub-cell holding the crossing point.
  auto given = [&](const typename L::M& leave, const F& sta, const F& nsa) {
    return select(leave, select(sta > F(0.0f), F(0.0f), F(kGrid2Far)), nsa);
  };
  const F pt = select(leaving, F(1.0f), F(0.0f));
  const Vec3<F> g{given(lx, st.x, ns.x), given(ly, st.y, ns.y), given(lz, st.z, ns.z)};
  const Vec3<F> from_point{select(lx, F(0.0f), pt), select(ly, F(0.0f), pt),
                           select(lz, F(0.0f), pt)};
  const auto found = best.w >= F(0.0f);                  // a hit inside this sub-cell ends the walk
  const auto past = past_tmax(t_exit, tmax, u.t_slack);  // a shadow ray past its light
  const auto done = found || outside || past;
  const Vec3<F> zero{F(0.0f), F(0.0f), F(0.0f)};
  const Vec4<F> next = grid2_cell(f, unit_cells, unit_subs, o, d, select(outside, zero, nc), t_exit,
                                  g, from_point, u, list);
  const Vec4<F> finished{F(kNone), F(kNone), F(0.0f), F(0.0f)};
  return select(walking, select(done, finished, next), trav);
}

struct Grid2Enter {
  static constexpr const char* name = "grid2 enter";
  static constexpr const char* paper_name = "inicioGrilla2 (extension)";
  static constexpr int outputs = 1;  // -> traversal
  enum Unit { kOrigins, kRays, kCells, kSubCells };
  static constexpr std::array<const char*, 4> units{"origins", "rays", "grid2_cells",
                                                    "grid2_subcells"};

  Grid2Uniforms grid2;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> ray = f.fetch_own(kRays);
    f.out(0) =
        grid2_entry(f, kCells, kSubCells, f.fetch_own(kOrigins).xyz(), ray.xyz(), ray.w, grid2);
  }
};

struct Grid2Step {
  static constexpr const char* name = "grid2 step";
  static constexpr const char* paper_name = "recorridoGrilla2 (extension)";
  static constexpr int outputs = 1;  // -> traversal
  enum Unit { kOrigins, kRays, kTraversal, kIntersection, kCells, kSubCells };
  static constexpr std::array<const char*, 6> units{
      "origins", "rays", "traversal", "intersection", "grid2_cells", "grid2_subcells"};
  static constexpr std::array<int, 1> passthrough{kTraversal};

  Grid2Uniforms grid2;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> trav = f.fetch_own(kTraversal);
    const auto walking = trav.x >= F(0.0f);
    Vec4<F> next = trav;
    if (f.branch(walking)) {
      const Vec4<F> best = f.fetch_own(kIntersection);
      const Vec3<F> o = f.fetch_own(kOrigins).xyz();
      const Vec4<F> ray = f.fetch_own(kRays);
      next = grid2_step(f, kCells, kSubCells, trav, best, o, ray.xyz(), ray.w, walking, grid2);
    }
    f.out(0) = next;
  }
};

// cargarCelda: the first triangle of the sub-cell just reached (traversal y: its list start; by
// (x, y), read from the sub-cell's texel, unit kSubCells), for a ray with nothing left to test
// (voxel state w = -1).
struct Grid2LoadCell {
  static constexpr const char* name = "grid2 load cell";
  static constexpr const char* paper_name = "cargarCelda (extension)";
  static constexpr int outputs = 1;  // -> voxel state
  enum Unit { kTraversal, kVoxelState, kLists, kSubCells };
  static constexpr std::array<const char*, 4> units{"traversal", "voxel_state", "grid2_lists",
                                                    "grid2_subcells"};
  static constexpr std::array<int, 1> passthrough{kVoxelState};

  Grid2Uniforms grid2;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> trav = f.fetch_own(kTraversal);
    const Vec4<F> vs = f.fetch_own(kVoxelState);
    const bool xy = grid2.xy > 0.5f;
    const auto load = (xy ? trav.x >= F(0.0f) : trav.y >= F(0.0f)) && (vs.w < F(0.0f));
    Vec4<F> next = vs;
    if (f.branch(load)) {
      if (xy) {
        const Vec4<F> sub = fetch_at(f, kSubCells, Addr<F>{trav.x, trav.y}, grid2.sub_width, true);
        next = load_list_at(f, kLists, Addr<F>{sub.x, sub.y}, vs, load, grid2);
      } else {
        next = load_list(f, kLists, trav.y, vs, load, grid2);
      }
    }
    f.out(0) = next;
  }
};

// interseccionesGrilla2: one triangle per pass, a hit counting only inside the sub-cell's
// segment trav.zw widened by t_slack (nearest_hit_in_segment, kernels/lists.h: the grid's
// in-voxel rule).
struct Grid2Intersections {
  static constexpr const char* name = "grid2 intersections";
  static constexpr const char* paper_name = "interseccionesGrilla2 (extension)";
  static constexpr int outputs = 1;  // -> intersection
  enum Unit { kOrigins, kRays, kTraversal, kVoxelState, kIntersection, kV0, kV1, kV2 };
  static constexpr std::array<const char*, 8> units{"origins",     "rays",         "traversal",
                                                    "voxel_state", "intersection", "vertices0",
                                                    "vertices1",   "vertices2"};
  static constexpr std::array<int, 1> passthrough{kIntersection};

  Grid2Uniforms grid2;
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
      next = nearest_hit_in_segment(f, kV0, o, ray, trav, vs, best, testing, scene, grid2.t_slack);
    }
    f.out(0) = next;
  }
};

// recorridoGrilla2 + cargarCelda (--mrt on): one step, and the first triangle of the sub-cell
// reached.
struct Grid2StepLoad {
  static constexpr const char* name = "grid2 step + load cell";
  static constexpr const char* paper_name = "recorridoGrilla2+cargarCelda (extension)";
  static constexpr int outputs = 2;  // -> traversal, voxel state
  enum Unit { kOrigins, kRays, kTraversal, kIntersection, kVoxelState, kCells, kSubCells, kLists };
  static constexpr std::array<const char*, 8> units{"origins",        "rays",        "traversal",
                                                    "intersection",   "voxel_state", "grid2_cells",
                                                    "grid2_subcells", "grid2_lists"};
  static constexpr std::array<int, 2> passthrough{kTraversal, kVoxelState};

  Grid2Uniforms grid2;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> trav = f.fetch_own(kTraversal);
    const Vec4<F> vs = f.fetch_own(kVoxelState);
    const auto walking = trav.x >= F(0.0f);
    Vec4<F> next = trav, nvs = vs;
    if (f.branch(walking)) {
      const Vec4<F> best = f.fetch_own(kIntersection);
      const Vec3<F> o = f.fetch_own(kOrigins).xyz();
      const Vec4<F> ray = f.fetch_own(kRays);
      if (grid2.xy > 0.5f) {
        Addr<F> list{trav.x, trav.x};
        next = grid2_step(f, kCells, kSubCells, trav, best, o, ray.xyz(), ray.w, walking, grid2,
                          &list);
        const auto load = walking && (next.x >= F(0.0f)) && (vs.w < F(0.0f));
        nvs = load_list_at(f, kLists, list, vs, load, grid2);
      } else {
        next = grid2_step(f, kCells, kSubCells, trav, best, o, ray.xyz(), ray.w, walking, grid2);
        const auto load = walking && (next.y >= F(0.0f)) && (vs.w < F(0.0f));
        nvs = load_list(f, kLists, next.y, vs, load, grid2);
      }
    }
    f.out(0) = next;
    f.out(1) = nvs;
  }
};

// interseccionesGrilla2 + proximoTriangulo (--mrt on): test the current triangle and move on.
struct Grid2IntersectNext {
  static constexpr const char* name = "grid2 intersections + next triangle";
  static constexpr const char* paper_name = "interseccionesGrilla2+proximoTriangulo (extension)";
  static constexpr int outputs = 2;  // -> intersection, voxel state
  enum Unit { kOrigins, kRays, kTraversal, kVoxelState, kIntersection, kV0, kV1, kV2, kLists };
  static constexpr std::array<const char*, 9> units{"origins",     "rays",         "traversal",
                                                    "voxel_state", "intersection", "vertices0",
                                                    "vertices1",   "vertices2",    "grid2_lists"};
  static constexpr std::array<int, 2> passthrough{kIntersection, kVoxelState};

  Grid2Uniforms grid2;
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
      next = nearest_hit_in_segment(f, kV0, o, ray, trav, vs, best, testing, scene, grid2.t_slack);
      nvs = next_in_list(f, kLists, vs, testing, grid2);
    }
    f.out(0) = next;
    f.out(1) = nvs;
  }
};

// recorridoGrilla2Iterativo (extension): the walk in one looping program. Each iteration tests
// the sub-cell's next triangle if one is left, else takes one step (loading the first triangle
// of the sub-cell reached). The host loads the entry sub-cell's first triangle before the loop.
struct Grid2Looping {
  static constexpr const char* name = "grid2 looping traversal";
  static constexpr const char* paper_name = "recorridoGrilla2Iterativo (extension)";
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
    kCells,
    kSubCells,
    kLists
  };
  static constexpr std::array<const char*, 11> units{
      "origins",   "rays",      "traversal",   "voxel_state",    "intersection", "vertices0",
      "vertices1", "vertices2", "grid2_cells", "grid2_subcells", "grid2_lists"};
  static constexpr std::array<int, 3> passthrough{kTraversal, kVoxelState, kIntersection};

  Grid2Uniforms grid2;
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
    if (grid2.xy > 0.5f) {
      // By (x, y): the step's sub-cell fetch brings the list start of the sub-cell it reaches.
      walk_lists_by_xy(
          f, steps, kV0, kLists, o, ray, trav, vs, best, grid2, scene,
          [&](const M& stepping, Addr<F>& list) {
            return grid2_step(f, kCells, kSubCells, trav, best, o, ray.xyz(), ray.w, stepping,
                              grid2, &list);
          },
          [](const Vec4<F>& next) { return next.x >= F(0.0f); });
      f.out(0) = trav;
      f.out(1) = vs;
      f.out(2) = best;
      return;
    }
    f.loop(steps, trav.x >= F(0.0f), [&](const M& act) {
      const M testing = act && (vs.w >= F(0.0f));
      best = nearest_hit_in_segment(f, kV0, o, ray, trav, vs, best, testing, scene, grid2.t_slack);
      const F pos = vs.x + F(1.0f);
      const F tri = list_entry(f, kLists, pos, grid2);
      const M stepping = act && !testing;
      const Vec4<F> next =
          grid2_step(f, kCells, kSubCells, trav, best, o, ray.xyz(), ray.w, stepping, grid2);
      const M load = stepping && (next.y >= F(0.0f));
      const F first = list_entry(f, kLists, next.y, grid2);
      vs = select(testing, Vec4<F>{pos, F(0.0f), F(0.0f), tri},
                  select(load, Vec4<F>{next.y, F(0.0f), F(0.0f), first}, vs));
      trav = select(stepping, next, trav);
      return trav.x >= F(0.0f);
    });
    f.out(0) = trav;
    f.out(1) = vs;
    f.out(2) = best;
  }
};

}  // namespace kernels
