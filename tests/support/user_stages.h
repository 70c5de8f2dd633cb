// Kernels of one's own for the frame's stages (host/trace/user_stage.h), as a user writes them in
// C++: the project's shader and camera written against the stages' uniforms (their frames must be
// the project's bit for bit), and a toon shader and a fisheye camera that are not.
#pragma once

#include <array>

#include "kernels/generate_rays.h"
#include "kernels/shader.h"
#include "kernels/stages.h"

namespace test_support {

// kernels::Shader, its uniforms taken from the stage's: the frame's shading, bit for bit.
struct ShaderFromStage {
  static constexpr const char* name = "shader from stage";
  static constexpr const char* paper_name = "shader (user)";
  static constexpr int outputs = 1;
  static constexpr std::array<const char*, 11> units{
      "surface",   "rays",      "result",   "shadow_hits", "colors",  "vertices0",
      "vertices1", "vertices2", "normals0", "normals1",    "normals2"};
  kernels::ShaderStage stage;
  kernels::ShadingModel model = kernels::ShadingModel::phong;

  template <class L>
  void operator()(vgpu::Fragments<L>& f) const {
    kernels::Shader sh;
    sh.scene.width = stage.scene_width;
    sh.model = model;
    sh.light = stage.light;
    sh.light_color = stage.light_color;
    sh.first_light = stage.first_light != 0;
    sh.last_light = stage.last_light != 0;
    sh.shadows = stage.shadows != 0;
    sh.shadow_transmittance = stage.shadow_transmittance != 0;
    sh.ambient = stage.ambient;
    sh.background = stage.background;
    sh.specular = stage.specular;
    sh.atten_dist = stage.atten_dist;
    sh(f);
  }
};

// kernels::GenerateRays through the stage's sample point: the frame's primary rays, bit for bit
// (at the pixel centre, and each sample frame's jitter as GenerateSampleRays takes it).
struct CameraFromStage {
  static constexpr const char* name = "camera from stage";
  static constexpr const char* paper_name = "generadorRayos (user)";
  static constexpr int outputs = 1;
  kernels::CameraStage stage;

  template <class L>
  void operator()(vgpu::Fragments<L>& f) const {
    using F = typename L::F;
    kernels::GenerateRays g;
    g.forward = stage.forward, g.right = stage.right, g.up = stage.up;
    g.tan_half_fov = stage.tan_half_fov, g.aspect = stage.aspect;
    g.width = stage.width, g.height = stage.height;
    f.out(0) = g.ray_through<L>(f.x + F(stage.jitter_x - 0.5f), f.y + F(stage.jitter_y - 0.5f));
  }
};

// Toon shading: the diffuse term in three bands, no ambient band below the first, and the
// project's blend (the result's rgb plus w (1 - a) times this light's colour; the last light
// sets the reflected ray's weight w a). Reads 7 of the stage's units.
struct Toon {
  static constexpr const char* name = "toon";
  static constexpr const char* paper_name = "toon (user shader)";
  static constexpr int outputs = 1;
  static constexpr std::array<const char*, 7> units{"surface",  "rays",     "result",  "colors",
                                                    "normals0", "normals1", "normals2"};
  kernels::ShaderStage stage;
  float bands = 3;

  template <class L>
  void operator()(vgpu::Fragments<L>& f) const {
    using F = typename L::F;
    using vgpu::floor, vgpu::max, vgpu::select, vgpu::sqrt;
    const vgpu::Vec4<F> surf = f.fetch_own(0), res = f.fetch_own(2);
    const F w = res.w;
    const auto hit = surf.w >= F(0.0f);
    const vgpu::Vec4<F> mat = kernels::fetch_id(f, 3, surf.w, stage.scene_width);
    // The corners' normals, averaged (flat bands need no barycentrics).
    const vgpu::Vec3<F> n =
        vgpu::normalize(kernels::fetch_id(f, 4, surf.w, stage.scene_width).xyz() +
                        kernels::fetch_id(f, 5, surf.w, stage.scene_width).xyz() +
                        kernels::fetch_id(f, 6, surf.w, stage.scene_width).xyz());
    const vgpu::Vec3<F> d = f.fetch_own(1).xyz();
    const vgpu::Vec3<F> to = kernels::splat<F>(stage.light) - surf.xyz();
    const vgpu::Vec3<F> l = to * (F(1.0f) / sqrt(vgpu::dot(to, to)));
    // Facing the eye: flip a normal that faces away from it.
    const F s = select(vgpu::dot(n, d) > F(0.0f), F(-1.0f), F(1.0f));
    const F lambert = max(vgpu::dot(n, l) * s, F(0.0f));
    const F band = floor(lambert * F(bands) + F(0.5f)) / F(bands);
    const F first = F(stage.first_light);
    const F k = band + first * F(stage.ambient.r);
    const F share = w * (F(1.0f) - mat.w);
    const vgpu::Vec3<F> c{mat.x * k * F(stage.light_color.r) * share,
                          mat.y * k * F(stage.light_color.g) * share,
                          mat.z * k * F(stage.light_color.b) * share};
    const F last = F(stage.last_light);
    const F weight = select(hit, w * mat.w, F(0.0f)) * last + w * (F(1.0f) - last);
    f.out(0) = {res.x + select(hit, c.x, F(0.0f)), res.y + select(hit, c.y, F(0.0f)),
                res.z + select(hit, c.z, F(0.0f)), weight};
  }
};

// A stereographic fisheye: image point (sx, sy), scaled by k = tan_half_fov / 2, to direction
// (2 sx, 2 sy, 1 - r^2) / (1 + r^2) in the camera's basis (r^2 = sx^2 + sy^2): unit length with no
// trigonometry, a half angle of 2 atan(k) at the image's top edge, wider than the pinhole's.
struct Fisheye {
  static constexpr const char* name = "fisheye";
  static constexpr const char* paper_name = "generadorRayos (fisheye)";
  static constexpr int outputs = 1;
  kernels::CameraStage stage;

  template <class L>
  void operator()(vgpu::Fragments<L>& f) const {
    using F = typename L::F;
    // Each uniform enters as its own constant (none folded on the host), so that a recording
    // can name them (tests/trace/test_user_stages.cpp records it as a Python kernel would be).
    const F k = F(0.5f) * F(stage.tan_half_fov);
    const F px = f.x + F(stage.jitter_x) - F(0.5f), py = f.y + F(stage.jitter_y) - F(0.5f);
    const F sx = (F(2.0f) * px / F(stage.width) - F(1.0f)) * F(stage.aspect) * k;
    const F sy = (F(1.0f) - F(2.0f) * py / F(stage.height)) * k;
    const F r2 = sx * sx + sy * sy;
    const F inv = F(1.0f) / (F(1.0f) + r2);
    const F a = F(2.0f) * sx * inv, b = F(2.0f) * sy * inv, c = (F(1.0f) - r2) * inv;
    f.out(0) = {F(stage.forward.x) * c + F(stage.right.x) * a + F(stage.up.x) * b,
                F(stage.forward.y) * c + F(stage.right.y) * a + F(stage.up.y) * b,
                F(stage.forward.z) * c + F(stage.right.z) * a + F(stage.up.z) * b, F(stage.far)};
  }
};

}  // namespace test_support
