// The texture unit's filtering, as a 2004 part did it for 8-bit colour textures: nearest,
// bilinear (the 2x2 texels around the sample, weighted by its position) and mipmapped trilinear
// (bilinear in the two levels around the level of detail, blended). Every texel it reads is one
// Fragments::fetch, so a filter's cost is its fetches: nearest 1, bilinear 4, trilinear 8 texels
// per sample, counted by the counting run like any other fetch (kFilterTexels).
//
// A mip chain lies in one texture as rectangles (MipLevel, texels), so that several textures
// share one unit as an atlas (NVIDIA's "Improve Batching Using Texture Atlases", 2004): the
// wrap modes are applied to texel indices inside a level's rectangle, never across it, and a
// filter never reads a neighbouring rectangle. Coordinates (s, t) are normalised, glTF's: (0, 0)
// the top-left corner of the image, t down, texel (i, j) with row j from the top.
#pragma once

#include "vgpu/fragment.h"

namespace vgpu {

enum class Filter { nearest = 0, bilinear = 1, trilinear = 2 };
// Texels read per sample (the fetches a filter costs).
inline constexpr int kFilterTexels[] = {1, 4, 8};

// Wrap modes, as the floats a texture table holds (the sampler's state of glTF).
enum class Wrap { repeat = 0, clamp_to_edge = 1, mirrored_repeat = 2 };

// One level of a mip chain: its rectangle in the texture, texels (origin x, y; size w, h).
template <class F>
struct MipLevel {
  F x, y, w, h;
};

// Texel index i (an integer value, any sign) of a level n texels wide, wrapped into [0, n) by
// `mode` (a Wrap as a float). Integer arithmetic in floats, exact below 2^24: the quotient's
// floor may be one off where a device divides inexactly (GLSL allows it), the corrections put
// it back.
template <class F>
inline F wrap_texel(const F& i, const F& n, const F& mode) {
  F rep = i - n * floor(i / n);
  rep = select(rep >= n, rep - n, rep);
  rep = select(rep < F(0.0f), rep + n, rep);
  const F clamped = min(max(i, F(0.0f)), n - F(1.0f));
  const F two = n + n;
  F m = i - two * floor(i / two);
  m = select(m >= two, m - two, m);
  m = select(m < F(0.0f), m + two, m);
  const F mirrored = select(m >= n, two - F(1.0f) - m, m);
  return select(mode == F(float(Wrap::repeat)), rep,
                select(mode == F(float(Wrap::clamp_to_edge)), clamped, mirrored));
}

// The texel (i, j) of a level (indices already wrapped): one fetch at its centre.
template <class L>
inline Vec4<typename L::F> level_texel(const Fragments<L>& f, int unit,
                                       const MipLevel<typename L::F>& lv, const typename L::F& i,
                                       const typename L::F& j) {
  using F = typename L::F;
  return f.fetch(unit, lv.x + i + F(0.5f), lv.y + j + F(0.5f));
}

template <class F>
inline Vec4<F> lerp(const Vec4<F>& a, const Vec4<F>& b, const F& t) {
  return {a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t, a.z + (b.z - a.z) * t,
          a.w + (b.w - a.w) * t};
}

// GL_NEAREST in one level: the texel whose square holds (s, t). One fetch.
template <class L>
inline Vec4<typename L::F> sample_nearest(const Fragments<L>& f, int unit,
                                          const MipLevel<typename L::F>& lv, const typename L::F& s,
                                          const typename L::F& t, const typename L::F& wrap_s,
                                          const typename L::F& wrap_t) {
  const auto i = wrap_texel(floor(s * lv.w), lv.w, wrap_s);
  const auto j = wrap_texel(floor(t * lv.h), lv.h, wrap_t);
  return level_texel(f, unit, lv, i, j);
}

// GL_LINEAR in one level: the four texels whose centres surround (s, t), weighted by the
// sample's position between them. Four fetches.
template <class L>
inline Vec4<typename L::F> sample_bilinear(const Fragments<L>& f, int unit,
                                           const MipLevel<typename L::F>& lv,
                                           const typename L::F& s, const typename L::F& t,
                                           const typename L::F& wrap_s,
                                           const typename L::F& wrap_t) {
  using F = typename L::F;
  const F x = s * lv.w - F(0.5f), y = t * lv.h - F(0.5f);  // texel space, centres at integers
  const F x0 = floor(x), y0 = floor(y);
  const F fx = x - x0, fy = y - y0;
  const F i0 = wrap_texel(x0, lv.w, wrap_s), i1 = wrap_texel(x0 + F(1.0f), lv.w, wrap_s);
  const F j0 = wrap_texel(y0, lv.h, wrap_t), j1 = wrap_texel(y0 + F(1.0f), lv.h, wrap_t);
  const Vec4<F> top = lerp(level_texel(f, unit, lv, i0, j0), level_texel(f, unit, lv, i1, j0), fx);
  const Vec4<F> bottom =
      lerp(level_texel(f, unit, lv, i0, j1), level_texel(f, unit, lv, i1, j1), fx);
  return lerp(top, bottom, fy);
}

// GL_LINEAR_MIPMAP_LINEAR: bilinear in levels `fine` and `coarse` (the next one), blended by
// `frac` in [0, 1]. Eight fetches.
template <class L>
inline Vec4<typename L::F> sample_trilinear(const Fragments<L>& f, int unit,
                                            const MipLevel<typename L::F>& fine,
                                            const MipLevel<typename L::F>& coarse,
                                            const typename L::F& frac, const typename L::F& s,
                                            const typename L::F& t, const typename L::F& wrap_s,
                                            const typename L::F& wrap_t) {
  return lerp(sample_bilinear(f, unit, fine, s, t, wrap_s, wrap_t),
              sample_bilinear(f, unit, coarse, s, t, wrap_s, wrap_t), frac);
}

inline constexpr int kMaxMipLevels = 16;  // a 32768-texel side has 16 levels

// The level of detail of a footprint `rho` level-0 texels wide (the larger of the sample's
// texel-space derivatives): lambda = log2(rho), clamped to [0, levels - 1], as the level below
// (`level`, an integer value) and the fraction towards the next (`frac`). log2's fraction is
// taken piecewise linear, rho / 2^level - 1 (within 0.086 of log2 between powers of two), so
// every device computes the same levels and weights from the same rho: comparisons and exact
// divisions by powers of two, no LG2 whose precision differs between drivers.
template <class F>
inline void level_of_detail(const F& rho, const F& levels, F& level, F& frac) {
  level = F(0.0f);
  F scale = F(1.0f);
  for (int k = 1; k < kMaxMipLevels; ++k) {
    const auto above = rho >= F(float(1 << k)) && F(float(k)) < levels;
    level = select(above, F(float(k)), level);
    scale = select(above, F(float(1 << k)), scale);
  }
  frac = rho / scale - F(1.0f);
  frac = select(frac > F(0.0f), frac, F(0.0f));  // NaN (a degenerate footprint) -> level 0
  frac = select(frac < F(1.0f), frac, F(1.0f));
  frac = select(level < levels - F(1.0f), frac, F(0.0f));  // the last level blends with nothing
}

}  // namespace vgpu
