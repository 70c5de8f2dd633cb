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
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "host/common/version.h"
#include "tests/cli/cli_helpers.h"

namespace fs = std::filesystem;
using namespace clitest;

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
  check_refused("--profile gf9", "--profile", "gf9 not in {gf5700,r300,gf6600,rtx4090,h200,h100}");
  check_refused("--precision fp8", "--precision", "fp8 not in {fp32,fp24,fp16,auto}");
  check_refused("--engine gpu", "--engine", "gpu not in {stream,gl,cpu}");
  check_refused("--stats xml", "--stats", "xml not in {table,json,none}");
  check_refused("--aa adaptive --aa-criterion cones", "--aa-criterion",
                "cones not in {image,object,budget}");
  check_refused("--aa-criterion object", "--aa-criterion object",
                "decides where adaptive sampling refines: add --aa adaptive");
  check_refused("--aa-criterion budget", "--aa-criterion budget",
                "decides where adaptive sampling refines: add --aa adaptive");
  check_refused("--aa adaptive --spp 16 --aa-budget 30,0", "--aa-budget",
                "each share is a percentage of the pixels that hit, above 0 and at most 100");
  check_refused("--aa adaptive --spp 16 --aa-budget 130", "--aa-budget", "130");
  check_refused("--compact maybe", "--compact", "maybe not in {on,off}");
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

TEST_CASE("two refused options are two lines, one each, exit 2 and no image") {
  const fs::path out =
      fs::temp_directory_path() / ("vgpu_cli_two_" + std::to_string(::getpid()) + ".png");
  const Outcome o = run("render bunny-low -q --stats none --out " + out.string() +
                        " --steps-per-pass 4 --gl-device 0");
  CHECK(o.status == 2);
  CHECK(o.err ==
        "vgpu-rt: --steps-per-pass needs --kernels looping\n"
        "vgpu-rt: --gl-device needs --engine gl\n");
  CHECK(o.out.empty());
  CHECK_FALSE(fs::exists(out));
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
        "{gf5700,r300,gf6600,rtx4090,h200,h100}", "{stream,gl,cpu}", "1x1..16384x16384",
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
  for (const auto& [bound_args, bound_problem] : cases) {
    // Named copies: clang 14 cannot capture a structured binding (CAPTURE, INFO).
    const auto& args = bound_args;
    const auto& problem = bound_problem;
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
  const fs::path dir = fresh_dir("render");
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
  for (const auto& [bound_name, bound_type] : rgb.channels) {
    // Named copies: clang 14 cannot capture a structured binding (CAPTURE, INFO).
    const auto& name = bound_name;
    const auto& type = bound_type;
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

  // The statistics: the keys docs/cli.md promises, with this run's values.
  nlohmann::json j;
  REQUIRE_NOTHROW(j = nlohmann::json::parse(slurp(dir / "stats.json")));
  for (const char* key :
       {"scene", "triangles", "grid", "profile", "size", "init_ms", "render_ms", "totals",
        "kernels", "masks", "mrt", "fused_programs", "kernel_variant", "sampling"})
    CHECK_MESSAGE(j.contains(key), key);
  CHECK(j.value("scene", "") == "sphere");
  CHECK(j.value("version", "") == host::version());
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

// --accel kdtree and --accel auto (tests/trace/test_structure_walks.cpp tests the walk itself).
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
  // The cheapest of those the first probes priced within the band of the cheapest (each probed
  // again where "refined" names it), a tie going to the candidate listed first.
  REQUIRE(au["coarse_ms"].is_object());
  double coarse = 1e300;
  for (const auto& [k, v] : au["coarse_ms"].items()) coarse = std::min(coarse, v.get<double>());
  double band_best = 1e300;
  for (const char* k : {"grid", "grid2", "bvh", "kdtree"})
    if (au["coarse_ms"][k].get<double>() <= 1.2 * coarse)
      band_best = std::min(band_best, au["predicted_ms"][k].get<double>());
  CHECK(au["predicted_ms"][chosen].get<double>() == band_best);
  // A 32x32 frame: its first probes are 16x16, as large as half the frame, so no second round.
  CHECK(au["probe_size"] == nlohmann::json::array({16, 16}));
  CHECK(au["refine_size"].is_null());
  CHECK(au["refined"].empty());
  REQUIRE(au["stopped"].is_array());
  for (const auto& s : au["stopped"]) {  // priced (a lower bound), never probed again here
    CAPTURE(s);
    CHECK(au["predicted_ms"].contains(s.get<std::string>()));
  }
  CHECK(au["coarse_ms"] == au["predicted_ms"]);
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

TEST_CASE(
    "a texture past the profile's atlas is fitted by default and refused as before with "
    "--textures refuse") {
  // A 2048x2048 PNG (18 KB, left half red, right half blue): its chain needs a 3072x2048 atlas,
  // past r300's 2048. r300 cannot run the textured shader, so the fitted render runs on the CPU
  // engine (the fit follows --profile on every engine); the refusal is the stream engine's.
  const std::string scene = std::string(VGPU_TEST_DATA) + "/gltf/texture_2048.gltf";
  const fs::path out = fresh_dir("textures") / "fit.png";
  const Outcome fit = run("render " + scene + " -q --stats none --size 8x8 --profile r300 " +
                          "--engine cpu --out " + out.string());
  INFO(fit.err);
  CHECK(fit.status == 0);
  CHECK(fs::exists(out));
  CHECK(std::count(fit.err.begin(), fit.err.end(), '\n') == 1);
  CHECK(fit.err ==
        "vgpu-rt: textures scaled down so that their atlas fits profile r300's 2048x2048 texels: "
        "image 0 (texture_2048.png) 2048x2048 -> 1024x1024 (1/2 a side, mip level 1 as its base) "
        "(--textures refuse: refuse instead)\n");
  fs::remove(out);
  // The refusal keeps its message and exit status (1: the profile cannot, the file is sound).
  const Outcome refuse = run("render " + scene + " -q --stats none --size 8x8 --profile r300 " +
                             "--textures refuse --out " + out.string());
  CHECK(refuse.status == 1);
  check_one_line(refuse, "the scene's textures need a 3072x2048 atlas (mip chains included)",
                 "profile r300 holds at most 2048x2048 texels in one texture");
  CHECK_FALSE(fs::exists(out));
  check_refused("--textures shrink", "--textures", "shrink not in {fit,refuse}");
  fs::remove_all(out.parent_path());
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
  const fs::path dir = fresh_dir("bvh");
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

TEST_CASE("the object criterion's passes are counted and priced, and the statistics name it") {
  const fs::path dir = fresh_dir("cones");
  const Outcome o =
      run("render bunny-refl --size 16x16 --bounces 1 --aa adaptive --spp 4 "
          "--aa-criterion object --aa-cone-depth 3 -q --stats none --predict "
          "--stats-json " +
          (dir / "stats.json").string());
  REQUIRE(o.status == 0);
  nlohmann::json j;
  REQUIRE_NOTHROW(j = nlohmann::json::parse(slurp(dir / "stats.json")));
  CHECK(j["sampling"]["mode"] == "adaptive");
  CHECK(j["sampling"]["criterion"] == "object");
  CHECK(j["sampling"]["cone_depth"] == 3.0);
  // guardarConos and guardarReflejos once (the centre frame), marcarConos once (one level);
  // never the image criterion's guardarImpactos or marcarPixeles.
  std::map<std::string, uint64_t> passes;
  for (const auto& k : j["kernels"]) passes[k["name"].get<std::string>()] = k["passes"];
  CHECK(passes["keep cones"] == 1);
  CHECK(passes["keep reflected"] == 1);
  CHECK(passes["mark cones"] == 1);
  CHECK(passes.count("keep hits") == 0);
  CHECK(passes.count("mark pixels") == 0);
  // The image criterion's statistics have no criterion (they stay as they were).
  const Outcome image =
      run("render bunny-refl --size 16x16 --bounces 1 --aa adaptive --spp 4 -q "
          "--aa-criterion image --stats none --stats-json " +
          (dir / "image.json").string());
  REQUIRE(image.status == 0);
  CHECK_FALSE(nlohmann::json::parse(slurp(dir / "image.json"))["sampling"].contains("criterion"));
}

TEST_CASE(
    "adaptive sampling decides by the budget unless told otherwise, and its search's passes are "
    "counted, priced and named in the statistics") {
  const fs::path dir = fresh_dir("budget");
  const Outcome o =
      run("render bunny-refl --size 24x24 --bounces 1 --aa adaptive --spp 16 --aa-budget 25,20 "
          "--stats-json " +
          (dir / "stats.json").string());
  REQUIRE(o.status == 0);
  nlohmann::json j;
  REQUIRE_NOTHROW(j = nlohmann::json::parse(slurp(dir / "stats.json")));
  CHECK(j["sampling"]["criterion"] == "budget");
  CHECK(j["sampling"]["threshold"].get<double>() == doctest::Approx(0.05));
  CHECK(j["sampling"]["budget_shares"][0].get<double>() == doctest::Approx(0.25));
  CHECK(j["sampling"]["budget_shares"][1].get<double>() == doctest::Approx(0.20));
  const auto& levels = j["sampling"]["budget_levels"];
  REQUIRE(levels.size() == 2);
  // Each level: puntuarConos and cortarPuntajes once, pixelesPuntuados once per search step
  // (the first level's count of every pixel that hits among them).
  std::map<std::string, uint64_t> passes;
  for (const auto& k : j["kernels"]) passes[k["name"].get<std::string>()] = k["passes"];
  CHECK(passes["score cones"] == 2);
  CHECK(passes["cut scores"] == 2);
  CHECK(passes["scored hits"] == levels[0]["counting_passes"].get<uint64_t>() +
                                     levels[1]["counting_passes"].get<uint64_t>());
  CHECK(passes["keep cones"] == 1);
  CHECK(passes.count("mark pixels") == 0);
  CHECK(levels[1]["budget_pixels"].get<uint64_t>() < levels[0]["budget_pixels"].get<uint64_t>());
  CHECK(levels[0]["threshold"].get<double>() >= 0.05 - 1e-7);
  // The kept 4 x 4 level: 17 rays at most, not 21.
  CHECK(j["sampling"]["samples_per_pixel_max"] == 17);
  // The table says what each level's search found.
  CHECK(o.out.find("aa budget level 1: at most") != std::string::npos);
  CHECK(o.out.find("aa budget level 2: at most") != std::string::npos);
  // Priced, the search's read-backs with the rest.
  CHECK(j["predicted_ms"]["gf6600"].get<double>() > 0);
  CHECK(j["totals"]["query_readbacks"].get<uint64_t>() >= passes["scored hits"]);
}

TEST_CASE("beams are refused where they cannot apply, one line and exit 2") {
  check_refused("--beams on --accel auto", "--beams on", "with --accel auto, --beams auto");
  check_refused("--beams on --precision fp16", "--beams on", "needs fp32 ray state");
  check_refused("--beam-tile 4", "--beam-tile", "needs --beams on");
  check_refused("--beams maybe", "--beams", "maybe not in {off,on,auto}");
  check_refused("--beams on --aa adaptive --spp 4", "--beams on", "add --compact off");
}

TEST_CASE(
    "beams on renders the same image on the emulator and the CPU tracer, and their JSON counts "
    "the same tiles, beam passes and misses") {
  const fs::path dir = fs::temp_directory_path() / ("vgpu_cli_beams_" + std::to_string(::getpid()));
  Outcome o;
  const nlohmann::json off = render_json("--bounces 0", dir, o);
  REQUIRE(o.status == 0);
  const std::string image_off = slurp(dir / "image.png");
  const nlohmann::json on = render_json("--bounces 0 --beams on", dir, o);
  INFO("vgpu-rt render --beams on -> " << o.err);
  REQUIRE(o.status == 0);
  CHECK(slurp(dir / "image.png") == image_off);
  CHECK(!off.contains("beams"));
  const nlohmann::json& b = on["beams"];
  CHECK(b["on"] == true);
  CHECK(b["tile"] == 8);
  CHECK(b["tiles"] == 16);  // 32x32 in 8x8 tiles
  CHECK(b["passes"].get<uint64_t>() > 0);
  CHECK(b["tiles_missed"].get<uint64_t>() < 16);
  // The CPU tracer marches the same beams (the same counts) and counts their steps; its image
  // is its own with beams off.
  const nlohmann::json cpu_off = render_json("--bounces 0 --engine cpu", dir, o);
  REQUIRE(o.status == 0);
  const std::string cpu_image_off = slurp(dir / "image.png");
  const nlohmann::json cpu_on = render_json("--bounces 0 --engine cpu --beams on", dir, o);
  INFO("vgpu-rt render --engine cpu --beams on -> " << o.err);
  REQUIRE(o.status == 0);
  CHECK(slurp(dir / "image.png") == cpu_image_off);
  CHECK(!cpu_off.contains("beams"));
  REQUIRE(cpu_on.contains("beams"));
  const nlohmann::json& c = cpu_on["beams"];
  for (const char* key : {"on", "tile", "passes", "tiles", "tiles_missed"}) CHECK(c[key] == b[key]);
  CHECK(c["steps"].get<uint64_t>() >= c["tiles"].get<uint64_t>());
  CHECK(cpu_on["cpu"]["voxel_steps"].get<uint64_t>() <
        cpu_off["cpu"]["voxel_steps"].get<uint64_t>());
  CHECK(!b.contains("entry_depth"));  // the grid's beams march; no node to start at
  // Through the kd-tree: the depth of the nodes the rays start at, the same on both engines,
  // in the JSON and the table.
  const nlohmann::json kd =
      render_json("--bounces 0 --accel kdtree --beams on --beam-tile 4", dir, o);
  REQUIRE(o.status == 0);
  const Outcome table =
      run("render bunny-low --size 32x32 -q --bounces 0 --accel kdtree --beams "
          "on --beam-tile 4 --out " +
          (dir / "table.png").string());
  REQUIRE(table.status == 0);
  CHECK(table.out.find("levels below the root on average") != std::string::npos);
  const nlohmann::json kd_cpu =
      render_json("--bounces 0 --accel kdtree --beams on --beam-tile 4 --engine cpu", dir, o);
  REQUIRE(o.status == 0);
  const nlohmann::json& d = kd["beams"]["entry_depth"];
  CHECK(d["mean"].get<double>() > 0.0);
  CHECK(d["max"].get<uint64_t>() >= 1);
  CHECK(kd_cpu["beams"]["entry_depth"] == d);
  fs::remove_all(dir);
}

TEST_CASE("beams auto renders the same image, and its JSON and table say what it chose and why") {
  const fs::path dir = fs::temp_directory_path() / ("vgpu_cli_auto_" + std::to_string(::getpid()));
  Outcome o;
  render_json("--bounces 0", dir, o);
  REQUIRE(o.status == 0);
  const std::string image_off = slurp(dir / "image.png");
  // The low bunny at 32x32: beams are predicted 0.90x of the primary trace (tests/trace).
  const nlohmann::json on = render_json("--bounces 0 --beams auto --beam-tile 8", dir, o);
  INFO("vgpu-rt render --beams auto -> " << o.err);
  REQUIRE(o.status == 0);
  CHECK(slurp(dir / "image.png") == image_off);
  const nlohmann::json& b = on["beams"];
  CHECK(b["on"] == true);
  CHECK(b["tiles"] == 16);
  const nlohmann::json& au = b["auto"];
  CHECK(au["probed"] == true);
  CHECK(au["probe"] == nlohmann::json::array({32, 32}));
  CHECK(au["primary_ms"]["on"].get<double>() < au["primary_ms"]["off"].get<double>());
  CHECK(au["why"].get<std::string>().rfind("on: ", 0) == 0);
  // Where beams cannot run, off without a word on stderr, and the JSON says why.
  const nlohmann::json cpu = render_json("--bounces 0 --beams auto --engine cpu", dir, o);
  REQUIRE(o.status == 0);
  CHECK(o.err.empty());
  CHECK(cpu["beams"]["on"] == false);
  CHECK_FALSE(cpu["beams"].contains("tiles"));
  CHECK(cpu["beams"]["auto"]["probed"] == false);
  CHECK(cpu["beams"]["auto"]["why"].get<std::string>().find("the cpu engine runs none") !=
        std::string::npos);
  // Through the BVH and the two-level grid it probes, and keeps what the probes predict.
  for (const char* accel : {"bvh", "grid2"}) {
    CAPTURE(accel);
    const nlohmann::json j =
        render_json(std::string("--bounces 0 --beams auto --accel ") + accel, dir, o);
    REQUIRE(o.status == 0);
    const nlohmann::json& ba = j["beams"]["auto"];
    CHECK(ba["probed"] == true);
    CHECK(j["beams"]["on"] ==
          (ba["primary_ms"]["on"].get<double>() < 0.98 * ba["primary_ms"]["off"].get<double>()));
  }
  // The statistics table's summary names the choice.
  const Outcome table = run("render bunny-low --size 32x32 -q --bounces 0 --beams auto --out " +
                            (dir / "image.png").string());
  REQUIRE(table.status == 0);
  CHECK(table.out.find("beams auto: on: primary rays") != std::string::npos);
  CHECK(table.out.find("beams 8x8: 16 tiles") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("the kernels command lists the grids' beam kernels and prints each one's GLSL") {
  const Outcome list = run("kernels");
  REQUIRE(list.status == 0);
  for (const char* name : {"beam-march", "beams-missed", "beam-entry", "grid2-beam-entry"}) {
    CAPTURE(name);
    CHECK(list.out.find(std::string("\n") + name + " ") != std::string::npos);
    const Outcome glsl = run(std::string("kernels ") + name + " --glsl");
    CHECK(glsl.status == 0);
    CHECK(glsl.out.find("void main()") != std::string::npos);
  }
  CHECK(list.out.find("rayosHaz (extension)") != std::string::npos);
  CHECK(list.out.find("inicioHazGrilla2 (extension)") != std::string::npos);
}
