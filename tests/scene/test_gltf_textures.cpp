// Tests for the glTF loader's textures (host/scene/gltf_textures.cpp): baseColorTexture, its
// TEXCOORD_0, sampler wraps, KHR_texture_transform, images embedded, in a .glb's buffer view or
// beside the file, and the refusals. Images are decoded by a stand-in decoder here (the real one
// lives above this room, in host/image, and is tested in tests/image).
#include <doctest/doctest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "host/scene/gltf_loader.h"

namespace {

std::string data_path(const std::string& name) {
  return std::string(VGPU_TEST_DATA) + "/gltf/" + name;
}

// A decoder that keeps the bytes it was given and returns a 2x2 RGB image: sRGB 1.0, 0.5, 0.0
// and 0.2 in the first texel's channels r, g, b, the rest 1.
struct StandIn {
  std::vector<std::vector<unsigned char>> seen;
  host::LoadOptions options() {
    host::LoadOptions o;
    o.read_image = [this](const std::vector<unsigned char>& bytes) {
      seen.push_back(bytes);
      host::ImagePixels px;
      px.width = 2;
      px.height = 2;
      px.channels = 3;
      px.pixels.assign(12, 1.0f);
      px.pixels[0] = 1.0f, px.pixels[1] = 0.5f, px.pixels[2] = 0.0f;
      return px;
    };
    return o;
  }
};

std::string error_of(const std::string& name, const host::LoadOptions& options) {
  try {
    host::load_scene(data_path(name), options);
  } catch (const host::InputError& e) {
    return e.what();
  }
  return "";
}

// The loader's message is one line "PATH: ..." containing `reason`.
void check_rejected(const std::string& name, const std::string& reason,
                    const host::LoadOptions& options) {
  const std::string message = error_of(name, options);
  INFO("message: " << message);
  CHECK(message.starts_with(data_path(name) + ": "));
  CHECK(message.find(reason) != std::string::npos);
  CHECK(message.find('\n') == std::string::npos);
}

}  // namespace

TEST_CASE("A textured quad gives each corner its TEXCOORD_0 and its material the texture") {
  StandIn d;
  const host::Scene s = host::load_scene(data_path("textured.gltf"), d.options());
  REQUIRE(s.triangle_count() == 2);
  REQUIRE(s.textures.size() == 1);
  REQUIRE(s.uv0.size() == 2);
  CHECK(s.materials[0].texture == 0);
  // Triangle 0 is corners 0, 2, 1 of the quad: (-1, 1), (-1, -1), (1, 1) with uv (0, 0), (0, 1),
  // (1, 0).
  CHECK(s.p0[0] == glm::vec3(-1, 1, 0));
  CHECK(s.uv0[0] == glm::vec2(0, 0));
  CHECK(s.uv1[0] == glm::vec2(0, 1));
  CHECK(s.uv2[0] == glm::vec2(1, 0));
  CHECK(s.uv2[1] == glm::vec2(1, 1));
  const host::SceneTexture& t = s.textures[0];
  CHECK(t.width == 2);
  CHECK(t.height == 2);
  CHECK(t.wrap_s == host::WrapMode::clamp_to_edge);
  CHECK(t.wrap_t == host::WrapMode::mirrored_repeat);
  // sRGB decoded to linear: 1 -> 1, 0.5 -> 0.214, 0 -> 0; alpha 1 for RGB.
  CHECK(t.texels[0].r == 1.0f);
  CHECK(t.texels[0].g == doctest::Approx(0.21404).epsilon(1e-4));
  CHECK(t.texels[0].b == 0.0f);
  CHECK(t.texels[0].a == 1.0f);
  // The decoder got the embedded PNG.
  REQUIRE(d.seen.size() == 1);
  CHECK(d.seen[0].size() > 8);
  CHECK(d.seen[0][1] == 'P');
}

TEST_CASE("An image in a .glb buffer view or beside the file reads the same bytes as embedded") {
  StandIn d;
  for (const char* name : {"textured.gltf", "textured.glb", "textured_external.gltf"}) {
    CAPTURE(name);
    const host::Scene s = host::load_scene(data_path(name), d.options());
    CHECK(s.textures.size() == 1);
    CHECK(s.uv2.size() == 2);
  }
  REQUIRE(d.seen.size() == 3);
  CHECK(d.seen[1] == d.seen[0]);
  CHECK(d.seen[2] == d.seen[0]);
}

TEST_CASE("KHR_texture_transform is applied to each corner: scale, then offset") {
  StandIn d;
  const host::Scene s = host::load_scene(data_path("textured_transform.gltf"), d.options());
  // u' = 2 u + 0.5, v' = v.
  CHECK(s.uv0[0] == glm::vec2(0.5f, 0.0f));
  CHECK(s.uv1[0] == glm::vec2(0.5f, 1.0f));
  CHECK(s.uv2[0] == glm::vec2(2.5f, 0.0f));
}

TEST_CASE("Scenes without textures keep no texture coordinates") {
  StandIn d;
  const host::Scene s = host::load_scene(data_path("materials.gltf"), d.options());
  CHECK(s.textures.empty());
  CHECK(s.uv0.empty());
  CHECK(d.seen.empty());
}

TEST_CASE("A texture that cannot be read is rejected naming the file, the image and the reason") {
  StandIn d;
  check_rejected("texture_missing.gltf", "image 0 (no_such_texture.png): cannot read", d.options());
  host::LoadOptions failing;
  failing.read_image = [](const std::vector<unsigned char>&) -> host::ImagePixels {
    throw std::runtime_error("not a PNG or JPEG image");
  };
  check_rejected("texture_not_an_image.gltf",
                 "image 0: cannot read the image: not a PNG or JPEG image", failing);
  check_rejected("textured.gltf", "image 0: no image decoder was given", host::LoadOptions{});
}

TEST_CASE("A TEXCOORD_0 accessor of the wrong type is rejected naming the accessor") {
  StandIn d;
  check_rejected("texcoord_vec3.gltf",
                 "mesh 0 primitive 0 TEXCOORD_0: accessor 0 must be VEC2 of float, or of "
                 "normalized unsigned byte or short components",
                 d.options());
}
