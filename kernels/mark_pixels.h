// marcarPixeles (an extension, --aa adaptive): a pixel still a candidate gets more samples where
// a 4-neighbour hit another surface (its key differs: another material, or a miss) or the
// colour estimate bends there: its second difference along x or y (left + right - 2 own, above
// + below - 2 own) exceeds the threshold in some channel. A step between two pixels bends at
// both (by the step's size); a shade or reflection that changes evenly does not, though its
// neighbours differ, so its pixels keep their one ray (their centre ray is their mean).
#pragma once

#include "kernels/common.h"

namespace kernels {

struct MarkPixels {
  static constexpr const char* name = "mark pixels";
  static constexpr const char* paper_name = "marcarPixeles (extension)";
  static constexpr int outputs = 1;  // -> marks
  enum Unit { kMarks, kColour };
  static constexpr std::array<const char*, 2> units{"marks", "colour_estimate"};

  float threshold = 0.1f;  // colour units (linear, 1 = white)

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> own = f.fetch_own(kMarks);
    const Vec4<F> c = f.fetch_own(kColour);
    // The neighbours left, right, above, below (the texture units clamp at the image's edge):
    // their surface keys, and the colour's second difference along each axis.
    auto key = [&](float dx, float dy) { return f.fetch(kMarks, f.x + F(dx), f.y + F(dy)).y; };
    auto colour = [&](float dx, float dy) { return f.fetch(kColour, f.x + F(dx), f.y + F(dy)); };
    auto bends = [&](const Vec4<F>& a, const Vec4<F>& b) {
      const F two(2.0f);
      const F d = max(max(abs(a.x + b.x - two * c.x), abs(a.y + b.y - two * c.y)),
                      abs(a.z + b.z - two * c.z));
      return d > F(threshold);
    };
    const auto edge = (key(-1, 0) != own.y) || (key(1, 0) != own.y) || (key(0, -1) != own.y) ||
                      (key(0, 1) != own.y) || bends(colour(-1, 0), colour(1, 0)) ||
                      bends(colour(0, -1), colour(0, 1));
    const auto marked = (own.x > F(0.0f)) && edge;
    f.out(0) = {select(marked, F(1.0f), F(0.0f)), own.y, F(0.0f), F(0.0f)};
  }
};

// pixelesMarcados: counts the marked pixels (the unmarked are discarded, so an occlusion query
// counts the rest).
struct MarkedPixels {
  static constexpr const char* name = "marked pixels";
  static constexpr const char* paper_name = "pixelesMarcados (extension)";
  static constexpr int outputs = 1;  // a dummy target: the count is what matters
  static constexpr bool idle_discards = true;
  enum Unit { kMarks };
  static constexpr std::array<const char*, 1> units{"marks"};

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> m = f.fetch_own(kMarks);
    f.discard(m.x <= F(0.0f));
    f.out(0) = {F(1.0f), F(0.0f), F(0.0f), F(0.0f)};
  }
};

}  // namespace kernels
