// The render subcommand's options (RenderArgs) and their CLI11 validators: every value is
// checked as it is parsed, before any work; main.cpp checks their combinations.
#pragma once

#include <glm/glm.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "host/trace/user_stage.h"
#include "vgpu/lanes.h"

// CLI11 is declared, not included: only the files that build or parse a command line compile
// its header-only implementation (about 10 s of the build each).
namespace CLI {
class App;
}

namespace cli {

struct RenderArgs {
  std::string scene = "bunny";
  std::string size = "256x256";
  std::string out;
  int bounces = 2;
  std::string shading = "phong";
  std::string texture_filter = "trilinear";
  std::string textures = "fit";  // --textures fit|refuse
  std::string shadows = "on";
  std::string grid = "auto";
  std::string accel = "grid";
  std::string profile = "gf5700";
  int threads = 0;
  int lanes = vgpu::kLanes;
  std::string masks = "off";
  std::string mrt = "off";
  std::string beams = "off";
  int beam_tile = 8;
  std::string addressing = "auto";
  std::string ray_streams = "auto";
  std::string compact = "on";
  std::string stats = "table";
  std::string stats_json;
  std::string stats_csv;
  std::string report;
  std::vector<std::string> aovs;
  std::string trace_pixel;
  bool quiet = false;
  bool predict = false;
  std::string engine = "stream";
  std::string gl_device = "auto";
  std::string gl_readback = "auto";
  std::string precision = "fp32";
  std::string formats;
  std::string kernels = "multipass";
  std::string walk = "batches";
  int steps_per_pass = 32;
  int spp = 1;
  std::string aa = "none";
  std::optional<float> aa_threshold;        // --aa-threshold; 0.1, with the budget criterion 0.05
  std::optional<std::string> aa_criterion;  // --aa-criterion image|object|budget (budget)
  std::vector<float> aa_budget{30.0f, 28.0f};  // --aa-budget, percent per level
  float aa_cone_depth = 2.0f;                  // --aa-cone-depth
  bool steps_given = false;
  bool walk_given = false;
  std::string time;       // --time T
  std::string frames;     // --frames A:B:N or N
  std::string animation;  // --animation NAME|INDEX[,NAME|INDEX...]
  std::string update = "rebuild";
  bool update_given = false;
  int report_frame = 0;  // --report-frame K (1-based; 0: not given)
  // Not an option of the command line: the stages a library caller (the Python module, another
  // C++ project) replaces with kernels of its own (host/trace/user_stage.h).
  host::UserKernels user;
};

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// "WxH" as two positive sides, or nullopt.
std::optional<glm::ivec2> parse_size(const std::string& text);
// "X,Y" pixel coordinates, or nullopt.
std::optional<glm::ivec2> parse_pixel(const std::string& text);
// --aa's value: none, adaptive, undersample or undersample:K; K (default 2) for undersample,
// 0 otherwise, or nullopt.
std::optional<int> parse_aa(const std::string& text);

// Adds every `render` option to `render`, parsed into `a`.
void add_render_options(CLI::App& render, RenderArgs& a);

}  // namespace cli
