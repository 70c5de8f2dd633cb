// copiarFilas (an extension: glass, issue 25): texel (x, y) of the target takes texel
// (x, y + rows) of the input. Moves a chunk of W x H elements between a stream level's tall
// texture (W wide, a chunk every H rows) and the per-pixel textures a walk traces, in either
// direction (rows = +chunk row, or -chunk row with the pass drawn over the chunk's rows).
#pragma once

#include "kernels/common.h"

namespace kernels {

struct CopyRows {
  static constexpr const char* name = "row copy";
  static constexpr const char* paper_name = "copiarFilas (extension)";
  static constexpr int outputs = 1;
  enum Unit { kIn };
  static constexpr std::array<const char*, 1> units{"stream"};

  float rows = 0;  // texels, whole rows

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    f.out(0) = f.fetch(kIn, f.x, f.y + F(rows));
  }
};

}  // namespace kernels
