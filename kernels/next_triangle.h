// proximoTriangulo: advances each ray to the next triangle of its voxel's list. At the -1 that
// closes the list the ray is marked ready for traversal (voxel state w = -1).
#pragma once

#include "kernels/common.h"
#include "kernels/lists.h"

namespace kernels {

// The voxel state `vs` moved on to the next list entry, for the lanes where `testing`; other
// lanes keep it. Shared with the fused intersections + next triangle program (kernels/fused.h).
template <class L>
inline Vec4<typename L::F> next_in_list(const Fragments<L>& f, int unit_lists,
                                        const Vec4<typename L::F>& vs, const typename L::M& testing,
                                        const ListUniforms& lists) {
  const bool xy = lists.xy > 0.5f;
  return load_list_at(f, unit_lists, addr_next(list_pos(vs, lists), lists.list_width, xy), vs,
                      testing, lists);
}

struct NextTriangle {
  static constexpr const char* name = "next triangle";
  static constexpr const char* paper_name = "proximoTriangulo";
  static constexpr int outputs = 1;  // -> voxel state
  enum Unit { kVoxelState, kLists };
  static constexpr std::array<const char*, 2> units{"voxel_state", "triangle_lists"};
  static constexpr std::array<int, 1> passthrough{kVoxelState};

  // Every structure walks its lists with this kernel: only the lists' uniforms are read.
  ListUniforms lists;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> vs = f.fetch_own(kVoxelState);
    const auto testing = vs.w >= F(0.0f);
    Vec4<F> next = vs;
    if (f.branch(testing)) next = next_in_list(f, kLists, vs, testing, lists);
    f.out(0) = next;
  }
};

}  // namespace kernels
