// The scene as the renderer sees it: flattened world-space triangles, materials, camera, lights.
// Filled by the glTF loader (host/scene/gltf_loader.cpp); read by the grid builder, the texture
// uploader and the CPU reference tracer.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace host {

// Any problem with an input file. what() is one line that names the file and the problem.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Material {
  glm::vec3 color{0.8f};  // linear rgb, from baseColorFactor
  float reflect = 0.0f;   // reflection coefficient a_i of the paper's blend formula
  int texture = -1;       // index into Scene::textures (baseColorTexture), -1: none
  // Glass (KHR_materials_transmission, KHR_materials_ior, KHR_materials_volume): the share of
  // light transmitted through the surface, the index of refraction inside it, and the volume's
  // absorption (Beer's law: colour reached after attenuation_distance world units inside).
  float transmission = 0.0f;          // transmissionFactor, 0: opaque (the paper's model)
  float ior = 1.5f;                   // KHR_materials_ior's default
  glm::vec3 attenuation_color{1.0f};  // KHR_materials_volume, linear rgb
  float attenuation_distance = 0.0f;  // world units; 0: no absorption (the spec's infinity)
};

// The sampler's wrap modes (glTF's REPEAT, CLAMP_TO_EDGE, MIRRORED_REPEAT), numbered as
// vgpu::Wrap.
enum class WrapMode { repeat = 0, clamp_to_edge = 1, mirrored_repeat = 2 };

// A base-colour texture: its image's texels, linear rgb (decoded from sRGB as glTF says) with
// alpha, row 0 = the image's top row, and its sampler's wraps. The material's colour multiplies
// it. One per (image, sampler) pair the materials use.
struct SceneTexture {
  std::string name;  // for messages, e.g. "image 0 (duck.png)"
  int width = 0, height = 0;
  std::vector<glm::vec4> texels;  // width * height, row-major
  WrapMode wrap_s = WrapMode::repeat, wrap_t = WrapMode::repeat;
};

// glTF conventions: looks down local -Z, +Y up, yfov vertical (radians).
struct Camera {
  glm::vec3 position{0.0f};     // world space
  glm::vec3 forward{0, 0, -1};  // unit, world space
  glm::vec3 up{0, 1, 0};        // unit, orthogonal to forward
  float yfov = 0.8f;            // radians
};

struct PointLight {
  glm::vec3 position{0.0f};  // world space
  glm::vec3 color{1.0f};     // linear rgb times intensity
};

struct Bounds {
  glm::vec3 lo{std::numeric_limits<float>::max()};
  glm::vec3 hi{-std::numeric_limits<float>::max()};
  void extend(glm::vec3 p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  bool empty() const { return lo.x > hi.x; }
};

// Triangles are stored structure-of-arrays, in the renderer's internal order. `id[i]` is the
// input triangle id of internal triangle i: its index in the flattened input order (nodes
// depth-first pre-order, a mesh's primitives in order, triangles in index order, strips and fans
// expanded), kept even when degenerate triangles are dropped.
struct Scene {
  std::string source;                 // file path, for messages
  std::string name;                   // short name (file stem)
  std::vector<glm::vec3> p0, p1, p2;  // corners, world space
  std::vector<glm::vec3> n0, n1, n2;  // corner normals, world space, unit length
  std::vector<uint32_t> material;     // index into materials, per triangle
  std::vector<uint32_t> id;           // input triangle id, per triangle
  std::vector<Material> materials;
  // Texture coordinates of each triangle's corners (glTF's, (0, 0) the image's top-left, with
  // KHR_texture_transform applied), per triangle like p0/p1/p2; empty when no material has a
  // texture. A triangle whose material has none holds (0, 0).
  std::vector<glm::vec2> uv0, uv1, uv2;
  std::vector<SceneTexture> textures;
  // One line saying which textures were scaled down to fit the profile and by how much
  // (LoadOptions::fit_textures); empty when none was.
  std::string textures_fitted;
  std::optional<Camera> camera;       // first camera node met depth-first, if any
  std::vector<PointLight> lights;     // KHR_lights_punctual point lights, or the default light
  bool default_light = false;         // true when lights holds the documented default
  uint32_t input_triangles = 0;       // triangles in the flattened input, degenerate included
  uint32_t dropped_degenerate = 0;    // zero-area triangles dropped
  std::vector<std::string> warnings;  // e.g. "skipped 2 LINES primitives"

  size_t triangle_count() const { return p0.size(); }
  // The host's copy of the triangles, their materials and texture images, bytes (the arrays' sizes:
  // the pages written): the memory model's scene term (host/report/memory_json.h).
  uint64_t host_bytes() const;
  // Appends a triangle: corners, corner normals (unit), material index and input id.
  void add_triangle(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 na, glm::vec3 nb, glm::vec3 nc,
                    uint32_t mat, uint32_t input_id) {
    p0.push_back(a), p1.push_back(b), p2.push_back(c);
    n0.push_back(na), n1.push_back(nb), n2.push_back(nc);
    material.push_back(mat);
    id.push_back(input_id);
  }
  // The same with the face normal at every corner (+z for a zero-area triangle).
  void add_flat_triangle(glm::vec3 a, glm::vec3 b, glm::vec3 c, uint32_t mat, uint32_t input_id) {
    const glm::vec3 n = glm::cross(b - a, c - a);
    const glm::vec3 u = glm::length(n) > 0 ? glm::normalize(n) : glm::vec3(0, 0, 1);
    add_triangle(a, b, c, u, u, u, mat, input_id);
  }
  Bounds bounds() const {
    Bounds b;
    for (size_t i = 0; i < p0.size(); ++i) {
      b.extend(p0[i]);
      b.extend(p1[i]);
      b.extend(p2[i]);
    }
    return b;
  }
  // The scene's padded box, the world box every acceleration structure is built in (scene.cpp):
  // bounds() grown on every side by
  //   pad = max(kScenePadRelative · |diagonal|, kScenePadMagnitude · max|coordinate|)
  // and rounded outward to float. A scene without triangles gets [-1, 1]³ (any box will do).
  Bounds box() const;
};

// The padding of Scene::box(). The relative term keeps triangles off the box's faces and gives a
// flat scene a non-zero extent (2·pad) along its flat axis; the magnitude term (≈ 8 float ulps)
// keeps the padding from vanishing when a small scene sits far from the origin.
inline constexpr double kScenePadRelative = 1e-4;
inline constexpr double kScenePadMagnitude = 1e-6;

}  // namespace host
