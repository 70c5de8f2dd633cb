// The command line's animation options as a user meets them (issue 23): --time, --frames,
// --animation, --update and --report-frame; bad values are refused with one line and exit 2, and
// a sequence writes numbered files and one statistics record per frame.
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

#include "tests/cli/cli_helpers.h"

namespace fs = std::filesystem;
using namespace clitest;

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
  for (const char* bad : {"0:1", "0:1:2:3", "a:1:2", "0:1:2.5", "0:nan:2", ":1:2", "2.5", "x"})
    check_refused(std::string("--frames ") + bad, "--frames",
                  "expected A:B:N (N frames evenly from A to B seconds, e.g. 0:2:25) or N (N "
                  "frames over the animations' keys, e.g. 25), got '" +
                      std::string(bad) + "'");
  check_refused("--frames 0", "--frames", "0: the frame count must be 1 to 100000, got 0");
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
  // Both files without a number: both refused, one line each.
  const std::string png = (dir / "a.png").string();
  const Outcome both =
      run("render bunny-low -q --stats none --out " + png + " --frames 0:1:2 --aov hit=" + hit);
  CHECK(both.status == 2);
  const std::string need =
      ": 2 frames need '#' in the file name for the frame number (e.g. "
      "frame_####.png)\n";
  CHECK(both.err == "vgpu-rt: --out " + png + need + "vgpu-rt: --aov " + hit + need);
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
  for (const auto& [bound_args, bound_problem] : cases) {
    // Named copies: clang 14 cannot capture a structured binding (CAPTURE, INFO).
    const auto& args = bound_args;
    const auto& problem = bound_problem;
    const Outcome o = run("render " + args + " -q --stats none --out " + out.string());
    INFO("vgpu-rt render " << args << " -> " << o.err);
    CHECK(o.status == 2);
    check_one_line(o, "", problem);
    CHECK_FALSE(fs::exists(out));
  }
}

TEST_CASE("a file's animations play together by default, and two of one node's path are refused") {
  // two_animations.gltf: "rise" (the outer cube, 0-2 s) and "spin" (its child, 1-3 s).
  const std::string two = std::string(VGPU_TEST_DATA) + "/gltf/two_animations.gltf";
  const std::string clash = std::string(VGPU_TEST_DATA) + "/gltf/animations_clash.gltf";
  const fs::path dir = fresh_dir("two_animations");
  const std::string common = " -q --size 24x16 --bounces 0 --stats none --stats-json ";
  // --frames N without bounds: N frames over both animations' keys, 0 to 3 s.
  Outcome o = run("render " + two + " --frames 4" + common + (dir / "all.json").string());
  INFO(o.err);
  REQUIRE(o.status == 0);
  const nlohmann::json all = nlohmann::json::parse(slurp(dir / "all.json"));
  CHECK(all["animation"]["name"] == "rise + spin");
  CHECK(all["animation"]["index"].is_null());
  CHECK(all["animation"]["start"] == 0.0);
  CHECK(all["animation"]["end"] == 3.0);
  REQUIRE(all["animation"]["played"].size() == 2);
  CHECK(all["animation"]["played"][1] ==
        nlohmann::json({{"name", "spin"}, {"index", 1}, {"start", 1.0}, {"end", 3.0}}));
  REQUIRE(all["frames"].size() == 4);
  for (int f = 0; f < 4; ++f) CHECK(all["frames"][size_t(f)]["time"] == double(f));
  // One chosen animation: its own keys, 1 to 3 s for "spin".
  o = run("render " + two + " --frames 3 --animation spin" + common + (dir / "spin.json").string());
  REQUIRE(o.status == 0);
  const nlohmann::json spin = nlohmann::json::parse(slurp(dir / "spin.json"));
  CHECK(spin["animation"]["name"] == "spin");
  CHECK(spin["animation"]["index"] == 1);
  CHECK(spin["frames"][0]["time"] == 1.0);
  CHECK(spin["frames"][2]["time"] == 3.0);
  // The default and the comma list that names both render the same frame.
  o = run("render " + two + " --time 1 --out " + (dir / "all.png").string() + common +
          (dir / "t.json").string());
  REQUIRE(o.status == 0);
  o = run("render " + two + " --time 1 --animation spin,rise --out " + (dir / "list.png").string() +
          common + (dir / "t.json").string());
  REQUIRE(o.status == 0);
  CHECK(compare(dir / "all.png", dir / "list.png", 0).differing_percent == 0);
  o = run("render " + two + " --time 1 --animation rise --out " + (dir / "rise.png").string() +
          common + (dir / "t.json").string());
  REQUIRE(o.status == 0);
  CHECK(compare(dir / "all.png", dir / "rise.png", 0).differing_percent > 0);
  // Two chosen animations of one node's path: refused, naming the file, the node and the path.
  o = run("render " + clash + " --time 0.5 --animation 0,1 --out " + (dir / "no.png").string() +
          common + (dir / "no.json").string());
  CHECK(o.status == 2);
  check_one_line(o, "--animation 0,1: " + clash,
                 "animations 0 'left' and 1 'right' both drive node 0 translation; they cannot "
                 "play together");
  CHECK_FALSE(fs::exists(dir / "no.png"));
  o = run("render " + clash + " --time 0.5 --animation 0,walk" + common +
          (dir / "no.json").string());
  CHECK(o.status == 2);
  check_one_line(o, "--animation 0,walk", "has no animation named or numbered 'walk'");
  // By default such a file plays its first animation alone, and says so.
  o = run("render " + clash + " --time 0.5" + common + (dir / "first.json").string());
  CHECK(o.status == 0);
  CHECK(o.err == "vgpu-rt: " + clash +
                     ": animations 0 'left' and 1 'right' both drive node 0 translation, so they "
                     "cannot play together: animation 0 'left' plays alone (--animation "
                     "chooses)\n");
  CHECK(nlohmann::json::parse(slurp(dir / "first.json"))["animation"]["name"] == "left");
  // `scenes FILE` lists the animations with their key times and durations.
  o = run("scenes " + two + " " + clash);
  CHECK(o.status == 0);
  CHECK(o.out == two +
                     ": 26 triangles  animations: 0 'rise' 0-2 s (2 s), 1 'spin' 1-3 s (2 s); all "
                     "play together by default\n" +
                     clash +
                     ": 1 triangles  animations: 0 'left' 0-1 s (1 s), 1 'right' 0-1 s (1 s); "
                     "animations 0 'left' and 1 'right' both drive node 0 translation: the first "
                     "plays alone by default\n");
  fs::remove_all(dir);
}

TEST_CASE("a multi-frame render writes numbered files and one statistics record per frame") {
  const fs::path dir = fresh_dir("frames");
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
  CHECK(j["animation"]["index"] == 0);
  CHECK(j["animation"]["end"] == 2.0);
  CHECK_FALSE(j["animation"].contains("played"));  // one animation: the object as before
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

TEST_CASE("a refitted BVH gives the rebuilt BVH's hit ids and depths on every frame of hop" * doctest::test_suite("sweep")) {
  const fs::path dir = fresh_dir("refit");
  const std::string common = "render hop --accel bvh --frames 0:2:5 --size 48x40 -q --stats none";
  render_update_modes(common, dir, {"rebuild", "refit", "auto"});
  const nlohmann::json refit = nlohmann::json::parse(slurp(dir / "refit.json"));
  const nlohmann::json rebuild = nlohmann::json::parse(slurp(dir / "rebuild.json"));
  CHECK(refit["update"] == "refit");
  REQUIRE(refit["frames"].size() == 5);
  for (int f = 1; f <= 5; ++f) {
    CAPTURE(f);
    for (const char* mode : {"refit", "auto"}) check_same_hits(dir, "rebuild", mode, f);
    const nlohmann::json& u = refit["frames"][size_t(f - 1)]["update"];
    CHECK(u["mode"] == (f == 1 ? "initial" : "refit"));
    // A refit keeps the topology: the same node count as the first frame's build.
    CHECK(refit["frames"][size_t(f - 1)]["accel"]["nodes"] ==
          rebuild["frames"][0]["accel"]["nodes"]);
  }
  fs::remove_all(dir);
}

TEST_CASE("--report-frame puts frame K of a refitted sequence in the report and the pass CSV") {
  const fs::path dir = fresh_dir("report_frame");
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
  for (const auto& [bound_args, bound_option, bound_problem] :
       std::vector<std::array<std::string, 3>>{
           {"--time 1 --report-frame 1" + report, "--report-frame", "needs --frames"},
           {"--frames 0:1:2 --report-frame 1", "--report-frame", "needs --report or --stats-csv"},
           {"--frames 0:2:3 --report-frame 4" + report, "--report-frame 4",
            "--frames 0:2:3 gives 3 frames, numbered from 1"},
           {"--frames 0:2:3 --report-frame 0" + report, "--report-frame", "not in range"},
           {"--frames 0:1:2" + report, "--report",
            "follows one frame: render it with --time T, or name one of the frames with "
            "--report-frame K"}}) {
    // Named copies: clang 14 cannot capture a structured binding (CAPTURE, INFO).
    const auto& args = bound_args;
    const auto& option = bound_option;
    const auto& problem = bound_problem;
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

TEST_CASE("the scatter scene's refitted BVH hits what a rebuild hits while its SAH cost grows" * doctest::test_suite("sweep")) {
  // scripts/scenes/scatter_scene.py writes the larger animation of docs/studies/animation.md: ten
  // full bunnies that start inside one another and hop apart.
  const fs::path dir = fresh_dir("scatter");
  const std::string script = std::string(VGPU_TEST_DATA) + "/../../scripts/scenes/scatter_scene.py";
  REQUIRE(std::system(("python3 " + script + " " + dir.string() + " >/dev/null").c_str()) == 0);
  const std::string common = "render " + (dir / "scatter.gltf").string() +
                             " --accel bvh --frames 0:0.5:3 --size 16x12 -q --stats none";
  render_update_modes(common, dir, {"rebuild", "refit"});
  const nlohmann::json refit = nlohmann::json::parse(slurp(dir / "refit.json"));
  const nlohmann::json rebuild = nlohmann::json::parse(slurp(dir / "rebuild.json"));
  REQUIRE(refit["frames"].size() == 3);
  CHECK(refit["frames"][0]["triangles"].get<int>() >= 30000);
  std::vector<double> ratio;
  for (int f = 1; f <= 3; ++f) {
    CAPTURE(f);
    check_same_hits(dir, "rebuild", "refit", f);
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
  const fs::path dir = fresh_dir("static");
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

TEST_CASE(
    "dense streams write their frames and costs in the statistics table, the JSON and the "
    "report; --compact off writes none") {
  const fs::path dir = fresh_dir("dense");
  const std::string json = (dir / "d.json").string(), html = (dir / "d.html").string();
  const Outcome o =
      run("render classic --size 24x24 --aa undersample:2 --stats table -q "
          "--stats-json " +
          json + " --report " + html);
  INFO(o.err);
  REQUIRE(o.status == 0);
  // The lattice frame and the gaps' frame.
  CHECK(o.out.find("dense streams: 2 gated frames") != std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(slurp(json));
  REQUIRE(j.contains("compact"));
  CHECK(j["compact"]["frames"] == 2);
  CHECK(j["compact"]["packs"] == 2);
  CHECK(j["compact"]["slots"].get<uint64_t>() < j["compact"]["pixels"].get<uint64_t>());
  CHECK(j["compact"]["compaction"]["passes"] == 2);
  const std::string page = slurp(html);
  CHECK(page.find("\"compact\":{\"packs\"") != std::string::npos);
  CHECK(page.find("Dense streams: ${fmt(c.frames)}") != std::string::npos);
  REQUIRE(run("render classic --size 24x24 --aa undersample:2 --compact off -q --stats none "
              "--stats-json " +
              json)
              .status == 0);
  CHECK_FALSE(nlohmann::json::parse(slurp(json)).contains("compact"));
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
