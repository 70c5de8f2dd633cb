// A shading stage of this project's own: toon shading in the frame (vgpu-rt's host/trace/
// user_stage.h). One pass per light, as the stage asks: the diffuse term in `bands` flat bands
// over the first corner's normal (flat shading), the ambient term on the first light's pass, and
// vgpu-rt's blend (the result so far plus w (1 - a) times this light's colour; the last light's
// pass sets the reflected ray's weight, w a). Reads 5 of the stage's textures, by name.
#pragma once

#include <array>

#include "kernels/common.h"  // fetch_id: a triangle's texel in the scene's textures
#include "kernels/stages.h"  // kernels::ShaderStage: what the frame sets before each pass
#include "vgpu/program.h"

struct ToonShader {
  static constexpr const char* name = "toon shading";
  static constexpr const char* paper_name = "shader (toon, own kernel)";
  static constexpr int outputs = 1;
  enum Unit { kSurface, kRays, kResult, kColors, kNormals };
  static constexpr std::array<const char*, 5> units{"surface", "rays", "result", "colors",
                                                    "normals0"};

  kernels::ShaderStage stage;  // the light, its colour, first/last light, the scene's width...
  float bands = 3;

  template <class L>
  void operator()(vgpu::Fragments<L>& f) const {
    using F = typename L::F;
    using vgpu::floor, vgpu::max, vgpu::select;
    const vgpu::Vec4<F> surf = f.fetch_own(kSurface);  // hit point, triangle id (-1: none)
    const vgpu::Vec4<F> res = f.fetch_own(kResult);    // colour so far, weight w
    const vgpu::Vec3<F> d = f.fetch_own(kRays).xyz();
    const auto hit = surf.w >= F(0.0f);
    const vgpu::Vec4<F> mat = kernels::fetch_id(f, kColors, surf.w, stage.scene_width);
    vgpu::Vec3<F> n =
        vgpu::normalize(kernels::fetch_id(f, kNormals, surf.w, stage.scene_width).xyz());
    n = select(vgpu::dot(n, d) > F(0.0f), -n, n);  // facing the ray
    const vgpu::Vec3<F> l = vgpu::normalize(kernels::splat<F>(stage.light) - surf.xyz());
    const F band = floor(max(vgpu::dot(n, l), F(0.0f)) * F(bands)) / F(bands);
    const F k = (band + F(stage.first_light) * F(stage.ambient.r)) * res.w * (F(1.0f) - mat.w);
    const F last = F(stage.last_light);
    f.out(0) = {res.x + select(hit, mat.x * k * F(stage.light_color.r), F(0.0f)),
                res.y + select(hit, mat.y * k * F(stage.light_color.g), F(0.0f)),
                res.z + select(hit, mat.z * k * F(stage.light_color.b), F(0.0f)),
                select(hit, res.w * mat.w, F(0.0f)) * last + res.w * (F(1.0f) - last)};
  }
};
