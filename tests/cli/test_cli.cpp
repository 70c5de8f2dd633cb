// The command line as a user meets it: every bad option value is refused by CLI11's validators
// (or a check of option combinations) with one line on stderr that names the option or file and
// the problem, exit status 2 and no output file; a successful render writes the image, the AOVs
// and the statistics asked for, in their formats and at the image's size, and nothing else.
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
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
  check_refused("--accel magic", "--accel", "magic not in {grid,bvh,kdtree,auto}");
}
