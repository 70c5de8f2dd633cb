// Hardware profiles as data: what a fragment program may do on each modeled GPU, and the
// figures the cost model needs. Every figure carries its source; figures with no public source
// are marked "model parameter" (fitted or assumed, see docs/studies/table1.md).
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
  // A card the GL device measures: what its driver's GL_RENDERER string holds ("NVIDIA H200/",
  // not a GH200's), so that measurements on it are priced with this profile. Empty for the
  // cards only modeled.
  std::string gl_renderer;
  int pipelines = 0;         // fragment pipelines (pixels shaded per clock)
  double core_mhz = 0;       // core clock
  double mem_gbps = 0;       // memory bandwidth, GB/s (1e9 bytes/s)
  int max_outputs = 1;       // color outputs (render targets) one program may write
  int max_instructions = 0;  // static instructions per fragment program
  Branching branching = Branching::none;
  int branch_granularity = 1;  // pixels that branch together (dynamic branching only)
  // The frames run as the GLSL the recorder generates (the GL device's profiles), whose
  // f.branch() blocks run under a select, not a branch: no batch of idle fragments skips a
  // branch's body, whatever the part's branching (the cost model's branch_body_share is 0).
  bool branches_as_selects = false;
  int max_texture_size = 0;  // texels per side
  // The board's memory, MiB, the largest board sold with the part (0: not recorded): a frame
  // whose textures (as this card holds them, by format) need more is refused.
  int memory_mib = 0;
  // Texture image units a fragment program may read (OpenGL's GL_MAX_TEXTURE_IMAGE_UNITS under
  // ARB_fragment_program, Direct3D 9's samplers): unit u exists where u < texture_units. The
  // emulator binds at most kMaxTextureUnits (vgpu/fragment.h) whatever the profile says.
  int texture_units = 16;
  Format precision = Format::fp32;  // full arithmetic precision of the fragment units
  bool has_fp16 = true;             // a half-precision arithmetic mode (NV3x+ "half"; not R300)
  double bus_mbps = 0;              // host to GPU bus, MB/s, for program uploads
  double program_load_us = 0;  // driver cost of binding another fragment program (model parameter)
  double readback_us = 0;      // occlusion-query read-back: pipeline drain + sync (model parameter)
  double pass_us = 0;          // fixed cost of one render-to-texture pass (model parameter)
  // Reading a texture back to the host (the image at the end of a frame): a fixed cost and a
  // rate (0: not modelled; the 2004 cards' read-backs are outside Table 1's timings).
  double download_us = 0;
  double download_gbps = 0;
  // The host's own pass over what it read back, in bytes read back a second (0: not modelled):
  // the frame's image and its depth and hit-id arrays are filled from the downloaded textures
  // into memory fresh each frame (host/trace/stream/stream_tracer.cpp).
  double download_host_gbps = 0;
  int instruction_bytes = 16;  // bytes of one encoded instruction (program upload size)
  // Fragment-unit throughput, for the cost model (host/model/cost_model.h).
  int alu_lanes = 4;            // scalar lanes one arithmetic instruction drives (4: vec4 ALU)
  double alu_per_clock = 1;     // arithmetic instructions per pipeline per clock, fp16
  double fp32_rate = 1;         // fp32 arithmetic throughput relative to fp16
  double fp24_rate = 1;         // fp24 throughput relative to fp16 (a part without fp24 units
                                // computes fp24 values in fp32: its fp32 rate)
  double texels_per_clock = 1;  // texture fetches per pipeline per clock
  // Whole-chip bandwidths in bytes per clock where a part is bound by them rather than by the
  // figures above (0: not modelled). A modern part fetches 32-bit texel components, not texels,
  // per clock, and writes its render targets through a few raster-output units.
  double texture_bytes_per_clock = 0;  // texel bytes fetched per clock, all texture units
  double output_bytes_per_clock = 0;   // render-target bytes written per clock, all ROPs
  // The cache between the texture units and memory (0: not modelled). A pass whose footprint
  // (Counters::footprint_bytes: what it fetches and writes) is larger than l2_bytes finds what
  // the passes before it wrote evicted, and fetches at texture_spilled_bytes_per_clock instead of
  // texture_bytes_per_clock: a stream read in order through a least-recently-used cache smaller
  // than it hits nothing.
  double l2_bytes = 0;
  double texture_spilled_bytes_per_clock = 0;
  // Data-dependent loops (Fragments::loop): 0 where the profile has none (fp30, ps_2_0), else the
  // most iterations one loop may be given. A looping program's batch is branch_granularity
  // pixels: it iterates until its last pixel leaves the loop.
  int max_loop_iterations = 0;
  double loop_overhead_clocks = 0;  // clocks a pixel spends on one iteration's loop/break
  // Latencies of one lane, for a looping pass's longest lane (vgpu/span.h; 0: not modelled):
  // clocks from a fetch's issue to its texel, and per operation of a dependent chain.
  double fetch_latency_clocks = 0;
  double operation_latency_clocks = 0;

  // Arithmetic throughput at format f, relative to alu_per_clock (the fp16 rate).
  double rate(Format f) const {
    return f == Format::fp32 ? fp32_rate : f == Format::fp24 ? fp24_rate : 1.0;
  }
  // The format the fragment units compute in when a program asks for f: never finer than the
  // profile's precision (R300 computes everything in fp24), fp16 only where the part has it.
  Format computes(Format f) const;
};

// Bits of precision of a format (significand, implicit bit included): fp32 24, fp24 17, fp16 11.
constexpr int significand_bits(Format f) {
  return f == Format::fp32 ? 24 : f == Format::fp24 ? 17 : 11;
}
// The format with fewer bits of the two.
constexpr Format coarser(Format a, Format b) {
  return significand_bits(a) <= significand_bits(b) ? a : b;
}

// The built-in profiles: gf5700, r300, gf6600, rtx4090, h200 and the cards measured since.
const std::vector<Profile>& profiles();
// Looks a profile up by name; throws std::invalid_argument naming the known ones.
const Profile& profile(std::string_view name);
// The profile measured on the card whose GL_RENDERER string this is (Profile::gl_renderer), or
// nullptr where no profile was measured on that card.
const Profile* profile_for_renderer(std::string_view renderer);

}  // namespace vgpu
