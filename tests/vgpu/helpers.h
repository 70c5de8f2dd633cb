// Helpers shared by the vgpu tests: deterministic texture contents, bitwise comparisons and a
// kernel that reads one texel at coordinates taken from another texture, and one that loops.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "vgpu/vgpu.h"

namespace vgpu_test {

// splitmix64: a fixed sequence, so every run and every machine sees the same texels.
inline uint64_t mix(uint64_t& state) {
  uint64_t z = (state += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// Values in [-1, 1); with specials, about one texel channel in 16 is NaN, +-inf, +-0, 1e30 or
// a binary32 subnormal instead, to reach the NaN and signed-zero corners of every operation.
inline void fill_pattern(vgpu::Texture& t, uint64_t seed, bool specials = true) {
  const float inf = std::numeric_limits<float>::infinity();
  const float special[] = {
      std::numeric_limits<float>::quiet_NaN(), inf, -inf, 0.0f, -0.0f, 1e30f, -1e30f, 1e-40f};
  uint64_t s = seed;
  for (int y = 0; y < t.height(); ++y)
    for (int x = 0; x < t.width(); ++x)
      for (int c = 0; c < t.channels(); ++c) {
        const uint64_t r = mix(s);
        float v = float(int64_t(r >> 40) - (int64_t(1) << 23)) / float(1 << 23);
        if (specials && (r & 15) == 0) v = special[(r >> 4) % 8];
        t.set(x, y, c, v);
      }
}

// Same shape and the same bits in every channel of every texel (NaN payloads included).
inline bool same_bits(const vgpu::Texture& a, const vgpu::Texture& b) {
  return a.width() == b.width() && a.height() == b.height() && a.channels() == b.channels() &&
         std::memcmp(a.data().data(), b.data().data(), a.data().size_bytes()) == 0;
}

inline bool same_bits(const vgpu::Stencil& a, const vgpu::Stencil& b) {
  if (a.width() != b.width() || a.height() != b.height()) return false;
  for (int y = 0; y < a.height(); ++y)
    if (std::memcmp(a.row(y), b.row(y), size_t(a.width())) != 0) return false;
  return true;
}

// out(0) = texRECT(unit 0, unit 1's texel .xy): samples any coordinates in one pass.
struct Lookup {
  static constexpr const char* name = "lookup";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  template <class L>
  void operator()(vgpu::Fragments<L>& f) const {
    const auto uv = f.fetch_own(1);
    f.out(0) = f.fetch(0, uv.x, uv.y);
  }
};

// out(0) = unit 0's own texel: a copy, so the store's rounding is the only change.
struct Copy {
  static constexpr const char* name = "copy";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  template <class L>
  void operator()(vgpu::Fragments<L>& f) const {
    f.out(0) = f.fetch_own(0);
  }
};

// Counts up to the texel's x: out = (iterations run, x, 0, 0). A fragment with x <= 0
// never enters the loop.
struct CountTo {
  static constexpr const char* name = "count to";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  int budget = 16;
  template <class L>
  void operator()(vgpu::Fragments<L>& f) const {
    using F = typename L::F;
    using M = typename L::M;
    const F n = f.fetch_own(0).x;
    F c = F(0.0f);
    f.loop(budget, n > F(0.0f), [&](const M& active) {
      c = vgpu::select(active, c + F(1.0f), c);
      return c < n;
    });
    f.out(0) = {c, n, F(0.0f), F(0.0f)};
  }
};

}  // namespace vgpu_test
