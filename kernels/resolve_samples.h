// resolverMuestras (an extension, --spp N): the box filter, one pass at the end of the frame:
// each pixel's colour is the mean of its samples (sum / count).
#pragma once

#include "kernels/common.h"

namespace kernels {

struct ResolveSamples {
  static constexpr const char* name = "resolve samples";
  static constexpr const char* paper_name = "resolverMuestras (extension)";
  static constexpr int outputs = 1;  // -> result
  enum Unit { kSum };
  static constexpr std::array<const char*, 1> units{"sample_sum"};

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> sum = f.fetch_own(kSum);
    const F n = max(sum.w, F(1.0f));
    f.out(0) = {sum.x / n, sum.y / n, sum.z / n, F(1.0f)};
  }
};

}  // namespace kernels
