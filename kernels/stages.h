// The stages of the frame a kernel of one's own can replace (issue 48), and what the frame tells
// that kernel before each of the stage's passes: the uniforms the project's own kernel for the
// stage reads, by name. A C++ functor keeps them in a data member `stage` (the frame copies them
// there, host/trace/user_stage.h); a kernel written in Python reads those it declares among its
// uniforms by these names (f.light_x, f.uniform("first_light")).
//
//   shading (replaces kernels::Shader, paper "shader"): one pass per light; the units are
//     kernels::Shader::units, bound by name; output 0 replaces the result texel: rgb the colour
//     so far plus this light's contribution, w the weight of the reflected ray (set by the last
//     light's pass, else passed on).
//   camera (replaces kernels::GenerateRays, paper "generadorRayos"): once per frame, or per
//     sample frame under --spp; no units; output 0 is the primary ray's direction (unit length)
//     in xyz and its tmax in w (far: the project's "no limit"). Every primary ray starts at the
//     eye (the origins texture).
#pragma once

#include <array>
#include <glm/glm.hpp>
#include <type_traits>

#include "kernels/common.h"
#include "kernels/shader.h"

namespace kernels {

struct ShaderStage {
  static constexpr const char* stage = "shader";
  static constexpr const auto& units = Shader::units;  // bound by name

  glm::vec3 light{0.0f}, light_color{1.0f};  // world space; rgb x intensity
  float first_light = 1, last_light = 1;     // 1: this pass is the frame's first / last light's
  // 1: unit shadow_hits holds this light's shadow rays' hits (w >= 0: the light is blocked); or,
  // with shadow_transmittance 1 (a scene with glass), w is the light's transmittance.
  float shadows = 0, shadow_transmittance = 0;
  glm::vec3 ambient{0.1f}, background{0.0f};
  float specular = 0.5f;     // the project's phong ks
  float atten_dist = 10.0f;  // world units: phong-atten's distance of half intensity
  float scene_width = 1;     // texels per row of the scene's textures: triangle i at
                             // (i mod width + 0.5, floor(i / width) + 0.5)

  // Every uniform with its name, in this order (each_uniform below).
  template <class S, class Fn>
  static void fields(S& s, Fn& fn) {
    fn("light_x", s.light.x), fn("light_y", s.light.y), fn("light_z", s.light.z);
    fn("light_r", s.light_color.r), fn("light_g", s.light_color.g), fn("light_b", s.light_color.b);
    fn("first_light", s.first_light), fn("last_light", s.last_light);
    fn("shadows", s.shadows), fn("shadow_transmittance", s.shadow_transmittance);
    fn("ambient_r", s.ambient.r), fn("ambient_g", s.ambient.g), fn("ambient_b", s.ambient.b);
    fn("background_r", s.background.r), fn("background_g", s.background.g);
    fn("background_b", s.background.b);
    fn("specular", s.specular), fn("atten_dist", s.atten_dist), fn("scene_width", s.scene_width);
  }
};

struct CameraStage {
  static constexpr const char* stage = "camera";
  static constexpr std::array<const char*, 0> units{};

  glm::vec3 eye{0.0f};  // where every primary ray starts (already in the origins texture)
  glm::vec3 forward{0, 0, -1}, right{1, 0, 0}, up{0, 1, 0};  // the camera's basis, world space
  float tan_half_fov = 0.5f, aspect = 1.0f;                  // vertical field of view; W / H
  float width = 1, height = 1;                               // image size, pixels
  // The sample position within the pixel (0.5, 0.5: its centre; --spp N moves it per sample
  // frame): a fragment's f.x, f.y are its pixel's centre, its sample point (in pixels from the
  // image's top-left corner) is (f.x + jitter_x - 0.5, f.y + jitter_y - 0.5).
  float jitter_x = 0.5f, jitter_y = 0.5f;
  float far = kFar;  // the tmax of a ray without limit

  template <class S, class Fn>
  static void fields(S& s, Fn& fn) {
    fn("eye_x", s.eye.x), fn("eye_y", s.eye.y), fn("eye_z", s.eye.z);
    fn("forward_x", s.forward.x), fn("forward_y", s.forward.y), fn("forward_z", s.forward.z);
    fn("right_x", s.right.x), fn("right_y", s.right.y), fn("right_z", s.right.z);
    fn("up_x", s.up.x), fn("up_y", s.up.y), fn("up_z", s.up.z);
    fn("tan_half_fov", s.tan_half_fov), fn("aspect", s.aspect);
    fn("width", s.width), fn("height", s.height);
    fn("jitter_x", s.jitter_x), fn("jitter_y", s.jitter_y), fn("far", s.far);
  }
};

// fn(name, value) for every uniform of a stage's (ShaderStage, CameraStage), in its order; value
// is a float& where `stage` is not const.
template <class S, class Fn>
void each_uniform(S& stage, Fn&& fn) {
  std::remove_const_t<S>::fields(stage, fn);
}

}  // namespace kernels
