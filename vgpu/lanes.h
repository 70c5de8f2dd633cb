// The fragment processor's lanes: W fragments shaded together as one host SIMD vector.
// Kernels are written once against a lane family L (L::F float lanes, L::M lane mask) and run
// at every width; width 1 is the scalar reference the wider widths are tested against.
// Vectors are one register per component (Vec3<F>{x, y, z}), as in SwiftShader.
#pragma once

#include <cmath>
#include <cstdint>
#include <experimental/simd>
#include <type_traits>

namespace vgpu {

namespace stdx = std::experimental;

// The default width: one AVX2 register of fp32 on the x86-64-v3 baseline.
inline constexpr int kLanes = 8;

// Widths 4 and 8 use the target's own vector ABI (SSE / AVX registers, masks as vector masks);
// fixed_size would keep masks as bit sets, so every compare and select converts between the two.
// Width 1 (the scalar reference) and 16 (two registers) stay fixed_size. Same IEEE operations
// either way: results are bit-identical across widths.
template <int W>
using LaneAbi = std::conditional_t<W == 4 || W == 8, stdx::simd_abi::deduce_t<float, W>,
                                   stdx::simd_abi::fixed_size<W>>;

template <int W>
struct SimdLanes {
  static constexpr int width = W;
  static constexpr bool counting = false;
  static constexpr bool recording = false;
  using F = stdx::simd<float, LaneAbi<W>>;
  using M = typename F::mask_type;
};

// Free functions every lane family provides, so kernel code reads the same at any width.
// Forced inline: these are one or two instructions each, and GCC leaves some of them as calls
// in the large kernel translation units (with their operands passed through memory).
#define VGPU_LANE_INLINE [[gnu::always_inline]] inline

template <class T, class A>
VGPU_LANE_INLINE stdx::simd<T, A> select(const stdx::simd_mask<T, A>& m, const stdx::simd<T, A>& a,
                                         const stdx::simd<T, A>& b) {
  stdx::simd<T, A> r = b;
  stdx::where(m, r) = a;
  return r;
}
template <class T, class A>
VGPU_LANE_INLINE bool any(const stdx::simd_mask<T, A>& m) {
  return stdx::any_of(m);
}
template <class T, class A>
VGPU_LANE_INLINE bool all(const stdx::simd_mask<T, A>& m) {
  return stdx::all_of(m);
}
template <class T, class A>
VGPU_LANE_INLINE int lanes_on(const stdx::simd_mask<T, A>& m) {
  return stdx::popcount(m);
}
template <class T, class A>
VGPU_LANE_INLINE stdx::simd<T, A> rsqrt(const stdx::simd<T, A>& v) {
  return T(1) / stdx::sqrt(v);
}
using stdx::abs;
using stdx::floor;
using stdx::max;
using stdx::min;
using stdx::sqrt;
// MIN and MAX as fragment programs define them (ARB_fragment_program: MIN = a < b ? a : b,
// MAX = a > b ? a : b), so a NaN or a signed zero gives the same result at every width:
// stdx::min is std::min at width 1 but minps at wider widths, and those disagree on NaN and
// +-0. Non-templates, so overload resolution prefers them to stdx::min found by ADL.
#define VGPU_LANE_MIN_MAX(W)                                                                       \
  VGPU_LANE_INLINE stdx::fixed_size_simd<float, W> min(const stdx::fixed_size_simd<float, W>& a,   \
                                                       const stdx::fixed_size_simd<float, W>& b) { \
    return select(a < b, a, b);                                                                    \
  }                                                                                                \
  VGPU_LANE_INLINE stdx::fixed_size_simd<float, W> max(const stdx::fixed_size_simd<float, W>& a,   \
                                                       const stdx::fixed_size_simd<float, W>& b) { \
    return select(a > b, a, b);                                                                    \
  }
VGPU_LANE_MIN_MAX(1)
VGPU_LANE_MIN_MAX(4)
VGPU_LANE_MIN_MAX(8)
VGPU_LANE_MIN_MAX(16)
#undef VGPU_LANE_MIN_MAX
// The same for the other float ABIs (SimdLanes<4>::F and <8>::F): more specialized than
// stdx::min / stdx::max, so partial ordering prefers these.
template <class A>
VGPU_LANE_INLINE stdx::simd<float, A> min(const stdx::simd<float, A>& a,
                                          const stdx::simd<float, A>& b) {
  return select(a < b, a, b);
}
template <class A>
VGPU_LANE_INLINE stdx::simd<float, A> max(const stdx::simd<float, A>& a,
                                          const stdx::simd<float, A>& b) {
  return select(a > b, a, b);
}

// ---------------------------------------------------------------------------------------------
// The counting lane family: one fragment in plain floats, where every arithmetic, compare and
// select is one fragment-program instruction. Running a kernel once in this family, with every
// branch taken (the NV3x model: no dynamic branching, both sides execute), yields its static
// instruction count and its texture fetches per fragment, derived from the kernel code itself.
struct OpCounter {
  static inline thread_local uint64_t ops = 0;
};
struct CFloat;
struct CMask {
  bool v = false;
  CMask() = default;
  CMask(bool b) : v(b) {}  // as a SIMD mask broadcasts one bool (M(false), clang included)
  friend CMask operator&&(CMask a, CMask b) {
    ++OpCounter::ops;
    return {a.v && b.v};
  }
  friend CMask operator||(CMask a, CMask b) {
    ++OpCounter::ops;
    return {a.v || b.v};
  }
  friend CMask operator!(CMask a) {
    ++OpCounter::ops;
    return {!a.v};
  }
};
struct CFloat {
  float v = 0;
  CFloat() = default;
  CFloat(float f) : v(f) {}  // constants are free (literal registers)
#define VGPU_COUNTED_BINOP(op)                    \
  friend CFloat operator op(CFloat a, CFloat b) { \
    ++OpCounter::ops;                             \
    return CFloat(a.v op b.v);                    \
  }                                               \
  CFloat& operator op##=(CFloat b) {              \
    return *this = *this op b;                    \
  }
  VGPU_COUNTED_BINOP(+)
  VGPU_COUNTED_BINOP(-)
  VGPU_COUNTED_BINOP(*)
  VGPU_COUNTED_BINOP(/)
#undef VGPU_COUNTED_BINOP
  friend CFloat operator-(CFloat a) {
    ++OpCounter::ops;
    return CFloat(-a.v);
  }
#define VGPU_COUNTED_CMP(op)                     \
  friend CMask operator op(CFloat a, CFloat b) { \
    ++OpCounter::ops;                            \
    return {a.v op b.v};                         \
  }
  VGPU_COUNTED_CMP(<)
  VGPU_COUNTED_CMP(<=)
  VGPU_COUNTED_CMP(>)
  VGPU_COUNTED_CMP(>=)
  VGPU_COUNTED_CMP(==)
  VGPU_COUNTED_CMP(!=)
#undef VGPU_COUNTED_CMP
};
inline CFloat select(CMask m, CFloat a, CFloat b) {
  ++OpCounter::ops;
  return m.v ? a : b;
}
inline bool any(CMask m) {
  return m.v;
}
inline bool all(CMask m) {
  return m.v;
}
inline int lanes_on(CMask m) {
  return m.v ? 1 : 0;
}
inline CFloat min(CFloat a, CFloat b) {
  ++OpCounter::ops;
  return a.v < b.v ? a : b;
}
inline CFloat max(CFloat a, CFloat b) {
  ++OpCounter::ops;
  return a.v > b.v ? a : b;
}
inline CFloat abs(CFloat a) {
  ++OpCounter::ops;
  return CFloat(std::fabs(a.v));
}
inline CFloat floor(CFloat a) {
  ++OpCounter::ops;
  return CFloat(std::floor(a.v));
}
inline CFloat sqrt(CFloat a) {
  ++OpCounter::ops;
  return CFloat(std::sqrt(a.v));
}
inline CFloat rsqrt(CFloat a) {
  ++OpCounter::ops;
  return CFloat(1.0f / std::sqrt(a.v));
}

struct CountingLanes {
  static constexpr int width = 1;
  static constexpr bool counting = true;
  static constexpr bool recording = false;
  using F = CFloat;
  using M = CMask;
};

// Lane i of a value, for host code and tests.
template <class T, class A>
inline T lane(const stdx::simd<T, A>& v, int i) {
  return v[i];
}
template <class T, class A>
inline bool lane(const stdx::simd_mask<T, A>& m, int i) {
  return m[i];
}
inline float lane(CFloat v, int) {
  return v.v;
}
inline bool lane(CMask m, int) {
  return m.v;
}

// ---------------------------------------------------------------------------------------------
// Vectors of lanes, one register per component.
template <class F>
struct Vec3 {
  F x, y, z;
  [[gnu::always_inline]] friend Vec3 operator+(const Vec3& a, const Vec3& b) {
    return {a.x + b.x, a.y + b.y, a.z + b.z};
  }
  [[gnu::always_inline]] friend Vec3 operator-(const Vec3& a, const Vec3& b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
  }
  [[gnu::always_inline]] friend Vec3 operator*(const Vec3& a, const F& s) {
    return {a.x * s, a.y * s, a.z * s};
  }
  [[gnu::always_inline]] friend Vec3 operator*(const F& s, const Vec3& a) {
    return {a.x * s, a.y * s, a.z * s};
  }
  [[gnu::always_inline]] friend Vec3 operator*(const Vec3& a, const Vec3& b) {
    return {a.x * b.x, a.y * b.y, a.z * b.z};
  }
  [[gnu::always_inline]] friend Vec3 operator-(const Vec3& a) { return {-a.x, -a.y, -a.z}; }
};
template <class F>
struct Vec4 {
  F x, y, z, w;
  Vec3<F> xyz() const { return {x, y, z}; }
};
template <class F>
VGPU_LANE_INLINE F dot(const Vec3<F>& a, const Vec3<F>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class F>
VGPU_LANE_INLINE Vec3<F> cross(const Vec3<F>& a, const Vec3<F>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class F>
VGPU_LANE_INLINE Vec3<F> normalize(const Vec3<F>& a) {
  return a * rsqrt(dot(a, a));
}
template <class M, class F>
VGPU_LANE_INLINE Vec3<F> select(const M& m, const Vec3<F>& a, const Vec3<F>& b) {
  return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)};
}
template <class M, class F>
VGPU_LANE_INLINE Vec4<F> select(const M& m, const Vec4<F>& a, const Vec4<F>& b) {
  return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z), select(m, a.w, b.w)};
}

#undef VGPU_LANE_INLINE

}  // namespace vgpu
