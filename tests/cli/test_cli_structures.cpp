// The command line's view of the table of structures (host/accel/accel.h: kAccelRows): --accel's
// help names every row with its description, and its allowed set is every row's name and auto.
// The rows themselves are checked in tests/trace/test_structures.cpp.
#include <string>

#include "host/accel/accel.h"
#include "tests/cli/cli_helpers.h"

using namespace clitest;

namespace {

// `text` with every run of white space one space (the help may wrap a description).
std::string one_spaced(const std::string& text) {
  std::string out;
  for (char ch : text) {
    const bool space = std::isspace(static_cast<unsigned char>(ch)) != 0;
    if (space && (out.empty() || out.back() == ' ')) continue;
    out += space ? ' ' : ch;
  }
  return out;
}

}  // namespace

TEST_CASE("the --accel help names every row of the table of structures, with its description") {
  const Outcome o = run("render --help");
  REQUIRE(o.status == 0);
  const std::string help = one_spaced(o.out);
  std::string allowed = "{";
  for (const host::AccelRow& row : host::kAccelRows) {
    const std::string entry = std::string(row.name) + " (" + std::string(row.description) + ")";
    CHECK_MESSAGE(help.find(entry) != std::string::npos, entry);
    allowed += std::string(row.name) + ",";
  }
  allowed += "auto}";
  CHECK_MESSAGE(help.find(allowed) != std::string::npos, allowed);
}

TEST_CASE("a structure whose indices outgrow what its format addresses exits 2 with one line") {
  // A limit of the input against the structure (scale, issue 50): the user's to change, as a bad
  // file is; the kd-tree's list positions on the bunny pass fp16's 1023.
  const clitest::Outcome o =
      clitest::run("render bunny --accel kdtree --formats voxel=fp16 --size 16x16 --quiet");
  CHECK(o.status == 2);
  clitest::check_one_line(o, "kd-tree: list positions reach",
                          "the voxel group's fp16 addresses texels exactly only to 1023 (give "
                          "it fp24 or fp32: --formats voxel=fp32)");
  CHECK(o.out.empty());
}
