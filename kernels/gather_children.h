// reunirHijos (an extension: glass, issue 25): the colour returns to the pixel without scatter.
// After the deepest level is shaded, one pass per level, deepest first: each ray of level k adds
// the (already gathered) colours of its children in level k + 1, found at slots
// S[i] - count[i] and the next one (S the inclusive prefix sums of the spawn counts), to its
// own shaded contribution (weight x local colour). Level 0's pass writes the pixels' colours.
#pragma once

#include "kernels/glass.h"

namespace kernels {

struct GatherChildren {
  static constexpr const char* name = "children gather";
  static constexpr const char* paper_name = "reunirHijos (extension)";
  static constexpr int outputs = 1;  // -> the level's gathered colour (level 0: result)
  enum Unit { kColour, kScan, kSplit, kChildren };
  static constexpr std::array<const char*, 4> units{"colour", "scan", "split", "children"};

  float width = 1;  // width of the stream textures, texels

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> own = f.fetch_own(kColour);
    const F n = f.fetch_own(kSplit).z;
    const F first = f.fetch_own(kScan).x - n;
    const Vec3<F> c1 = fetch_id(f, kChildren, max(first, F(0.0f)), width).xyz();
    const Vec3<F> c2 = fetch_id(f, kChildren, max(first + F(1.0f), F(0.0f)), width).xyz();
    const Vec3<F> none = splat<F>(glm::vec3(0.0f));
    const Vec3<F> add = select(n >= F(0.5f), c1, none) + select(n >= F(1.5f), c2, none);
    f.out(0) = {own.x + add.x, own.y + add.y, own.z + add.z, own.w};
  }
};

}  // namespace kernels
