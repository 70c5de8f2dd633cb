// sumaPrefijos (an extension: stream reduction, Horn, GPU Gems 2 ch. 36): one pass of the
// inclusive prefix sum of a stream's counts, Hillis-Steele style. Element i adds element
// i - offset (offset 1, 2, 4, ... over log2(n) passes), each pass reading the previous pass's
// texture (never the one it writes). Output x = the partial sum; element i at
// (i mod width, i div width).
#pragma once

#include "kernels/glass.h"

namespace kernels {

struct ScanStream {
  static constexpr const char* name = "stream scan";
  static constexpr const char* paper_name = "sumaPrefijos (extension)";
  static constexpr int outputs = 1;  // -> scan (1 channel)
  enum Unit { kIn };
  static constexpr std::array<const char*, 1> units{"counts"};

  float width = 1;   // stream texture width, texels
  float offset = 1;  // 2^pass, elements
  int channel = 0;   // the input's channel holding the counts (2: the split texture's z)

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const F i = stream_index(f.x, f.y, width);
    const F k = i - F(offset);
    const auto has = k >= F(0.0f);
    const Vec4<F> own = f.fetch_own(kIn), prev = fetch_id(f, kIn, max(k, F(0.0f)), width);
    auto pick = [&](const Vec4<F>& v) {
      return channel == 0 ? v.x : channel == 1 ? v.y : channel == 2 ? v.z : v.w;
    };
    const F s = pick(own) + select(has, pick(prev), F(0.0f));
    f.out(0) = {s, F(0.0f), F(0.0f), F(0.0f)};
  }
};

}  // namespace kernels
