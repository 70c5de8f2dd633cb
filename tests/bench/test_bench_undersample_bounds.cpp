// bench_undersample_bounds as docs/sampling.md uses it: its figures hang together (the floor is
// what the fill changes beyond the budget, the rule's image is the CPU tracer's own), and a bad
// scene is refused with exit 2 and no JSON written.
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

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

}  // namespace

TEST_CASE(
    "the undersampling bounds put the floor at the fill's changes beyond a third of the "
    "rays, and the rule's image is the CPU tracer's") {
  const fs::path out = json_path();
  REQUIRE(run("--size 64 --scenes " VGPU_SCENES "/bunny-refl.gltf " VGPU_SCENES
              "/sphere-alone.gltf --thresholds 0.1 0.02 --json " +
              out.string()) == 0);
  std::ifstream f(out);
  const nlohmann::json j = nlohmann::json::parse(f);
  fs::remove(out);
  CHECK(j["size"] == 64);
  CHECK(j["k"] == 2);
  REQUIRE(j["bounds"].size() == 4);
  for (const auto& b : j["bounds"]) {
    CAPTURE(b.dump());
    // 64x64, K = 2: lattice rows and columns 0, 2, ..., 62 and the last (63): 33 x 33 pixels.
    CHECK(b["lattice"].get<double>() == doctest::Approx(33.0 * 33.0 / 4096.0));
    CHECK(b["budget"].get<double>() == doctest::Approx((4096 / 3 - 33 * 33) / 4096.0));
    const double fill = b["fill_changes"], budget = b["budget"];
    CHECK(b["floor"].get<double>() == doctest::Approx(std::max(0.0, fill - budget)));
    CHECK(b["after_keys"].get<double>() >= b["floor"].get<double>() - 1e-12);
    CHECK(b["ranked_changed"].get<double>() >= b["floor"].get<double>() - 1e-12);
    CHECK(b["rule_changed"].get<double>() <= fill + 1e-12);
    CHECK(b["rule_rays"].get<double>() >= b["lattice"].get<double>());
    CHECK(b["rule_matches_tracer"] == true);
    CHECK(b["pixels_per_triangle"].get<double>() > 1.0);
  }
  // A lower threshold traces more gaps and changes fewer pixels.
  const auto& hi = j["bounds"][0];
  const auto& lo = j["bounds"][1];
  CHECK(hi["threshold"] == 0.1);
  CHECK(lo["rule_rays"].get<double>() >= hi["rule_rays"].get<double>());
  CHECK(lo["rule_changed"].get<double>() <= hi["rule_changed"].get<double>());
}

TEST_CASE("the undersampling bounds refuse a scene that is not there, writing nothing") {
  const fs::path out = json_path();
  CHECK(run("--size 16 --scenes no-such-scene --json " + out.string()) == 2);
  CHECK_FALSE(fs::exists(out));
}
