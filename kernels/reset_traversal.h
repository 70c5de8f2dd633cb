// reinicializarTraversal: after a ray's origin and direction change (reflected and shadow rays),
// recompute where it stands in the grid: the voxel holding its new origin (or where it enters
// the box) and the ray parameter t of that entry.
#pragma once

#include "kernels/init_traversal.h"

namespace kernels {

struct ResetTraversal {
  static constexpr const char* name = "reset traversal";
  static constexpr const char* paper_name = "reinicializarTraversal";
  static constexpr int outputs = 1;  // -> traversal
  enum Unit { kOrigins, kRays };
  static constexpr std::array<const char*, 2> units{"origins", "rays"};

  GridUniforms grid;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> o = f.fetch_own(kOrigins), ray = f.fetch_own(kRays);
    f.out(0) = grid_entry<L>(o.xyz(), ray.xyz(), ray.w, grid);
  }
};

}  // namespace kernels
