// acumularMuestras (an extension, --spp N): adds a sample frame's colour to the pixel's running
// sum, as the accumulation buffer of 2004 did; a counts the samples added. Under --aa adaptive
// only the pixels marked for more samples add theirs.
#pragma once

#include "kernels/common.h"

namespace kernels {

struct AccumulateSamples {
  static constexpr const char* name = "accumulate samples";
  static constexpr const char* paper_name = "acumularMuestras (extension)";
  static constexpr int outputs = 1;  // -> sample sum
  enum Unit { kSum, kResult, kMarks };
  static constexpr std::array<const char*, 3> units{"sample_sum", "result", "marks"};

  // --aa adaptive: only marked pixels (marks x > 0) add their sample; `restart` (a level's
  // first sample) drops their earlier samples, since the level's samples replace them.
  bool gated = false, restart = false;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    Vec4<F> sum = f.fetch_own(kSum);
    const Vec4<F> c = f.fetch_own(kResult);
    if (!gated) {
      f.out(0) = {sum.x + c.x, sum.y + c.y, sum.z + c.z, sum.w + F(1.0f)};
      return;
    }
    const auto marked = f.fetch_own(kMarks).x > F(0.0f);
    const Vec4<F> base = restart ? Vec4<F>{F(0.0f), F(0.0f), F(0.0f), F(0.0f)} : sum;
    const Vec4<F> added = {base.x + c.x, base.y + c.y, base.z + c.z, base.w + F(1.0f)};
    f.out(0) = select(marked, added, sum);
  }
};

}  // namespace kernels
