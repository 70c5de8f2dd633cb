// The statistics object of one frame (stats_json.h); its keys and their order are what
// --stats-json has always written.

// GCC 12 reports false positives inside nlohmann_json's templates.
#if defined(__GNUC__) && !defined(__clang__)  // GCC's warnings; clang has neither
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wrestrict"
#endif
#include "host/report/stats_json.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "host/common/memory.h"
#include "host/common/version.h"
#include "host/model/cost_model.h"
#include "host/model/formats.h"
#include "host/report/counters_json.h"
#include "host/report/memory_json.h"
#include "host/report/stats_parts_json.h"
#include "host/trace/mrt.h"
#include "vgpu/vgpu.h"

namespace host {

namespace {

// Stages replaced by kernels of one's own (host/trace/user_stage.h): each under the stage's name,
// with the program's name (its passes are under that name in "kernels") and units.
nlohmann::ordered_json user_kernels_json(const UserKernels& user) {
  nlohmann::ordered_json u = nlohmann::ordered_json::object();
  auto stage = [&](const char* key, const auto& k, const char* replaces) {
    if (!k) return;
    const vgpu::Program& p = k->program();
    u[key] = {{"program", p.name()},
              {"replaces", replaces},
              {"instructions", p.analyze().instructions},
              {"units", k->units()}};
  };
  stage("shader", user.shader, "shader");
  stage("camera", user.camera, "generate rays");
  return u;
}

// The `accel` object: the structure, how its textures are addressed, its own statistics, the
// walk's work and --accel auto's choice.
nlohmann::ordered_json accel_json(const FrameStatsInputs& in) {
  const Accel& accel = in.accel;
  const RenderOptions& opt = in.options;
  const RenderResult& r = in.result;
  StreamTracer* tracer = in.tracer;
  const bool cpu = in.engine == "cpu";
  nlohmann::ordered_json acc;
  acc["structure"] = accel.name();
  // How the stream engines' walk addresses the structure's textures (RenderOptions::addressing).
  if (tracer) acc["addressing"] = tracer->addresses_by_xy() ? "xy" : "linear";
  const nlohmann::ordered_json own = accel_stats_json(accel.stats());  // the structure's fields
  for (const auto& [key, v] : own.items()) acc[key] = v;
  if (!cpu) {
    const WalkWork w = walk_work(r.stats, r.rays_traced);
    acc["work"] = {{"voxel_steps", w.voxel_steps},
                   {"nodes_visited", w.nodes_visited},
                   {"triangle_tests", w.triangle_tests},
                   {"loop_iterations", w.loop_iterations}};
    // kd-restart's restarts, where the passes show them (WalkWork::restarts); else null.
    acc["work"]["restarts"] =
        w.restarts >= 0 ? nlohmann::ordered_json(w.restarts) : nlohmann::ordered_json();
  }
  if (in.choice) {
    nlohmann::ordered_json au;
    au["probe_size"] = {in.choice->probe_width, in.choice->probe_height};
    au["profile"] = opt.profile;
    au["predicted_ms"] = in.choice->predicted_ms;
    au["coarse_ms"] = in.choice->coarse_ms;
    au["refine_size"] =
        in.choice->refine_width > 0
            ? nlohmann::ordered_json{in.choice->refine_width, in.choice->refine_height}
            : nlohmann::ordered_json();  // half the size is no larger than the first probes
    au["refined"] = in.choice->refined;
    au["stopped"] = in.choice->stopped;
    au["probe_passes"] = in.choice->probe_passes;
    au["probe_ms"] = in.choice->probe_ms;
    au["why"] = in.choice->why;
    acc["auto"] = au;
  }
  return acc;
}

}  // namespace

nlohmann::ordered_json frame_stats_json(const FrameStatsInputs& in) {
  const Scene& scene = in.scene;
  StreamTracer* tracer = in.tracer;  // device() is not const
  const Accel& accel = in.accel;
  const RenderOptions& opt = in.options;
  const RenderResult& r = in.result;
  const CpuStats& cpu_stats = in.cpu_stats;
  const bool cpu = in.engine == "cpu", gl = in.engine == "gl";
  nlohmann::ordered_json j{{"version", host::version()}};  // an object: {"version": ...}
  j["scene"] = scene.name;
  j["scene_path"] = in.scene_path;
  j["engine"] = in.engine;
  if (tracer) j["device"] = tracer->device().description();
  j["triangles"] = scene.triangle_count();
  j["input_triangles"] = scene.input_triangles;
  j["dropped_degenerate"] = scene.dropped_degenerate;
  // The grid's resolution and references (another structure: its box's one voxel, grid_res).
  const glm::ivec3 grid_res = accel.grid_res();
  j["grid"] = {grid_res.x, grid_res.y, grid_res.z};
  j["grid_references"] = accel.grid_references();
  j["accel"] = accel_json(in);
  j["profile"] = opt.profile;
  j["size"] = {r.width, r.height};
  j["bounces"] = opt.bounces;
  j["iterations"] = r.iterations;
  j["shading"] = in.shading;
  j["shadows"] = opt.shadows;
  if (!scene.textures.empty()) {  // base-colour textures (kernels/base_color.h)
    j["textures"] = scene.textures.size();
    j["texture_filter"] = in.texture_filter;
  }
  j["masks"] = opt.masks;
  j["mrt"] = opt.mrt;  // fused two-output passes (kernels/fused.h)
  j["fused_programs"] = opt.mrt ? mrt_programs() : std::vector<std::string>{};
  j["kernel_variant"] = in.kernels;  // multipass | looping ("kernels" lists the programs)
  if (opt.looping) j["steps_per_pass"] = opt.steps_per_pass;
  if (opt.user.any()) j["user_kernels"] = user_kernels_json(opt.user);
  j["threads"] = opt.threads;
  j["lanes"] = opt.lanes;
  // How the emulator ran the grid walks: in batches or pass by pass (same statistics), and why
  // a walk ran pass by pass (omitted where every walk ran in batches).
  if (!cpu && !gl) {
    j["walk"] = r.batch_walk ? "batches" : "passes";
    if (!r.walk_reason.empty()) j["walk_passes_because"] = r.walk_reason;
  }
  j["precision"] = in.precision;
  if (!cpu) j["formats"] = formats_json(opt.formats);
  j["init_ms"] = in.init_ms;
  j["grid_build_ms"] = accel.grid_build_ms();
  j["render_ms"] = r.render_ms;
  const MemoryTerms memory = memory_terms(scene, accel, tracer, r);
  if (tracer) j["texture_bytes"] = memory.textures;
  const uint64_t peak = peak_resident_bytes();
  j["peak_rss_bytes"] = peak;
  j["memory"] = memory_json(memory, peak);
  if (cpu)
    j["cpu"] = {{"rays", cpu_stats.rays},
                {"voxel_steps", cpu_stats.voxel_steps},
                {"triangle_tests", cpu_stats.triangle_tests},
                {"nodes_visited", cpu_stats.nodes_visited},
                {"restarts", cpu_stats.restarts},
                {"reflected", cpu_stats.reflected},
                {"refracted", cpu_stats.refracted},
                {"total_internal", cpu_stats.total_internal},
                {"glass_shadow_crossings", cpu_stats.glass_shadow_crossings}};
  j["rays_traced"] = r.rays_traced;
  if (r.streams.on) j["streams"] = streams_json(r.streams);  // glass's ray streams
  if (r.compact.on) j["compact"] = compact_json(r.compact);  // the sampling modes' dense streams
  j["rays_unfinished"] = r.rays_unfinished;
  // Beams over tiles (--beams on): the tile size, beam passes (rayosHaz), tiles marched over the
  // frame's primary traces, and tiles whose whole beam missed the grid. Absent with beams off,
  // so such a frame's JSON is what it was before beams.
  if (opt.beams) {
    j["beams"] = {{"on", opt.beams},
                  {"tile", opt.beam_tile},
                  {"passes", r.beam_passes},
                  {"tiles", r.beam_tiles},
                  {"tiles_missed", r.beam_tiles_missed}};
    // The CPU tracer marches the same beams one tile at a time: the passes are the most steps
    // one tile's beam ran (what the passes would have been), and it also counts every step.
    if (cpu) j["beams"]["steps"] = cpu_stats.beam_steps;
    // Through the BVH or the kd-tree: the depth of the node each tile's rays started at (0 the
    // root), the mean over the tiles and the deepest.
    if (r.beam_depths && r.beam_tiles > 0)
      j["beams"]["entry_depth"] = {{"mean", double(r.beam_depth_sum) / double(r.beam_tiles)},
                                   {"max", r.beam_depth_max}};
  }
  // --beams auto: what it chose and why; with beams off, {"on": false} and the choice alone.
  if (const BeamsChoice* bc = in.beams_choice) {
    nlohmann::ordered_json& b = j["beams"];
    if (!opt.beams) b["on"] = false;
    nlohmann::ordered_json au = {{"profile", opt.profile}, {"probed", bc->probed}};
    if (bc->probed) {
      au["probe"] = {bc->probe_width, bc->probe_height};
      au["primary_ms"] = {{"off", bc->off_ms}, {"on", bc->on_ms}};  // the probes, predicted
      au["probe_ms"] = bc->probe_ms;
      au["probe_model_ms"] = bc->probe_model_ms;
    }
    au["why"] = bc->why;
    b["auto"] = au;
  }
  // Supersampling (--spp): samples per pixel and the passes it added to the first sample frame.
  {
    double mean = double(r.samples);
    uint64_t most = uint64_t(r.samples);
    if (!r.rays_per_pixel.empty()) {
      uint64_t total = 0;
      most = 0;
      for (const uint32_t n : r.rays_per_pixel) total += n, most = std::max<uint64_t>(most, n);
      mean = double(total) / double(r.rays_per_pixel.size());
    }
    j["sampling"] = {{"mode", opt.undersample > 0           ? "undersample"
                              : opt.adaptive && opt.spp > 1 ? "adaptive"
                                                            : "uniform"},
                     {"spp", opt.spp},
                     {"samples_per_pixel_mean", mean},
                     {"samples_per_pixel_max", most},
                     {"passes_added", cpu ? 0 : r.stats.totals.passes - r.first_frame_passes}};
    if (opt.adaptive) j["sampling"]["threshold"] = opt.threshold();
    // The object and budget criteria only (the image criterion's JSON stays as it was).
    if (opt.adaptive && opt.aa_criterion != RenderOptions::AaCriterion::image) {
      const bool budget = opt.aa_criterion == RenderOptions::AaCriterion::budget;
      j["sampling"]["criterion"] = budget ? "budget" : "object";
      j["sampling"]["cone_depth"] = opt.cone_depth;
      if (budget) {
        nlohmann::ordered_json shares = nlohmann::ordered_json::array();
        for (const float b : opt.aa_budget) shares.push_back(std::round(double(b) * 1e6) / 1e6);
        j["sampling"]["budget_shares"] = std::move(shares);
        nlohmann::ordered_json levels = nlohmann::ordered_json::array();
        for (const RenderResult::BudgetLevel& b : r.budget_levels)
          levels.push_back({{"threshold", b.threshold},
                            {"budget_pixels", b.budget},
                            {"counting_passes", b.steps}});
        j["sampling"]["budget_levels"] = std::move(levels);
      }
    }
    if (opt.undersample > 0) j["sampling"]["k"] = opt.undersample;
  }
  {
    nlohmann::ordered_json stats = frame_counters_json(r.stats);
    if (gl)  // the emulator's SIMD model: a driver does not show its lanes
      for (const char* key :
           {"lanes_idle", "idle_in_batch32", "idle_in_batch1024", "loop_iterations",
            "loop_lane_slots", "loop_lanes_idle", "loop_batch_iterations", "loop_idle_instructions",
            "loop_idle_fetches", "loop_dependent_instructions"}) {
        stats["totals"][key] = nullptr;
        for (auto& k : stats["programs"]) k[key] = nullptr;
      }
    j["totals"] = std::move(stats["totals"]);
    j["downloads"] = stats["downloads"];
    j["download_bytes"] = stats["download_bytes"];
    j["kernels"] = std::move(stats["programs"]);
  }
  // The cost model's prediction for every built-in profile (the counters do not depend on it).
  nlohmann::ordered_json predicted_ms, predicted_breakdown;
  for (const vgpu::Profile& p : vgpu::profiles()) {
    if (cpu || gl) break;  // no passes, or no SIMD counters to predict from
    if (!prices(p, opt.looping, opt.steps_per_pass)) {
      predicted_ms[p.name] = nullptr;  // the looping program cannot run there
      continue;
    }
    const CostBreakdown c = predict(r.stats, p);
    predicted_ms[p.name] = c.total_ms;
    for (const auto& [key, v] : c.items()) predicted_breakdown[p.name][key] = v;
  }
  j["predicted_ms"] = predicted_ms;
  j["predicted_breakdown"] = predicted_breakdown;
  auto what_if =
      nlohmann::ordered_json::array();  // MRT and resident programs (docs/studies/table1.md)
  for (const auto& [name, s] : cpu || gl ? decltype(what_ifs(r.stats)){} : what_ifs(r.stats)) {
    nlohmann::ordered_json w = {{"name", name}, {"totals", counters_json(s.totals)}};
    for (const vgpu::Profile& p : vgpu::profiles())
      for (const auto& [key, v] : predict(s, p).items()) w["predicted_breakdown"][p.name][key] = v;
    what_if.push_back(w);
  }
  j["predicted_what_if"] = what_if;
  return j;
}

nlohmann::ordered_json animation_json(const std::vector<Animation>& animations,
                                      const std::vector<size_t>& played) {
  if (played.empty()) return nullptr;
  nlohmann::ordered_json each = nlohmann::ordered_json::array();
  std::string name;
  double start = 0, end = 0;
  for (size_t i = 0; i < played.size(); ++i) {
    const Animation& an = animations.at(played[i]);
    each.push_back({{"name", an.name}, {"index", played[i]}, {"start", an.start}, {"end", an.end}});
    name += (i ? " + " : "") + an.name;
    start = i ? std::min(start, an.start) : an.start;
    end = i ? std::max(end, an.end) : an.end;
  }
  if (played.size() == 1) return each[0];  // one animation: as before issue 34
  return {{"name", name}, {"index", nullptr}, {"start", start}, {"end", end}, {"played", each}};
}

nlohmann::ordered_json frame_update_json(const std::string& mode, double pose_ms,
                                         AccelKind structure, double build_ms, double write_ms,
                                         const StreamTracer::Upload& up, bool uploaded) {
  nlohmann::ordered_json update = {
      {"mode", mode},
      {"pose_ms", pose_ms},
      {"structure", accel_name(structure)},
      {"build_ms", build_ms},
      {"write_ms", write_ms},
      {"uploaded_bytes", uploaded ? nlohmann::ordered_json(up.bytes) : nullptr},
      {"uploaded_textures", up.textures}};
  nlohmann::ordered_json charged;
  for (const vgpu::Profile& p : vgpu::profiles()) {
    if (!uploaded) break;
    const UpdateCost c = predict_update(up.bytes, build_ms, p);
    charged[p.name] = {
        {"upload_ms", c.upload_ms}, {"build_ms", c.build_ms}, {"total_ms", c.total_ms}};
  }
  update["predicted"] = charged;
  return update;
}

void add_moving_frame(StatsJson& j, int frame, double time, const StatsJson& animation,
                      StatsJson update) {
  j["frame"] = frame;
  j["time"] = time;
  j["animation"] = animation;
  j["update"] = std::move(update);
}

StatsJson frames_stats_json(const std::string& scene, const std::string& scene_path,
                            const StatsJson& animation, const std::string& update,
                            std::vector<StatsJson> frames) {
  const size_t count = frames.size();
  return {{"version", host::version()}, {"scene", scene},   {"scene_path", scene_path},
          {"animation", animation},     {"update", update}, {"frame_count", count},
          {"frames", std::move(frames)}};
}

std::string stats_text(const StatsJson& j) {
  return j.dump(2) + "\n";
}

void write_stats_json(const std::string& path, const nlohmann::ordered_json& j) {
  const std::string tmp = path + ".tmp";
  std::ofstream f(tmp);
  f << stats_text(j);
  f.close();
  if (!f || std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw InputError(path + ": cannot write the statistics");
  }
}

}  // namespace host
