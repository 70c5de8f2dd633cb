// The version: one place (VERSION) defines it, and the command line, the statistics JSON
// (tests/report/test_stats_parts_json.cpp, tests/cli/test_cli.cpp) and the Python module
// (python/tests/test_render.py) show it.
#include <doctest/doctest.h>

#include <string>

#include "host/common/version.h"
#include "tests/cli/cli_helpers.h"

using namespace clitest;

TEST_CASE("vgpu-rt --version prints the version of the VERSION file and exits 0") {
  const Outcome o = run("--version");
  CHECK(o.status == 0);
  CHECK(o.out == std::string("vgpu-rt ") + host::version() + "\n");
  CHECK(o.err.empty());
  std::string file = slurp(fs::path(VGPU_SCENES_DIR).parent_path() / "VERSION");
  while (!file.empty() && (file.back() == '\n' || file.back() == ' ')) file.pop_back();
  CHECK(file == host::version());
}
