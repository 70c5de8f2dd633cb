// Reduced-precision arithmetic: a lane family whose every operation rounds its result to fp24
// (R300) or fp16 (NV3x "half"), as those fragment units computed. A kernel written once over
// lanes runs unchanged in it, so any scene can be rendered as the GeForce FX's half precision
// or the Radeon 9700's fp24 would have computed it (`--precision`).
#pragma once

#include "vgpu/format.h"
#include "vgpu/lanes.h"

namespace vgpu {

template <int W, Format Fm>
struct RFloat {
  using S = stdx::fixed_size_simd<float, W>;
  using mask_type = typename S::mask_type;
  S v;

  // Every value that enters a register is rounded to the register's format.
  static S round(const S& x) {
    alignas(64) float a[W];
    x.copy_to(a, stdx::element_aligned);
    for (int i = 0; i < W; ++i) a[i] = round_to(Fm, a[i]);
    return S(a, stdx::element_aligned);
  }
  RFloat() = default;
  RFloat(float f) : v(round_to(Fm, f)) {}  // constants are rounded too
  explicit RFloat(const S& s) : v(round(s)) {}
  template <class G>
  requires std::is_invocable_r_v<float, G, std::integral_constant<size_t, 0>>
  explicit RFloat(G&& gen) : v(round(S(std::forward<G>(gen)))) {}

  float operator[](size_t i) const { return v[i]; }
  template <class Tag>
  void copy_to(float* p, Tag t) const {
    v.copy_to(p, t);
  }
  template <class Tag>
  void copy_from(const float* p, Tag t) {
    v.copy_from(p, t);
    v = round(v);
  }

#define VGPU_ROUNDED_BINOP(op)                                  \
  friend RFloat operator op(const RFloat& a, const RFloat& b) { \
    return RFloat(S(a.v op b.v));                               \
  }                                                             \
  RFloat& operator op##=(const RFloat& b) {                     \
    return *this = *this op b;                                  \
  }
  VGPU_ROUNDED_BINOP(+)
  VGPU_ROUNDED_BINOP(-)
  VGPU_ROUNDED_BINOP(*)
  VGPU_ROUNDED_BINOP(/)
#undef VGPU_ROUNDED_BINOP
  friend RFloat operator-(const RFloat& a) {
    RFloat r;
    r.v = -a.v;
    return r;
  }  // exact
#define VGPU_ROUNDED_CMP(op)                                       \
  friend mask_type operator op(const RFloat& a, const RFloat& b) { \
    return a.v op b.v;                                             \
  }
  VGPU_ROUNDED_CMP(<)
  VGPU_ROUNDED_CMP(<=)
  VGPU_ROUNDED_CMP(>)
  VGPU_ROUNDED_CMP(>=)
  VGPU_ROUNDED_CMP(==)
  VGPU_ROUNDED_CMP(!=)
#undef VGPU_ROUNDED_CMP
};

template <int W, Format Fm>
inline RFloat<W, Fm> select(const typename RFloat<W, Fm>::mask_type& m, const RFloat<W, Fm>& a,
                            const RFloat<W, Fm>& b) {
  RFloat<W, Fm> r;
  r.v = select(m, a.v, b.v);  // exact: picks one of two representable values
  return r;
}
template <int W, Format Fm>
inline RFloat<W, Fm> min(const RFloat<W, Fm>& a, const RFloat<W, Fm>& b) {
  return select(a < b, a, b);
}
template <int W, Format Fm>
inline RFloat<W, Fm> max(const RFloat<W, Fm>& a, const RFloat<W, Fm>& b) {
  return select(a > b, a, b);
}
template <int W, Format Fm>
inline RFloat<W, Fm> abs(const RFloat<W, Fm>& a) {
  RFloat<W, Fm> r;
  r.v = stdx::abs(a.v);
  return r;
}
template <int W, Format Fm>
inline RFloat<W, Fm> floor(const RFloat<W, Fm>& a) {
  return RFloat<W, Fm>(stdx::floor(a.v));
}
template <int W, Format Fm>
inline RFloat<W, Fm> sqrt(const RFloat<W, Fm>& a) {
  return RFloat<W, Fm>(stdx::sqrt(a.v));
}
// RSQ is one instruction: one rounding.
template <int W, Format Fm>
inline RFloat<W, Fm> rsqrt(const RFloat<W, Fm>& a) {
  return RFloat<W, Fm>(typename RFloat<W, Fm>::S(1.0f) / stdx::sqrt(a.v));
}

template <int W, Format Fm>
struct RoundedLanes {
  static constexpr int width = W;
  static constexpr bool counting = false;
  static constexpr bool recording = false;
  static constexpr Format precision = Fm;
  using F = RFloat<W, Fm>;
  using M = typename F::mask_type;
};

}  // namespace vgpu
