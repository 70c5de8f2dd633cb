// contarRayos (an extension: glass, issue 25): counts, inside an occlusion query, the elements of
// a stream whose `channel` is at least `threshold`: the reflected (split x) or refracted
// (split y) rays spawned, the total internal reflections (split w), or the shadow rays still
// crossing glass (rays w = tmax >= 0).
#pragma once

#include "kernels/common.h"

namespace kernels {

struct CountStream {
  static constexpr const char* name = "stream count";
  static constexpr const char* paper_name = "contarRayos (extension)";
  static constexpr int outputs = 1;  // a dummy target: the count is what matters
  static constexpr bool idle_discards = true;
  enum Unit { kIn };
  static constexpr std::array<const char*, 1> units{"stream"};

  int channel = 0;
  float threshold = 1.0f / 512.0f;
  float rows = 0;  // the chunk's first row in a tall stream texture (the target is W x H)

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> v = f.fetch(kIn, f.x, f.y + F(rows));
    const F c = channel == 0 ? v.x : channel == 1 ? v.y : channel == 2 ? v.z : v.w;
    f.discard(c < F(threshold));
    f.out(0) = {F(1.0f), F(0.0f), F(0.0f), F(0.0f)};
  }
};

}  // namespace kernels
