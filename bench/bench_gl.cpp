// bench_gl: the paper's passes on a real OpenGL driver (the GL device) beside the virtual GPU.
// Prints, and writes as JSON, per scene and image size: wall ms and GPU ms (timer queries) of a
// frame and of every kernel, passes and query read-backs, medians of several runs, with the
// emulator's host ms and the cost model's predictions for the same counters; and the fixed
// costs of one pass, one query read-back and one program switch, measured on tiny passes.
// Frames can run glass's ray streams (--ray-streams) and the sampling modes (--sampling), each
// priced beside its measurement like the paper's frame, and with beams over tiles (--beams on,
// docs/studies/groups.md).
// Needs no OpenImageIO and no display: it runs on any machine with EGL (llvmpipe, NVIDIA).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <regex>
#include <sstream>

#include "bench/gl_probes/gl_probes.h"
#include "gl/context.h"
#include "gl/gl_device.h"
#include "host/accel/accel.h"
#include "host/accel/grid.h"
#include "host/accel/grid2.h"
#include "host/image/image_io.h"
#include "host/model/cost_model.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/sampling.h"
#include "host/trace/stream/stream_tracer.h"
#include "host/trace/validate.h"
#include "vgpu/gpu.h"

namespace {

using bench_gl_probes::Clock;
using bench_gl_probes::median;
using bench_gl_probes::ms_since;
using json = nlohmann::ordered_json;

// Each series' median, by name (null where there are none: the emulator's frames).
json medians(const std::map<std::string, std::vector<double>>& series) {
  if (series.empty()) return json();
  json out = json::object();
  for (const auto& [name, v] : series) out[name] = median(v);
  return out;
}

// Tiny programs for the fixed costs: copy the own texel (one fetch, one output), the same with
// one multiply (a second program, so switching between them is a real program change), and a
// two-target copy (MRT, the profile's outputs permitting).
struct CopyTexel {
  static constexpr const char* name = "copy texel";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  static constexpr std::array<const char*, 1> units{"source"};
  template <class L>
  void operator()(vgpu::Fragments<L>& f) const {
    f.out(0) = f.fetch_own(0);
  }
};
struct ScaleTexel {
  static constexpr const char* name = "scale texel";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  static constexpr std::array<const char*, 1> units{"source"};
  template <class L>
  void operator()(vgpu::Fragments<L>& f) const {
    const vgpu::Vec4<typename L::F> v = f.fetch_own(0);
    f.out(0) = {v.x * typename L::F(0.5f), v.y, v.z, v.w};
  }
};
struct CopyTwice {
  static constexpr const char* name = "copy to two targets";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 2;
  static constexpr std::array<const char*, 2> units{"source_a", "source_b"};
  template <class L>
  void operator()(vgpu::Fragments<L>& f) const {
    f.out(0) = f.fetch_own(0);
    f.out(1) = f.fetch_own(1);
  }
};

struct Fixed {
  double wall_us = 0, gpu_us = 0;
};

// n passes of program p (alternating with q when given) over a size x size target, ping-ponged,
// each inside an occlusion query read back at once when `readback`; per pass, medians of runs.
Fixed time_passes(gl::GlDevice& d, int size, int n, int runs, bool readback, const vgpu::Program& p,
                  const vgpu::Program* q, int targets = 1) {
  std::vector<vgpu::Texture> tex;
  for (int i = 0; i < 2 * targets; ++i)
    tex.push_back(d.make_texture("t" + std::to_string(i), size, size, 4));
  for (auto& t : tex) d.upload(t);
  std::vector<double> wall, gpu;
  for (int r = 0; r <= runs; ++r) {  // run 0 warms up (compiles)
    d.finish();
    d.stats().clear();
    const auto t0 = Clock::now();
    for (int i = 0; i < n; ++i) {
      const int a = i & 1, b = a ^ 1;
      d.use_program(q && (i & 1) ? *q : p);
      d.unbind_textures();
      for (int k = 0; k < targets; ++k) d.bind_texture(k, tex[size_t(2 * k + a)]);
      if (targets == 1)
        d.set_targets({&tex[size_t(b)]});
      else
        d.set_targets({&tex[size_t(b)], &tex[size_t(2 + b)]});
      if (readback) d.begin_query();
      d.draw();
      if (readback) d.end_query();
    }
    d.finish();
    const double w = ms_since(t0);
    if (r == 0) continue;
    wall.push_back(1e3 * w / n);
    gpu.push_back(1e3 * d.stats().totals.device_ms / n);
  }
  return {median(wall), median(gpu)};
}

// A sampling mode of --sampling: spp:N (N rays per pixel, the accumulation frames),
// adaptive:N (adaptive supersampling up to N) or undersample:K (the lattice of every K-th
// pixel, then the gaps); a ":gated" suffix runs the gated frames over the whole target
// (--compact off) instead of the dense streams; adaptive's ":image" or ":object" suffix its
// criterion instead of the default, the budget. Returns false for anything else, or N not a
// square from 1 to 256.
bool parse_sampling(const std::string& text, host::RenderOptions& opt) {
  std::smatch m;
  if (!std::regex_match(
          text, m, std::regex(R"((spp|adaptive|undersample):(\d{1,4})(:gated)?(:image|:object)?)")))
    return false;
  const int n = std::stoi(m[2]);
  opt.spp = 1;
  opt.adaptive = false;
  opt.undersample = 0;
  opt.compact = !m[3].matched;
  opt.aa_criterion = m[4] == ":image"    ? host::RenderOptions::AaCriterion::image
                     : m[4] == ":object" ? host::RenderOptions::AaCriterion::object
                                         : host::RenderOptions::AaCriterion::budget;
  if (m[4].matched && m[1] != "adaptive") return false;
  if (m[1] == "undersample") {
    opt.undersample = n;
    return n >= 1 && n <= 64;
  }
  opt.spp = n;
  opt.adaptive = m[1] == "adaptive";
  return host::spp_refusal(n).empty();
}

struct FrameRun {
  std::vector<double> wall, gpu, host;
  std::map<std::string, std::vector<double>> kernel_gpu, kernel_host;
  // The GL device's host time by call (gl::GlDevice::HostTimes) and the rest of the wall time,
  // the host's own work between calls, each timed frame; and the GL objects it made in them.
  std::map<std::string, std::vector<double>> split, made;
  vgpu::FrameStats stats;
  uint64_t rays_traced = 0;
  bool streams = false;  // the frame ran as ray streams (--ray-streams on, or a glass scene)
  uint64_t beam_passes = 0, beam_tiles = 0, beam_tiles_missed = 0;  // --beams on: the last frame's
  std::string device;
  int warmup_frames = 0;    // frames after the compiling one, run before timing (--warmup-ms)
  double warmup_ms = 0;     // their wall time, ms
  double timed_from_s = 0;  // when the timed frames began and ended, seconds since the Unix
  double timed_to_s = 0;    // epoch (system clock): to match them with a GPU clock log
};

// Seconds since the Unix epoch, as nvidia-smi's log stamps its samples.
double unix_s() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

FrameRun run_frames(const host::Scene& scene, const host::Accel& accel, const host::Camera& cam,
                    host::RenderOptions opt, int runs, int warmup_ms,
                    const std::string& dump_dir = "") {
  FrameRun fr;
  host::StreamTracer tracer(scene, accel, opt);
  fr.device = tracer.device().description();
  auto* gld = dynamic_cast<gl::GlDevice*>(&tracer.device());
  if (gld && !dump_dir.empty()) {
    std::filesystem::create_directories(dump_dir);
    gld->dump_programs_to(dump_dir);
  }
  for (int r = 0; r <= runs; ++r) {  // run 0 warms up (the GL device compiles its programs)
    if (r == 1 && gld && warmup_ms > 0) {
      // A GPU left idle (the emulator's frames before) lowers its clock; frames of this very
      // configuration until warmup_ms have passed bring it back up before timing starts.
      const auto t0 = Clock::now();
      while (ms_since(t0) < warmup_ms) {
        tracer.render(cam);
        ++fr.warmup_frames;
      }
      fr.warmup_ms = ms_since(t0);
    }
    if (r == 1) fr.timed_from_s = unix_s();
    const gl::GlDevice::HostTimes h0 = gld ? gld->host_times() : gl::GlDevice::HostTimes{};
    const host::RenderResult res = tracer.render(cam);
    if (r == 0) continue;
    if (gld) {
      const gl::GlDevice::HostTimes& h = gld->host_times();
      const std::pair<const char*, double> calls[] = {{"draw", h.draw_ms - h0.draw_ms},
                                                      {"query_wait", h.wait_ms - h0.wait_ms},
                                                      {"download", h.download_ms - h0.download_ms},
                                                      {"upload", h.upload_ms - h0.upload_ms},
                                                      {"clear", h.clear_ms - h0.clear_ms},
                                                      {"settle", h.settle_ms - h0.settle_ms}};
      double in_calls = 0;
      for (const auto& [name, ms] : calls) {
        fr.split[name].push_back(ms);
        in_calls += ms;
      }
      fr.split["between_calls"].push_back(res.render_ms - in_calls);
      fr.made["textures"].push_back(double(h.textures_made - h0.textures_made));
      fr.made["framebuffers"].push_back(double(h.framebuffers_made - h0.framebuffers_made));
      fr.made["programs"].push_back(double(h.programs_linked - h0.programs_linked));
      fr.made["textures_freed"].push_back(double(h.textures_freed - h0.textures_freed));
      fr.made["glsl_printed"].push_back(double(h.variants_printed - h0.variants_printed));
      fr.made["glsl_reused"].push_back(double(h.variants_reused - h0.variants_reused));
    }
    fr.wall.push_back(res.render_ms);
    fr.gpu.push_back(res.stats.totals.device_ms);
    for (const auto& p : res.stats.programs) {
      fr.kernel_gpu[p.name].push_back(p.counters.device_ms);
      fr.kernel_host[p.name].push_back(p.counters.host_ms);
    }
    fr.stats = res.stats;
    fr.rays_traced = res.rays_traced;
    fr.streams = res.streams.on;
    fr.beam_passes = res.beam_passes;
    fr.beam_tiles = res.beam_tiles;
    fr.beam_tiles_missed = res.beam_tiles_missed;
  }
  fr.timed_to_s = unix_s();
  return fr;
}

// The command line.
struct Args {
  std::string device = "auto", json_path, grid_text = "auto";  // the CLI's --grid default
  std::vector<std::string> scenes = {"sphere-alone", "bunny", "bunny-mirror"};
  std::vector<int> sizes = {256};
  int runs = 3, micro_passes = 200, threads = 0, warmup_ms = 0;
  std::string dump_programs;
  bool no_stream = false, no_frames = false;
  std::string wait_mode = "block";
  std::vector<std::string> variants = {"multipass"};
  std::vector<std::string> accels = {"grid"};
  int bounces = 2;
  std::vector<std::string> ray_streams = {"off"}, sampling = {"spp:1"}, beams = {"off"};
  bool shadows = false, no_fixed = false, latency = false, coherence = false;
};

// Declares every option of bench_gl on app, bound to a.
void add_options(CLI::App& app, Args& a) {
  app.add_option("--gl-device", a.device, "auto, or an EGL device index")->capture_default_str();
  app.add_option("--scenes", a.scenes, "Scene names or .gltf paths")->capture_default_str();
  app.add_option("--sizes", a.sizes, "Image sizes (square)")
      ->capture_default_str()
      ->check(CLI::Range(8, 4096));
  app.add_option("--grid", a.grid_text, "Grid: auto, N or AxBxC")->capture_default_str();
  app.add_option("--runs", a.runs, "Timed runs per figure (after one warm-up)")
      ->capture_default_str()
      ->check(CLI::Range(1, 100));
  app.add_option("--dump-programs", a.dump_programs,
                 "GL frames: write every program the driver links, GLSL and program binary "
                 "(NVIDIA's holds its compiled assembly as text), under DIR/scene_accel_variant/");
  app.add_option("--warmup-ms", a.warmup_ms,
                 "GL frames: after the warm-up frame, run frames of the same configuration until "
                 "this many ms have passed before timing (a GPU idle before them has lowered its "
                 "clock); 0: none")
      ->capture_default_str()
      ->check(CLI::Range(0, 600000));
  app.add_option("--micro-passes", a.micro_passes, "Passes per fixed-cost measurement")
      ->capture_default_str()
      ->check(CLI::Range(10, 100000));
  app.add_option("--threads", a.threads, "Host threads of the vgpu runs (0: all cores)")
      ->capture_default_str()
      ->check(CLI::Range(0, 256));
  app.add_flag("--no-stream", a.no_stream, "Skip the vgpu (emulator) runs");
  app.add_option("--variants", a.variants,
                 "Pipelines per frame: multipass (the paper's, Table 1's gf5700 profile), mrt "
                 "(fused two-output passes) and looping (the looping kernels), both on the h200 "
                 "profile")
      ->check(CLI::IsMember({"multipass", "mrt", "looping"}))
      ->capture_default_str();
  app.add_option("--readback-wait", a.wait_mode,
                 "GL frames: block (GL_QUERY_RESULT), poll (spin on GL_QUERY_RESULT_AVAILABLE), "
                 "both, or none (no GL frames: the emulator's counts and predictions only)")
      ->check(CLI::IsMember({"block", "poll", "both", "none"}))
      ->capture_default_str();
  std::vector<std::string> accel_words;  // the table's (host/accel/accel.h: kAccelRows)
  for (const host::AccelRow& row : host::kAccelRows) accel_words.emplace_back(row.name);
  app.add_option("--accel", a.accels,
                 "Acceleration structures per frame: " + host::accel_names() +
                     " (as vgpu-rt render --accel; the grid's resolution is --grid)")
      ->check(CLI::IsMember(accel_words))
      ->capture_default_str();
  app.add_option("--bounces", a.bounces,
                 "Reflection iterations after the primary one (0: primary "
                 "rays only)")
      ->capture_default_str()
      ->check(CLI::Range(0, 16));
  app.add_option("--ray-streams", a.ray_streams,
                 "Per frame: off (the paper's reflections), on (reflections through glass's ray "
                 "streams: split, compaction, gather); a scene with glass always runs them")
      ->check(CLI::IsMember({"off", "on"}))
      ->capture_default_str();
  app.add_option("--sampling", a.sampling,
                 "Sampling modes per frame: spp:N (N a square, 1 to 256), adaptive:N (--aa "
                 "adaptive up to N, the budget criterion; adaptive:N:image, adaptive:N:object "
                 "the other criteria), undersample:K (--aa undersample:K, K 1 to 64); "
                 "adaptive:N:gated, undersample:K:gated with --compact off")
      ->check(CLI::Validator(
          [](std::string& t) -> std::string {
            host::RenderOptions o;
            return parse_sampling(t, o)
                       ? ""
                       : "expected spp:N, adaptive:N (N 1, 4, 9, ..., 256) or undersample:K (K "
                         "1 to 64), got '" +
                             t + "'";
          },
          "MODE", "sampling"))
      ->capture_default_str();
  app.add_option("--beams", a.beams,
                 "Per frame: off, on (beams over tiles, 8x8 pixels, before the primary rays' "
                 "walk: docs/studies/groups.md; every structure)")
      ->check(CLI::IsMember({"off", "on"}))
      ->capture_default_str();
  app.add_flag("--shadows", a.shadows, "Shadow rays in the frames (off: Table 1's setting)");
  app.add_flag("--no-fixed", a.no_fixed, "Skip the fixed-cost passes (frames only)");
  app.add_flag("--no-frames", a.no_frames, "Only the fixed costs");
  app.add_flag("--latency", a.latency,
               "Also measure latencies: one fragment following a chain of dependent texel "
               "fetches (RGBA32F textures of 16x16, 512x512 and 2048x2048 texels) and of "
               "dependent multiply-adds, GPU time per iteration (needs a GL device)");
  app.add_flag("--coherence", a.coherence,
               "Also measure where a warp's fetches go: a 256x256 pass of 64 independent "
               "fetches a fragment from one 512x512 RGBA32F texture, with every fragment on one "
               "texel, each 8x4 tile on one, neighbours on adjacent texels, and each on a random "
               "one; GPU time against the cost model's price, the same for all four (needs a GL "
               "device)");
  app.add_option("--json", a.json_path, "Also write every figure as JSON to this file");
}

// The fixed costs, on a device of its own (gf6600: two outputs for the MRT pass): one pass, one
// query read-back and one program switch on tiny passes, then texture clears and downloads and
// passes over large targets. Adds pass_us, readback_us, program_switch_us and fixed to out.
void measure_fixed_costs(const Args& a, json& out) {
  const int runs = a.runs, micro_passes = a.micro_passes;
  gl::GlDevice d(vgpu::profile("gf6600"), a.device, gl::GlDevice::ReadbackWait::block);
  vgpu::KernelProgram<CopyTexel> copy;
  vgpu::KernelProgram<ScaleTexel> scale;
  vgpu::KernelProgram<CopyTwice> twice;
  json fixed = json::array();
  auto row = [&](const std::string& what, int size, const Fixed& f) {
    std::printf("  %-46s %5dx%-5d wall %9.2f us  gpu %9.2f us\n", what.c_str(), size, size,
                f.wall_us, f.gpu_us);
    fixed.push_back({{"what", what}, {"size", size}, {"wall_us", f.wall_us}, {"gpu_us", f.gpu_us}});
  };
  std::printf("fixed costs, per pass (medians of %d runs of %d passes):\n", runs, micro_passes);
  for (int size : {1, 64, 256}) {
    const Fixed pass = time_passes(d, size, micro_passes, runs, false, copy, nullptr);
    const Fixed rb = time_passes(d, size, micro_passes, runs, true, copy, nullptr);
    const Fixed sw = time_passes(d, size, micro_passes, runs, false, copy, &scale);
    row("pass", size, pass);
    row("pass + blocking query read-back", size, rb);
    row("pass, program switched every pass", size, sw);
    if (size == 1) {
      out["pass_us"] = pass.wall_us;
      out["readback_us"] = rb.wall_us - pass.wall_us;
      out["program_switch_us"] = sw.wall_us - pass.wall_us;
    }
  }
  gl::GlDevice dp(vgpu::profile("gf6600"), a.device, gl::GlDevice::ReadbackWait::poll);
  for (int size : {1, 256})
    row("pass + polled query read-back", size,
        time_passes(dp, size, micro_passes, runs, true, copy, nullptr));
  // Texture work outside passes: a clear, and a read-back of one RGBA32F texture to the host
  // (glGetTexImage; the image at the end of a frame), each after a glFinish.
  for (int size : {256, 1024, 2048}) {
    vgpu::Texture t = d.make_texture("readback", size, size, 4);
    d.upload(t);
    std::vector<double> clear_us, down_us;
    for (int r = 0; r <= runs; ++r) {
      d.finish();
      auto t0 = Clock::now();
      d.clear(t, {0.f, 0.f, 0.f, 0.f});
      d.finish();
      const double c = 1e3 * ms_since(t0);
      t0 = Clock::now();
      d.download(t);
      const double w = 1e3 * ms_since(t0);
      if (r == 0) continue;
      clear_us.push_back(c);
      down_us.push_back(w);
    }
    row("clear one RGBA32F texture", size, {median(clear_us), 0});
    row("download one RGBA32F texture", size, {median(down_us), 0});
  }
  for (int size : {1024, 2048}) {
    const int n = std::max(10, micro_passes / 10);
    row("pass, one RGBA32F target", size, time_passes(d, size, n, runs, false, copy, nullptr));
    row("pass + blocking query read-back", size,
        time_passes(d, size, n, runs, true, copy, nullptr));
    row("pass + polled query read-back", size, time_passes(dp, size, n, runs, true, copy, nullptr));
    row("pass, two RGBA32F targets (MRT)", size,
        time_passes(d, size, std::max(10, micro_passes / 10), runs, false, twice, nullptr, 2));
  }
  std::printf(
      "  => one pass %.2f us, one query read-back %.2f us, one program switch %.2f us "
      "(1x1 passes, wall)\n",
      out["pass_us"].get<double>(), out["readback_us"].get<double>(),
      out["program_switch_us"].get<double>());
  out["fixed"] = fixed;
}

// One kernel's figures in a frame; for an emulator frame (!gl) the cost model's prediction of
// its passes' work and fixed costs on the h200.
json kernel_json(const FrameRun& fr, const vgpu::FrameStats::ProgramTotals& p, bool gl) {
  json k = {{"name", p.name},
            {"paper_name", p.paper_name},
            {"passes", p.counters.passes},
            {"gpu_ms", gl ? json(median(fr.kernel_gpu.at(p.name))) : json()},
            {"host_ms", median(fr.kernel_host.at(p.name))}};
  if (!gl) {
    vgpu::FrameStats one;
    one.programs = {p};
    one.totals = p.counters;
    for (const vgpu::Profile& hp : vgpu::profiles()) {  // every card the GL device measures
      if (hp.gl_renderer.empty()) continue;
      const host::CostBreakdown b = host::predict(one, hp);
      k["predicted_" + hp.name + "_ms"] = b.total_ms;
      k["predicted_" + hp.name + "_work_ms"] = b.arithmetic_ms + b.texture_ms + b.memory_ms;
      k["predicted_" + hp.name + "_latency_ms"] = b.latency_ms;
      k["predicted_" + hp.name + "_fetch_wait_ms"] = b.fetch_wait_ms;  // of the work
      // The demands (CostBreakdown): the work is the largest of them plus the fetch wait.
      k["predicted_" + hp.name + "_arithmetic_demand_ms"] = b.arithmetic_demand_ms;
      k["predicted_" + hp.name + "_texture_demand_ms"] = b.texture_demand_ms;
      k["predicted_" + hp.name + "_memory_demand_ms"] = b.memory_demand_ms;
    }
    // The emulator's counts of the kernel's passes, named as host::counters_json names them
    // (bench_gl does not link host_report, which brings OpenImageIO, to travel to a GPU host).
    json counters;
    for (const auto& [name, field] : vgpu::kCounterFields) counters[name] = p.counters.*field;
    k["counters"] = counters;
  }
  return k;
}

// What one frame configuration names, beside its measurements.
struct FrameKey {
  std::string scene, accel, variant, streams, mode, engine, beams;
  int size = 0;
};

// One frame configuration's figures as JSON, and its line on stdout.
json frame_json(const FrameKey& key, const host::RenderOptions& opt, const FrameRun& fr, int runs) {
  const bool gl = key.engine != "stream";
  const auto waits = fr.split.find("query_wait");  // the read-backs' waits, GL frames only
  const double wait = waits == fr.split.end() ? 0.0 : median(waits->second);
  json f = {{"scene", key.scene},
            {"accel", key.accel},
            {"bounces", opt.bounces},
            {"variant", key.variant},
            {"shadows", opt.shadows},
            {"ray_streams", key.streams},
            {"streams_ran", fr.streams},
            {"sampling", key.mode},
            {"beams", key.beams},
            {"beam_passes", fr.beam_passes},
            {"beam_tiles", fr.beam_tiles},
            {"beam_tiles_missed", fr.beam_tiles_missed},
            {"size", key.size},
            {"engine", key.engine},
            {"device", fr.device},
            {"runs", runs},
            {"warmup_frames", fr.warmup_frames},
            {"warmup_ms", fr.warmup_ms},
            {"timed_from_s", fr.timed_from_s},
            {"timed_to_s", fr.timed_to_s},
            {"wall_ms", median(fr.wall)},
            {"wall_runs_ms", fr.wall},  // every timed frame, in order
            {"gpu_ms", gl ? json(median(fr.gpu)) : json()},
            {"readback_wait_ms", gl ? json(wait) : json()},
            {"host_split_ms", medians(fr.split)},
            {"gl_objects_made", medians(fr.made)},
            {"gpu_runs_ms", gl ? json(fr.gpu) : json()},
            {"passes", fr.stats.totals.passes},
            {"query_readbacks", fr.stats.totals.query_readbacks},
            {"program_loads", fr.stats.totals.program_loads},
            {"fragments_shaded", fr.stats.totals.fragments_shaded},
            {"rays_traced", fr.rays_traced}};
  json kernels = json::array();
  for (const auto& p : fr.stats.programs) kernels.push_back(kernel_json(fr, p, gl));
  f["kernels"] = kernels;
  if (!gl) {
    json pred;
    for (const vgpu::Profile& p : vgpu::profiles())
      pred[p.name] = host::prices(p, opt.looping, opt.steps_per_pass)
                         ? json(host::predict(fr.stats, p).total_ms)
                         : json(nullptr);  // the looping program cannot run there
    f["predicted_ms"] = pred;
    for (const vgpu::Profile& hp : vgpu::profiles()) {  // every card the GL device measures
      if (hp.gl_renderer.empty()) continue;
      json card = json::object();
      for (const auto& [k, v] : host::predict(fr.stats, hp).items()) card[k] = v;
      f["predicted_" + hp.name] = card;
    }
  }
  std::printf("%-14s %4dx%-4d %-6s %-9s %-7s streams %-3s %-13s beams %-3s wall %9.1f ms",
              key.scene.c_str(), key.size, key.size, key.accel.c_str(), key.variant.c_str(),
              key.engine.c_str(), key.streams.c_str(), key.mode.c_str(), key.beams.c_str(),
              median(fr.wall));
  if (gl)
    std::printf("  gpu %9.1f ms  wait %8.1f ms  warm-up %d frames", median(fr.gpu), wait,
                fr.warmup_frames);
  else
    std::printf("  h200 predicted %8.1f ms", f["predicted_ms"]["h200"].get<double>());
  std::printf("  passes %6llu  read-backs %5llu\n",
              static_cast<unsigned long long>(fr.stats.totals.passes),
              static_cast<unsigned long long>(fr.stats.totals.query_readbacks));
  std::fflush(stdout);
  return f;
}

// The profile a variant's frames run on: the paper's pipeline at Table 1's profile (the CLI's
// default); its future work (MRT fused passes, the looping kernels) needs a profile with several
// outputs and loops: the h200's.
std::string profile_for(const std::string& variant) {
  return variant == "multipass" ? "gf5700" : "h200";
}

// One frame's options: docs/studies/table1.md's settings at `size`, with a variant, a ray-stream
// setting, a sampling mode, beams and an engine.
host::RenderOptions frame_options(const Args& a, int size, const std::string& variant,
                                  const std::string& streams, const std::string& mode,
                                  const std::string& beams, const std::string& engine) {
  host::RenderOptions opt;
  opt.width = opt.height = size;
  opt.bounces = a.bounces;
  opt.shading = kernels::ShadingModel::phong;
  opt.shadows = a.shadows;
  opt.threads = a.threads;
  opt.gl_device = a.device;
  opt.mrt = variant == "mrt";
  opt.looping = variant == "looping";
  opt.profile = profile_for(variant);
  opt.ray_streams = streams == "on";
  opt.beams = beams == "on";
  parse_sampling(mode, opt);  // checked when parsed
  opt.device = engine != "stream" ? "gl" : "vgpu";
  opt.gl_readback = engine == "gl-poll" ? "poll" : "block";
  return opt;
}

// The engines --readback-wait and --no-stream ask for.
std::vector<std::string> engines_of(const Args& a) {
  std::vector<std::string> engines;
  if (a.wait_mode == "block" || a.wait_mode == "both") engines.push_back("gl");
  if (a.wait_mode == "poll" || a.wait_mode == "both") engines.push_back("gl-poll");
  if (!a.no_stream) engines.push_back("stream");
  return engines;
}

// host::validate over every frame the options ask for, before any device or scene is built:
// one line per refused option of each refused combination (empty: every frame can run).
std::vector<std::string> refused_frames(const Args& a) {
  std::vector<std::string> lines;
  for (int size : a.sizes)
    for (const std::string& variant : a.variants)
      for (const std::string& streams : a.ray_streams)
        for (const std::string& mode : a.sampling)
          for (const std::string& beams : a.beams)
            for (const std::string& engine : engines_of(a)) {
              const host::RenderOptions opt =
                  frame_options(a, size, variant, streams, mode, beams, engine);
              for (const host::Refusal& r : host::validate(opt, vgpu::profile(opt.profile)))
                lines.push_back(variant + ", ray streams " + streams + ", " + mode + ", beams " +
                                beams + ", " + engine + ": " + r.why);
            }
  std::sort(lines.begin(), lines.end());
  lines.erase(std::unique(lines.begin(), lines.end()), lines.end());
  return lines;
}

// The frames of one scene at one size: every structure, variant, ray-stream setting, sampling
// mode and engine, appended to frames.
void scene_frames(const Args& a, const host::Scene& scene, int size,
                  const std::vector<std::string>& engines, json& frames) {
  // Each structure once per profile, as the CLI builds it for the frame's profile (the grid's
  // auto resolution is capped by the profile's largest texture).
  std::map<std::pair<std::string, std::string>, std::unique_ptr<host::Accel>> built;
  auto structure = [&](const std::string& name, const std::string& profile) -> host::Accel& {
    auto& s = built[{name, profile}];
    if (!s) {
      const host::AccelParams params{
          host::grid_spec_for(host::parse_grid_spec(a.grid_text), scene, vgpu::profile(profile))};
      s = host::make_accel(host::parse_accel_kind(name), scene, params);
    }
    return *s;
  };
  const host::Camera cam = host::scene_camera(scene);
  for (const std::string& accel_name : a.accels)
    for (const std::string& variant : a.variants) {
      const host::Accel& accel = structure(accel_name, profile_for(variant));
      for (const std::string& streams : a.ray_streams)
        for (const std::string& mode : a.sampling)
          for (const std::string& beams : a.beams)
            for (const std::string& engine : engines) {
              const host::RenderOptions opt =
                  frame_options(a, size, variant, streams, mode, beams, engine);
              const std::string dump =
                  a.dump_programs.empty()
                      ? ""
                      : a.dump_programs + "/" + scene.name + "_" + accel_name + "_" + variant;
              const FrameRun fr = run_frames(scene, accel, cam, opt, a.runs, a.warmup_ms, dump);
              const FrameKey key{scene.name, accel_name, variant, streams,
                                 mode,       engine,     beams,   size};
              frames.push_back(frame_json(key, opt, fr, a.runs));
            }
    }
}

// Every frame: the scenes by the sizes, on the engines --readback-wait and --no-stream ask for.
json measure_frames(const Args& a) {
  const std::vector<std::string> engines = engines_of(a);
  json frames = json::array();
  for (const std::string& name : a.scenes) {
    const host::Scene scene = host::load_scene(host::resolve_scene(name), host::with_images());
    for (int size : a.sizes) scene_frames(a, scene, size, engines, frames);
  }
  return frames;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench_gl: the stream ray tracer's passes on the GL device beside the vgpu"};
  Args a;
  add_options(app, a);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {  // --help exits 0; a bad option 2, as vgpu-rt does
    return app.exit(e) == 0 ? 0 : 2;
  }
  if ((a.latency || a.coherence) && a.wait_mode == "none") {
    std::fprintf(stderr, "bench_gl: %s needs a GL device (--readback-wait block, poll or both)\n",
                 a.latency ? "--latency" : "--coherence");
    return 2;
  }
  // Every frame's options, checked before any device or scene is built (host::validate).
  if (!a.no_frames)
    if (const std::vector<std::string> refused = refused_frames(a); !refused.empty()) {
      for (const std::string& line : refused) std::fprintf(stderr, "bench_gl: %s\n", line.c_str());
      return 2;
    }

  try {
    json out;
    if (a.wait_mode != "none") {
      gl::GlDevice d(vgpu::profile("gf6600"), a.device, gl::GlDevice::ReadbackWait::block);
      out["device"] = d.description();
      out["renderer"] = d.context().renderer();
      out["gl_version"] = d.context().version();
      // The profile measured on this card, which its frames are to be compared with (null where
      // none was: scripts/docs/cells.py then refuses them).
      const vgpu::Profile* card = vgpu::profile_for_renderer(d.context().renderer());
      out["card_profile"] = card ? json(card->name) : json();
      std::printf("device: %s\n", d.description().c_str());
    }
    if (a.wait_mode != "none" && !a.no_fixed) measure_fixed_costs(a, out);
    if (a.latency) {
      gl::GlDevice d(vgpu::profile("h200"), a.device, gl::GlDevice::ReadbackWait::poll);
      out["latency"] = bench_gl_probes::measure_latencies(d, a.runs, std::max(a.warmup_ms, 200));
    }
    if (a.coherence) {
      gl::GlDevice d(vgpu::profile("h200"), a.device, gl::GlDevice::ReadbackWait::poll);
      const vgpu::Profile* card = vgpu::profile_for_renderer(d.context().renderer());
      out["coherence"] = bench_gl_probes::measure_coherence(d, a.runs, std::max(a.warmup_ms, 200),
                                                            card ? *card : vgpu::profile("h100"));
    }
    if (!a.no_frames) {
      out["grid"] = a.grid_text;  // --grid, which the frames record nowhere else
      out["frames"] = measure_frames(a);
    }
    if (!a.json_path.empty()) {
      std::ofstream f(a.json_path);
      f << out.dump(2) << "\n";
      if (!f) throw std::runtime_error(a.json_path + ": cannot write");
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_gl: %s\n", e.what());
    return 1;
  }
  return 0;
}
