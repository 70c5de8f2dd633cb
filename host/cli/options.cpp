// The render subcommand's options and validators (see options.h).
#include "host/cli/options.h"

#include <CLI/CLI.hpp>
#include <iterator>
#include <regex>
#include <string>
#include <vector>

#include "host/accel/accel.h"
#include "host/accel/grid.h"
#include "host/cli/frames.h"
#include "host/image/image_io.h"
#include "host/scene/scene.h"
#include "host/trace/sampling.h"
#include "vgpu/profile.h"

namespace cli {
namespace {

// Largest image side: the render target limit of the largest profile (vgpu/profile.cpp).
constexpr int kMaxImageSide = 16384;
// Host threads: 0 (one per core) or 1..kMaxThreads; more than this only queues context switches.
constexpr int kMaxThreads = 256;

// --accel's help: every structure of the table (host/accel/accel.h: kAccelRows) with its
// description, then auto; the rows after the first (the paper's) are extensions.
std::string accel_help() {
  std::string help = "Acceleration structure the rays walk: ";
  for (const host::AccelRow& row : host::kAccelRows)
    help += std::string(row.name) + " (" + std::string(row.description) + ") | ";
  help +=
      "auto (builds each, renders a probe at a quarter of the size with each, again at half the "
      "size with those priced within 20% of the cheapest, and keeps the one the cost model "
      "predicts cheapest on --profile; a probe stops once its passes' fixed costs alone price it "
      "out). ";
  const size_t n = std::size(host::kAccelRows);
  for (size_t i = 1; i < n; ++i)
    help += (i == 1 ? "" : i + 1 < n ? ", " : " and ") + std::string(host::kAccelRows[i].name);
  return help + (n > 2 ? " are extensions" : " is an extension") + "; docs/studies/structures.md";
}

// --accel's words: the table's names, then auto.
std::vector<std::string> accel_choices() {
  std::vector<std::string> choices;
  for (const host::AccelRow& row : host::kAccelRows) choices.emplace_back(row.name);
  choices.emplace_back("auto");
  return choices;
}

}  // namespace

std::optional<glm::ivec2> parse_size(const std::string& text) {
  std::smatch m;
  if (!std::regex_match(text, m, std::regex(R"((\d{1,9})[xX](\d{1,9}))"))) return std::nullopt;
  return glm::ivec2(std::stoi(m[1]), std::stoi(m[2]));
}

std::optional<glm::ivec2> parse_pixel(const std::string& text) {
  std::smatch m;
  if (!std::regex_match(text, m, std::regex(R"((\d{1,9}),(\d{1,9}))"))) return std::nullopt;
  return glm::ivec2(std::stoi(m[1]), std::stoi(m[2]));
}

namespace {

// CLI11 validators: each returns an empty string for a good value, else the problem (CLI11
// prefixes the option name; main() prints it on one line and exits with 2).
const CLI::Validator kSizeCheck(
    [](std::string& text) -> std::string {
      const std::optional<glm::ivec2> s = parse_size(text);
      if (!s) return "expected WxH (e.g. 256x256), got '" + text + "'";
      if (s->x < 1 || s->y < 1 || s->x > kMaxImageSide || s->y > kMaxImageSide)
        return text + " is outside the limit 1x1.." + std::to_string(kMaxImageSide) + "x" +
               std::to_string(kMaxImageSide);
      return {};
    },
    "WxH in 1x1..16384x16384", "SIZE");

const CLI::Validator kPixelCheck(
    [](std::string& text) -> std::string {
      return parse_pixel(text) ? "" : "expected X,Y (e.g. 128,128), got '" + text + "'";
    },
    "X,Y", "PIXEL");

const CLI::Validator kGridCheck(
    [](std::string& text) -> std::string {
      try {
        host::parse_grid_spec(text);
        return {};
      } catch (const std::invalid_argument& e) {
        return e.what();
      }
    },
    "auto | N | AxBxC, each 1.." + std::to_string(host::kMaxGridRes), "GRID");

const CLI::Validator kSppCheck(
    [](std::string& text) -> std::string {
      try {
        size_t used = 0;
        const int n = std::stoi(text, &used);
        if (used == text.size()) return host::spp_refusal(n);
      } catch (const std::exception&) {
      }
      return "expected a square from 1 to " + std::to_string(host::kMaxSpp) + ", got '" + text +
             "'";
    },
    "1, 4, 9, ..., 256", "N");

}  // namespace

std::optional<int> parse_aa(const std::string& text) {
  if (text == "none" || text == "adaptive") return 0;
  std::smatch m;
  if (!std::regex_match(text, m, std::regex(R"(undersample(:(\d{1,4}))?)"))) return std::nullopt;
  const int k = m[2].matched ? std::stoi(m[2]) : 2;
  if (k < 1 || k > 64) return std::nullopt;
  return k;
}

namespace {

const CLI::Validator kAaCheck(
    [](std::string& text) -> std::string {
      return parse_aa(text) ? ""
                            : "expected none, adaptive, undersample or undersample:K (K 1 to 64), "
                              "got '" +
                                  text + "'";
    },
    "none | adaptive | undersample[:K]", "MODE");

const CLI::Validator kThresholdCheck(
    [](std::string& text) -> std::string {
      try {
        size_t used = 0;
        const double v = std::stod(text, &used);
        if (used == text.size() && std::isfinite(v) && v >= 0) return {};
      } catch (const std::exception&) {
      }
      return "expected a colour difference of 0 or more (linear, 1 = white), got '" + text + "'";
    },
    "0 or more", "T");

const CLI::Validator kTimeCheck([](std::string& text) { return cli::time_problem(text); },
                                "seconds, 0 or more", "T");

const CLI::Validator kFramesCheck(
    [](std::string& text) {
      cli::FrameRange range;
      return cli::frames_problem(text, range);
    },
    "A:B:N, N frames from A to B seconds, or N over the animations' keys", "A:B:N|N");

// --update: how the structure follows a moving scene (refit and auto: a BVH only, checked with
// --accel in main.cpp).
const CLI::Validator kUpdateCheck(
    [](std::string& text) -> std::string {
      if (text == "rebuild" || text == "refit" || text == "auto") return {};
      return "expected rebuild, refit or auto, got '" + text + "'";
    },
    "rebuild | refit | auto", "MODE");

// An output file: the extension is one of `exts` and its directory exists and is writable.
CLI::Validator output_check(std::vector<std::string> exts) {
  std::string desc;
  for (const std::string& e : exts) desc += (desc.empty() ? "FILE" : " | FILE") + e;
  return CLI::Validator(
      [exts](std::string& path) -> std::string {
        try {
          host::check_output_path(path, exts);
          return {};
        } catch (const host::InputError& e) {
          return e.what();
        }
      },
      desc, "OUTPUT");
}

// --aov KIND=FILE.exr: the AOVs are float images, so EXR only.
const CLI::Validator kAovCheck(
    [](std::string& aov) -> std::string {
      const auto eq = aov.find('=');
      const std::string kind = aov.substr(0, eq);
      if (eq == std::string::npos || eq + 1 == aov.size())
        return "expected depth=FILE.exr or hit=FILE.exr, got '" + aov + "'";
      if (kind != "depth" && kind != "hit")
        return "unknown AOV '" + kind + "' in '" + aov + "' (known: depth, hit)";
      try {
        host::check_output_path(aov.substr(eq + 1), {".exr"});
        return {};
      } catch (const host::InputError& e) {
        return e.what();
      }
    },
    "depth=FILE.exr | hit=FILE.exr", "AOV");

std::vector<std::string> profile_names() {
  std::vector<std::string> names;
  for (const vgpu::Profile& p : vgpu::profiles()) names.push_back(p.name);
  return names;
}

}  // namespace

void add_animation_options(CLI::App& render, RenderArgs& a);
void add_sampling_options(CLI::App& render, RenderArgs& a);

void add_render_options(CLI::App& render, RenderArgs& a) {
  const std::vector<std::string> on_off{"on", "off"};
  render.add_option("scene", a.scene, "glTF file (.gltf/.glb) or a scene name from scenes/")
      ->capture_default_str();
  render.add_option("--size", a.size, "Image size")->check(kSizeCheck)->capture_default_str();
  render.add_option("--out", a.out, "Write the image")->check(output_check({".png", ".exr"}));
  render.add_option("--bounces", a.bounces, "Reflection iterations after the primary one")
      ->check(CLI::Range(0, 64))
      ->capture_default_str();
  render.add_option("--shading", a.shading, "Shading model")
      ->check(CLI::IsMember({"diffuse", "phong", "phong-atten"}))
      ->capture_default_str();
  render
      .add_option("--texture-filter", a.texture_filter,
                  "How the shader's texture unit filters base-colour textures: nearest (1 "
                  "texel), bilinear (4), trilinear (8, mipmapped; level of detail from ray "
                  "differentials)")
      ->check(CLI::IsMember({"nearest", "bilinear", "trilinear"}))
      ->capture_default_str();
  render
      .add_option("--textures", a.textures,
                  "Base-colour textures larger than the profile's atlas holds: fit (each scaled "
                  "down by halves, a lower mip level as its base, the largest first; one line "
                  "says which) or refuse (the render is refused, exit 1)")
      ->check(CLI::IsMember({"fit", "refuse"}))
      ->capture_default_str();
  render.add_option("--shadows", a.shadows, "Shadow rays")
      ->check(CLI::IsMember(on_off))
      ->capture_default_str();
  render.add_option("--grid", a.grid, "Grid voxels per axis")
      ->check(kGridCheck)
      ->capture_default_str();
  render.add_option("--accel", a.accel, accel_help())
      ->check(CLI::IsMember(accel_choices()))
      ->capture_default_str();
  render
      .add_option("--profile", a.profile,
                  "Modeled card (the cpu engine uses only its texture limit, for --grid auto)")
      ->check(CLI::IsMember(profile_names()))
      ->capture_default_str();
  render.add_option("--threads", a.threads, "Host threads (0: one per core)")
      ->check(CLI::Range(0, kMaxThreads))
      ->capture_default_str();
  render
      .add_option("--lanes", a.lanes,
                  "SIMD lanes per batch, stream engine (1: scalar reference; fp24/fp16 run at 1 "
                  "or 8)")
      ->check(CLI::IsMember({1, 4, 8, 16}))
      ->capture_default_str();
  render
      .add_option("--masks", a.masks,
                  "Early-z masks for finished rays (paper's future work), stream engine")
      ->check(CLI::IsMember(on_off))
      ->capture_default_str();
  render
      .add_option("--mrt", a.mrt,
                  "Multiple render targets (paper's future work): fused two-output passes for "
                  "intersecciones + proximoTriangulo and traversal + actualizarVoxel; needs a "
                  "profile with more than one output (not gf5700); off: the paper's pipeline")
      ->check(CLI::IsMember(on_off))
      ->capture_default_str();
  render
      .add_option(
          "--beams", a.beams,
          "Beams over tiles (issue 35, docs/studies/groups.md): passes of one fragment per tile "
          "march each tile's beam through empty space, and the primary rays start where "
          "it stopped; the same image. Every structure (not --accel auto), fp32; every engine "
          "(stream, gl, cpu). auto: on where two probes of the primary trace priced by the cost "
          "model "
          "say beams pay, else off")
      ->check(CLI::IsMember({"off", "on", "auto"}))
      ->capture_default_str();
  render.add_option("--beam-tile", a.beam_tile, "With --beams on or auto: pixels per tile side")
      ->check(CLI::Range(1, 256))
      ->capture_default_str();
  render
      .add_option("--addressing", a.addressing,
                  "How the kd-tree and the two-level grid address their textures: linear (one "
                  "float per pointer, exact to 2^23 entries in fp32), xy (a texel's column and "
                  "row, two channels, to the largest texture) or auto (linear while exact)")
      ->check(CLI::IsMember({"auto", "linear", "xy"}))
      ->capture_default_str();
  render
      .add_option("--ray-streams", a.ray_streams,
                  "Ray streams (glass, docs/studies/materials.md): auto, only for a scene with a "
                  "transmissive material; on, the paper's reflections through them too")
      ->check(CLI::IsMember({"auto", "on"}))
      ->capture_default_str();
  render
      .add_option("--compact", a.compact,
                  "Sampling that saves time (docs/studies/sampling.md): --aa adaptive's and "
                  "undersample's gated frames trace their marked pixels packed into a dense "
                  "stream (the same image); off: over the whole target, to compare")
      ->check(CLI::IsMember(on_off))
      ->capture_default_str();
  render.add_option("--stats", a.stats, "Statistics on stdout")
      ->check(CLI::IsMember({"table", "json", "none"}))
      ->capture_default_str();
  render.add_option("--stats-json", a.stats_json, "Also write the statistics as JSON")
      ->check(output_check({".json"}));
  render
      .add_option("--aov", a.aovs,
                  "Float AOV: depth (distance to the primary hit) or hit (triangle id)")
      ->check(kAovCheck);
  render
      .add_option("--trace-pixel", a.trace_pixel,
                  "Print every pass this pixel took part in and its state (stream engine)")
      ->check(kPixelCheck);
  render.add_flag("--quiet,-q", a.quiet, "No progress on stderr");
  render
      .add_option("--stats-csv", a.stats_csv,
                  "Also write one row per pass (kernel, fragments, fetches, query) as CSV")
      ->check(output_check({".csv"}));
  render
      .add_option("--report", a.report,
                  "Write an HTML report of the frame (timeline, cost maps, pixel history), "
                  "stream engine")
      ->check(output_check({".html"}));
  render
      .add_option("--precision", a.precision,
                  "Ray-state textures and kernel arithmetic, every group, stream engine (auto: "
                  "per group, the fewest bits this scene needs; the stats say why)")
      ->check(CLI::IsMember({"fp32", "fp24", "fp16", "auto"}))
      ->capture_default_str();
  render.add_option("--formats", a.formats,
                    "Per group, over --precision: GROUP=FORMAT[/ARITH],... with GROUP rays, "
                    "traversal, voxel, hits, colour, queries (e.g. colour=fp16/fp32)");
  render
      .add_option("--engine", a.engine,
                  "stream (the vgpu pipeline) | gl (the same passes on an OpenGL driver) | cpu "
                  "(double-precision reference)")
      ->check(CLI::IsMember({"stream", "gl", "cpu"}))
      ->capture_default_str();
  render
      .add_option("--gl-device", a.gl_device,
                  "With --engine gl: auto, or an EGL device index (see vgpu-rt gl-devices)")
      ->capture_default_str();
  render
      .add_option("--gl-readback", a.gl_readback,
                  "With --engine gl: how the host waits for an occlusion query: block (the "
                  "driver's GL_QUERY_RESULT wait), poll (spin on GL_QUERY_RESULT_AVAILABLE), "
                  "auto (poll on a hardware driver, block on a software one)")
      ->check(CLI::IsMember({"auto", "block", "poll"}))
      ->capture_default_str();
  render
      .add_option("--kernels", a.kernels,
                  "How rays walk the grid: multipass (the paper's kernels, one pass per step) | "
                  "looping (one data-dependent loop, Purcell's branching variant; needs dynamic "
                  "branching, e.g. --profile gf6600), stream engine")
      ->check(CLI::IsMember({"multipass", "looping"}))
      ->capture_default_str();
  render
      .add_option("--walk", a.walk,
                  "How the emulator runs the multipass grid walk on the host: batches (8 pixels "
                  "through every pass at a time, their state in registers, then the pass "
                  "sequence replayed for the statistics) | passes (pass by pass over the "
                  "target); same images and statistics, stream engine")
      ->check(CLI::IsMember({"batches", "passes"}))
      ->each([&a](const std::string&) { a.walk_given = true; })
      ->capture_default_str();
  add_sampling_options(render, a);
  render
      .add_option("--steps-per-pass", a.steps_per_pass,
                  "With --kernels looping: loop iterations per pass before the host's occlusion "
                  "query (the profile's loop limit applies: gf6600 255)")
      ->check(CLI::Range(1, 4096))
      ->each([&a](const std::string&) { a.steps_given = true; })
      ->capture_default_str();
  render.add_flag("--predict", a.predict,
                  "Print the cost model's predicted time for --profile, with its breakdown");
  add_animation_options(render, a);
}

// The sampling options: rays per pixel, and where adaptive modes trace more or fewer.
void add_sampling_options(CLI::App& render, RenderArgs& a) {
  render
      .add_option("--spp", a.spp,
                  "Rays per pixel, a square: a stratified, jittered n x n grid in each pixel "
                  "(seeded: the same image every run), one sample frame each, resolved by a box "
                  "filter; 1 is one ray through each pixel's centre")
      ->check(kSppCheck)
      ->capture_default_str();
  render
      .add_option("--aa", a.aa,
                  "Anti-aliasing: none (--spp rays in every pixel), adaptive (one ray per "
                  "pixel, then levels of 4, 16, ... up to --spp only where neighbours hit another "
                  "surface or the colour's second difference across the pixel exceeds "
                  "--aa-threshold) or undersample[:K] (one ray through every K-th pixel in x and "
                  "y, default 2, then through the pixels between those that hit different "
                  "surfaces or differ in colour by more than --aa-threshold; the rest blended, "
                  "corrected for the shade's curvature)")
      ->check(kAaCheck)
      ->capture_default_str();
  render
      .add_option("--aa-threshold", a.aa_threshold,
                  "With --aa adaptive: the colour's second difference (linear, per channel, "
                  "along x or y) that marks a pixel for more samples; with --aa undersample: the "
                  "colour difference between lattice pixels that has the pixels between traced "
                  "(and twice the largest second difference the blend corrects); with "
                  "--aa-criterion budget: the least score that can refine. Default 0.1, with "
                  "--aa-criterion budget 0.05")
      ->check(kThresholdCheck);
  render
      .add_option("--aa-criterion", a.aa_criterion,
                  "With --aa adaptive: what marks a pixel for more samples: image (a neighbour "
                  "hit another surface, or the colour's second difference exceeds "
                  "--aa-threshold) or object (the same, and where the pixel's cone is crossed by "
                  "a fold: the hit distances' second difference exceeds --aa-cone-depth cone "
                  "widths) or budget (the object criterion's edges as a score, the colour step "
                  "across them; each level refines the highest scores above --aa-threshold, as "
                  "many pixels that hit as --aa-budget allows, and the 4x4 level keeps the 2x2 "
                  "samples; docs/studies/sampling.md). Default budget")
      ->check(CLI::IsMember({"image", "object", "budget"}));
  render
      .add_option("--aa-budget", a.aa_budget,
                  "With --aa-criterion budget: per level, the percentage of the image's pixels "
                  "that hit that the level may refine (pixels that miss cost nothing); the last "
                  "repeats for deeper levels, e.g. 30,28")
      ->delimiter(',')
      ->check(CLI::Range(0.0f, 100.0f))
      ->capture_default_str();
  render
      .add_option("--aa-cone-depth", a.aa_cone_depth,
                  "With --aa-criterion object or budget: the hit distances' second difference "
                  "along x or y, "
                  "in widths of the pixel's cone at its hit, that marks a pixel")
      ->check(CLI::Range(0.0f, 1000.0f))
      ->capture_default_str();
}

// The animation options (issue 23; issue 34: every animation plays by default).
void add_animation_options(CLI::App& render, RenderArgs& a) {
  render
      .add_option("--time", a.time,
                  "Render the scene at T seconds of its animations (glTF: every animation of the "
                  "file plays, or those --animation names; a static scene renders as it is; "
                  "before the first key and after the last, the keys' values)")
      ->check(kTimeCheck);
  render
      .add_option("--frames", a.frames,
                  "Render N frames evenly from A to B seconds, both included (N = 1: A); with N "
                  "alone, from the first key time to the last of the animations played; --out "
                  "and --aov need '#' in the file name for the frame number, zero-padded, "
                  "numbered from 1 (frame_####.png: frame_0001.png, ...); --stats-json holds one "
                  "record per frame")
      ->check(kFramesCheck);
  render.add_option("--animation", a.animation,
                    "With --time or --frames: the animation to play, by name or index, or several "
                    "to play together as a comma list (e.g. 0,2). Default: every animation of the "
                    "file together, as glTF viewers play them, unless two drive the same path of "
                    "one node (then the first alone, with a note). `vgpu-rt scenes FILE` lists a "
                    "file's animations");
  render
      .add_option("--update", a.update,
                  "With --time or --frames: how the acceleration structure follows the moving "
                  "scene each frame: rebuild (the structure is built again), refit (--accel bvh: "
                  "the boxes move with the triangles, the topology stays) or auto (--accel bvh: "
                  "refit until the refitted tree's SAH cost passes 1.25 times its last build's, "
                  "then rebuild)")
      ->check(kUpdateCheck)
      ->each([&a](const std::string&) { a.update_given = true; })
      ->capture_default_str();
  render
      .add_option("--report-frame", a.report_frame,
                  "With --frames: the frame (1 to N) that --report and --stats-csv follow; a "
                  "refitted BVH's frame depends on the frames before it, so --time cannot give it")
      ->check(CLI::Range(1, kMaxFrames));
}

}  // namespace cli
