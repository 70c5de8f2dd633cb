// bench_mark_rules as scripts/docs/sampling_rules.py uses it: one file per scene of the size the
// index says, its centre and 4 x 4 colours where the fields say, and a bad scene refused with
// exit 2 and no index written.
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

int run(const std::string& args) {
  const std::string cmd = std::string(BENCH_MARK_RULES) + " " + args + " >/dev/null 2>&1";
  const int raw = std::system(cmd.c_str());
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
}

fs::path out_dir() {
  const fs::path p = fs::temp_directory_path() / ("vgpu_rules_" + std::to_string(::getpid()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

}  // namespace

TEST_CASE("the refinement-rule data holds every pixel's fields for each scene the index names") {
  const fs::path out = out_dir();
  REQUIRE(run("--size 8 --ref-spp 4 --scenes " VGPU_SCENES "/sphere.gltf --out " + out.string()) ==
          0);
  std::ifstream in(out / "index.json");
  REQUIRE(in);
  const nlohmann::json index = nlohmann::json::parse(in);
  CHECK(index["size"] == 8);
  const std::vector<std::string> fields = index["fields"];
  REQUIRE(fields.size() == 22);
  REQUIRE(index["scenes"].size() == 1);
  const nlohmann::json& scene = index["scenes"][0];
  CHECK(scene["spread"].get<double>() > 0.0);
  const fs::path file = out / scene["file"].get<std::string>();
  REQUIRE(fs::file_size(file) == 8 * 8 * fields.size() * sizeof(float));
  std::vector<float> data(8 * 8 * fields.size());
  std::ifstream f(file, std::ios::binary);
  f.read(reinterpret_cast<char*>(data.data()), std::streamsize(data.size() * sizeof(float)));
  auto at = [&](size_t pixel, const std::string& name) {
    for (size_t k = 0; k < fields.size(); ++k)
      if (fields[k] == name) return data[pixel * fields.size() + k];
    FAIL("no field " << name);
    return 0.0f;
  };
  int hits = 0;
  for (size_t p = 0; p < 64; ++p) {
    // A miss has no depth; every level traces at least as many rays as it has samples where the
    // centre ray entered the grid; the kept level traces 12 of the 4 x 4 level's 16 samples.
    if (at(p, "key") < 0) CHECK(at(p, "depth") == 0.0f);
    if (at(p, "key") >= 0) {
      ++hits;
      CHECK(at(p, "depth") > 0.0f);
    }
    if (at(p, "centre_rays") > 0) CHECK(at(p, "l4_rays") >= 16.0f);
    CHECK(at(p, "l4kept_rays") <= at(p, "l4_rays"));
    for (const char* c : {"centre_r", "l2_g", "l4_b", "ref_r", "l4kept_g"}) CHECK(at(p, c) >= 0.0f);
  }
  CHECK(hits > 0);
  fs::remove_all(out);
}

TEST_CASE("the refinement-rule data refuses a scene that is not there, writing no index") {
  const fs::path out = out_dir();
  CHECK(run("--size 8 --scenes no-such-scene --out " + out.string()) == 2);
  CHECK_FALSE(fs::exists(out / "index.json"));
  CHECK(run("--size 8 --scenes sphere --out " + (out / "missing").string()) != 0);
  fs::remove_all(out);
}
