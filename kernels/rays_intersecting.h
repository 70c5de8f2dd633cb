// rayosIntersectando: counts the rays that still have a triangle to test in their voxel.
// Writes nothing: other rays are discarded, so an occlusion query counts these.
#pragma once

#include "kernels/common.h"

namespace kernels {

struct RaysIntersecting {
  static constexpr const char* name = "rays intersecting";
  static constexpr const char* paper_name = "rayosIntersectando";
  static constexpr int outputs = 1;  // a dummy target: the count is what matters
  static constexpr bool idle_discards = true;
  enum Unit { kVoxelState };
  static constexpr std::array<const char*, 1> units{"voxel_state"};

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> vs = f.fetch_own(kVoxelState);
    f.discard(vs.w < F(0.0f));
    f.out(0) = {F(1.0f), F(0.0f), F(0.0f), F(0.0f)};
  }
};

}  // namespace kernels
