// rayosReflejados: counts the rays the shader reflected: those whose weight in the final colour
// (result alpha, the product of the reflection coefficients met) is still above zero.
#pragma once

#include "kernels/common.h"

namespace kernels {

struct ReflectedRays {
  static constexpr const char* name = "reflected rays";
  static constexpr const char* paper_name = "rayosReflejados";
  static constexpr int outputs = 1;  // a dummy target: the count is what matters
  static constexpr bool idle_discards = true;
  enum Unit { kResult };
  static constexpr std::array<const char*, 1> units{"result"};

  float min_weight = 1.0f / 512.0f;  // a ray that adds under 1/2 of an 8-bit step is not traced

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> res = f.fetch_own(kResult);
    f.discard(res.w < F(min_weight));
    f.out(0) = {F(1.0f), F(0.0f), F(0.0f), F(0.0f)};
  }
};

}  // namespace kernels
