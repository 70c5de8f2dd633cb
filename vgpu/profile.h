// Hardware profiles as data: what a fragment program may do on each modeled GPU, and the
// figures the cost model needs. Every figure carries its source; figures with no public source
// are marked "model parameter" (fitted or assumed, see docs/table1.md).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "vgpu/format.h"

namespace vgpu {

enum class Branching {
  none,     // fp30: conditionals evaluate both sides under masks, no data-dependent loops
  dynamic,  // fp40 and later: a branch skipped by every lane of a batch is not executed
};

struct Profile {
  std::string name;     // CLI name, e.g. "gf5700"
  std::string display;  // e.g. "GeForce FX 5700 (NV36), Cg fp30"
  std::string cg_profile;
  int pipelines = 0;         // fragment pipelines (pixels shaded per clock)
  double core_mhz = 0;       // core clock
  double mem_gbps = 0;       // memory bandwidth, GB/s (1e9 bytes/s)
  int max_outputs = 1;       // color outputs (render targets) one program may write
  int max_instructions = 0;  // static instructions per fragment program
  Branching branching = Branching::none;
  int branch_granularity = 1;       // pixels that branch together (dynamic branching only)
  int max_texture_size = 0;         // texels per side
  Format precision = Format::fp32;  // full arithmetic precision of the fragment units
  double bus_mbps = 0;              // host to GPU bus, MB/s, for program uploads
  double program_load_us = 0;  // driver cost of binding another fragment program (model parameter)
  double readback_us = 0;      // occlusion-query read-back: pipeline drain + sync (model parameter)
  double pass_us = 0;          // fixed cost of one render-to-texture pass (model parameter)
  int instruction_bytes = 16;  // bytes of one encoded instruction (program upload size)
  // Fragment-unit throughput, for the cost model (host/cost_model.h).
  int alu_lanes = 4;            // scalar lanes one arithmetic instruction drives (4: vec4 ALU)
  double alu_per_clock = 1;     // arithmetic instructions per pipeline per clock, fp16
  double fp32_rate = 1;         // fp32 arithmetic throughput relative to fp16
  double texels_per_clock = 1;  // texture fetches per pipeline per clock
};

// The built-in profiles: gf5700, gf6600, rtx4090.
const std::vector<Profile>& profiles();
// Looks a profile up by name; throws std::invalid_argument naming the known ones.
const Profile& profile(std::string_view name);

}  // namespace vgpu
