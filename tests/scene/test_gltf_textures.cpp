// Tests for the glTF loader's textures (host/scene/gltf_textures.cpp): baseColorTexture, its
// TEXCOORD_0, sampler wraps, KHR_texture_transform, images embedded, in a .glb's buffer view or
// beside the file, and the refusals. Images are decoded by a stand-in decoder here (the real one
// lives above this room, in host/image, and is tested in tests/image).
#include <doctest/doctest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "host/scene/gltf_loader.h"
#include "host/scene/texture_fit.h"

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

// ---- Textures fitted to a profile, sizes read from headers (host/scene/texture_fit.h) ----

namespace {

// The first 33 bytes of a PNG: its signature and an IHDR chunk stating width x height (8-bit
// RGB). Enough for a header reader; a decoder would fail on the missing image data.
std::vector<unsigned char> png_header(uint32_t width, uint32_t height) {
  std::vector<unsigned char> b{0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n',
                               0,    0,   0,   13,  'I',  'H',  'D',  'R'};
  for (uint32_t v : {width, height})
    for (int s = 24; s >= 0; s -= 8) b.push_back(static_cast<unsigned char>(v >> s));
  for (unsigned char c : {8, 2, 0, 0, 0, 0, 0, 0, 0}) b.push_back(c);  // depth .. CRC (unread)
  return b;
}

// textured.gltf with its image replaced by `png` written beside it in a fresh directory.
std::string scene_with_image(const std::string& tag, const std::vector<unsigned char>& png) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("vgpu_fit_" + tag + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ifstream in(data_path("textured.gltf"));
  std::string text((std::istreambuf_iterator<char>(in)), {});
  const size_t a = text.find("data:image/png;base64,");
  const size_t b = text.find('"', a);
  text.replace(a, b - a, "image.png");
  std::ofstream(dir / "scene.gltf") << text;
  std::ofstream(dir / "image.png", std::ios::binary)
      .write(reinterpret_cast<const char*>(png.data()), std::streamsize(png.size()));
  return (dir / "scene.gltf").string();
}

}  // namespace

TEST_CASE("An image whose header states 16384x16384 texels is refused before it is decoded") {
  // 16384^2 texels * 16 bytes = 4 GiB decoded, past the 1 GiB bound; the file is 33 bytes.
  const std::string path = scene_with_image("huge", png_header(16384, 16384));
  host::LoadOptions o;
  bool decoded = false;
  o.read_image = [&](const std::vector<unsigned char>&) -> host::ImagePixels {
    decoded = true;
    throw std::runtime_error("the decoder must not run");
  };
  std::string message;
  try {
    host::load_scene(path, o);
  } catch (const host::InputError& e) {
    message = e.what();
  }
  INFO(message);
  CHECK_FALSE(decoded);
  CHECK(message.starts_with(path + ": image 0 (image.png): its header says 16384x16384 texels"));
  CHECK(message.find("4096 MiB decoded, past the loader's bound of 1024 MiB") != message.npos);
  CHECK(message.find('\n') == std::string::npos);
  // A side past stb_image's 2^24 is still read from IHDR; 8192^2 (exactly 1 GiB) is within.
  CHECK(host::image_header_size(png_header(1u << 30, 3)) == glm::ivec2(1 << 30, 3));
  CHECK(host::image_header_size(png_header(8192, 8192)) == glm::ivec2(8192, 8192));
  CHECK_FALSE(host::image_header_size({'n', 'o', 't', ' ', 'a', 'n', ' ', 'i', 'm', 'a', 'g'}));
  std::filesystem::remove_all(std::filesystem::path(path).parent_path());
}

TEST_CASE("A texture too large for the atlas is fitted: its base becomes mip level 1, by hand") {
  // An 8x8 image in 2x2 blocks: block (bx, by) has r = bx mod 2, g = by mod 2, b = 1 (sRGB 0
  // and 1 are linear 0 and 1), except block (1, 1), a checker of r = 0 and 1. Its chain needs a
  // 12x8 atlas; an 8-texel limit halves it once: 4x4, each texel its block's mean.
  const std::string path = scene_with_image("fit", png_header(8, 8));
  host::LoadOptions o;
  o.read_image = [](const std::vector<unsigned char>&) {
    host::ImagePixels px;
    px.width = px.height = 8;
    px.channels = 3;
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) {
        const int bx = x / 2, by = y / 2;
        const float r = bx == 1 && by == 1 ? float((x + y) % 2) : float(bx % 2);
        for (float c : {r, float(by % 2), 1.0f}) px.pixels.push_back(c);
      }
    return px;
  };
  const host::Scene full = host::load_scene(path, o);
  CHECK(full.textures[0].width == 8);  // no limit: as decoded
  CHECK(full.textures_fitted.empty());
  o.fit_textures = 8;
  o.fit_for = "profile test";
  const host::Scene s = host::load_scene(path, o);
  const host::SceneTexture& t = s.textures[0];
  REQUIRE(t.width == 4);
  REQUIRE(t.height == 4);
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      CAPTURE(i);
      CAPTURE(j);
      const glm::vec4 c = t.texels[size_t(j * 4 + i)];
      CHECK(c.r == (i == 1 && j == 1 ? 0.5f : float(i % 2)));
      CHECK(c.g == float(j % 2));
      CHECK(c.b == 1.0f);
      CHECK(c.a == 1.0f);
    }
  CHECK(s.textures_fitted ==
        "textures scaled down so that their atlas fits profile test's 8x8 texels: image 0 "
        "(image.png) 8x8 -> 4x4 (1/2 a side, mip level 1 as its base) (--textures refuse: "
        "refuse instead)");
  // A 4-texel limit halves twice (4x4 needs 6x4, 2x2 needs 3x2): level 2, each texel the mean
  // of four level-1 texels, e.g. (0, 0): r = (0 + 1 + 0 + 0.5) / 4, g = (0 + 0 + 1 + 1) / 4.
  o.fit_textures = 4;
  const host::Scene s2 = host::load_scene(path, o);
  const host::SceneTexture& t2 = s2.textures[0];
  REQUIRE(t2.width == 2);
  REQUIRE(t2.height == 2);
  CHECK(t2.texels[0] == glm::vec4(0.375f, 0.5f, 1.0f, 1.0f));
  CHECK(t2.texels[3] == glm::vec4(0.5f, 0.5f, 1.0f, 1.0f));
  std::filesystem::remove_all(std::filesystem::path(path).parent_path());
}

TEST_CASE("The fitting rule halves the largest texture first until the atlas fits") {
  // One 4096^2 chain needs 6144x4096: halved once (3072x2048) it fits 4096; 2048^2 already does.
  CHECK(host::fit_halvings({{4096, 4096}}, 4096) == std::vector<int>{1});
  CHECK(host::fit_halvings({{2048, 2048}}, 4096) == std::vector<int>{0});
  CHECK(host::fit_halvings({{16384, 16384}}, 4096) == std::vector<int>{3});
  // Two 2048^2 chains (3072 wide each) need two shelves, 3072x4096: they fit. Three need
  // 3072x6144: the first (largest, lowest index) is halved, then the second.
  CHECK(host::fit_halvings({{2048, 2048}, {2048, 2048}}, 4096) == std::vector<int>{0, 0});
  CHECK(host::fit_halvings({{2048, 2048}, {2048, 2048}, {2048, 2048}}, 4096) ==
        std::vector<int>{1, 1, 0});
}
