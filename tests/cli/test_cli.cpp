// The command line as a user meets it: every bad option value is refused by CLI11's validators
// (or a check of option combinations) with one line on stderr, exit status 2 and no output file.
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;

struct Outcome {
  int status = -1;
  std::string err;  // everything written on stderr
};

// Runs `vgpu-rt ARGS` through the shell, stdout discarded, stderr captured in a file.
Outcome run(const std::string& args) {
  const fs::path err = fs::temp_directory_path() / ("vgpu_cli_err_" + std::to_string(::getpid()));
  const std::string cmd = std::string(VGPU_RT) + " " + args + " >/dev/null 2>" + err.string();
  const int raw = std::system(cmd.c_str());
  Outcome o;
  o.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  std::ifstream f(err);
  std::stringstream ss;
  ss << f.rdbuf();
  o.err = ss.str();
  fs::remove(err);
  return o;
}

// One refused render: exit 2, one line naming `option`, and no image written.
void check_refused(const std::string& args, const std::string& option) {
  const fs::path out =
      fs::temp_directory_path() / ("vgpu_cli_out_" + std::to_string(::getpid()) + ".png");
  const Outcome o = run("render bunny-low -q --stats none --out " + out.string() + " " + args);
  INFO("vgpu-rt render " << args << " -> " << o.err);
  CHECK(o.status == 2);
  CHECK(o.err.find(option) != std::string::npos);
  CHECK(std::count(o.err.begin(), o.err.end(), '\n') == 1);
  CHECK_FALSE(fs::exists(out));
}

}  // namespace

TEST_CASE("out-of-range numbers are refused with their allowed range") {
  check_refused("--threads -3", "--threads");
  check_refused("--threads 100000", "--threads");
  check_refused("--bounces 65", "--bounces");
  check_refused("--lanes 3", "--lanes");
}

TEST_CASE("an image size past the limit names the limit, not a parse failure") {
  const Outcome o = run("render bunny-low --size 100000x100000");
  CHECK(o.status == 2);
  CHECK(o.err.find("16384x16384") != std::string::npos);
  CHECK(o.err.find("parse") == std::string::npos);
  check_refused("--size 0x10", "--size");
  check_refused("--size 12", "--size");
}

TEST_CASE("names outside each option's set are refused") {
  check_refused("--shading glossy", "--shading");
  check_refused("--shadows yes", "--shadows");
  check_refused("--profile gf9", "--profile");
  check_refused("--precision fp8", "--precision");
  check_refused("--engine gpu", "--engine");
  check_refused("--stats xml", "--stats");
  check_refused("--grid 0", "--grid");
  check_refused("--trace-pixel 3", "--trace-pixel");
  check_refused("--trace-pixel 300,2", "--trace-pixel");
}

TEST_CASE("AOVs are float EXR files only") {
  check_refused("--aov depth=" + (fs::temp_directory_path() / "d.png").string(), "--aov");
  check_refused("--aov normal=" + (fs::temp_directory_path() / "n.exr").string(), "--aov");
  check_refused("--aov depth=", "--aov");
}

TEST_CASE("output files need a known extension and an existing directory") {
  const Outcome o = run("render bunny-low --out /no/such/dir/a.png");
  CHECK(o.status == 2);
  CHECK(o.err.find("/no/such/dir") != std::string::npos);
  const Outcome j = run("render bunny-low --out a.jpg");
  CHECK(j.status == 2);
  const Outcome s =
      run("render bunny-low --stats-json " + (fs::temp_directory_path() / "s.txt").string());
  CHECK(s.status == 2);
}

TEST_CASE("MRT fusion is refused with the looping kernels, which have no passes left to fuse") {
  check_refused("--profile gf6600 --kernels looping --mrt on", "--mrt on");
}

TEST_CASE("GL device settings are refused without the GL engine and checked against their set") {
  check_refused("--gl-readback poll", "--gl-readback");
  check_refused("--engine cpu --gl-device 0", "--gl-device");
  check_refused("--engine gl --gl-readback spin", "--gl-readback");
}

TEST_CASE("settings the cpu engine does not use are refused instead of recorded") {
  check_refused("--engine cpu --lanes 8", "--lanes");
  check_refused("--engine cpu --precision fp16", "--precision");
  check_refused("--engine cpu --masks on", "--masks");
  check_refused("--engine cpu --predict", "--predict");
  check_refused("--engine cpu --trace-pixel 1,1", "--trace-pixel");
  check_refused("--engine cpu --mrt on", "--mrt");
}

TEST_CASE("mrt on a profile with one output is refused, naming the fused program and the limit") {
  check_refused("--mrt on --profile gf5700", "program 'intersections + next triangle' writes 2");
  check_refused("--mrt on --profile gf5700", "gf5700 allows 1");
  check_refused("--mrt maybe", "--mrt");
  // Mixed arithmetic in the fused groups: refused once the formats are known.
  check_refused("--mrt on --profile gf6600 --lanes 8 --formats hits=fp16", "hits (fp16)");
}

TEST_CASE("reduced precision refuses lane widths it does not run at") {
  check_refused("--lanes 4 --precision fp24", "--lanes");
  check_refused("--lanes 16 --precision fp16", "--lanes");
}

TEST_CASE("compare refuses missing files and negative thresholds") {
  const Outcome o = run("compare /no/such/a.png /no/such/b.png");
  CHECK(o.status == 2);
  CHECK(std::count(o.err.begin(), o.err.end(), '\n') == 1);
  const Outcome t = run("compare /dev/null /dev/null --threshold -1");
  CHECK(t.status == 2);
}

TEST_CASE("help lists each option's allowed values and exits with 0") {
  const std::string help =
      (fs::temp_directory_path() / ("vgpu_cli_help_" + std::to_string(::getpid()))).string();
  const int raw = std::system((std::string(VGPU_RT) + " render --help >" + help).c_str());
  CHECK(WIFEXITED(raw));
  CHECK(WEXITSTATUS(raw) == 0);
  std::ifstream f(help);
  std::stringstream ss;
  ss << f.rdbuf();
  fs::remove(help);
  const std::string text = ss.str();
  for (const char* allowed :
       {"{diffuse,phong,phong-atten}", "[0 - 256]", "{1,4,8,16}",
        "{gf5700,r300,gf6600,rtx4090,h200}", "{stream,gl,cpu}", "1x1..16384x16384",
        "depth=FILE.exr", "{multipass,looping}", "[1 - 4096]", "{batches,passes}"})
    CHECK_MESSAGE(text.find(allowed) != std::string::npos, allowed);
}

TEST_CASE("the walk option is checked against its set and refused off the stream engine") {
  check_refused("--walk fragments", "--walk");
  check_refused("--engine cpu --walk passes", "--walk");
}

TEST_CASE("the looping kernels' options are checked before any work") {
  check_refused("--kernels loops", "--kernels");
  check_refused("--kernels looping --steps-per-pass 0", "--steps-per-pass");
  check_refused("--kernels looping --steps-per-pass 5000", "--steps-per-pass");
  check_refused("--steps-per-pass 8", "--steps-per-pass");
  check_refused("--engine cpu --kernels looping", "--kernels looping");
}

TEST_CASE("a looping render on a profile without loops or past its loop limit names the program") {
  for (const char* args : {"--kernels looping", "--kernels looping --profile r300",
                           "--kernels looping --profile gf6600 --steps-per-pass 256"}) {
    const Outcome o = run(std::string("render bunny-low -q --stats none --size 16x16 ") + args);
    INFO("vgpu-rt render " << args << " -> " << o.err);
    CHECK(o.status != 0);
    CHECK(o.err.find("program 'looping traversal'") != std::string::npos);
    CHECK(std::count(o.err.begin(), o.err.end(), '\n') == 1);
  }
  CHECK(run("render bunny-low -q --stats none --size 16x16 --kernels looping --profile gf6600 "
            "--steps-per-pass 255")
            .status == 0);
}
