// Adaptive undersampling (an extension, --aa undersample:K, after Akimoto, Mase & Suenaga 1991,
// the paper's reference 7): trace every K-th pixel in x and y (the lattice, with the last row
// and column), then only the pixels between lattice pixels whose surface keys or colours
// disagree; fill the rest from the four lattice pixels around them.
#pragma once

#include "kernels/common.h"

namespace kernels {

// The lattice cell around a pixel: its corners' coordinates (pixels) and whether the pixel is
// one of them. xi, yi are the pixel's integer coordinates.
struct LatticeUniforms {
  float k = 2;                  // lattice step, pixels
  float width = 1, height = 1;  // image size, pixels
};

template <class F>
struct LatticeCell {
  F x0, x1, y0, y1;
};

template <class F>
inline LatticeCell<F> lattice_cell(const F& xi, const F& yi, const LatticeUniforms& u) {
  const F x0 = floor(xi / F(u.k)) * F(u.k), y0 = floor(yi / F(u.k)) * F(u.k);
  return {x0, min(x0 + F(u.k), F(u.width - 1.0f)), y0, min(y0 + F(u.k), F(u.height - 1.0f))};
}

// marcarReticula: x = 1 on lattice pixels, 0 elsewhere.
struct MarkLattice {
  static constexpr const char* name = "mark lattice";
  static constexpr const char* paper_name = "marcarReticula (extension)";
  static constexpr int outputs = 1;  // -> marks

  LatticeUniforms lattice;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const F xi = f.x - F(0.5f), yi = f.y - F(0.5f);
    const LatticeCell<F> c = lattice_cell(xi, yi, lattice);
    const auto on_x = (xi == c.x0) || (xi == F(lattice.width - 1.0f));
    const auto on_y = (yi == c.y0) || (yi == F(lattice.height - 1.0f));
    f.out(0) = {select(on_x && on_y, F(1.0f), F(0.0f)), F(0.0f), F(0.0f), F(0.0f)};
  }
};

// marcarHuecos: x = 1 on a pixel between lattice pixels whose surface keys (guardarImpactos'
// y) are not all the same, or whose colours differ by more than the threshold in some channel:
// it is traced; 0 elsewhere (lattice pixels were traced already).
struct MarkGaps {
  static constexpr const char* name = "mark gaps";
  static constexpr const char* paper_name = "marcarHuecos (extension)";
  static constexpr int outputs = 1;  // -> marks
  enum Unit { kKeys, kSum };
  static constexpr std::array<const char*, 2> units{"surface_keys", "sample_sum"};

  LatticeUniforms lattice;
  float threshold = 0.1f;  // colour units (linear, 1 = white)

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const F xi = f.x - F(0.5f), yi = f.y - F(0.5f);
    const LatticeCell<F> c = lattice_cell(xi, yi, lattice);
    const F k00 = f.fetch(kKeys, c.x0 + F(0.5f), c.y0 + F(0.5f)).y;
    const F k10 = f.fetch(kKeys, c.x1 + F(0.5f), c.y0 + F(0.5f)).y;
    const F k01 = f.fetch(kKeys, c.x0 + F(0.5f), c.y1 + F(0.5f)).y;
    const F k11 = f.fetch(kKeys, c.x1 + F(0.5f), c.y1 + F(0.5f)).y;
    const auto on_x = (xi == c.x0) || (xi == F(lattice.width - 1.0f));
    const auto on_y = (yi == c.y0) || (yi == F(lattice.height - 1.0f));
    // The lattice pixels' colours (one sample each in the sum).
    const Vec4<F> c00 = f.fetch(kSum, c.x0 + F(0.5f), c.y0 + F(0.5f));
    const Vec4<F> c10 = f.fetch(kSum, c.x1 + F(0.5f), c.y0 + F(0.5f));
    const Vec4<F> c01 = f.fetch(kSum, c.x0 + F(0.5f), c.y1 + F(0.5f));
    const Vec4<F> c11 = f.fetch(kSum, c.x1 + F(0.5f), c.y1 + F(0.5f));
    auto spread = [](const F& a, const F& b, const F& c, const F& d) {
      return max(max(a, b), max(c, d)) - min(min(a, b), min(c, d));
    };
    const F colour =
        max(max(spread(c00.x, c10.x, c01.x, c11.x), spread(c00.y, c10.y, c01.y, c11.y)),
            spread(c00.z, c10.z, c01.z, c11.z));
    const auto disagree = (k10 != k00) || (k01 != k00) || (k11 != k00) || (colour > F(threshold));
    const auto gap = !(on_x && on_y) && disagree;
    f.out(0) = {select(gap, F(1.0f), F(0.0f)), F(0.0f), F(0.0f), F(0.0f)};
  }
};

// rellenarHuecos: traced pixels (sample count a > 0) take their colour; the others the
// bilinear blend of the four lattice pixels around them.
struct FillGaps {
  static constexpr const char* name = "fill gaps";
  static constexpr const char* paper_name = "rellenarHuecos (extension)";
  static constexpr int outputs = 1;  // -> result
  enum Unit { kSum };
  static constexpr std::array<const char*, 1> units{"sample_sum"};

  LatticeUniforms lattice;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const F xi = f.x - F(0.5f), yi = f.y - F(0.5f);
    const LatticeCell<F> c = lattice_cell(xi, yi, lattice);
    const Vec4<F> own = f.fetch_own(kSum);
    const Vec4<F> s00 = f.fetch(kSum, c.x0 + F(0.5f), c.y0 + F(0.5f));
    const Vec4<F> s10 = f.fetch(kSum, c.x1 + F(0.5f), c.y0 + F(0.5f));
    const Vec4<F> s01 = f.fetch(kSum, c.x0 + F(0.5f), c.y1 + F(0.5f));
    const Vec4<F> s11 = f.fetch(kSum, c.x1 + F(0.5f), c.y1 + F(0.5f));
    const F tx = select(c.x1 > c.x0, (xi - c.x0) / max(c.x1 - c.x0, F(1.0f)), F(0.0f));
    const F ty = select(c.y1 > c.y0, (yi - c.y0) / max(c.y1 - c.y0, F(1.0f)), F(0.0f));
    auto mean = [](const Vec4<F>& s) {
      const F n = max(s.w, F(1.0f));
      return Vec3<F>{s.x / n, s.y / n, s.z / n};
    };
    const Vec3<F> top = mean(s00) + (mean(s10) - mean(s00)) * tx;
    const Vec3<F> bottom = mean(s01) + (mean(s11) - mean(s01)) * tx;
    const Vec3<F> blend = top + (bottom - top) * ty;
    const Vec3<F> traced = mean(own);
    const auto was_traced = own.w > F(0.0f);
    f.out(0) = {select(was_traced, traced.x, blend.x), select(was_traced, traced.y, blend.y),
                select(was_traced, traced.z, blend.z), F(1.0f)};
  }
};

}  // namespace kernels
