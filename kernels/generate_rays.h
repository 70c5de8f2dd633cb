// generadorRayos: once per frame, one primary ray per pixel from the camera (paper Sec. 2.1);
// and its jittered variant for supersampling.
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
    // f.x, f.y are already pixel centres (x + 0.5, y + 0.5).
    f.out(0) = ray_through<L>(f.x, f.y);
  }

  // The ray through image point (px, py), in pixels from the top-left corner of the image.
  template <class L>
  Vec4<typename L::F> ray_through(const typename L::F& px, const typename L::F& py) const {
    using F = typename L::F;
    const F sx = (F(2.0f) * px / F(width) - F(1.0f)) * F(tan_half_fov * aspect);
    const F sy = (F(1.0f) - F(2.0f) * py / F(height)) * F(tan_half_fov);
    const Vec3<F> d = normalize(splat<F>(forward) + splat<F>(right) * sx + splat<F>(up) * sy);
    return {d.x, d.y, d.z, F(kFar)};
  }
};

// generadorRayosMuestra (an extension, --spp N): one ray per pixel through the sample position
// (jitter_x, jitter_y) within the pixel instead of its centre, the same for every pixel of a
// sample frame (the accumulation-buffer way: each frame moves the whole image by a sub-pixel
// offset, host/trace/sampling.h picks them).
struct GenerateSampleRays : GenerateRays {
  static constexpr const char* name = "generate sample rays";
  static constexpr const char* paper_name = "generadorRayosMuestra (extension)";

  enum Unit { kMarks };
  static constexpr std::array<const char*, 1> units{"marks"};

  float jitter_x = 0.5f, jitter_y = 0.5f;  // in [0, 1): 0 the pixel's left / top edge
  // --aa adaptive: only pixels marked for more samples (marks x > 0) get a ray; the others
  // get none (tmax -1), so their walk ends at once and masks skip them.
  bool gated = false;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    Vec4<F> ray = ray_through<L>(f.x + F(jitter_x - 0.5f), f.y + F(jitter_y - 0.5f));
    if (gated) ray.w = select(f.fetch_own(kMarks).x > F(0.0f), ray.w, F(kNone));
    f.out(0) = ray;
  }
};

}  // namespace kernels
