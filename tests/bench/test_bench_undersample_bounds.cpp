// bench_undersample_bounds as docs/studies/sampling.md uses it: its figures hang together (the
// floor is what the fill changes beyond the budget), the rule's image is the CPU tracer's own
// (compared here from the images the bench writes, not taken from its own verdict), and a bad scene
// is refused with exit 2 and no JSON written.
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

int run(const std::string& args) {
  const std::string cmd = std::string(BENCH_BOUNDS) + " " + args + " >/dev/null 2>&1";
  const int raw = std::system(cmd.c_str());
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
}

fs::path json_path() {
  return fs::temp_directory_path() / ("vgpu_bounds_" + std::to_string(::getpid()) + ".json");
}

// An RGB image read from a PFM file (as the bench writes it: little-endian, bottom row first),
// top row first.
struct Image {
  int w = 0, h = 0;
  std::vector<float> rgb;
  const float* at(int x, int y) const {
    return rgb.data() + (size_t(y) * size_t(w) + size_t(x)) * 3;
  }
};

Image read_pfm(const fs::path& path) {
  std::ifstream f(path, std::ios::binary);
  std::string magic;
  double scale = 0;
  Image im;
  f >> magic >> im.w >> im.h >> scale;
  f.get();  // the one whitespace character before the data
  REQUIRE(magic == "PF");
  REQUIRE(scale < 0);
  REQUIRE(im.w > 0);
  REQUIRE(im.h > 0);
  im.rgb.resize(size_t(im.w) * size_t(im.h) * 3);
  for (int y = im.h - 1; y >= 0; --y)
    f.read(reinterpret_cast<char*>(im.rgb.data() + size_t(y) * size_t(im.w) * 3),
           std::streamsize(size_t(im.w) * 3 * sizeof(float)));
  REQUIRE(f.good());
  return im;
}

// The largest difference of two images' channels.
double largest_difference(const Image& a, const Image& b) {
  REQUIRE(a.rgb.size() == b.rgb.size());
  double d = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) d = std::max(d, std::fabs(double(a.rgb[i]) - b.rgb[i]));
  return d;
}

}  // namespace

TEST_CASE(
    "the undersampling bounds put the floor at the fill's changes beyond a third of the "
    "rays, and the rule's image, read back from the bench's files, is the CPU tracer's") {
  const fs::path out = json_path();
  const fs::path images = out.string() + ".images";
  fs::create_directories(images);
  REQUIRE(run("--size 64 --scenes " VGPU_SCENES "/bunny-refl.gltf " VGPU_SCENES
              "/sphere-alone.gltf --thresholds 0.1 0.02 --json " +
              out.string() + " --images " + images.string()) == 0);
  std::ifstream f(out);
  const nlohmann::json j = nlohmann::json::parse(f);
  fs::remove(out);
  CHECK(j["size"] == 64);
  CHECK(j["k"] == 2);
  REQUIRE(j["bounds"].size() == 4);
  for (size_t row = 0; row < 4; ++row) {
    const auto& b = j["bounds"][row];
    CAPTURE(b.dump());
    // The images, compared here. The rule's image is the one-ray image with the gaps the rule
    // leaves untraced filled; the CPU tracer's undersample:2 must be the same to float
    // rounding (it blends its double colours, the bench its float image's).
    const std::string base = (images / std::to_string(row)).string();
    const Image full = read_pfm(base + "_full.pfm"), rule = read_pfm(base + "_rule.pfm"),
                tracer = read_pfm(base + "_tracer.pfm");
    REQUIRE(full.w == 64);
    REQUIRE(full.h == 64);
    const double tracer_off = largest_difference(tracer, rule);
    CHECK(tracer_off <= 1e-5);
    CHECK(b["rule_matches_tracer"] == (tracer_off <= 1e-5));
    // Not a vacuous comparison: some gaps were filled, so the images differ from the one-ray
    // image somewhere, but never on the lattice (K = 2: even rows and columns, and the last),
    // whose pixels every image traces alike.
    CHECK(largest_difference(tracer, full) > 1e-3);
    int lattice_off = 0;
    for (int y = 0; y < 64; ++y)
      for (int x = 0; x < 64; ++x)
        if ((x % 2 == 0 || x == 63) && (y % 2 == 0 || y == 63))
          for (int c = 0; c < 3; ++c) lattice_off += tracer.at(x, y)[c] != full.at(x, y)[c];
    CHECK(lattice_off == 0);
    // 64x64, K = 2: lattice rows and columns 0, 2, ..., 62 and the last (63): 33 x 33 pixels.
    CHECK(b["lattice"].get<double>() == doctest::Approx(33.0 * 33.0 / 4096.0));
    CHECK(b["budget"].get<double>() == doctest::Approx((4096 / 3 - 33 * 33) / 4096.0));
    const double fill = b["fill_changes"], budget = b["budget"];
    CHECK(b["floor"].get<double>() == doctest::Approx(std::max(0.0, fill - budget)));
    CHECK(b["after_keys"].get<double>() >= b["floor"].get<double>() - 1e-12);
    CHECK(b["ranked_changed"].get<double>() >= b["floor"].get<double>() - 1e-12);
    CHECK(b["rule_changed"].get<double>() <= fill + 1e-12);
    CHECK(b["rule_rays"].get<double>() >= b["lattice"].get<double>());
    CHECK(b["pixels_per_triangle"].get<double>() > 1.0);
  }
  // A lower threshold traces more gaps and changes fewer pixels.
  const auto& hi = j["bounds"][0];
  const auto& lo = j["bounds"][1];
  CHECK(hi["threshold"] == 0.1);
  CHECK(lo["rule_rays"].get<double>() >= hi["rule_rays"].get<double>());
  CHECK(lo["rule_changed"].get<double>() <= hi["rule_changed"].get<double>());
  fs::remove_all(images);
}

TEST_CASE("the undersampling bounds refuse a scene that is not there, writing nothing") {
  const fs::path out = json_path();
  CHECK(run("--size 16 --scenes no-such-scene --json " + out.string()) == 2);
  CHECK_FALSE(fs::exists(out));
}
