// The command line as a user meets it: every bad option value is refused by CLI11's validators
// (or a check of option combinations) with one line on stderr that names the option or file and
// the problem, exit status 2 and no output file; a successful render writes the image, the AOVs
// and the statistics asked for, in their formats and at the image's size, and nothing else.
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
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

namespace fs = std::filesystem;

struct Outcome {
  int status = -1;
  std::string out, err;  // everything written on stdout, on stderr
};

std::string slurp(const fs::path& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Runs `vgpu-rt ARGS` through the shell, stdout and stderr captured in files.
Outcome run(const std::string& args) {
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
void check_one_line(const Outcome& o, const std::string& what, const std::string& problem) {
  CHECK(o.err.rfind("vgpu-rt: ", 0) == 0);
  CHECK(std::count(o.err.begin(), o.err.end(), '\n') == 1);
  CHECK(o.err.back() == '\n');
  CHECK_MESSAGE(o.err.find(what) != std::string::npos, "names '" << what << "'");
  CHECK_MESSAGE(o.err.find(problem) != std::string::npos, "says '" << problem << "'");
  CHECK(o.out.empty());
}

// One refused render: exit 2, one line naming `option` and saying `problem`, no image written.
void check_refused(const std::string& args, const std::string& option, const std::string& problem) {
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

Png read_png_header(const fs::path& path) {
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

Exr read_exr_header(const fs::path& path) {
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

Comparison compare(const fs::path& a, const fs::path& b, double threshold) {
  const Outcome o =
      run("compare " + a.string() + " " + b.string() + " --threshold " + std::to_string(threshold));
  INFO("vgpu-rt compare " << a << " " << b << " -> " << o.out << o.err);
  CHECK(o.status == 0);
  Comparison c;
  CHECK(std::sscanf(o.out.c_str(), "%dx%d, %d channels: %lf%%", &c.width, &c.height, &c.channels,
                    &c.differing_percent) == 4);
  return c;
}

}  // namespace

TEST_CASE("out-of-range numbers are refused with their allowed range") {
  check_refused("--threads -3", "--threads", "-3 not in range 0 to 256");
  check_refused("--threads 100000", "--threads", "100000 not in range 0 to 256");
  check_refused("--bounces 65", "--bounces", "65 not in range 0 to 64");
  check_refused("--lanes 3", "--lanes", "3 not in {1,4,8,16}");
}

TEST_CASE("sample counts that are not squares from 1 to 256 are refused, naming the count") {
  check_refused("--spp 0", "--spp", "0 samples per pixel: they go from 1 to 256");
  check_refused("--spp 7", "--spp", "7 samples per pixel: not a square");
  check_refused("--spp 1024", "--spp", "1024 samples per pixel: they go from 1 to 256");
  check_refused("--spp four", "--spp", "expected a square from 1 to 256, got 'four'");
  check_refused("--aa magic", "--aa",
                "expected none, adaptive, undersample or undersample:K (K 1 to 64), got 'magic'");
  check_refused("--aa undersample:0", "--aa",
                "expected none, adaptive, undersample or undersample:K (K 1 to 64), got "
                "'undersample:0'");
  check_refused("--aa undersample --spp 4", "--aa undersample",
                "traces one ray per traced pixel; drop --spp 4");
  check_refused("--aa adaptive --aa-threshold -0.5", "--aa-threshold",
                "expected a colour difference of 0 or more (linear, 1 = white), got '-0.5'");
  check_refused("--aa adaptive --aa-threshold nan", "--aa-threshold",
                "expected a colour difference of 0 or more (linear, 1 = white), got 'nan'");
}

TEST_CASE("an image size past the limit names the limit, not a parse failure") {
  const Outcome o = run("render bunny-low --size 100000x100000");
  CHECK(o.status == 2);
  check_one_line(o, "--size", "100000x100000 is outside the limit 1x1..16384x16384");
  CHECK(o.err.find("parse") == std::string::npos);
  check_refused("--size 0x10", "--size", "0x10 is outside the limit 1x1..16384x16384");
  check_refused("--size 12", "--size", "expected WxH (e.g. 256x256), got '12'");
}

TEST_CASE("names outside each option's set are refused") {
  check_refused("--shading glossy", "--shading", "glossy not in {diffuse,phong,phong-atten}");
  check_refused("--shadows yes", "--shadows", "yes not in {on,off}");
  check_refused("--profile gf9", "--profile", "gf9 not in {gf5700,r300,gf6600,rtx4090,h200}");
  check_refused("--precision fp8", "--precision", "fp8 not in {fp32,fp24,fp16,auto}");
  check_refused("--engine gpu", "--engine", "gpu not in {stream,gl,cpu}");
  check_refused("--stats xml", "--stats", "xml not in {table,json,none}");
  check_refused("--grid 0", "--grid", "grid resolution '0': each count must be at least 1");
  check_refused("--trace-pixel 3", "--trace-pixel", "expected X,Y (e.g. 128,128), got '3'");
  check_refused("--trace-pixel 300,2", "--trace-pixel", "300,2 is outside the 256x256 image");
}

TEST_CASE("AOVs are float EXR files only") {
  const std::string png = (fs::temp_directory_path() / "d.png").string();
  check_refused("--aov depth=" + png, "--aov", png + ": unsupported extension '.png' (use .exr)");
  check_refused("--aov normal=" + (fs::temp_directory_path() / "n.exr").string(), "--aov",
                "unknown AOV 'normal'");
  check_refused("--aov depth=", "--aov", "expected depth=FILE.exr or hit=FILE.exr, got 'depth='");
}

TEST_CASE("output files need a known extension and an existing directory") {
  const Outcome o = run("render bunny-low --out /no/such/dir/a.png");
  CHECK(o.status == 2);
  check_one_line(o, "--out", "/no/such/dir/a.png: directory /no/such/dir does not exist");
  const Outcome j = run("render bunny-low --out a.jpg");
  CHECK(j.status == 2);
  check_one_line(j, "--out", "a.jpg: unsupported extension '.jpg' (use .png or .exr)");
  CHECK_FALSE(fs::exists("a.jpg"));
  const std::string txt = (fs::temp_directory_path() / "s.txt").string();
  check_refused("--stats-json " + txt, "--stats-json",
                txt + ": unsupported extension '.txt' (use .json)");
  CHECK_FALSE(fs::exists(txt));
}

TEST_CASE("a scene that is neither a file nor a bundled name is refused, naming it") {
  const Outcome o = run("render /no/such/scene.gltf -q --stats none");
  CHECK(o.status != 0);
  check_one_line(o, "/no/such/scene.gltf", "no such file or scene");
}

TEST_CASE("MRT fusion is refused with the looping kernels, which have no passes left to fuse") {
  check_refused("--profile gf6600 --kernels looping --mrt on", "--mrt on with --kernels looping",
                "no separate passes left to fuse");
}

TEST_CASE("GL device settings are refused without the GL engine and checked against their set") {
  check_refused("--gl-readback poll", "--gl-readback", "needs --engine gl");
  check_refused("--engine cpu --gl-device 0", "--gl-device", "needs --engine gl");
  check_refused("--engine gl --gl-readback spin", "--gl-readback", "spin not in {auto,block,poll}");
}

TEST_CASE("settings the cpu engine does not use are refused instead of recorded") {
  for (const char* option : {"--lanes 8", "--precision fp16", "--masks on", "--predict",
                             "--trace-pixel 1,1", "--mrt on"}) {
    const std::string name = std::string(option).substr(0, std::string(option).find(' '));
    check_refused(std::string("--engine cpu ") + option, name, "needs --engine stream");
  }
}

TEST_CASE("mrt on a profile with one output is refused, naming the fused program and the limit") {
  check_refused(
      "--mrt on --profile gf5700", "--mrt on",
      "program 'intersections + next triangle' writes 2 outputs; profile gf5700 allows 1");
  check_refused("--mrt maybe", "--mrt", "maybe not in {on,off}");
  // Mixed arithmetic in the fused groups: refused once the formats are known.
  check_refused("--mrt on --profile gf6600 --lanes 8 --formats hits=fp16", "--mrt on",
                "groups hits (fp16) and voxel (fp32) differ");
}

TEST_CASE("reduced precision refuses lane widths it does not run at") {
  check_refused("--lanes 4 --precision fp24", "--lanes 4", "--precision fp24 runs at 1 or 8 lanes");
  check_refused("--lanes 16 --precision fp16", "--lanes 16",
                "--precision fp16 runs at 1 or 8 lanes");
}

TEST_CASE("compare refuses missing files and negative thresholds") {
  const Outcome o = run("compare /no/such/a.png /no/such/b.png");
  CHECK(o.status == 2);
  check_one_line(o, "/no/such/a.png", "does not exist");
  const Outcome t = run("compare /dev/null /dev/null --threshold -1");
  CHECK(t.status == 2);
  check_one_line(t, "--threshold", "-1 not in range 0");
}

TEST_CASE("help lists each option's allowed values and exits with 0") {
  const Outcome o = run("render --help");
  CHECK(o.status == 0);
  CHECK(o.err.empty());
  for (const char* allowed :
       {"{diffuse,phong,phong-atten}", "[0 - 256]", "{1,4,8,16}",
        "{gf5700,r300,gf6600,rtx4090,h200}", "{stream,gl,cpu}", "1x1..16384x16384",
        "depth=FILE.exr", "{multipass,looping}", "[1 - 4096]", "{batches,passes}"})
    CHECK_MESSAGE(o.out.find(allowed) != std::string::npos, allowed);
}

TEST_CASE("the walk option is checked against its set and refused off the stream engine") {
  check_refused("--walk fragments", "--walk", "fragments not in {batches,passes}");
  check_refused("--engine cpu --walk passes", "--walk", "needs --engine stream");
}

TEST_CASE("the looping kernels' options are checked before any work") {
  check_refused("--kernels loops", "--kernels", "loops not in {multipass,looping}");
  check_refused("--kernels looping --steps-per-pass 0", "--steps-per-pass",
                "0 not in range 1 to 4096");
  check_refused("--kernels looping --steps-per-pass 5000", "--steps-per-pass",
                "5000 not in range 1 to 4096");
  check_refused("--steps-per-pass 8", "--steps-per-pass", "needs --kernels looping");
  check_refused("--engine cpu --kernels looping", "--kernels looping", "needs --engine stream");
}

TEST_CASE("a looping render on a profile without loops or past its loop limit names the program") {
  const std::pair<const char*, const char*> cases[] = {
      {"--kernels looping", "profile gf5700 (fp30) has no dynamic branching or loops"},
      {"--kernels looping --profile r300",
       "profile r300 (arbfp1) has no dynamic branching or loops"},
      {"--kernels looping --profile gf6600 --steps-per-pass 256",
       "loops up to 256 iterations; profile gf6600 allows 255"}};
  for (const auto& [args, problem] : cases) {
    const Outcome o = run(std::string("render bunny-low -q --stats none --size 16x16 ") + args);
    INFO("vgpu-rt render " << args << " -> " << o.err);
    CHECK(o.status != 0);
    check_one_line(o, "program 'looping traversal'", problem);
  }
  CHECK(run("render bunny-low -q --stats none --size 16x16 --kernels looping --profile gf6600 "
            "--steps-per-pass 255")
            .status == 0);
}

TEST_CASE("a render writes the image, the AOVs and the statistics asked for, and nothing else") {
  const fs::path dir =
      fs::temp_directory_path() / ("vgpu_cli_render_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string common = "render sphere --size 48x40 -q --stats none";
  const Outcome o = run(common + " --out " + (dir / "image.png").string() + " --aov depth=" +
                        (dir / "depth.exr").string() + " --aov hit=" + (dir / "hit.exr").string() +
                        " --stats-json " + (dir / "stats.json").string());
  INFO("vgpu-rt " << common << " ... -> " << o.err);
  REQUIRE(o.status == 0);
  CHECK(o.err.empty());  // -q: no progress
  CHECK(o.out.empty());  // --stats none
  // The files asked for (written under temporary names and renamed: none left behind).
  std::set<std::string> written;
  for (const auto& entry : fs::directory_iterator(dir)) written.insert(entry.path().filename());
  CHECK(written == std::set<std::string>{"depth.exr", "hit.exr", "image.png", "stats.json"});

  // The image: an 8-bit RGB PNG at the image size (48 wide, 40 high, not transposed).
  const Png png = read_png_header(dir / "image.png");
  CHECK(png.width == 48);
  CHECK(png.height == 40);
  CHECK(png.bit_depth == 8);
  CHECK(png.colour_type == 2);
  // The AOVs: one float channel each, over the image's pixels.
  for (const char* aov : {"depth.exr", "hit.exr"}) {
    CAPTURE(aov);
    const Exr e = read_exr_header(dir / aov);
    REQUIRE(e.ok);
    REQUIRE(e.channels.size() == 1);
    CHECK(e.channels[0].second == 2);  // FLOAT, not HALF
    CHECK(e.window[0] == 0);
    CHECK(e.window[1] == 0);
    CHECK(e.window[2] == 47);
    CHECK(e.window[3] == 39);
  }
  // What they hold: the cpu engine (the double-precision reference, its own code) gives the
  // same distances and triangle ids; its image as a float EXR has three float channels.
  const Outcome cpu = run(common + " --engine cpu --out " + (dir / "cpu.exr").string() +
                          " --aov depth=" + (dir / "cpu_depth.exr").string() +
                          " --aov hit=" + (dir / "cpu_hit.exr").string());
  REQUIRE(cpu.status == 0);
  const Exr rgb = read_exr_header(dir / "cpu.exr");
  REQUIRE(rgb.ok);
  REQUIRE(rgb.channels.size() == 3);
  for (const auto& [name, type] : rgb.channels) {
    CAPTURE(name);
    CHECK(type == 2);
  }
  CHECK(rgb.window[2] == 47);
  CHECK(rgb.window[3] == 39);
  const Comparison depth = compare(dir / "depth.exr", dir / "cpu_depth.exr", 1e-3);
  CHECK(depth.width == 48);
  CHECK(depth.height == 40);
  CHECK(depth.channels == 1);
  CHECK(depth.differing_percent <= 0.5);
  const Comparison hit = compare(dir / "hit.exr", dir / "cpu_hit.exr", 0.5);
  CHECK(hit.channels == 1);
  CHECK(hit.differing_percent <= 0.5);
  // And the two AOVs are not one buffer written twice.
  CHECK(compare(dir / "depth.exr", dir / "hit.exr", 0.5).differing_percent > 50);

  // The statistics: the keys README.md promises, with this run's values.
  nlohmann::json j;
  REQUIRE_NOTHROW(j = nlohmann::json::parse(slurp(dir / "stats.json")));
  for (const char* key :
       {"scene", "triangles", "grid", "profile", "size", "init_ms", "render_ms", "totals",
        "kernels", "masks", "mrt", "fused_programs", "kernel_variant", "sampling"})
    CHECK_MESSAGE(j.contains(key), key);
  CHECK(j.value("scene", "") == "sphere");
  CHECK(j.value("profile", "") == "gf5700");
  CHECK(j["size"] == nlohmann::json::array({48, 40}));
  REQUIRE(j["grid"].size() == 3);
  for (const auto& n : j["grid"]) CHECK(n.get<int>() > 0);
  CHECK(j["triangles"].get<int>() > 0);
  CHECK(j["init_ms"].is_number());
  CHECK(j["render_ms"].get<double>() > 0);
  CHECK(j["masks"] == false);
  CHECK(j["mrt"] == false);
  CHECK(j["fused_programs"] == nlohmann::json::array());
  CHECK(j["kernel_variant"] == "multipass");
  CHECK(j["sampling"] == nlohmann::json({{"mode", "uniform"},
                                         {"spp", 1},
                                         {"samples_per_pixel_mean", 1.0},
                                         {"samples_per_pixel_max", 1},
                                         {"passes_added", 0}}));
  const nlohmann::json& totals = j["totals"];
  for (const char* key : {"passes", "fragments_launched", "fragments_shaded", "texture_fetches",
                          "bytes_read", "bytes_written", "program_loads", "query_readbacks"}) {
    CAPTURE(key);
    REQUIRE(totals.contains(key));
    CHECK(totals[key].get<uint64_t>() > 0);
  }
  // Every pass of the stream tracer draws the whole image.
  CHECK(totals["fragments_launched"].get<uint64_t>() == totals["passes"].get<uint64_t>() * 48 * 40);
  // One entry per kernel, whose counters add up to the totals.
  REQUIRE(j["kernels"].is_array());
  uint64_t passes = 0, readbacks = 0;
  std::set<std::string> names;
  for (const auto& k : j["kernels"]) {
    REQUIRE(k.contains("name"));
    REQUIRE(k.contains("paper_name"));
    names.insert(k["name"].get<std::string>());
    passes += k["passes"].get<uint64_t>();
    readbacks += k["query_readbacks"].get<uint64_t>();
  }
  CHECK(passes == totals["passes"].get<uint64_t>());
  CHECK(readbacks == totals["query_readbacks"].get<uint64_t>());
  for (const char* kernel :
       {"generate rays", "init traversal", "rays in grid", "traversal", "intersections", "shader"})
    CHECK_MESSAGE(names.count(kernel) == 1, kernel);
  fs::remove_all(dir);
}

// --accel kdtree and --accel auto (tests/trace/test_kd_walk.cpp tests the walk itself).
namespace {

// A render of bunny-low at 32x32 with the statistics JSON read back; "" args added.
nlohmann::json render_json(const std::string& args, const fs::path& dir, Outcome& o) {
  fs::remove_all(dir);
  fs::create_directories(dir);
  o = run("render bunny-low --size 32x32 -q --stats none --out " + (dir / "image.png").string() +
          " --stats-json " + (dir / "stats.json").string() + " " + args);
  if (o.status != 0 || !fs::exists(dir / "stats.json")) return nlohmann::json();
  return nlohmann::json::parse(slurp(dir / "stats.json"));
}

}  // namespace

TEST_CASE("accel kdtree renders and its JSON names the kd-tree with its nodes, leaves and depth") {
  const fs::path dir = fs::temp_directory_path() / ("vgpu_cli_kd_" + std::to_string(::getpid()));
  Outcome o;
  const nlohmann::json j = render_json("--accel kdtree", dir, o);
  INFO("vgpu-rt render --accel kdtree -> " << o.err);
  REQUIRE(o.status == 0);
  CHECK(o.err.empty());
  CHECK(read_png_header(dir / "image.png").width == 32);
  REQUIRE(j.contains("accel"));
  const nlohmann::json& a = j["accel"];
  CHECK(a["structure"] == "kdtree");
  const uint64_t nodes = a["nodes"].get<uint64_t>(), leaves = a["leaves"].get<uint64_t>();
  CHECK(leaves > 1);
  CHECK(nodes == 2 * leaves - 1);  // every inner node has two children
  CHECK(a["depth"].get<int>() > 1);
  CHECK(a["max_leaf"].get<int>() > 0);
  CHECK(a["references"].get<uint64_t>() > 0);
  CHECK(a["work"]["nodes_visited"].get<uint64_t>() > 0);
  CHECK(a["work"]["triangle_tests"].get<uint64_t>() > 0);
  CHECK(a["work"]["voxel_steps"].get<uint64_t>() == 0);
  CHECK(a["work"]["restarts"].get<int64_t>() > 0);  // from cargarHojaKd's passes
  CHECK_FALSE(a.contains("auto"));
  fs::remove_all(dir);
}

TEST_CASE("accel grid2 renders and its JSON gives the coarse grid, crowded cells and sub-cells") {
  const fs::path dir = fs::temp_directory_path() / ("vgpu_cli_g2_" + std::to_string(::getpid()));
  Outcome o;
  const nlohmann::json j = render_json("--accel grid2", dir, o);
  INFO("vgpu-rt render --accel grid2 -> " << o.err);
  REQUIRE(o.status == 0);
  CHECK(o.err.empty());
  CHECK(read_png_header(dir / "image.png").width == 32);
  REQUIRE(j.contains("accel"));
  const nlohmann::json& a = j["accel"];
  CHECK(a["structure"] == "grid2");
  REQUIRE(a["coarse"].size() == 3);
  uint64_t cells = 1;
  for (const auto& r : a["coarse"]) cells *= r.get<uint64_t>();
  CHECK(a["crowded_cells"].get<uint64_t>() > 0);
  CHECK(a["crowded_cells"].get<uint64_t>() <= cells);
  CHECK(a["sub_cells"].get<uint64_t>() > cells);  // some cells are cut
  // Every sub-cell's list ends with a -1, and entry 0 is the empty cells' shared -1.
  CHECK(a["list_entries"].get<uint64_t>() > a["references"].get<uint64_t>());
  CHECK(a["max_list"].get<int>() > 0);
  CHECK(a["work"]["voxel_steps"].get<uint64_t>() > 0);
  CHECK(a["work"]["triangle_tests"].get<uint64_t>() > 0);
  CHECK(a["work"]["nodes_visited"].get<uint64_t>() == 0);
  CHECK(a["work"]["restarts"].is_null());  // no kd-tree
  fs::remove_all(dir);
}

TEST_CASE(
    "accel auto's JSON gives the predicted time of the grid, the BVH and the kd-tree and why") {
  const fs::path dir = fs::temp_directory_path() / ("vgpu_cli_auto_" + std::to_string(::getpid()));
  Outcome o;
  const nlohmann::json j = render_json("--accel auto", dir, o);
  INFO("vgpu-rt render --accel auto -> " << o.err);
  REQUIRE(o.status == 0);
  REQUIRE(j.contains("accel"));
  const nlohmann::json& a = j["accel"];
  REQUIRE(a.contains("auto"));
  const nlohmann::json& au = a["auto"];
  const std::string chosen = a["structure"].get<std::string>();
  CHECK((chosen == "grid" || chosen == "grid2" || chosen == "bvh" || chosen == "kdtree"));
  REQUIRE(au["predicted_ms"].is_object());
  CHECK(au["predicted_ms"].size() == 4);
  double best = 1e300;
  for (const char* k : {"grid", "grid2", "bvh", "kdtree"}) {
    CAPTURE(k);
    REQUIRE(au["predicted_ms"].contains(k));
    CHECK(au["predicted_ms"][k].get<double>() > 0);
    best = std::min(best, au["predicted_ms"][k].get<double>());
  }
  // The cheapest was taken, or the grid where nothing is predicted 10% cheaper than it.
  const double grid_ms = au["predicted_ms"]["grid"].get<double>();
  if (chosen == "grid")
    CHECK(best >= (1.0 - 0.10) * grid_ms);
  else
    CHECK(au["predicted_ms"][chosen].get<double>() == best);
  CHECK((best < (1.0 - 0.10) * grid_ms) == (chosen != "grid"));
  const std::string why = au["why"].get<std::string>();
  CHECK(why.rfind(chosen + " predicted ", 0) == 0);  // a sentence naming the choice first
  CHECK(why.find('\n') == std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("an unknown acceleration structure is refused with one line, exit 2 and no image") {
  check_refused("--accel nonsense", "--accel", "nonsense");
}

TEST_CASE("the texture filter is checked against its set and listed in --help") {
  check_refused("--texture-filter anisotropic", "--texture-filter",
                "anisotropic not in {nearest,bilinear,trilinear}");
  const Outcome o = run("render --help");
  CHECK(o.out.find("--texture-filter") != std::string::npos);
  CHECK(o.out.find("nearest,bilinear,trilinear") != std::string::npos);
}

TEST_CASE("a texture that cannot be read or a UV accessor of the wrong type: one line, no image") {
  const std::string data = std::string(VGPU_TEST_DATA) + "/gltf/";
  const fs::path out =
      fs::temp_directory_path() / ("vgpu_cli_texture_" + std::to_string(::getpid()) + ".png");
  struct Case {
    const char* file;
    const char* problem;
  };
  for (const Case& c :
       {Case{"texture_missing.gltf", "image 0 (no_such_texture.png): cannot read"},
        Case{"texture_not_an_image.gltf",
             "image 0: cannot read the image: not a PNG or JPEG image"},
        // libpng reports a PNG cut short on stderr too: still one line.
        Case{"texture_truncated.gltf", "image 0: cannot read the image: "},
        Case{"texcoord_vec3.gltf", "TEXCOORD_0: accessor 0 must be VEC2 of float"}}) {
    CAPTURE(c.file);
    for (const char* engine : {"stream", "cpu"}) {
      CAPTURE(engine);
      const Outcome o = run("render " + data + c.file + " -q --stats none --engine " + engine +
                            " --out " + out.string());
      CHECK(o.status != 0);
      check_one_line(o, data + c.file, c.problem);
      CHECK_FALSE(fs::exists(out));
    }
  }
}

TEST_CASE("a textured glb renders through the CLI, its JSON naming the textures and the filter") {
  const std::string id = std::to_string(::getpid());
  const fs::path out = fs::temp_directory_path() / ("vgpu_cli_duck_" + id + ".png"),
                 js = fs::temp_directory_path() / ("vgpu_cli_duck_" + id + ".json");
  const Outcome o = run("render " + std::string(VGPU_TEST_DATA) +
                        "/gltf/textured.glb -q --stats none --size 32x32 --texture-filter bilinear "
                        "--out " +
                        out.string() + " --stats-json " + js.string());
  INFO(o.err);
  REQUIRE(o.status == 0);
  CHECK(fs::exists(out));
  const auto j = nlohmann::json::parse(slurp(js));
  CHECK(j["textures"] == 1);
  CHECK(j["texture_filter"] == "bilinear");
  // An untextured scene's JSON has neither.
  const Outcome plain =
      run("render bunny-low -q --stats none --size 16x16 --stats-json " + js.string());
  REQUIRE(plain.status == 0);
  const auto p = nlohmann::json::parse(slurp(js));
  CHECK_FALSE(p.contains("textures"));
  CHECK_FALSE(p.contains("texture_filter"));
  fs::remove(out);
  fs::remove(js);
}

TEST_CASE("--accel bvh renders and its statistics name the structure and the hierarchy") {
  const fs::path dir = fs::temp_directory_path() / ("vgpu_cli_bvh_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const char* accel : {"bvh", "grid"}) {
    CAPTURE(accel);
    const Outcome o =
        run("render sphere --size 32x24 -q --stats none --accel " + std::string(accel) + " --out " +
            (dir / "image.png").string() + " --stats-json " + (dir / "stats.json").string());
    INFO("-> " << o.err);
    REQUIRE(o.status == 0);
    CHECK(o.err.empty());
    CHECK(o.out.empty());
    CHECK(read_png_header(dir / "image.png").width == 32);
    nlohmann::json j;
    REQUIRE_NOTHROW(j = nlohmann::json::parse(slurp(dir / "stats.json")));
    REQUIRE(j.contains("accel"));
    const nlohmann::json& a = j["accel"];
    CHECK(a["structure"] == accel);
    CHECK(j["rays_unfinished"] == 0);
    CHECK(j["rays_traced"].get<uint64_t>() > 0);
    std::set<std::string> names;
    for (const auto& k : j["kernels"]) names.insert(k["name"].get<std::string>());
    if (std::string(accel) == "bvh") {
      for (const char* key :
           {"nodes", "leaves", "depth", "max_leaf", "references", "sah_cost", "build_ms"})
        CHECK_MESSAGE(a.contains(key), key);
      const uint64_t nodes = a["nodes"].get<uint64_t>(), leaves = a["leaves"].get<uint64_t>();
      CHECK(nodes == 2 * leaves - 1);
      CHECK(leaves > 1);
      CHECK(a["references"] == j["triangles"]);  // each triangle in one leaf
      CHECK(a["max_leaf"].get<int>() >= 1);
      CHECK(a["max_leaf"].get<int>() <= 4);
      CHECK(a["depth"].get<int>() > 1);
      CHECK(a["sah_cost"].get<double>() > 1);
      // The walk's work: nodes visited and triangles tested, no voxel steps.
      CHECK(a["work"]["nodes_visited"].get<uint64_t>() > 0);
      CHECK(a["work"]["triangle_tests"].get<uint64_t>() > 0);
      CHECK(a["work"]["voxel_steps"] == 0);
      // The one-voxel grid beside it gives the scene box only.
      CHECK(j["grid"] == nlohmann::json::array({1, 1, 1}));
      for (const char* kernel : {"bvh enter", "bvh step", "bvh load leaf", "bvh intersections"})
        CHECK_MESSAGE(names.count(kernel) == 1, kernel);
      CHECK(names.count("traversal") == 0);
    } else {
      CHECK(a["voxels"] == j["grid"]);
      CHECK(a.contains("references"));
      CHECK_FALSE(a.contains("nodes"));
      CHECK(a["work"]["voxel_steps"].get<uint64_t>() > 0);
      CHECK(a["work"]["nodes_visited"] == 0);
      CHECK(names.count("traversal") == 1);
      CHECK(names.count("bvh step") == 0);
    }
  }
  fs::remove_all(dir);
}

TEST_CASE("an unknown acceleration structure is refused, naming the option and the set") {
  check_refused("--accel magic", "--accel", "magic not in {grid,grid2,bvh,kdtree,auto}");
}

// ---- animation (issue 23): --time, --frames, --animation, --update

TEST_CASE("bad times and frame ranges are refused with one line naming the problem") {
  check_refused("--time soon", "--time",
                "expected seconds, a number of 0 or more (e.g. 1.5), got 'soon'");
  check_refused("--time nan", "--time", "got 'nan'");
  check_refused("--time inf", "--time", "got 'inf'");
  check_refused("--time=-1", "--time",
                "-1: times are seconds from the animation's start, 0 or more");
  check_refused("--frames 2:1:3", "--frames",
                "2:1:3: the first time (2 s) is after the last (1 s)");
  check_refused("--frames 0:1:0", "--frames", "0:1:0: the frame count must be 1 to 100000, got 0");
  check_refused("--frames 0:1:200000", "--frames", "the frame count must be 1 to 100000");
  check_refused("--frames=-1:1:3", "--frames",
                "-1:1:3: times are seconds from the animation's start, 0 or more");
  for (const char* bad : {"0:1", "0:1:2:3", "a:1:2", "0:1:2.5", "0:nan:2", ":1:2"})
    check_refused(std::string("--frames ") + bad, "--frames",
                  "expected A:B:N (N frames evenly from A to B seconds, e.g. 0:2:25), got '" +
                      std::string(bad) + "'");
  check_refused("--time 1 --frames 0:1:2", "--time and --frames", "give one");
  check_refused("--animation hop", "--animation", "needs --time or --frames");
  check_refused("--update rebuild", "--update", "needs --time or --frames");
  check_refused("--time 1 --update refit", "--update",
                "refit: only a BVH's boxes can be refitted (--accel bvh); the grid and the "
                "kd-tree are rebuilt (--update rebuild)");
  check_refused("--time 1 --update auto --accel kdtree", "--update",
                "auto: only a BVH's boxes can be refitted");
  check_refused("--time 1 --update sometimes", "--update",
                "expected rebuild, refit or auto, got 'sometimes'");
}

TEST_CASE("several frames need a '#' frame number in every output file name") {
  check_refused("--frames 0:1:3", "--out",
                "3 frames need '#' in the file name for the frame number");
  // '#' in a directory name is not a frame number.
  const fs::path dir = fs::temp_directory_path() / ("vgpu_cli_#_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const Outcome o =
      run("render bunny-low -q --stats none --frames 0:1:2 --out " + (dir / "a.png").string());
  CHECK(o.status == 2);
  check_one_line(o, "--out", "2 frames need '#'");
  const std::string hit = (fs::temp_directory_path() / "hit.exr").string();
  check_refused("--frames 0:1:2 --aov hit=" + hit, "--out", "2 frames need '#'");
  const Outcome aov = run("render bunny-low -q --stats none --frames 0:1:2 --aov hit=" + hit);
  CHECK(aov.status == 2);
  check_one_line(aov, "--aov " + hit, "2 frames need '#'");
  const Outcome report =
      run("render bunny-low -q --stats none --frames 0:1:2 --report " + (dir / "r.html").string());
  CHECK(report.status == 2);
  check_one_line(report, "--report", "follows one frame: render it with --time T");
  CHECK(fs::is_empty(dir));
  fs::remove_all(dir);
}

TEST_CASE("an unknown animation, a skinned mesh and morph-target weights are refused by name") {
  check_refused("--time 1 --animation walk", "--animation walk",
                "has no animation named or numbered 'walk' (it has none)");
  const fs::path out =
      fs::temp_directory_path() / ("vgpu_cli_anim_" + std::to_string(::getpid()) + ".png");
  const std::pair<std::string, std::string> cases[] = {
      {"hop --time 1 --animation 1", "has no animation named or numbered '1' (it has 0 'hop')"},
      {std::string(VGPU_TEST_DATA) + "/gltf/skinned.gltf --time 0.5",
       "node 0 uses skin 0; skinned meshes are not supported"},
      {std::string(VGPU_TEST_DATA) + "/gltf/morph_weights.gltf --time 0.5",
       "animation 0 channel 0 animates morph-target weights (node 0); morph targets are not "
       "supported"}};
  for (const auto& [args, problem] : cases) {
    const Outcome o = run("render " + args + " -q --stats none --out " + out.string());
    INFO("vgpu-rt render " << args << " -> " << o.err);
    CHECK(o.status == 2);
    check_one_line(o, "", problem);
    CHECK_FALSE(fs::exists(out));
  }
}

TEST_CASE("a multi-frame render writes numbered files and one statistics record per frame") {
  const fs::path dir =
      fs::temp_directory_path() / ("vgpu_cli_frames_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string size = " --size 40x32 --stats none";
  const Outcome o =
      run("render hop --frames 0:2:3" + size + " --out " + (dir / "frame_###.png").string() +
          " --aov hit=" + (dir / "hit_#.exr").string() + " --stats-json " +
          (dir / "frames.json").string());
  INFO(o.err);
  REQUIRE(o.status == 0);
  std::set<std::string> written;
  for (const auto& entry : fs::directory_iterator(dir)) written.insert(entry.path().filename());
  CHECK(written == std::set<std::string>{"frame_001.png", "frame_002.png", "frame_003.png",
                                         "hit_1.exr", "hit_2.exr", "hit_3.exr", "frames.json"});
  CHECK(read_png_header(dir / "frame_003.png").width == 40);
  // A progress line per frame on stderr.
  for (int f = 1; f <= 3; ++f)
    CHECK(o.err.find("vgpu-rt: frame " + std::to_string(f) + "/3 (t = " + std::to_string(f - 1) +
                     " s): update ") != std::string::npos);
  CHECK(std::count(o.err.begin(), o.err.end(), '\n') == 3);
  nlohmann::json j;
  REQUIRE_NOTHROW(j = nlohmann::json::parse(slurp(dir / "frames.json")));
  CHECK(j["scene"] == "hop");
  CHECK(j["animation"]["name"] == "hop");
  CHECK(j["animation"]["end"] == 2.0);
  CHECK(j["update"] == "rebuild");
  REQUIRE(j["frames"].size() == 3);
  for (int f = 0; f < 3; ++f) {
    CAPTURE(f);
    const nlohmann::json& r = j["frames"][size_t(f)];
    CHECK(r["frame"] == f + 1);
    CHECK(r["time"] == double(f));
    CHECK(r["size"] == nlohmann::json::array({40, 32}));
    CHECK(r["render_ms"].get<double>() > 0);
    CHECK(r["totals"]["passes"].get<uint64_t>() > 0);
    const nlohmann::json& u = r["update"];
    CHECK(u["mode"] == (f == 0 ? "initial" : "rebuild"));
    CHECK(u["build_ms"].get<double>() > 0);
    // The moving bunny and sphere change the vertices, normals and grid every frame; the
    // colours never change. The bus charge is the bytes over the profile's bus.
    const uint64_t bytes = u["uploaded_bytes"].get<uint64_t>();
    CHECK(bytes > 0);
    if (f > 0) {
      const auto& names = u["uploaded_textures"];
      CHECK(std::find(names.begin(), names.end(), "vertices0") != names.end());
      CHECK(std::find(names.begin(), names.end(), "triangle lists") != names.end());
      CHECK(std::find(names.begin(), names.end(), "colors") == names.end());
    }
    CHECK(u["predicted"]["gf5700"]["upload_ms"].get<double>() ==
          doctest::Approx(1e3 * double(bytes) / 2112e6));
    CHECK(u["predicted"]["gf5700"]["build_ms"] == u["build_ms"]);
  }
  CHECK(j["frames"][0]["update"]["uploaded_bytes"].get<uint64_t>() >
        j["frames"][1]["update"]["uploaded_bytes"].get<uint64_t>());
  // The frames differ, and a frame rendered alone at its time (a new tracer) is the same image
  // as the one the updated tracer rendered in the sequence.
  CHECK(compare(dir / "hit_1.exr", dir / "hit_2.exr", 0.5).differing_percent > 1);
  const Outcome one = run("render hop --time 1" + size + " --out " + (dir / "one.png").string() +
                          " --stats-json " + (dir / "one.json").string() + " -q");
  REQUIRE(one.status == 0);
  CHECK(compare(dir / "one.png", dir / "frame_002.png", 0).differing_percent == 0);
  // One frame keeps the single-frame statistics object, with its time and update added.
  const nlohmann::json single = nlohmann::json::parse(slurp(dir / "one.json"));
  CHECK_FALSE(single.contains("frames"));
  CHECK(single["time"] == 1.0);
  CHECK(single["update"]["mode"] == "initial");
  CHECK(single["totals"]["passes"] == j["frames"][1]["totals"]["passes"]);
  fs::remove_all(dir);
}

TEST_CASE("a refitted BVH gives the rebuilt BVH's hit ids and depths on every frame of hop") {
  const fs::path dir = fs::temp_directory_path() / ("vgpu_cli_refit_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string common = "render hop --accel bvh --frames 0:2:5 --size 48x40 -q --stats none";
  for (const char* mode : {"rebuild", "refit", "auto"}) {
    const std::string m(mode);
    const Outcome o =
        run(common + " --update " + m + " --aov hit=" + (dir / (m + "_hit_#.exr")).string() +
            " --aov depth=" + (dir / (m + "_depth_#.exr")).string() + " --stats-json " +
            (dir / (m + ".json")).string());
    INFO(m << ": " << o.err);
    REQUIRE(o.status == 0);
  }
  const nlohmann::json refit = nlohmann::json::parse(slurp(dir / "refit.json"));
  const nlohmann::json rebuild = nlohmann::json::parse(slurp(dir / "rebuild.json"));
  CHECK(refit["update"] == "refit");
  REQUIRE(refit["frames"].size() == 5);
  for (int f = 1; f <= 5; ++f) {
    CAPTURE(f);
    const std::string n = std::to_string(f);
    for (const char* mode : {"refit", "auto"}) {
      const std::string m(mode);
      CHECK(compare(dir / ("rebuild_hit_" + n + ".exr"), dir / (m + "_hit_" + n + ".exr"), 0)
                .differing_percent == 0);
      CHECK(compare(dir / ("rebuild_depth_" + n + ".exr"), dir / (m + "_depth_" + n + ".exr"), 0)
                .differing_percent == 0);
    }
    const nlohmann::json& u = refit["frames"][size_t(f - 1)]["update"];
    CHECK(u["mode"] == (f == 1 ? "initial" : "refit"));
    // A refit keeps the topology: the same node count as the first frame's build.
    CHECK(refit["frames"][size_t(f - 1)]["accel"]["nodes"] ==
          rebuild["frames"][0]["accel"]["nodes"]);
  }
  fs::remove_all(dir);
}

TEST_CASE("--report-frame puts frame K of a refitted sequence in the report and the pass CSV") {
  const fs::path dir =
      fs::temp_directory_path() / ("vgpu_cli_report_frame_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const Outcome o =
      run("render hop --accel bvh --update refit --frames 0:2:4 --size 32x24 -q "
          "--stats none --report " +
          (dir / "r.html").string() + " --report-frame 3 --stats-csv " + (dir / "p.csv").string() +
          " --stats-json " + (dir / "f.json").string());
  INFO(o.err);
  REQUIRE(o.status == 0);
  const nlohmann::json j = nlohmann::json::parse(slurp(dir / "f.json"));
  REQUIRE(j["frames"].size() == 4);
  // The CSV has a header and one row per pass of frame 3, none of the other frames'.
  const std::string csv = slurp(dir / "p.csv");
  const auto rows = uint64_t(std::count(csv.begin(), csv.end(), '\n'));
  CHECK(rows == 1 + j["frames"][2]["totals"]["passes"].get<uint64_t>());
  CHECK(j["frames"][2]["totals"]["passes"] != j["frames"][1]["totals"]["passes"]);
  // The report carries frame 3's record: its time and its refit.
  const std::string html = slurp(dir / "r.html");
  const std::string time = nlohmann::json(j["frames"][2]["time"]).dump();
  CHECK(html.find("\"frame\":3,\"time\":" + time) != std::string::npos);
  CHECK(html.find("\"mode\":\"refit\"") != std::string::npos);
  CHECK(html.find("\"frame\":4,") == std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("--report-frame is refused without --frames, without a report, or past the last frame") {
  const fs::path html =
      fs::temp_directory_path() / ("vgpu_cli_rf_" + std::to_string(::getpid()) + ".html");
  const std::string report = " --report " + html.string();
  for (const auto& [args, option, problem] : std::vector<std::array<std::string, 3>>{
           {"--time 1 --report-frame 1" + report, "--report-frame", "needs --frames"},
           {"--frames 0:1:2 --report-frame 1", "--report-frame", "needs --report or --stats-csv"},
           {"--frames 0:2:3 --report-frame 4" + report, "--report-frame 4",
            "--frames 0:2:3 gives 3 frames, numbered from 1"},
           {"--frames 0:2:3 --report-frame 0" + report, "--report-frame", "not in range"},
           {"--frames 0:1:2" + report, "--report",
            "follows one frame: render it with --time T, or name one of the frames with "
            "--report-frame K"}}) {
    const Outcome o = run("render bunny-low -q --stats none " + args);
    INFO(args << " -> " << o.err);
    CHECK(o.status == 2);
    check_one_line(o, option, problem);
    CHECK_FALSE(fs::exists(html));
  }
}

TEST_CASE("the frame table lists each frame's update, its passes and the nodes its walk visited") {
  const Outcome o = run("render hop --accel bvh --update auto --frames 0:2:3 --size 24x16 -q");
  INFO(o.err);
  REQUIRE(o.status == 0);
  std::istringstream lines(o.out);
  std::string line;
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> header;
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    std::vector<std::string> w;
    for (std::string x; words >> x;) w.push_back(x);
    if (!w.empty() && w[0] == "frame") header = w;
    if (!header.empty() && w.size() >= 11 && std::isdigit(static_cast<unsigned char>(w[0][0])))
      rows.push_back(w);
  }
  // frame, time s, update, pose ms, build ms, textures ms, uploaded B, render ms, passes, nodes,
  // voxels ("time s" and the "ms"/"B" units are words of their own).
  REQUIRE(header.size() >= 11);
  CHECK(std::find(header.begin(), header.end(), "update") != header.end());
  CHECK(std::find(header.begin(), header.end(), "nodes") != header.end());
  REQUIRE(rows.size() == 3);
  CHECK(rows[0][2] == "initial");
  CHECK(rows[1][2] == "refit");
  CHECK(rows[2][2] == "refit");
  for (const auto& r : rows) {
    CHECK(std::stoull(r[8]) > 0);    // passes
    CHECK(std::stoull(r[9]) > 0);    // nodes visited by the BVH walk
    CHECK(std::stoull(r[10]) == 0);  // no voxel steps: the grid is one voxel, never walked
  }
}

TEST_CASE("the scatter scene's refitted BVH hits what a rebuild hits while its SAH cost grows") {
  // scripts/scatter_scene.py writes the larger animation of docs/animation.md: ten full bunnies
  // that start inside one another and hop apart.
  const fs::path dir =
      fs::temp_directory_path() / ("vgpu_cli_scatter_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string script = std::string(VGPU_TEST_DATA) + "/../../scripts/scatter_scene.py";
  REQUIRE(std::system(("python3 " + script + " " + dir.string() + " >/dev/null").c_str()) == 0);
  const std::string common = "render " + (dir / "scatter.gltf").string() +
                             " --accel bvh --frames 0:0.5:3 --size 16x12 -q --stats none";
  for (const char* mode : {"rebuild", "refit"}) {
    const std::string m(mode);
    const Outcome o =
        run(common + " --update " + m + " --aov hit=" + (dir / (m + "_hit_#.exr")).string() +
            " --aov depth=" + (dir / (m + "_depth_#.exr")).string() + " --stats-json " +
            (dir / (m + ".json")).string());
    INFO(m << ": " << o.err);
    REQUIRE(o.status == 0);
  }
  const nlohmann::json refit = nlohmann::json::parse(slurp(dir / "refit.json"));
  const nlohmann::json rebuild = nlohmann::json::parse(slurp(dir / "rebuild.json"));
  REQUIRE(refit["frames"].size() == 3);
  CHECK(refit["frames"][0]["triangles"].get<int>() >= 30000);
  std::vector<double> ratio;
  for (int f = 1; f <= 3; ++f) {
    CAPTURE(f);
    const std::string n = std::to_string(f);
    CHECK(compare(dir / ("rebuild_hit_" + n + ".exr"), dir / ("refit_hit_" + n + ".exr"), 0)
              .differing_percent == 0);
    CHECK(compare(dir / ("rebuild_depth_" + n + ".exr"), dir / ("refit_depth_" + n + ".exr"), 0)
              .differing_percent == 0);
    ratio.push_back(refit["frames"][size_t(f - 1)]["accel"]["sah_cost"].get<double>() /
                    rebuild["frames"][size_t(f - 1)]["accel"]["sah_cost"].get<double>());
  }
  // Frame 1 is the same build; as the bunnies move apart the refitted boxes grow and overlap.
  CHECK(ratio[0] == doctest::Approx(1.0).epsilon(1e-12));
  CHECK(ratio[1] > 1.5);
  CHECK(ratio[2] > ratio[1]);
  fs::remove_all(dir);
}

TEST_CASE("a static scene at any time renders as it is, and a render without a time is unchanged") {
  const fs::path dir =
      fs::temp_directory_path() / ("vgpu_cli_static_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string common = "render classic --size 32x24 -q --stats none";
  REQUIRE(run(common + " --out " + (dir / "plain.png").string() + " --stats-json " +
              (dir / "plain.json").string())
              .status == 0);
  REQUIRE(run(common + " --time 7.5 --out " + (dir / "at.png").string()).status == 0);
  CHECK(compare(dir / "plain.png", dir / "at.png", 0).differing_percent == 0);
  const nlohmann::json plain = nlohmann::json::parse(slurp(dir / "plain.json"));
  for (const char* key : {"frames", "frame", "time", "update", "animation"})
    CHECK_MESSAGE(!plain.contains(key), key);
  // hop without a time is its rest pose, the file's node transforms (its time 0).
  REQUIRE(
      run("render hop --size 32x24 -q --stats none --out " + (dir / "rest.png").string()).status ==
      0);
  REQUIRE(
      run("render hop --size 32x24 -q --stats none --time 0 --out " + (dir / "zero.png").string())
          .status == 0);
  CHECK(compare(dir / "rest.png", dir / "zero.png", 0).differing_percent == 0);
  fs::remove_all(dir);
}

TEST_CASE("with --accel bvh or kdtree every frame rebuilds the structure and uploads its changes") {
  const fs::path dir = fs::temp_directory_path() / ("vgpu_cli_tree_" + std::to_string(::getpid()));
  for (const std::string structure : {"bvh", "kdtree"}) {
    CAPTURE(structure);
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string common = "render hop --accel " + structure + " --size 32x24 -q --stats none";
    const Outcome o = run(common + " --frames 0:1:2 --out " + (dir / "f_#.png").string() +
                          " --stats-json " + (dir / "f.json").string());
    INFO(o.err);
    REQUIRE(o.status == 0);
    const nlohmann::json j = nlohmann::json::parse(slurp(dir / "f.json"));
    REQUIRE(j["frames"].size() == 2);
    const nlohmann::json& second = j["frames"][1];
    CHECK(second["accel"]["structure"] == structure);
    CHECK(second["update"]["structure"] == structure);
    CHECK(second["update"]["build_ms"].get<double>() > 0);
    const auto& names = second["update"]["uploaded_textures"];
    const std::string nodes = structure == "bvh" ? "bvh nodes lo" : "kd nodes";
    CHECK(std::find(names.begin(), names.end(), nodes) != names.end());
    CHECK(std::find(names.begin(), names.end(), "vertices0") != names.end());
    // The second frame, rendered by the updated tracer, is the frame rendered alone.
    REQUIRE(run(common + " --time 1 --out " + (dir / "one.png").string()).status == 0);
    CHECK(compare(dir / "one.png", dir / "f_2.png", 0).differing_percent == 0);
  }
  fs::remove_all(dir);
}

TEST_CASE("ray streams write their levels and costs in the statistics, and refuse a traced pixel") {
  const fs::path dir =
      fs::temp_directory_path() / ("vgpu_cli_streams_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string json = (dir / "s.json").string(), png = (dir / "s.png").string();
  const Outcome o =
      run("render bunny-refl --size 32x32 --ray-streams on --stats table -q "
          "--stats-json " +
          json + " --out " + png);
  INFO(o.err);
  REQUIRE(o.status == 0);
  CHECK(o.out.find("ray streams: level rays") != std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(slurp(dir / "s.json"));
  REQUIRE(j.contains("streams"));
  const nlohmann::json& s = j["streams"];
  REQUIRE(s["levels"].size() == 3);
  CHECK(s["levels"][0]["rays"] == 32 * 32);
  CHECK(s["levels"][1]["rays"] == s["levels"][0]["reflected"]);
  CHECK(s["levels"][0]["refracted"] == 0);
  CHECK(s["compaction"]["passes"].get<int>() > 0);
  CHECK(s["gather"]["passes"] == 2);
  // The frame report shows the levels (its summary reads the run's "streams").
  const std::string html = (dir / "s.html").string();
  const Outcome rep =
      run("render bunny-refl --size 24x24 --ray-streams on -q --stats none --report " + html);
  INFO(rep.err);
  REQUIRE(rep.status == 0);
  const std::string page = slurp(html);
  CHECK(page.find("\"streams\":{\"levels\"") != std::string::npos);
  CHECK(page.find("Ray streams: ${levels}") != std::string::npos);
  // The paper's pipeline writes no streams.
  REQUIRE(run("render bunny-refl --size 16x16 -q --stats none --stats-json " + json).status == 0);
  CHECK_FALSE(nlohmann::json::parse(slurp(dir / "s.json")).contains("streams"));
  // Bad values: one line, status 2, nothing written.
  fs::remove(png);
  const Outcome bad = run("render bunny-refl --size 16x16 -q --ray-streams sometimes --out " + png);
  CHECK(bad.status == 2);
  CHECK(bad.err.find("--ray-streams") != std::string::npos);
  const Outcome cpu =
      run("render bunny-refl --size 16x16 -q --ray-streams on --engine cpu --out " + png);
  CHECK(cpu.status == 2);
  CHECK(cpu.err.find("--ray-streams on needs --engine stream") != std::string::npos);
  const Outcome half =
      run("render bunny-refl --size 64x64 -q --ray-streams on --precision fp16 --out " + png);
  CHECK(half.status != 0);
  CHECK(half.err.find("fp16 arithmetic holds their indices exactly only up to 2048") !=
        std::string::npos);
  const Outcome traced =
      run("render bunny-refl --size 16x16 -q --ray-streams on --trace-pixel 3,3 --out " + png);
  CHECK(traced.status != 0);
  CHECK(traced.err.find("--trace-pixel") != std::string::npos);
  CHECK(std::count(traced.err.begin(), traced.err.end(), '\n') == 1);
  CHECK_FALSE(fs::exists(png));
  fs::remove_all(dir);
}

TEST_CASE(
    "a glass material with a bad ior or transmissionFactor: one line naming it, exit 2, no "
    "image") {
  const std::string data = std::string(VGPU_TEST_DATA) + "/gltf/";
  const fs::path out =
      fs::temp_directory_path() / ("vgpu_cli_glass_" + std::to_string(::getpid()) + ".png");
  struct Case {
    const char* file;
    const char* problem;
  };
  for (const Case& c :
       {Case{"glass_ior_below_one.gltf", "material 1: KHR_materials_ior.ior 0.5 is below 1"},
        Case{"glass_ior_string.gltf", "material 1: KHR_materials_ior.ior is not a number"},
        Case{"glass_transmission_above_one.gltf",
             "material 1: KHR_materials_transmission.transmissionFactor 1.5 is outside [0, 1]"}}) {
    CAPTURE(c.file);
    for (const char* engine : {"stream", "cpu"}) {
      CAPTURE(engine);
      const Outcome o = run("render " + data + c.file + " -q --stats none --engine " + engine +
                            " --out " + out.string());
      CHECK(o.status == 2);
      check_one_line(o, data + c.file, c.problem);
      CHECK_FALSE(fs::exists(out));
    }
  }
}

TEST_CASE("the glass scene on the cpu engine counts its rays by kind per iteration in the JSON") {
  const std::string id = std::to_string(::getpid());
  const fs::path json = fs::temp_directory_path() / ("vgpu_cli_glass_" + id + ".json");
  const Outcome o =
      run("render glass --engine cpu --size 32x32 -q --stats table --stats-json " + json.string());
  INFO(o.err);
  REQUIRE(o.status == 0);
  CHECK(o.out.find("glass: ") != std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(slurp(json));
  fs::remove(json);
  const nlohmann::json& cpu = j["cpu"];
  const size_t iterations = j["iterations"].get<size_t>();
  CHECK(iterations == 3);  // --bounces 2
  uint64_t spawned = 0;
  for (const char* kind : {"reflected", "refracted", "total_internal"}) {
    CAPTURE(kind);
    REQUIRE(cpu[kind].size() == iterations);
    CHECK(cpu[kind][iterations - 1] == 0);  // the last iteration spawns none
  }
  for (const char* kind : {"reflected", "refracted"})  // total_internal is part of reflected
    for (const auto& n : cpu[kind]) spawned += n.get<uint64_t>();
  CHECK(cpu["refracted"][0].get<uint64_t>() > 0);       // the glass is seen, and refracts
  CHECK(cpu["total_internal"][1].get<uint64_t>() > 0);  // inside glass, past the critical angle
  CHECK(cpu["total_internal"][1] <= cpu["reflected"][1]);
  CHECK(cpu["glass_shadow_crossings"].get<uint64_t>() > 0);
  // Every ray cast is a primary, a spawned or a shadow ray.
  CHECK(cpu["rays"].get<uint64_t>() > 32 * 32 + spawned);
  // An opaque scene spawns reflected rays only.
  const Outcome opaque = run("render classic --engine cpu --size 32x32 -q --stats json");
  REQUIRE(opaque.status == 0);
  const nlohmann::json c = nlohmann::json::parse(opaque.out)["cpu"];
  CHECK(c["reflected"][0].get<uint64_t>() > 0);
  CHECK(c["refracted"] == nlohmann::json::array({0, 0, 0}));
  CHECK(c["total_internal"] == nlohmann::json::array({0, 0, 0}));
  CHECK(c["glass_shadow_crossings"] == 0);
  CHECK(opaque.out.find("glass: ") == std::string::npos);
}
