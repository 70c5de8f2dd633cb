// vgpu-rt render as a library call (render.h): the options parsed into a plan, the scene
// loaded and its structure built, each frame rendered and its files and statistics written.
// The command line (main.cpp) and the Python module (python/) both run a render through it.

// GCC 12 reports false positives inside the JSON library's templates (host/report/stats_value.h).
#if defined(__GNUC__) && !defined(__clang__)  // GCC's warnings; clang has neither
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wrestrict"
#endif
#include "host/cli/render.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <numeric>
#include <optional>

#include "host/accel/accel.h"
#include "host/accel/grid.h"
#include "host/cli/frames.h"
#include "host/cli/options.h"
#include "host/common/parallel.h"
#include "host/image/image_io.h"
#include "host/model/cost_model.h"
#include "host/model/formats.h"
#include "host/report/report.h"
#include "host/report/stats_json.h"
#include "host/scene/animation.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/cpu/cpu_tracer.h"
#include "host/trace/sampling.h"
#include "host/trace/stream/accel_choice.h"
#include "host/trace/stream/devices.h"
#include "host/trace/stream/mark_streams.h"
#include "host/trace/stream/ray_streams.h"
#include "host/trace/stream/stream_tracer.h"
#include "host/trace/validate.h"
#include "vgpu/vgpu.h"

namespace cli {

namespace {

// Passes on what the tracer shows while `on`, and drops it otherwise: --report-frame K points the
// report's recorder at frame K of a sequence (a refitted BVH's frame K depends on the frames
// before it, so --time cannot render it alone).
class OneFrame final : public host::PassObserver {
 public:
  explicit OneFrame(host::PassObserver& to) : to_(to) {}
  bool on = false;
  void iteration(int i) override {
    if (on) to_.iteration(i);
  }
  void trace_begin(TraceKind k) override {
    if (on) to_.trace_begin(k);
  }
  void trace_end() override {
    if (on) to_.trace_end();
  }
  void pass_begin(const vgpu::Stencil* work) override {
    if (on) to_.pass_begin(work);
  }
  void pass(const Pass& p) override {
    if (on) to_.pass(p);
  }
  void query(uint64_t result, const vgpu::Stencil* written, const vgpu::FrameStats& s) override {
    if (on) to_.query(result, written, s);
  }

 private:
  host::PassObserver& to_;
};

// What a render was asked for, once every option and every combination was checked: the tracer's
// options, and what the command line keeps for itself.
struct RenderPlan {
  host::RenderOptions opt;
  host::FormatRequest formats;  // resolved once the scene and its structure are known
  host::GridSpec grid_spec;
  std::string aov_depth, aov_hit;  // --aov files (empty: not written)
  std::vector<double> times;       // the frames' times (one frame: {0} or --time)
  bool span_frames = false;        // --frames N: times spread over the played animations' keys
  bool animating = false, cpu = false, gl = false;
  std::optional<host::BeamsChoice> beams_choice;  // --beams auto's, made at initialization
  host::Request request;                          // the options as written, for host::validate
};

// The command line's options that RenderOptions does not hold, for host::validate.
host::Request request_of(const RenderArgs& a, bool lanes_given, const RenderPlan& plan,
                         bool observer) {
  host::Request q;
  q.engine = a.engine;
  q.accel = a.accel;
  q.beams = a.beams;
  q.precision = a.precision;
  q.formats = a.formats;
  q.aa = a.aa;
  q.aa_criterion = a.aa_criterion;
  q.size = a.size;
  q.trace_pixel = a.trace_pixel;
  q.predict = a.predict;
  q.lanes_given = lanes_given;
  q.steps_given = a.steps_given;
  q.walk_given = a.walk_given;
  q.time = a.time;
  q.frames = a.frames;
  q.animation = a.animation;
  q.update = a.update;
  q.update_given = a.update_given;
  q.frame_count = plan.times.size();
  q.report_frame = a.report_frame;
  for (const auto& [option, file] : {std::pair<std::string, std::string>{"--out", a.out},
                                     {"--aov", plan.aov_depth},
                                     {"--aov", plan.aov_hit}})
    if (!file.empty()) q.files.push_back({option, file, cli::has_frame_number(file)});
  q.report = !a.report.empty();
  q.stats_csv = !a.stats_csv.empty();
  q.gl_device = a.gl_device;
  q.gl_readback = a.gl_readback;
  q.observer = observer;
  q.report_max_pixels = host::kReportMaxPixels;
  return q;
}

// Parse: the options into a plan, refusing what cannot run before any work (host::validate's
// refusals, one line each: UsageError, exit 2). `observer`: a caller follows the passes.
RenderPlan parse_render(const RenderArgs& a, bool lanes_given, bool observer) {
  // CLI11 checked each value; what is left are combinations of options (host::validate).
  RenderPlan plan;
  host::RenderOptions& opt = plan.opt;
  const glm::ivec2 size = *parse_size(a.size);
  opt.width = size.x;
  opt.height = size.y;
  opt.bounces = a.bounces;
  opt.shading = host::parse_shading(a.shading);
  opt.shadows = a.shadows == "on";
  opt.texture_filter = a.texture_filter == "nearest"    ? vgpu::Filter::nearest
                       : a.texture_filter == "bilinear" ? vgpu::Filter::bilinear
                                                        : vgpu::Filter::trilinear;
  opt.masks = a.masks == "on";
  opt.mrt = a.mrt == "on";
  opt.beams = a.beams == "on";
  opt.beam_tile = a.beam_tile;
  opt.addressing = a.addressing == "linear" ? host::RenderOptions::Addressing::linear
                   : a.addressing == "xy"   ? host::RenderOptions::Addressing::xy
                                            : host::RenderOptions::Addressing::automatic;
  opt.ray_streams = a.ray_streams == "on";
  opt.compact = a.compact == "on";
  opt.looping = a.kernels == "looping";
  opt.steps_per_pass = a.steps_per_pass;
  opt.batch_walk = a.walk == "batches";
  opt.spp = a.spp;
  opt.adaptive = a.aa == "adaptive";
  opt.undersample = a.aa == "adaptive" || a.aa == "none" ? 0 : *parse_aa(a.aa);
  opt.user = a.user;
  // --aa-criterion: budget unless given; only adaptive sampling reads it.
  const std::string criterion = a.aa_criterion.value_or("budget");
  opt.aa_criterion = criterion == "object"   ? host::RenderOptions::AaCriterion::object
                     : criterion == "budget" ? host::RenderOptions::AaCriterion::budget
                                             : host::RenderOptions::AaCriterion::image;
  // Unset: 0.1, or the budget's floor 0.05 (RenderOptions::threshold).
  opt.aa_threshold = a.aa_threshold;
  opt.aa_budget.clear();
  for (const float b : a.aa_budget) opt.aa_budget.push_back(b / 100.0f);
  opt.cone_depth = a.aa_cone_depth;
  opt.profile = vgpu::profile(a.profile).name;
  opt.threads = a.threads;
  opt.lanes = a.lanes;
  plan.grid_spec = host::parse_grid_spec(a.grid);
  std::string& aov_depth = plan.aov_depth;
  std::string& aov_hit = plan.aov_hit;
  for (const std::string& aov : a.aovs) {
    const auto eq = aov.find('=');
    (aov.compare(0, eq, "depth") == 0 ? aov_depth : aov_hit) = aov.substr(eq + 1);
  }
  if (!a.trace_pixel.empty()) {
    opt.trace_pixel = *parse_pixel(a.trace_pixel);
    opt.trace_out = &std::cout;
  }
  plan.cpu = a.engine == "cpu";
  plan.gl = a.engine == "gl";
  // Animation (issue 23): the frames' times.
  plan.animating = !a.time.empty() || !a.frames.empty();
  std::vector<double>& times = plan.times;
  times = {0.0};
  if (!a.time.empty()) times = {cli::parse_time(a.time)};
  if (!a.frames.empty()) {
    cli::FrameRange range;
    cli::frames_problem(a.frames, range);  // CLI11 checked it
    times = cli::frame_times(range);       // --frames N: set once the file is read
    plan.span_frames = !range.bounded;
  }
  // Every combination of options that cannot run, before any work (with fp32 formats: MRT's
  // formats are checked again once resolved).
  opt.formats = host::Formats::all(vgpu::Format::fp32);
  plan.request = request_of(a, lanes_given, plan, observer);
  if (const auto refused = host::validate(opt, vgpu::profile(opt.profile), &plan.request);
      !refused.empty())
    throw UsageError(host::refusal_lines(refused));
  plan.formats = host::parse_format_request(a.precision, a.formats);  // validate parsed it
  if (plan.gl) {
    opt.device = "gl";
    opt.gl_device = a.gl_device;
    opt.gl_readback = a.gl_readback;
  }
  if (!a.report.empty()) host::check_output_path(a.report, {".html"});
  if (!a.stats_csv.empty()) host::check_output_path(a.stats_csv, {".csv"});
  return plan;
}

// Write (--stats table, one frame): the pass statistics, the scene and its structure, the options
// and the times. `animation_text` names what --time posed (read only when animating).
void print_table(const RenderArgs& a, const RenderPlan& plan, const host::Scene& scene,
                 const host::Accel& accel, const host::AccelChoice* choice,
                 const host::RenderResult& r, const host::CpuStats& cpu_stats, double init_ms,
                 host::StreamTracer* tracer, const std::string& animation_text) {
  const host::RenderOptions& opt = plan.opt;
  const bool cpu = plan.cpu, gl = plan.gl, animating = plan.animating;
  if (cpu) {
    std::printf(
        "CPU reference (double precision, recursive Whitted): %llu rays, %llu voxel steps, %llu "
        "triangle tests\n",
        static_cast<unsigned long long>(cpu_stats.rays),
        static_cast<unsigned long long>(cpu_stats.voxel_steps),
        static_cast<unsigned long long>(cpu_stats.triangle_tests));
    // Glass (docs/studies/materials.md): the rays of each kind, summed over the iterations.
    auto sum = [](const std::vector<uint64_t>& v) {
      return static_cast<unsigned long long>(std::accumulate(v.begin(), v.end(), uint64_t(0)));
    };
    if (sum(cpu_stats.refracted) + sum(cpu_stats.total_internal) +
            cpu_stats.glass_shadow_crossings >
        0)
      std::printf(
          "glass: %llu reflected rays (%llu of them totally internally), %llu refracted; %llu "
          "shadow-ray crossings\n",
          sum(cpu_stats.reflected), sum(cpu_stats.total_internal), sum(cpu_stats.refracted),
          static_cast<unsigned long long>(cpu_stats.glass_shadow_crossings));
  } else
    std::cout << r.stats.to_table();
  std::printf(
      "scene %s: %zu triangles (%u dropped as degenerate), grid %dx%dx%d (%llu references)\n",
      scene.name.c_str(), scene.triangle_count(), scene.dropped_degenerate, accel.grid_res().x,
      accel.grid_res().y, accel.grid_res().z,
      static_cast<unsigned long long>(accel.grid_references()));
  if (const std::string line = accel.describe(); !line.empty()) std::printf("%s\n", line.c_str());
  if (choice)
    std::printf("accel auto: %s (probes %.0f ms)\n", choice->why.c_str(), choice->probe_ms);
  if (plan.beams_choice)
    std::printf("beams auto: %s (probes %.0f ms)\n", plan.beams_choice->why.c_str(),
                plan.beams_choice->probe_ms);
  std::printf("%s %s, %dx%d, %d iteration(s), %s shading, shadows %s, masks %s, mrt %s\n",
              cpu ? "engine" : "profile", cpu ? "cpu" : opt.profile.c_str(), r.width, r.height,
              r.iterations, a.shading.c_str(), a.shadows.c_str(), a.masks.c_str(), a.mrt.c_str());
  if (!cpu) std::cout << "formats (texture and arithmetic, per group):\n" << describe(opt.formats);
  if (opt.beams) {
    std::printf("beams %dx%d: %llu tiles, %llu beam passes, %llu tiles missed the scene",
                opt.beam_tile, opt.beam_tile, static_cast<unsigned long long>(r.beam_tiles),
                static_cast<unsigned long long>(r.beam_passes),
                static_cast<unsigned long long>(r.beam_tiles_missed));
    if (r.beam_depths && r.beam_tiles > 0)
      std::printf("; rays start %.2f levels below the root on average, %llu at most",
                  double(r.beam_depth_sum) / double(r.beam_tiles),
                  static_cast<unsigned long long>(r.beam_depth_max));
    std::printf("\n");
  }
  // --aa-criterion budget: each level's threshold and budget (kernels/cone_budget.h).
  for (size_t l = 0; l < r.budget_levels.size(); ++l) {
    const auto& b = r.budget_levels[l];
    std::printf(
        "aa budget level %zu: at most %llu pixels that hit, threshold %.6g (%llu counting "
        "passes)\n",
        l + 1, static_cast<unsigned long long>(b.budget), double(b.threshold),
        static_cast<unsigned long long>(b.steps));
  }
  if (r.streams.on) std::cout << host::describe(r.streams);
  if (r.compact.on) std::cout << host::describe(r.compact);
  std::printf("initialization %.1f ms (grid %.1f ms), render %.1f ms (%s)\n", init_ms,
              accel.grid_build_ms(), r.render_ms,
              cpu            ? "host CPU"
              : gl           ? "wall, GL device"
              : r.batch_walk ? "host, emulated, walks in batches"
                             : "host, emulated");
  if (gl)
    std::printf("device %s: passes %.2f ms of GPU time (timer queries)\n",
                tracer->device().description().c_str(), r.stats.totals.device_ms);
  if (animating) std::printf("time %g s of %s\n", plan.times[0], animation_text.c_str());
}

// One line of the frames table (--frames with --stats table).
struct FrameLine {
  double time, pose_ms, build_ms, write_ms, render_ms;
  uint64_t uploaded, passes;
  double predicted_ms;
  std::string action;                   // initial, rebuild or refit
  uint64_t nodes_visited, voxel_steps;  // the walk's work (a tree's nodes, the grid's voxels)
};

// Write (--stats table, several frames): one line per frame, then the initialization.
void print_frames_table(const RenderArgs& a, const RenderPlan& plan, const host::Scene& scene,
                        host::AccelKind accel, const host::RenderResult& r,
                        const std::vector<FrameLine>& lines, double init_ms,
                        const std::string& animation_text) {
  const host::RenderOptions& opt = plan.opt;
  const bool cpu = plan.cpu;
  std::printf("scene %s, %s, %zu frames, %s, --update %s, %dx%d, %s %s\n", scene.name.c_str(),
              animation_text.c_str(), lines.size(), std::string(host::accel_name(accel)).c_str(),
              a.update.c_str(), r.width, r.height, cpu ? "engine" : "profile",
              cpu ? "cpu" : opt.profile.c_str());
  std::printf("%6s %9s %8s %9s %9s %11s %12s %10s %8s %12s %12s%s\n", "frame", "time s", "update",
              "pose ms", "build ms", "textures ms", "uploaded B", "render ms", "passes", "nodes",
              "voxels", a.predict ? "  predicted ms" : "");
  for (size_t f = 0; f < lines.size(); ++f) {
    const FrameLine& l = lines[f];
    std::printf("%6zu %9.4g %8s %9.2f %9.2f %11.2f %12llu %10.1f %8llu %12llu %12llu", f + 1,
                l.time, l.action.c_str(), l.pose_ms, l.build_ms, l.write_ms,
                static_cast<unsigned long long>(l.uploaded), l.render_ms,
                static_cast<unsigned long long>(l.passes),
                static_cast<unsigned long long>(l.nodes_visited),
                static_cast<unsigned long long>(l.voxel_steps));
    if (a.predict) std::printf("  %12.3f", l.predicted_ms);
    std::printf("\n");
  }
  std::printf("initialization %.1f ms (the first frame's grid and uploads)\n", init_ms);
}

// Build: which of the scene's animations play, ascending (none when the file has none).
// --animation names one (a name, even with commas in it, else an index) or a comma list; without
// it every animation of the file plays, as glTF viewers play them, unless two drive the same
// path of one node: they are alternatives then (a walk and a run), and the first plays alone, as
// before issue 34, with a note. Refuses a name the file does not have, and two named animations
// that drive the same path of one node (UsageError, exit 2).
std::vector<size_t> played_animations(const RenderArgs& a, const std::string& path,
                                      const host::AnimatedScene& animated) {
  const std::vector<host::Animation>& list = animated.animations();
  if (a.animation.empty()) {
    const std::vector<size_t> all = animated.all();
    const std::string why = animated.clash(all);
    if (why.empty()) return all;
    std::fprintf(stderr,
                 "vgpu-rt: %s: %s, so they cannot play together: animation 0 '%s' plays alone "
                 "(--animation chooses)\n",
                 path.c_str(), why.c_str(), list[0].name.c_str());
    return {0};
  }
  std::vector<size_t> played;
  if (const std::optional<size_t> whole = animated.find(a.animation)) {
    played = {*whole};
  } else {
    for (size_t start = 0;;) {
      const size_t comma = std::min(a.animation.find(',', start), a.animation.size());
      const std::string item = a.animation.substr(start, comma - start);
      const std::optional<size_t> found = animated.find(item);
      if (!found) {
        std::string known;
        for (size_t i = 0; i < list.size(); ++i)
          known += (i ? ", " : "") + std::to_string(i) + " '" + list[i].name + "'";
        throw UsageError("--animation " + a.animation + ": " + path +
                         " has no animation named or numbered '" + item + "' (" +
                         (known.empty() ? "it has none" : "it has " + known) + ")");
      }
      played.push_back(*found);
      if (comma == a.animation.size()) break;
      start = comma + 1;
    }
    std::sort(played.begin(), played.end());
    played.erase(std::unique(played.begin(), played.end()), played.end());
  }
  if (const std::string why = animated.clash(played); !why.empty())
    throw UsageError("--animation " + a.animation + ": " + path + ": " + why +
                     "; they cannot play together");
  return played;
}

// What plays, for the tables: "animation 'hop'", "animations 'rise' + 'spin'", or `none`.
std::string played_text(const host::AnimatedScene* animated, const std::vector<size_t>& played,
                        const std::string& none) {
  if (played.empty()) return none;
  std::string text = played.size() > 1 ? "animations " : "animation ";
  for (size_t i = 0; i < played.size(); ++i)
    text += (i ? " + '" : "'") + animated->animations()[played[i]].name + "'";
  return text;
}

// Write: a frame's image and AOVs (numbered when animating: frame_####.png).
void write_images(const RenderArgs& a, const RenderPlan& plan, const host::RenderResult& r,
                  int number) {
  auto numbered = [&](const std::string& file) {
    return plan.animating ? cli::frame_path(file, number) : file;
  };
  if (!a.out.empty()) host::write_image(numbered(a.out), r.width, r.height, 3, r.rgb);
  if (!plan.aov_depth.empty())
    host::write_image(numbered(plan.aov_depth), r.width, r.height, 1, r.depth);
  if (!plan.aov_hit.empty())
    host::write_image(numbered(plan.aov_hit), r.width, r.height, 1, r.hit_id);
}

// Build: the report's recorder (--report, --stats-csv) as the tracer's observer; with
// --report-frame K, behind a OneFrame that passes on frame K alone.
void attach_recorder(const RenderArgs& a, host::RenderOptions& opt,
                     std::optional<host::FrameRecorder>& recorder,
                     std::optional<OneFrame>& one_frame) {
  if (a.report.empty() && a.stats_csv.empty()) return;
  recorder.emplace(opt.width, opt.height, opt.masks, a.report.empty() ? 0 : host::kHistoryStride,
                   opt.trace_pixel ? std::vector{*opt.trace_pixel} : std::vector<glm::ivec2>{},
                   !a.report.empty());
  opt.observer = &*recorder;
  if (a.report_frame) opt.observer = &one_frame.emplace(*recorder);
}

// Progress on stderr: the iteration, and within its walks the passes and the rays still walking
// (or a walk in batches' share done and its time left), rewritten in place on a terminal every
// tenth of a second; elsewhere a line per iteration and a line within a walk every 5 s.
void set_progress(host::RenderOptions& opt, bool tty) {
  struct Line {
    bool tty;
    int it = 0, n = 0;
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  };
  auto line = std::make_shared<Line>(Line{tty});
  opt.progress = [line](int it, int n) {
    line->it = it;
    line->n = n;
    std::fprintf(stderr,
                 line->tty ? "\rvgpu-rt: iteration %d/%d\033[K" : "vgpu-rt: iteration %d/%d\n", it,
                 n);
    std::fflush(stderr);
  };
  opt.progress_every_ms = tty ? 100 : 5000;
  opt.walk_progress = [line](const host::WalkProgress& w) {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - line->start).count();
    std::string what;
    if (w.done >= 0) {
      what = std::string(w.rays) + ", " + std::to_string(int(100 * w.done)) +
             "% of the pixels walked (in batches)";
      if (w.left_ms >= 0) {
        char left[64];
        std::snprintf(left, sizeof left, ", about %.1f s left in this walk", w.left_ms / 1000);
        what += left;
      }
    } else {
      what = std::string(w.rays) + ": " + w.query + " counted " + std::to_string(w.rays_walking) +
             ", " + std::to_string(w.passes) + " passes";
    }
    std::fprintf(stderr,
                 line->tty ? "\rvgpu-rt: iteration %d/%d: %s; %.1f s\033[K"
                           : "vgpu-rt: iteration %d/%d: %s; %.1f s\n",
                 line->it, line->n, what.c_str(), s);
    std::fflush(stderr);
  };
}

}  // namespace

RenderArgs parse_render_args(const std::vector<std::string>& args, bool& lanes_given) {
  CLI::App app{"vgpu-rt render"};
  RenderArgs a;
  add_render_options(app, a);
  try {
    app.parse(std::vector<std::string>(args.rbegin(), args.rend()));  // CLI11 takes them reversed
  } catch (const CLI::ParseError& e) {
    throw UsageError(e.what());
  }
  lanes_given = app.count("--lanes") > 0;
  return a;
}

std::vector<RenderOptionInfo> render_option_infos() {
  CLI::App app{"vgpu-rt render"};
  RenderArgs a;
  add_render_options(app, a);
  std::vector<RenderOptionInfo> out;
  for (const CLI::Option* o : app.get_options()) {
    if (o->get_lnames().empty()) continue;  // the scene (positional) and --help
    const std::string name = o->get_lnames().front();
    if (name == "help") continue;
    out.push_back({name, o->get_default_str(), o->get_description(), o->get_expected_max() == 0});
  }
  return out;
}

int run_render(const RenderArgs& a, bool lanes_given, RenderOutcome* outcome,
               host::PassObserver* observer) {
  RenderPlan plan = parse_render(a, lanes_given, observer != nullptr);
  host::RenderOptions& opt = plan.opt;
  const host::FormatRequest& formats = plan.formats;
  const host::GridSpec& grid_spec = plan.grid_spec;
  const std::vector<double>& times = plan.times;
  const bool animating = plan.animating, cpu = plan.cpu, gl = plan.gl;
  std::optional<host::FrameRecorder> recorder;
  std::optional<OneFrame> one_frame;  // --report-frame K: the recorder sees frame K alone
  attach_recorder(a, opt, recorder, one_frame);
  if (observer) opt.observer = observer;  // validate refused it beside another or several frames

  // The scene: as the file has it, or posed at each frame's time (--time, --frames).
  const std::string path = host::resolve_scene(a.scene);
  std::optional<host::AnimatedScene> animated;
  std::vector<size_t> animation;  // the animations played together
  // Textures fitted to the profile's largest texture (docs/studies/materials.md), whatever the
  // engine, so that the CPU reference samples what the card would.
  host::LoadOptions load = host::with_images();
  if (a.textures == "fit") {
    load.fit_textures = vgpu::profile(opt.profile).max_texture_size;
    load.fit_for = "profile " + opt.profile;
  }
  if (animating) {
    animated.emplace(path, load);
    animation = played_animations(a, path, *animated);
    animated->check(animation);  // skinned meshes, morph-target weights: one line, exit 2
    if (plan.span_frames) {      // --frames N: over the played animations' keys
      const auto [first, last] = animated->span(animation);
      plan.times = cli::frame_times({first, last, int(times.size())});
    }
  }
  const host::StatsJson animation_json =
      animated ? host::animation_json(animated->animations(), animation) : host::StatsJson();
  auto pose_start = std::chrono::steady_clock::now();
  host::Scene scene = animated ? animated->at(animation, times[0]) : host::load_scene(path, load);
  if (!scene.textures_fitted.empty())
    std::fprintf(stderr, "vgpu-rt: %s\n", scene.textures_fitted.c_str());
  double pose_ms = animated ? host::ms_since(pose_start) : 0.0;
  const host::Scene& rest = animated ? animated->rest() : scene;  // frames a camera-less file
  const auto t0 = std::chrono::steady_clock::now();
  // The structure (make_accel): the one asked for, or with --accel auto every kind, each
  // probed below and the cheapest kept.
  const bool auto_accel = a.accel == "auto";
  const host::AccelParams params{host::grid_spec_for(grid_spec, scene, vgpu::profile(opt.profile))};
  std::vector<std::unique_ptr<host::Accel>> built;
  if (auto_accel)
    for (host::AccelKind k : host::kAccelKinds) built.push_back(host::make_accel(k, scene, params));
  else
    built.push_back(host::make_accel(host::parse_accel_kind(a.accel), scene, params));
  auto formats_for = [&](const host::Accel& accel) {
    return host::resolve(formats, scene, accel, vgpu::profile(opt.profile));
  };
  opt.formats = formats_for(*built.front());
  // Again with the formats resolved (MRT's) and the scene (a glass scene's ray streams).
  if (const auto refused = host::validate(opt, vgpu::profile(opt.profile), &plan.request, &scene);
      !refused.empty())
    throw UsageError(host::refusal_lines(refused));
  const float aspect = float(opt.width) / float(opt.height);
  // A frame's camera: the file's (moving with its node), else the rest scene's framing.
  auto camera_for = [&](const host::Scene& s) {
    return host::scene_camera(s.camera ? s : rest, aspect);
  };
  const bool several = times.size() > 1;
  const bool tty = ::isatty(2) && !a.quiet && !several;
  if (!a.quiet && !several) set_progress(opt, tty);  // several: a line per frame
  std::optional<host::AccelChoice> choice;
  size_t chosen = 0;
  if (auto_accel) {
    std::vector<host::AccelCandidate> candidates;
    for (const auto& accel : built) candidates.push_back({accel.get(), formats_for(*accel)});
    choice = host::choose_accel(scene, candidates, opt, camera_for(scene));
    for (size_t i = 0; i < built.size(); ++i)
      if (built[i]->kind() == choice->kind) chosen = i;
    opt.formats = formats_for(*built[chosen]);
  }
  const std::unique_ptr<host::Accel> walked = std::move(built[chosen]);
  built.clear();  // the structures not chosen
  host::Accel& accel = *walked;
  if (a.beams == "auto") {  // on the structure walked, with its formats
    plan.beams_choice = host::choose_beams(scene, accel, opt, camera_for(scene), a.engine);
    opt.beams = plan.beams_choice->on;
  }
  std::optional<host::StreamTracer> tracer;
  if (!cpu) tracer.emplace(scene, accel, opt);
  const double init_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  host::CpuStats cpu_stats;
  host::RenderResult r;
  // One frame's statistics object (the whole --stats-json of a render that is not animated).
  auto record = [&](double frame_init_ms) {
    return host::frame_stats_json({scene, path, a.engine, tracer ? &*tracer : nullptr, accel,
                                   choice ? &*choice : nullptr, opt, r, cpu_stats, a.shading,
                                   a.texture_filter, a.kernels, a.precision, frame_init_ms,
                                   plan.beams_choice ? &*plan.beams_choice : nullptr});
  };

  // Frame by frame: the scene posed, the structure rebuilt, the static textures that changed
  // uploaded again (--update rebuild), the frame rendered and its files written.
  host::StatsJson j;
  std::vector<host::StatsJson> frames_json;
  std::vector<FrameLine> lines;
  std::optional<std::pair<host::RenderResult, host::StatsJson>> reported;  // --report-frame
  std::string action = "initial";
  for (size_t f = 0; f < times.size(); ++f) {
    const int number = int(f) + 1;
    host::StreamTracer::Upload up;
    double write_ms = 0;
    if (f > 0) {
      pose_start = std::chrono::steady_clock::now();
      scene = animated->at(animation, times[f]);
      pose_ms = host::ms_since(pose_start);
      action = accel.update(scene, a.update);  // rebuilt (or a BVH refitted), in its new box
      const auto tu = std::chrono::steady_clock::now();
      if (tracer) up = tracer->update(scene, accel);
      write_ms = host::ms_since(tu);
    } else if (tracer) {
      up.bytes = tracer->static_bytes();  // the first frame's: initialization uploads them all
    }
    const host::Camera cam = camera_for(scene);
    cpu_stats = {};
    if (one_frame) one_frame->on = number == a.report_frame;
    r = cpu ? host::render_cpu(scene, accel, cam, opt, &cpu_stats) : tracer->render(cam);
    if (tty) std::fprintf(stderr, "\n");
    if (recorder && (!one_frame || one_frame->on)) recorder->finish(r.stats);

    write_images(a, plan, r, number);

    j = record(f == 0 ? init_ms : 0.0);
    double predicted = 0;
    if (!cpu && !gl) predicted = host::predict(r.stats, vgpu::profile(opt.profile)).total_ms;
    if (animating) {
      host::add_moving_frame(
          j, number, times[f], animation_json,
          host::frame_update_json(f == 0 ? std::string("initial") : action, pose_ms, accel.kind(),
                                  accel.build_ms(), write_ms, up, tracer.has_value()));
      if (several) frames_json.push_back(j);
      if (number == a.report_frame) reported.emplace(r, j);
      if (!a.quiet)
        std::fprintf(stderr,
                     "vgpu-rt: frame %d/%zu (t = %g s): update %.1f ms (pose %.1f, %s %.1f, "
                     "textures %.1f), %llu bytes uploaded; render %.1f ms, %llu passes\n",
                     number, times.size(), times[f], pose_ms + accel.build_ms() + write_ms, pose_ms,
                     std::string(accel.name()).c_str(), accel.build_ms(), write_ms,
                     static_cast<unsigned long long>(up.bytes), r.render_ms,
                     static_cast<unsigned long long>(r.stats.totals.passes));
    }
    const host::WalkWork work = cpu ? host::WalkWork{} : host::walk_work(r.stats);
    lines.push_back({times[f], pose_ms, accel.build_ms(), write_ms, r.render_ms, up.bytes,
                     r.stats.totals.passes, predicted, f == 0 ? std::string("initial") : action,
                     cpu ? cpu_stats.nodes_visited : work.nodes_visited,
                     cpu ? cpu_stats.voxel_steps : work.voxel_steps});
  }
  if (several)
    j = host::frames_stats_json(scene.name, path, animation_json, a.update, std::move(frames_json));
  if (!a.stats_json.empty()) host::write_stats_json(a.stats_json, j);
  if (!a.stats_csv.empty()) host::write_stats_csv(a.stats_csv, *recorder);
  if (!a.report.empty())
    host::write_report(a.report, *recorder, reported ? reported->first : r,
                       reported ? reported->second : j);
  if (a.stats == "json") {
    std::cout << host::stats_text(j);
  } else if (a.stats == "table" && several) {
    print_frames_table(a, plan, scene, accel.kind(), r, lines, init_ms,
                       played_text(animated ? &*animated : nullptr, animation,
                                   "animation none (the scene is static)"));
  } else if (a.stats == "table") {
    print_table(a, plan, scene, accel, choice ? &*choice : nullptr, r, cpu_stats, init_ms,
                tracer ? &*tracer : nullptr,
                played_text(animated ? &*animated : nullptr, animation,
                            "no animation (the scene is static)"));
  }
  if (outcome) {
    outcome->result = std::move(r);
    outcome->stats = std::move(j);
    outcome->frames = times.size();
    return 0;  // --predict's lines are the caller's to print
  }
  if (a.predict && !several) {
    const vgpu::Profile& p = vgpu::profile(opt.profile);
    std::cout << host::describe(host::predict(r.stats, p), p);
  }
  return 0;
}

}  // namespace cli
