// intersecciones: tests each ray against one triangle of its current voxel per pass (paper
// Sec. 2.3) and keeps the nearest hit. A hit counts only inside the current voxel, between the
// ray's entry and exit parameters (with a small slack, t_slack, so a hit on a shared voxel face
// is not lost to rounding); a hit beyond the voxel is found again in the voxel that holds it.
#pragma once

#include "kernels/common.h"
#include "kernels/lists.h"

namespace kernels {

// Texture units of the inputs nearest_hit fetches besides the voxel and intersection states.
struct HitUnits {
  int origins, rays, traversal, v0;  // v0, v0 + 1, v0 + 2: the three vertex textures
};

// The intersection state `best` after testing triangle vs.w, for the lanes where `testing`;
// other lanes keep `best`. Shared with the fused intersections + next triangle program
// (kernels/fused.h).
template <class L>
inline Vec4<typename L::F> nearest_hit(const Fragments<L>& f, const HitUnits& u,
                                       const Vec4<typename L::F>& vs,
                                       const Vec4<typename L::F>& best,
                                       const typename L::M& testing, const GridUniforms& grid,
                                       const SceneUniforms& scene) {
  using F = typename L::F;
  const Vec3<F> o = f.fetch_own(u.origins).xyz();
  const Vec4<F> ray = f.fetch_own(u.rays);
  const Vec4<F> trav = f.fetch_own(u.traversal);
  const Vec3<F> d = ray.xyz();
  F bu, bv;
  const F t = hit_triangle(f, u.v0, o, d, vs.w, scene, bu, bv);
  // The voxel's segment: from where the ray entered it (trav.w) to where it leaves.
  const F t_exit = min3(voxel_exits(o, d, trav.xyz(), grid));
  const auto in_voxel = in_segment(t, trav.w, t_exit, grid.t_slack);
  const auto nearer = testing && in_voxel && (t < best.x) && (t < ray.w);
  return select(nearer, Vec4<F>{t, bu, bv, vs.w}, best);
}

struct Intersections {
  static constexpr const char* name = "intersections";
  static constexpr const char* paper_name = "intersecciones";
  static constexpr int outputs = 1;  // -> intersection
  enum Unit { kOrigins, kRays, kTraversal, kVoxelState, kIntersection, kV0, kV1, kV2 };
  static constexpr std::array<const char*, 8> units{"origins",     "rays",         "traversal",
                                                    "voxel_state", "intersection", "vertices0",
                                                    "vertices1",   "vertices2"};
  static constexpr std::array<int, 1> passthrough{kIntersection};

  GridUniforms grid;
  SceneUniforms scene;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> vs = f.fetch_own(kVoxelState);
    const Vec4<F> best = f.fetch_own(kIntersection);
    const auto testing = vs.w >= F(0.0f);
    Vec4<F> next = best;
    if (f.branch(testing))
      next = nearest_hit(f, {kOrigins, kRays, kTraversal, kV0}, vs, best, testing, grid, scene);
    f.out(0) = next;
  }
};

}  // namespace kernels
