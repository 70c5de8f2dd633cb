// rayosEnGrilla: counts the rays still walking the grid (no hit yet, not out of the grid).
// Writes nothing: finished rays are discarded, so an occlusion query counts the rest.
#pragma once

#include "kernels/common.h"

namespace kernels {

struct RaysInGrid {
  static constexpr const char* name = "rays in grid";
  static constexpr const char* paper_name = "rayosEnGrilla";
  static constexpr int outputs = 1;  // a dummy target: the count is what matters
  static constexpr bool idle_discards = true;
  enum Unit { kTraversal };
  static constexpr std::array<const char*, 1> units{"traversal"};

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> trav = f.fetch_own(kTraversal);
    f.discard(trav.x < F(0.0f));
    f.out(0) = {F(1.0f), F(0.0f), F(0.0f), F(0.0f)};
  }
};

}  // namespace kernels
