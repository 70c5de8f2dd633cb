// guardarImpactos (an extension, --aa adaptive): after the primary trace of the first frame,
// each pixel's surface key, the material of the triangle its primary ray hit (-1: none), into
// the mark texture, with every pixel a candidate for more samples.
#pragma once

#include "kernels/common.h"

namespace kernels {

struct KeepHits {
  static constexpr const char* name = "keep hits";
  static constexpr const char* paper_name = "guardarImpactos (extension)";
  static constexpr int outputs = 1;  // -> marks
  enum Unit { kIntersection, kMaterials };
  static constexpr std::array<const char*, 2> units{"intersection", "triangle_materials"};

  SceneUniforms scene;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> hit = f.fetch_own(kIntersection);
    const auto hits = hit.w >= F(0.0f);
    const F material = fetch_id(f, kMaterials, max(hit.w, F(0.0f)), scene.width).x;
    f.out(0) = {F(1.0f), select(hits, material, F(-1.0f)), F(0.0f), F(0.0f)};
  }
};

}  // namespace kernels
