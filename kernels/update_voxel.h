// actualizarVoxel: for each ray that has just entered a voxel, the first triangle to test there:
// the voxel pointer texture gives the start of the voxel's list, the list gives the triangle.
// An empty voxel's list is just -1, so the ray goes straight back to traversal.
#pragma once

#include "kernels/common.h"
#include "kernels/lists.h"

namespace kernels {

// The first list entry of the voxel `trav` stands in, for the lanes where `load`; other lanes
// keep the voxel state `vs`. Shared with the fused traversal + update voxel program
// (kernels/fused.h).
template <class L>
inline Vec4<typename L::F> first_in_voxel(const Fragments<L>& f, int unit_pointers, int unit_lists,
                                          const Vec4<typename L::F>& trav,
                                          const Vec4<typename L::F>& vs, const typename L::M& load,
                                          const GridUniforms& grid) {
  using F = typename L::F;
  // Voxel (X, Y, Z) lives at texel (X * sizeY + Y, Z).
  const F px = trav.x * F(grid.res.y) + trav.y + F(0.5f), py = trav.z + F(0.5f);
  const F start = f.fetch(unit_pointers, px, py).x;
  return load_list(f, unit_lists, start, vs, load, grid);
}

struct UpdateVoxel {
  static constexpr const char* name = "update voxel";
  static constexpr const char* paper_name = "actualizarVoxel";
  static constexpr int outputs = 1;  // -> voxel state
  enum Unit { kTraversal, kVoxelState, kPointers, kLists };
  static constexpr std::array<const char*, 4> units{"traversal", "voxel_state", "voxel_pointers",
                                                    "triangle_lists"};
  static constexpr std::array<int, 1> passthrough{kVoxelState};

  GridUniforms grid;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> trav = f.fetch_own(kTraversal);
    const Vec4<F> vs = f.fetch_own(kVoxelState);
    const auto load = (trav.x >= F(0.0f)) && (vs.w < F(0.0f));
    Vec4<F> next = vs;
    if (f.branch(load)) next = first_in_voxel(f, kPointers, kLists, trav, vs, load, grid);
    f.out(0) = next;
  }
};

}  // namespace kernels
