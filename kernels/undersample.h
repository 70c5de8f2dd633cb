// Adaptive undersampling (an extension, --aa undersample:K, after Akimoto, Mase & Suenaga 1991,
// the paper's reference 7): trace every K-th pixel in x and y (the lattice, with the last row
// and column), then only the pixels between lattice pixels whose surface keys or colours
// disagree; fill the rest from the four lattice pixels around them.
#pragma once

#include "kernels/common.h"

namespace kernels {

// The lattice: its step and the image size.
struct LatticeUniforms {
  float k = 2;                  // lattice step, pixels
  float width = 1, height = 1;  // image size, pixels
};

// The lattice cell around a fragment's pixel: its corners (pixel coordinates) and whether the
// pixel is one of them.
template <class L>
struct LatticeCell {
  using F = typename L::F;
  F xi, yi;              // the pixel
  F x0, x1, y0, y1;      // its cell's corners
  typename L::M corner;  // the pixel is a lattice pixel (traced first)

  LatticeCell(const Fragments<L>& f, const LatticeUniforms& u)
      : xi(f.x - F(0.5f)),
        yi(f.y - F(0.5f)),
        x0(floor(xi / F(u.k)) * F(u.k)),
        x1(min(x0 + F(u.k), F(u.width - 1.0f))),
        y0(floor(yi / F(u.k)) * F(u.k)),
        y1(min(y0 + F(u.k), F(u.height - 1.0f))),
        corner(((xi == x0) || (xi == F(u.width - 1.0f))) &&
               ((yi == y0) || (yi == F(u.height - 1.0f)))) {}

  // The four corners' texels of unit `unit`: (x0, y0), (x1, y0), (x0, y1), (x1, y1).
  std::array<Vec4<F>, 4> fetch(const Fragments<L>& f, int unit) const {
    return {f.fetch(unit, x0 + F(0.5f), y0 + F(0.5f)), f.fetch(unit, x1 + F(0.5f), y0 + F(0.5f)),
            f.fetch(unit, x0 + F(0.5f), y1 + F(0.5f)), f.fetch(unit, x1 + F(0.5f), y1 + F(0.5f))};
  }
};

// marcarReticula: x = 1 on lattice pixels, 0 elsewhere.
struct MarkLattice {
  static constexpr const char* name = "mark lattice";
  static constexpr const char* paper_name = "marcarReticula (extension)";
  static constexpr int outputs = 1;  // -> marks

  LatticeUniforms lattice;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const LatticeCell<L> c(f, lattice);
    f.out(0) = {select(c.corner, F(1.0f), F(0.0f)), F(0.0f), F(0.0f), F(0.0f)};
  }
};

// marcarHuecos: x = 1 on a pixel between lattice pixels whose surface keys (guardarImpactos'
// y) are not all the same, or whose colours differ by more than the threshold in some channel:
// it is traced; 0 elsewhere (lattice pixels were traced already). Only the lattice pixels its
// fill would blend count: a pixel on a lattice row (or column) lies between the two lattice
// pixels of that row, and their cell's other corners have weight 0 in its blend.
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
    const LatticeCell<L> c(f, lattice);
    std::array<Vec4<F>, 4> k = c.fetch(f, kKeys);
    // The lattice pixels' colours (one sample each in the sum).
    std::array<Vec4<F>, 4> s = c.fetch(f, kSum);
    // Corners outside the blend (x1 on the cell's left column, y1 on its top row) stand in as
    // corner (x0, y0), which then agrees with itself.
    const auto use_x1 = c.xi != c.x0, use_y1 = c.yi != c.y0;
    k[1] = select(use_x1, k[1], k[0]);
    k[2] = select(use_y1, k[2], k[0]);
    k[3] = select(use_x1 && use_y1, k[3], k[0]);
    s[1] = select(use_x1, s[1], s[0]);
    s[2] = select(use_y1, s[2], s[0]);
    s[3] = select(use_x1 && use_y1, s[3], s[0]);
    auto spread = [](const F& a, const F& b, const F& c, const F& d) {
      return max(max(a, b), max(c, d)) - min(min(a, b), min(c, d));
    };
    const F colour =
        max(max(spread(s[0].x, s[1].x, s[2].x, s[3].x), spread(s[0].y, s[1].y, s[2].y, s[3].y)),
            spread(s[0].z, s[1].z, s[2].z, s[3].z));
    const auto disagree =
        (k[1].y != k[0].y) || (k[2].y != k[0].y) || (k[3].y != k[0].y) || (colour > F(threshold));
    const auto gap = !c.corner && disagree;
    f.out(0) = {select(gap, F(1.0f), F(0.0f)), F(0.0f), F(0.0f), F(0.0f)};
  }
};

// The blend's error where the colour curves: between lattice pixels a and b, K apart, a
// straight blend of a colour whose second derivative is c misses it by t(1 - t) K^2 c / 2 at the
// fraction t from a. The lattice measures K^2 c as the second difference at a (the lattice
// pixels a - K, a, b) and at b (a, b, b + K); the fill subtracts t(1 - t) / 2 of the smaller of
// the two (minmod: 0 where they differ in sign), so that an edge beyond the cell, whose second
// difference is large at one end only, changes nothing, where a smooth shade gets the
// Catmull-Rom blend's midpoint back (the mean of the two ends' differences, which on a smooth
// shade differ little).
template <class F>
F minmod(const F& a, const F& b) {
  return select(a * b > F(0.0f), select(abs(a) < abs(b), a, b), F(0.0f));
}
// The correction's second difference: minmod of the two ends', and 0 unless both are within
// the threshold (a shade that bends gently; a stripe two lattice steps wide bends as much at
// both ends as a curve, and a step has a large second difference: those keep the straight
// blend, which marcarHuecos' spread test already judged good enough).
template <class F>
F gentle_bend(const F& a, const F& b, const F& limit) {
  return select(max(abs(a), abs(b)) <= limit, minmod(a, b), F(0.0f));
}

// rellenarHuecos: traced pixels (sample count a > 0) take their colour; the others the
// bilinear blend of the four lattice pixels around them, less the curvature correction above
// along x (on the cell's two rows) and along y (on its two columns, blended by the pixel's x):
// 13 fetches, where a lattice pixel one step beyond the cell is out of the image or the cell is
// narrower than K (the last column or row), no correction along that axis.
struct FillGaps {
  static constexpr const char* name = "fill gaps";
  static constexpr const char* paper_name = "rellenarHuecos (extension)";
  static constexpr int outputs = 1;  // -> result
  enum Unit { kSum };
  static constexpr std::array<const char*, 1> units{"sample_sum"};

  LatticeUniforms lattice;
  float threshold = 0.1f;  // --aa-threshold: the largest second difference corrected

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const LatticeCell<L> c(f, lattice);
    const Vec4<F> own = f.fetch_own(kSum);
    const std::array<Vec4<F>, 4> s = c.fetch(f, kSum);
    const F tx = select(c.x1 > c.x0, (c.xi - c.x0) / max(c.x1 - c.x0, F(1.0f)), F(0.0f));
    const F ty = select(c.y1 > c.y0, (c.yi - c.y0) / max(c.y1 - c.y0, F(1.0f)), F(0.0f));
    auto mean = [](const Vec4<F>& v) {
      const F n = max(v.w, F(1.0f));
      return Vec3<F>{v.x / n, v.y / n, v.z / n};
    };
    const Vec3<F> m00 = mean(s[0]), m10 = mean(s[1]), m01 = mean(s[2]), m11 = mean(s[3]);
    // The lattice pixels one step beyond the cell (coordinates clamped into the image; where
    // one is outside, `along_x` or `along_y` is false and its colour is not used).
    const F k(lattice.k);
    const F xm = max(c.x0 - k, F(0.0f)), xp = min(c.x1 + k, F(lattice.width - 1.0f));
    const F ym = max(c.y0 - k, F(0.0f)), yp = min(c.y1 + k, F(lattice.height - 1.0f));
    const auto along_x =
        (c.x0 - k >= F(0.0f)) && (c.x1 + k <= F(lattice.width - 1.0f)) && (c.x1 - c.x0 == k);
    const auto along_y =
        (c.y0 - k >= F(0.0f)) && (c.y1 + k <= F(lattice.height - 1.0f)) && (c.y1 - c.y0 == k);
    auto at = [&](const F& px, const F& py) {
      return mean(f.fetch(kSum, px + F(0.5f), py + F(0.5f)));
    };
    const Vec3<F> w0 = at(xm, c.y0), e0 = at(xp, c.y0), w1 = at(xm, c.y1), e1 = at(xp, c.y1);
    const Vec3<F> n0 = at(c.x0, ym), s0 = at(c.x0, yp), n1 = at(c.x1, ym), s1 = at(c.x1, yp);
    const F two(2.0f);
    // The correction, per channel, between lattice pixels a and b with outer neighbours o (before
    // a) and p (after b).
    auto bend = [&](const Vec3<F>& o, const Vec3<F>& a, const Vec3<F>& b, const Vec3<F>& p,
                    const F& t) {
      const F w = t * (F(1.0f) - t) * F(0.5f);
      const F lim(threshold * 0.5f);
      return Vec3<F>{w * gentle_bend(o.x - two * a.x + b.x, a.x - two * b.x + p.x, lim),
                     w * gentle_bend(o.y - two * a.y + b.y, a.y - two * b.y + p.y, lim),
                     w * gentle_bend(o.z - two * a.z + b.z, a.z - two * b.z + p.z, lim)};
    };
    const Vec3<F> zero{F(0.0f), F(0.0f), F(0.0f)};
    auto only = [](const auto& m, const Vec3<F>& v, const Vec3<F>& otherwise) {
      return Vec3<F>{select(m, v.x, otherwise.x), select(m, v.y, otherwise.y),
                     select(m, v.z, otherwise.z)};
    };
    const Vec3<F> top = m00 + (m10 - m00) * tx - only(along_x, bend(w0, m00, m10, e0, tx), zero);
    const Vec3<F> bottom = m01 + (m11 - m01) * tx - only(along_x, bend(w1, m01, m11, e1, tx), zero);
    const Vec3<F> left = bend(n0, m00, m01, s0, ty), right = bend(n1, m10, m11, s1, ty);
    const Vec3<F> down = only(along_y, left + (right - left) * tx, zero);
    const Vec3<F> blend = top + (bottom - top) * ty - down;
    const Vec3<F> traced = mean(own);
    const auto was_traced = own.w > F(0.0f);
    f.out(0) = {select(was_traced, traced.x, blend.x), select(was_traced, traced.y, blend.y),
                select(was_traced, traced.z, blend.z), F(1.0f)};
  }
};

}  // namespace kernels
