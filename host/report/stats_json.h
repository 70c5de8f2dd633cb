#pragma once
// The statistics of one rendered frame as JSON (vgpu-rt render --stats-json, --stats json, and
// the frame a report shows): the scene, the structure walked, the options, the pass counters
// and the cost model's predictions. The command line gathers the pieces; this file names them.

#include <nlohmann/json.hpp>
#include <string>

#include "host/accel/accel.h"
#include "host/report/stats_value.h"
#include "host/scene/animation.h"
#include "host/scene/scene.h"
#include "host/trace/cpu/cpu_tracer.h"
#include "host/trace/render_options.h"
#include "host/trace/stream/accel_choice.h"
#include "host/trace/stream/stream_tracer.h"

namespace host {

// What one frame's statistics object is made of. The strings are the command line's words
// (--engine, --shading, --texture-filter, --kernels, --precision), written as given.
struct FrameStatsInputs {
  const Scene& scene;
  const std::string& scene_path;
  const std::string& engine;  // stream, cpu or gl
  StreamTracer* tracer;       // nullptr: the CPU reference rendered the frame
  const Accel& accel;         // the structure walked
  const AccelChoice* choice;  // --accel auto's choice, else nullptr
  const RenderOptions& options;
  const RenderResult& result;
  const CpuStats& cpu_stats;  // the CPU reference's counts (engine cpu)
  const std::string& shading;
  const std::string& texture_filter;
  const std::string& kernels;
  const std::string& precision;
  double init_ms;  // initialization charged to this frame (the first), else 0
  const BeamsChoice* beams_choice = nullptr;  // --beams auto's choice, else nullptr
};

nlohmann::ordered_json frame_stats_json(const FrameStatsInputs& in);

// What posed a moving scene's frames: the animations of `animations` whose indices `played`
// holds, played together (every animation of the file by default, or those --animation names).
// One animation: its {name, index, start, end} (start and end its first and last key time).
// Several: {name, index, start, end, played}, their names joined by " + ", a null index, the
// first and last key time of any of them, and `played` each one's {name, index, start, end}.
// Null when none plays (a file without animations).
nlohmann::ordered_json animation_json(const std::vector<Animation>& animations,
                                      const std::vector<size_t>& played);

// What a frame of an animation cost to update (the "update" object of --frames and --time): the
// host's work (`mode`: initial, rebuild or refit), the bytes sent to the device, and the cost
// model's charge for them on each profile (host/model/cost_model.h, predict_update). `uploaded`:
// whether a device took them (false: the CPU reference, whose bytes and charges are null).
nlohmann::ordered_json frame_update_json(const std::string& mode, double pose_ms,
                                         AccelKind structure, double build_ms, double write_ms,
                                         const StreamTracer::Upload& up, bool uploaded);

// A moving scene's frame (--time, --frames): its statistics object `j` (frame_stats_json) with
// "frame" (1 to N), "time", "animation" (animation_json) and "update" (frame_update_json) added.
void add_moving_frame(StatsJson& j, int frame, double time, const StatsJson& animation,
                      StatsJson update);

// --frames' document: {scene, scene_path, animation, update (the --update mode), frame_count,
// frames}, `frames` each frame's object (add_moving_frame).
StatsJson frames_stats_json(const std::string& scene, const std::string& scene_path,
                            const StatsJson& animation, const std::string& update,
                            std::vector<StatsJson> frames);

// The document as --stats json prints it and --stats-json writes it: indented by 2, then a
// newline.
std::string stats_text(const StatsJson& j);

// Writes stats_text(j) to `path` through a temporary file renamed over it; throws InputError
// naming the path when it cannot.
void write_stats_json(const std::string& path, const nlohmann::ordered_json& j);

}  // namespace host
