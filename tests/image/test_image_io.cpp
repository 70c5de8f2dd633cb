// Image files through the image module (host/image/image_io.h): written atomically, byte-identical
// from one write to the next (no timestamp), read back equal by compare_images.
#include <doctest/doctest.h>
#include <unistd.h>

#include <ctime>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "host/image/image_io.h"
#include "host/scene/scene.h"

namespace {

namespace fs = std::filesystem;

std::string bytes_of(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

fs::path temp_file(const std::string& name) {
  return fs::temp_directory_path() / ("vgpu_image_" + std::to_string(::getpid()) + "_" + name);
}

}  // namespace

TEST_CASE("an image written twice gives the same bytes and carries no write date") {
  const std::vector<float> px = {0.0f, 0.25f, 0.5f, 1.0f, -1.0f, 3.5f};
  // Today's date as OpenImageIO writes DateTime ("YYYY:MM:DD hh:mm:ss").
  char today[16];
  const std::time_t now = std::time(nullptr);
  std::strftime(today, sizeof today, "%Y:%m:%d", std::localtime(&now));
  for (const char* ext : {".exr", ".png"}) {
    const fs::path a = temp_file(std::string("a") + ext), b = temp_file(std::string("b") + ext);
    host::write_image(a.string(), 3, 2, 1, px);
    host::write_image(b.string(), 3, 2, 1, px);
    const std::string ba = bytes_of(a);
    CHECK_MESSAGE(ba.size() > 0, ext);
    CHECK_MESSAGE(ba == bytes_of(b), ext);
    CHECK_MESSAGE(ba.find(today) == std::string::npos, ext);
    fs::remove(a);
    fs::remove(b);
  }
}

TEST_CASE("compare_images reads back a float image exactly and refuses a missing one") {
  const std::vector<float> px = {0.0f, 0.25f, 0.5f, 1.0f, -1.0f, 3.5f};
  const fs::path a = temp_file("c.exr");
  host::write_image(a.string(), 3, 2, 1, px);
  const host::ImageComparison c = host::compare_images(a.string(), a.string(), 0.0);
  CHECK(c.width == 3);
  CHECK(c.height == 2);
  CHECK(c.max_error == 0.0);
  CHECK_THROWS_AS(host::compare_images(a.string(), temp_file("missing.exr").string(), 0.0),
                  host::InputError);
  fs::remove(a);
}

TEST_CASE("a failed image write leaves no file behind") {
  const fs::path dir = temp_file("ro");
  fs::create_directory(dir);
  const fs::path p = dir / "x.exr";
  // 0 channels: the writer refuses, and neither the file nor its temporary remains.
  CHECK_THROWS_AS(host::write_image(p.string(), 2, 2, 0, {}), host::InputError);
  CHECK(fs::is_empty(dir));
  fs::remove_all(dir);
}

TEST_CASE("decode_image reads a PNG texture from memory and refuses bytes that are no image") {
  const std::string png = bytes_of(std::string(VGPU_TEST_DATA) + "/gltf/textured_external.png");
  const host::ImagePixels px = host::decode_image({png.begin(), png.end()});
  REQUIRE(px.width == 2);
  REQUIRE(px.height == 2);
  REQUIRE(px.channels == 3);
  // Red, green / blue, white (tests/data/gltf/make_cases.py), row 0 at the top.
  const std::vector<float> expected = {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
  CHECK(px.pixels == expected);
  const std::string junk = "not an image at all";
  CHECK_THROWS_WITH(host::decode_image({junk.begin(), junk.end()}), "not a PNG or JPEG image");
  // A PNG cut short.
  CHECK_THROWS(host::decode_image({png.begin(), png.begin() + 40}));
}
