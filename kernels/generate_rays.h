// generadorRayos: once per frame, one primary ray per pixel from the camera (paper Sec. 2.1).
// Generalises the paper's fixed camera (rays from z = 0 towards (0, 0, -1)) to a real camera:
// pixel (x, y), y = 0 the top row, ray through the pixel centre (the CLI's camera contract).
#pragma once

#include "kernels/common.h"

namespace kernels {

struct GenerateRays {
  static constexpr const char* name = "generate rays";
  static constexpr const char* paper_name = "generadorRayos";
  static constexpr int outputs = 1;  // -> rays

  glm::vec3 forward{0, 0, -1}, right{1, 0, 0}, up{0, 1, 0};  // camera basis, world space
  float tan_half_fov = 0.5f, aspect = 1.0f;
  float width = 1, height = 1;  // image size, pixels

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    // f.x, f.y are already pixel centres (x + 0.5, y + 0.5).
    const F sx = (F(2.0f) * f.x / F(width) - F(1.0f)) * F(tan_half_fov * aspect);
    const F sy = (F(1.0f) - F(2.0f) * f.y / F(height)) * F(tan_half_fov);
    const Vec3<F> d = normalize(splat<F>(forward) + splat<F>(right) * sx + splat<F>(up) * sy);
    f.out(0) = {d.x, d.y, d.z, F(kFar)};
  }
};

}  // namespace kernels
