// initTraversal: once per frame, the voxel where each primary ray enters the grid (paper
// Sec. 2.2): the smallest t that brings the camera ray onto the grid box (slab test), and the
// voxel holding that point. Rays that miss the box are done at once.
#pragma once

#include "kernels/common.h"
#include "kernels/lists.h"

namespace kernels {

// Shared with reinicializarTraversal: entry (voxel, t) of a ray from o along d, tmax bounding it.
template <class L>
inline Vec4<typename L::F> grid_entry(const Vec3<typename L::F>& o, const Vec3<typename L::F>& d,
                                      const typename L::F& tmax, const GridUniforms& g) {
  using F = typename L::F;
  // The slab test (kernels/lists.h) on the grid's box, lo to lo + cell * res per axis.
  F tnear = F(0.0f), tfar = tmax;
  clip_to_slab(o.x, d.x, g.lo.x, g.lo.x + g.cell.x * g.res.x, tnear, tfar);
  clip_to_slab(o.y, d.y, g.lo.y, g.lo.y + g.cell.y * g.res.y, tnear, tfar);
  clip_to_slab(o.z, d.z, g.lo.z, g.lo.z + g.cell.z * g.res.z, tnear, tfar);
  const auto enters = (tnear <= tfar) && (tmax >= F(0.0f));
  const Vec3<F> p = o + d * tnear;  // world space, on or inside the box
  auto cell_of = [&](const F& pa, float lo, float cell, float res) {
    return min(max(floor((pa - F(lo)) / F(cell)), F(0.0f)), F(res - 1.0f));
  };
  const Vec4<F> entry{cell_of(p.x, g.lo.x, g.cell.x, g.res.x),
                      cell_of(p.y, g.lo.y, g.cell.y, g.res.y),
                      cell_of(p.z, g.lo.z, g.cell.z, g.res.z), tnear};
  const Vec4<F> done{F(kNone), F(0.0f), F(0.0f), F(0.0f)};
  return select(enters, entry, done);
}

struct InitTraversal {
  static constexpr const char* name = "init traversal";
  static constexpr const char* paper_name = "initTraversal";
  static constexpr int outputs = 1;  // -> traversal
  enum Unit { kRays };
  static constexpr std::array<const char*, 1> units{"rays"};

  glm::vec3 eye{0.0f};  // camera position, world space: every primary ray starts there
  GridUniforms grid;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> ray = f.fetch_own(kRays);
    f.out(0) = grid_entry<L>(splat<F>(eye), ray.xyz(), ray.w, grid);
  }
};

}  // namespace kernels
