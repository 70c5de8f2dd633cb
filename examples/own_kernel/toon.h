// A kernel of this project's own: a toon ramp. Each channel of the input texel is quantized to
// `levels` bands (floor(v * levels) / levels), and texels darker than `ink` (their first
// channel) are drawn as ink (0) in every channel but alpha, which passes through. Written as the
// project's kernels are: a functor over lanes, with uniforms as data members.
#pragma once

#include <array>

#include "vgpu/program.h"

struct Toon {
  static constexpr const char* name = "toon ramp";
  static constexpr const char* paper_name = "toon (own kernel)";
  static constexpr int outputs = 1;
  static constexpr std::array<const char*, 1> units{"colour"};

  float levels = 4;  // bands per channel
  float ink = 0.1f;  // first channels below this are ink

  template <class L>
  void operator()(vgpu::Fragments<L>& f) const {
    using F = typename L::F;
    using vgpu::floor;  // the lane operations, for every lane family
    using vgpu::select;
    const vgpu::Vec4<F> c = f.fetch_own(0);
    const auto dark = c.x < F(ink);
    vgpu::Vec4<F> o;
    o.x = select(dark, F(0.0f), floor(c.x * F(levels)) / F(levels));
    o.y = select(dark, F(0.0f), floor(c.y * F(levels)) / F(levels));
    o.z = select(dark, F(0.0f), floor(c.z * F(levels)) / F(levels));
    o.w = c.w;
    f.out(0) = o;
  }
};
