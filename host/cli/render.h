// `vgpu-rt render` as a library call: the command line (main.cpp) runs it with its arguments,
// the Python module (python/) with the keyword arguments of vgpu_rt.render turned into the same
// arguments, so both check the same options with the same messages and render the same frames.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "host/cli/options.h"
#include "host/common/install_paths.h"  // registers an installed prefix (scenes, images)
#include "host/report/stats_value.h"
#include "host/trace/render_options.h"

namespace cli {

// What a render leaves for a caller other than the command line: the last frame's result (its
// image, AOVs and pass statistics) and the statistics object --stats-json writes.
struct RenderOutcome {
  host::RenderResult result;
  host::StatsJson stats;  // written by the report room (host/report/stats_json.h)
  size_t frames = 0;      // frames rendered (--frames: several; stats then holds them all)
};

// Parses `render`'s arguments (the scene, then options as on the command line, e.g. {"bunny",
// "--size", "64x64"}) as the command line does; throws UsageError with CLI11's message for a
// bad value. `lanes_given`: whether --lanes was among them.
RenderArgs parse_render_args(const std::vector<std::string>& args, bool& lanes_given);

// One render option as `vgpu-rt render --help` shows it: its long name without the dashes,
// its default (empty: none) and its description; `flag`: an option without a value.
struct RenderOptionInfo {
  std::string name, default_value, description;
  bool flag = false;
};
std::vector<RenderOptionInfo> render_option_infos();

// Runs the render `a` asks for: checks the options' combinations (UsageError), loads the scene
// (host::InputError), renders each frame and writes the files the options name. Without
// `outcome` it prints what --stats and --predict ask for on stdout, as the command line does;
// with it, the last frame and the statistics object are left there. `observer` (not owned),
// when given, is shown every pass of the one frame rendered (the stream engine only).
int run_render(const RenderArgs& a, bool lanes_given, RenderOutcome* outcome = nullptr,
               host::PassObserver* observer = nullptr);

}  // namespace cli
