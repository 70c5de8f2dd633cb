// traversal: one step of the 3D-DDA (Amanatides & Woo) per pass (paper Sec. 2.2). A ray whose
// voxel produced a valid hit is done; otherwise it moves to the next voxel along the ray, and
// is done when that voxel lies outside the grid, or begins past the ray's tmax (a shadow ray's
// light): a hit there could not pass t < tmax, as the CPU tracer's walk has it. Ties (the ray
// leaves through an edge or a corner) step every tied axis at once, so the walk never visits a
// voxel for zero length.
#pragma once

#include "kernels/common.h"
#include "kernels/lists.h"

namespace kernels {

// One DDA step of the traversal state `trav` of a ray from o along d (bounded by tmax) whose
// intersection state is `hit`, for the lanes where `walking`; other lanes keep `trav`. Shared with
// the fused traversal + update voxel program (kernels/fused.h).
template <class L, class F = typename L::F>
inline Vec4<F> dda_step(const Vec4<F>& trav, const Vec4<F>& hit, const Vec3<F>& o, const Vec3<F>& d,
                        const F& tmax, const typename L::M& walking, const GridUniforms& grid) {
  const Vec3<F> vox = trav.xyz();
  const Vec3<F> exits = voxel_exits(o, d, vox, grid);
  const F t_exit = min3(exits);
  auto step = [&](const F& da, const F& ta) {
    return select(ta == t_exit, select(da > F(0.0f), F(1.0f), F(-1.0f)), F(0.0f));
  };
  const Vec3<F> nv{vox.x + step(d.x, exits.x), vox.y + step(d.y, exits.y),
                   vox.z + step(d.z, exits.z)};
  const auto outside = (nv.x < F(0.0f)) || (nv.y < F(0.0f)) || (nv.z < F(0.0f)) ||
                       (nv.x >= F(grid.res.x)) || (nv.y >= F(grid.res.y)) ||
                       (nv.z >= F(grid.res.z));
  const auto found = hit.w >= F(0.0f);                      // a hit inside this voxel ends the walk
  const auto past = past_tmax(t_exit, tmax, grid.t_slack);  // a shadow ray past its light
  const auto done = found || outside || past;
  const Vec4<F> stepped{nv.x, nv.y, nv.z, t_exit};
  const Vec4<F> finished{F(kNone), F(0.0f), F(0.0f), trav.w};
  return select(walking, select(done, finished, stepped), trav);
}

struct Traversal {
  static constexpr const char* name = "traversal";
  static constexpr const char* paper_name = "traversal";
  static constexpr int outputs = 1;  // -> traversal
  enum Unit { kOrigins, kRays, kTraversal, kIntersection };
  static constexpr std::array<const char*, 4> units{"origins", "rays", "traversal", "intersection"};
  static constexpr std::array<int, 1> passthrough{kTraversal};  // done rays keep their state

  GridUniforms grid;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> trav = f.fetch_own(kTraversal);
    const Vec4<F> hit = f.fetch_own(kIntersection);
    const Vec3<F> o = f.fetch_own(kOrigins).xyz();
    const Vec4<F> ray = f.fetch_own(kRays);
    const auto walking = trav.x >= F(0.0f);
    Vec4<F> next = trav;
    if (f.branch(walking)) next = dda_step<L>(trav, hit, o, ray.xyz(), ray.w, walking, grid);
    f.out(0) = next;
  }
};

}  // namespace kernels
