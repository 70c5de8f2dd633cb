// acumularMuestras (an extension, --spp N): adds a sample frame's colour to the pixel's running
// sum, as the accumulation buffer of 2004 did; a counts the samples added.
#pragma once

#include "kernels/common.h"

namespace kernels {

struct AccumulateSamples {
  static constexpr const char* name = "accumulate samples";
  static constexpr const char* paper_name = "acumularMuestras (extension)";
  static constexpr int outputs = 1;  // -> sample sum
  enum Unit { kSum, kResult };
  static constexpr std::array<const char*, 2> units{"sample_sum", "result"};

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> sum = f.fetch_own(kSum);
    const Vec4<F> c = f.fetch_own(kResult);
    f.out(0) = {sum.x + c.x, sum.y + c.y, sum.z + c.z, sum.w + F(1.0f)};
  }
};

}  // namespace kernels
