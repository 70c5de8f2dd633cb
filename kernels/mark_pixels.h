// marcarPixeles (an extension, --aa adaptive): a pixel still a candidate gets more samples where
// a 4-neighbour hit another surface (its key differs: another material, or a miss) or its
// colour estimate differs from a neighbour's by more than the threshold in some channel.
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
    // The neighbours left, right, above, below (the texture units clamp at the image's edge).
    auto differs = [&](float dx, float dy) {
      const F u = f.x + F(dx), v = f.y + F(dy);
      const Vec4<F> m = f.fetch(kMarks, u, v);
      const Vec4<F> n = f.fetch(kColour, u, v);
      const F diff = max(max(abs(n.x - c.x), abs(n.y - c.y)), abs(n.z - c.z));
      return (m.y != own.y) || (diff > F(threshold));
    };
    const auto edge = differs(-1, 0) || differs(1, 0) || differs(0, -1) || differs(0, 1);
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
