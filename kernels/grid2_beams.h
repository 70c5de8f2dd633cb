// Beams over tiles through the two-level grid (an extension, issue 35; docs/studies/groups.md): the
// beams march over the coarse grid as they march over the uniform grid (rayosHaz, kernels/beams.h,
// on the coarse grid's beam distances), and each pixel's ray starts at the sub-cell its walk
// (kernels/grid2.h) would reach where its tile's beam stopped (inicioHazGrilla2).
//
// Why the start is the walk's own state, bit for bit: every coarse cell the ray crosses before
// its beam's t is empty, so its sub-grid is one cell, and the walk leaves it where
// SubGrid::exits puts that cell's far face along each axis. That face depends on the cell's
// coordinate along the axis alone, so along each axis the walk crosses a fixed, increasing
// sequence of faces, and it takes the three sequences' faces in order of t (tied ones at once).
// It therefore stands in coarse cell v, entered at te, exactly when along every axis the faces
// it crossed to come from its entry cell to v lie at or before te (te the last of them) and the
// next face lies after te. The entry checks that in the walk's arithmetic, and enters v as the
// walk's step enters a coarse cell (grid2_cell: the first or last sub-cell along the axes
// crossed at te, the one holding the point at te along the others).
#pragma once

#include "kernels/beams.h"
#include "kernels/grid2.h"

namespace kernels {

// inicioHazGrilla2: inicioGrilla2 for a pixel whose tile's beam marched over the coarse grid:
// the sub-cell the walk reaches in the coarse cell holding the ray's point at its tile's t, or
// where the ray enters the box (inicioGrilla2's state) where the checks above fail; done where
// the whole tile misses.
struct Grid2BeamEntry {
  static constexpr const char* name = "grid2 beam entry";
  static constexpr const char* paper_name = "inicioHazGrilla2 (extension)";
  static constexpr int outputs = 1;  // -> traversal
  enum Unit { kOrigins, kRays, kBeams, kCells, kSubCells };
  static constexpr std::array<const char*, 5> units{"origins", "rays", "beams", "grid2_cells",
                                                    "grid2_subcells"};

  BeamUniforms beams;  // its grid: the coarse grid's box
  Grid2Uniforms grid2;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Grid2Uniforms& u = grid2;
    const Vec4<F> ray = f.fetch_own(kRays);
    const Vec3<F> o = f.fetch_own(kOrigins).xyz(), d = ray.xyz();
    GridUniforms coarse;  // grid_entry reads the box alone
    coarse.lo = u.lo;
    coarse.cell = u.cell;
    coarse.res = u.res;
    const Vec4<F> e = grid_entry<L>(o, d, ray.w, coarse);
    const Vec4<F> b = fetch_tile(f, kBeams, beams.tile);
    const F ts = b.y;
    // The coarse cell v holding the ray's point at ts, and per axis the faces crossed from the
    // entry cell: n (zero along an axis the ray runs parallel to, where v must be the entry's).
    const Vec3<F> p = o + d * ts;
    const Vec3<F> v{floor((p.x - F(u.lo.x)) / F(u.cell.x)), floor((p.y - F(u.lo.y)) / F(u.cell.y)),
                    floor((p.z - F(u.lo.z)) / F(u.cell.z))};
    auto dir = [](const F& da) { return select(da > F(0.0f), F(1.0f), F(-1.0f)); };
    const Vec3<F> s{dir(d.x), dir(d.y), dir(d.z)};
    const Vec3<F> n = (v - e.xyz()) * s;
    auto fits = [](const F& va, const F& ea, const F& na, const F& da, float res) {
      const auto parallel = da == F(0.0f);
      return (va >= F(0.0f)) && (va <= F(res - 1.0f)) &&
             ((parallel && (va == ea)) || (!parallel && (na >= F(0.0f))));
    };
    // The far faces (exits) of an empty coarse cell's one sub-cell, as the walk's step
    // computes them: in the cell before v along each axis (the face into v), and in v (the
    // next face along each axis).
    const Vec4<F> one{F(1.0f), F(1.0f), F(1.0f), F(0.0f)};
    const Vec3<F> first{F(0.0f), F(0.0f), F(0.0f)};
    const Vec3<F> into = SubGrid<L>(v - s, one, u).exits(o, d, first);
    const Vec3<F> after = SubGrid<L>(v, one, u).exits(o, d, first);
    const F none = F(-kFar);
    const Vec3<F> face{select(n.x >= F(1.0f), into.x, none), select(n.y >= F(1.0f), into.y, none),
                       select(n.z >= F(1.0f), into.z, none)};
    const F te = max(max(face.x, face.y), face.z);
    const auto entered = e.x >= F(0.0f);
    const auto moved = entered && fits(v.x, e.x, n.x, d.x, u.res.x) &&
                       fits(v.y, e.y, n.y, d.y, u.res.y) && fits(v.z, e.z, n.z, d.z, u.res.z) &&
                       (te > none) && (te < min3(after)) && (te <= ts);
    // Entering v as the step enters a coarse cell: along the axes crossed at te, the first (or
    // last) sub-cell; along the others, the sub-cell holding the point at te.
    auto given = [](const F& da) { return select(da > F(0.0f), F(0.0f), F(kGrid2Far)); };
    auto point = [&](const F& fa) { return select(fa == te, F(0.0f), F(1.0f)); };
    const Vec3<F> zero{F(0.0f), F(0.0f), F(0.0f)}, all{F(1.0f), F(1.0f), F(1.0f)};
    const Vec3<F> cc = select(moved, v, select(entered, e.xyz(), zero));  // a done ray reads 0
    const Vec3<F> g = select(moved, Vec3<F>{given(d.x), given(d.y), given(d.z)}, zero);
    const Vec3<F> fp = select(moved, Vec3<F>{point(face.x), point(face.y), point(face.z)}, all);
    const Vec4<F> in = grid2_cell(f, kCells, kSubCells, o, d, cc, select(moved, te, e.w), g, fp, u);
    const auto missed = b.z > F(0.0f);
    const Vec4<F> done{F(kNone), F(kNone), F(0.0f), F(0.0f)};
    f.out(0) = select(entered && !missed, in, done);
  }
};

}  // namespace kernels
