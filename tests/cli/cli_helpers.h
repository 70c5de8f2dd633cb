// The CLI tests' helpers (test_cli.cpp, test_cli_frames.cpp): run vgpu-rt with arguments and
// capture its exit status and output, check a refusal's one line, and read back the headers of
// the PNG and EXR files it writes and compare's verdict.
#pragma once

#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace clitest {

namespace fs = std::filesystem;

struct Outcome {
  int status = -1;
  std::string out, err;  // everything written on stdout, on stderr
};

// An empty folder of this process under the system's temporary one: vgpu_cli_TAG_PID.
inline fs::path fresh_dir(const std::string& tag) {
  const fs::path dir =
      fs::temp_directory_path() / ("vgpu_cli_" + tag + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

inline std::string slurp(const fs::path& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Runs `vgpu-rt ARGS` through the shell, stdout and stderr captured in files.
inline Outcome run(const std::string& args) {
  const std::string id = std::to_string(::getpid());
  const fs::path out = fs::temp_directory_path() / ("vgpu_cli_out_" + id),
                 err = fs::temp_directory_path() / ("vgpu_cli_err_" + id);
  // Under the sanitizer build, LeakSanitizer's own thread-stopping tracer crashed (signal 11 in
  // its StopTheWorld) at the exit of a successful render started from this test process, though
  // not from a shell or from a plain ASan parent: the child's leak check is off here (its
  // AddressSanitizer and UndefinedBehaviorSanitizer checks stay on); the code it runs is
  // leak-checked by the library tests.
  const std::string cmd = "ASAN_OPTIONS=\"${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0\" " +
                          std::string(VGPU_RT) + " " + args + " >" + out.string() + " 2>" +
                          err.string();
  const int raw = std::system(cmd.c_str());
  Outcome o;
  o.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  o.out = slurp(out);
  o.err = slurp(err);
  fs::remove(out);
  fs::remove(err);
  return o;
}

// An error as main() prints it: one line on stderr, "vgpu-rt: ", naming `what` (the option or
// the file) and `problem`; nothing on stdout.
inline void check_one_line(const Outcome& o, const std::string& what, const std::string& problem) {
  CHECK(o.err.rfind("vgpu-rt: ", 0) == 0);
  CHECK(std::count(o.err.begin(), o.err.end(), '\n') == 1);
  CHECK(o.err.back() == '\n');
  CHECK_MESSAGE(o.err.find(what) != std::string::npos, "names '" << what << "'");
  CHECK_MESSAGE(o.err.find(problem) != std::string::npos, "says '" << problem << "'");
  CHECK(o.out.empty());
}

// One refused render: exit 2, one line naming `option` and saying `problem`, no image written.
inline void check_refused(const std::string& args, const std::string& option,
                          const std::string& problem) {
  const fs::path out =
      fs::temp_directory_path() / ("vgpu_cli_image_" + std::to_string(::getpid()) + ".png");
  const Outcome o = run("render bunny-low -q --stats none --out " + out.string() + " " + args);
  INFO("vgpu-rt render " << args << " -> " << o.err);
  CHECK(o.status == 2);
  check_one_line(o, option, problem);
  CHECK_FALSE(fs::exists(out));
}

// The IHDR of a PNG file: size, bit depth and colour type (2: RGB).
struct Png {
  uint32_t width = 0, height = 0;
  int bit_depth = 0, colour_type = -1;
};

inline Png read_png_header(const fs::path& path) {
  const std::string b = slurp(path);
  Png p;
  if (b.size() < 26 || b.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0 || b.compare(12, 4, "IHDR") != 0)
    return p;
  auto be32 = [&b](size_t at) {
    uint32_t v = 0;
    for (size_t i = 0; i < 4; ++i) v = v << 8 | uint8_t(b[at + i]);
    return v;
  };
  p.width = be32(16);
  p.height = be32(20);
  p.bit_depth = uint8_t(b[24]);
  p.colour_type = uint8_t(b[25]);
  return p;
}

// The header of an OpenEXR file: its channels (name, pixel type: 1 half, 2 float) and data
// window (xmin, ymin, xmax, ymax), read by hand (the format's little-endian attribute list).
struct Exr {
  bool ok = false;
  std::vector<std::pair<std::string, int32_t>> channels;
  int32_t window[4] = {-1, -1, -1, -1};
};

inline Exr read_exr_header(const fs::path& path) {
  const std::string b = slurp(path);
  Exr e;
  if (b.size() < 8 || b.compare(0, 4, "\x76\x2f\x31\x01") != 0) return e;
  size_t at = 8;
  auto word = [&](std::string& s) {
    const size_t end = b.find('\0', at);
    if (end == std::string::npos) return false;
    s = b.substr(at, end - at);
    at = end + 1;
    return true;
  };
  for (;;) {
    std::string name, type;
    if (!word(name)) return e;
    if (name.empty()) break;  // the header's end
    int32_t size = 0;
    if (!word(type) || at + 4 > b.size()) return e;
    std::memcpy(&size, b.data() + at, 4);
    at += 4;
    if (size < 0 || at + size_t(size) > b.size()) return e;
    const std::string value = b.substr(at, size_t(size));
    at += size_t(size);
    if (name == "channels" && type == "chlist") {
      // name, int32 pixel type, pLinear + 3 reserved bytes, int32 x and y sampling; then a 0.
      for (size_t p = 0; p < value.size() && value[p] != '\0';) {
        const size_t end = value.find('\0', p);
        if (end == std::string::npos || end + 17 > value.size()) return e;
        int32_t pixel_type = 0;
        std::memcpy(&pixel_type, value.data() + end + 1, 4);
        e.channels.emplace_back(value.substr(p, end - p), pixel_type);
        p = end + 17;
      }
    }
    if (name == "dataWindow" && type == "box2i" && size == 16)
      std::memcpy(e.window, value.data(), 16);
  }
  e.ok = true;
  return e;
}

// `vgpu-rt compare A B --threshold T`: the image size, channels and the share of pixels (in %)
// that differ by more than T.
struct Comparison {
  int width = 0, height = 0, channels = 0;
  double differing_percent = -1;
};

inline Comparison compare(const fs::path& a, const fs::path& b, double threshold) {
  const Outcome o =
      run("compare " + a.string() + " " + b.string() + " --threshold " + std::to_string(threshold));
  INFO("vgpu-rt compare " << a << " " << b << " -> " << o.out << o.err);
  CHECK(o.status == 0);
  Comparison c;
  CHECK(std::sscanf(o.out.c_str(), "%dx%d, %d channels: %lf%%", &c.width, &c.height, &c.channels,
                    &c.differing_percent) == 4);
  return c;
}

// Renders `common` once per --update mode into dir: hit and depth AOVs per frame
// (MODE_hit_#.exr, MODE_depth_#.exr) and the statistics (MODE.json).
inline void render_update_modes(const std::string& common, const fs::path& dir,
                                std::initializer_list<const char*> modes) {
  for (const char* mode : modes) {
    const std::string m(mode);
    const Outcome o =
        run(common + " --update " + m + " --aov hit=" + (dir / (m + "_hit_#.exr")).string() +
            " --aov depth=" + (dir / (m + "_depth_#.exr")).string() + " --stats-json " +
            (dir / (m + ".json")).string());
    INFO(m << ": " << o.err);
    REQUIRE(o.status == 0);
  }
}

// Frame n's hit ids and depths of --update mode `b` equal mode `a`'s, pixel for pixel.
inline void check_same_hits(const fs::path& dir, const std::string& a, const std::string& b,
                            int n) {
  const std::string f = std::to_string(n);
  CHECK(compare(dir / (a + "_hit_" + f + ".exr"), dir / (b + "_hit_" + f + ".exr"), 0)
            .differing_percent == 0);
  CHECK(compare(dir / (a + "_depth_" + f + ".exr"), dir / (b + "_depth_" + f + ".exr"), 0)
            .differing_percent == 0);
}

}  // namespace clitest
