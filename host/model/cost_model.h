// The cost model: predicts how long a frame would take on a modeled GPU from the virtual GPU's
// statistics (vgpu::FrameStats) and the profile's hardware figures (vgpu::Profile). It explains
// the paper's Table 1; docs/studies/table1.md lists every parameter with its source or marks it
// fitted.
//
// Per pass:  time = max(arithmetic, texture, memory) + fetch wait + latency + pass_us
//   arithmetic = ALU instructions / (pipelines x clock x alu_per_clock x precision rate), each
//                at the rate of the precision it ran at (Counters::alu_fp24 / alu_fp16,
//                Profile::rate: NV3x fp16 full speed, fp32 and fp24 half)
//   texture    = texel fetches / (pipelines x clock x texels_per_clock), or where the profile
//                gives one, texel bytes / (texture_bytes_per_clock x clock) if that is longer;
//                at texture_spilled_bytes_per_clock instead where the pass's footprint
//                (Counters::footprint_bytes) is larger than the profile's l2_bytes
//   memory     = (bytes read + bytes written) / bandwidth, or where the profile gives one,
//                bytes written / (output_bytes_per_clock x clock) if that is longer (the ROPs)
// Looping passes add, per lane slot of a batch still iterating (Counters::loop_lane_slots),
// the body's instructions and fetches for lanes already out (ALU and texture time, no bytes)
// and Profile::loop_overhead_clocks of the pipeline.
//   latency    = a looping pass's longest lane: the most iterations one fragment ran times the
//                body's longest chain of dependent operations (vgpu/span.h), each fetch in it
//                at Profile::fetch_latency_clocks, each operation at operation_latency_clocks
//                (0 where the profile does not model them). Work over the pipelines plus the
//                longest lane: the bound a greedy schedule keeps (Brent 1974).
//   fetch wait = on the same profiles, a loop body's arithmetic between two of its fetches
//                (Counters::loop_dependent_instructions) at the arithmetic rate, at most the
//                texture time: added to the pass's bottleneck, not overlapped with it.
// Per frame:  + program loads (bytes over the bus + program_load_us each)
//             + query read-backs (readback_us each: a pipeline drain and a CPU round trip)
//             + texture downloads (download_us each + bytes / download_gbps, where modelled,
//               + bytes / download_host_gbps: the host filling the frame's arrays from them)
//             + clears (bytes / bandwidth, counted with memory)
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "vgpu/profile.h"
#include "vgpu/stats.h"

namespace host {

// Model parameters that are not hardware facts. The hardware figures, and the fixed costs
// (pass_us, program_load_us, readback_us) fitted on Table 1, live in vgpu::Profile.
struct CostParams {
  // Counted scalar operations one vec4 instruction does. The statistics count every scalar
  // operation of the kernel code (vgpu/lanes.h, CountingLanes); a Cg compiler packs vector code
  // into 4-wide instructions (a dot product is one DP3, a cross product a MUL and a MAD).
  // Assumed 3: hand count of the ray-triangle test, 62 scalar operations in about 22 fp30
  // instructions, and of voxel_exits, 27 in about 9. Capped by the profile's alu_lanes.
  double scalar_ops_per_instruction = 3.0;
  // Dynamic branching (Branching::dynamic) is not a parameter: the virtual GPU counts the
  // branch-idle fragments that sit in batches idle as a whole (Counters::idle_in_batch32 and
  // idle_in_batch1024, 8x4 and 32x32 pixel tiles); the profile's branch_granularity picks one
  // (1024 for >= 256, else 32). Without dynamic branching (fp30) nothing is skipped, nor on a
  // profile whose programs run their branches as selects (Profile::branches_as_selects, the
  // generated GLSL: defaults_for sets branch_body_share 0).
  // Share of a program's operations, fetches and bytes read inside its f.branch() block, i.e.
  // what a skipping batch saves. Assumed 0.75 from the kernels' code: intersecciones (most of
  // every frame) keeps 132 of 135 operations but only 6 of 8 fetches (84 of 116 bytes) inside.
  double branch_body_share = 0.75;
  // Fixed costs, copied from the profile by defaults_for (fitted, see docs/studies/table1.md).
  double pass_us = 0;          // one render-to-texture pass: driver, target switch, pipeline fill
  double program_load_us = 0;  // driver cost of binding another fragment program
  double readback_us = 0;      // one occlusion-query read-back: pipeline drain + CPU round trip
};

// The profile's fixed costs and the assumed parameters above for its branching model.
CostParams defaults_for(const vgpu::Profile& profile);

// Predicted frame time, ms, by where it goes. The first three are the pass work attributed to
// each pass's bottleneck (the larger of the three demands), so that
//   total = arithmetic + texture + memory + latency + per_pass + program_load + readback
//           + download.
// wasted_ms is part of that pass work: the share spent on idle fragments, whose ray is finished
// or has nothing to do in the pass (no triangle left in its voxel while other rays test theirs):
// the fragments an early-z mask (--masks on) would skip.
struct CostBreakdown {
  double arithmetic_ms = 0;    // passes bounded by the ALUs
  double texture_ms = 0;       // passes bounded by texture fetch rate
  double memory_ms = 0;        // passes bounded by memory bandwidth, plus clears
  double per_pass_ms = 0;      // passes x pass_us
  double program_load_ms = 0;  // program bytes over the bus + program_load_us per load
  double bus_ms = 0;           // of program_load_ms: the program bytes over the bus alone
  double readback_ms = 0;      // query read-backs x readback_us
  double download_ms = 0;      // texture read-backs: download_us each + bytes / download_gbps
                               // + bytes / download_host_gbps
  double wasted_ms = 0;        // of the pass work: idle fragments (finished rays)
  // Of the pass work: what passes larger than the profile's L2 spend fetching beyond the
  // in-cache rate (Profile::l2_bytes, texture_spilled_bytes_per_clock).
  double l2_spill_ms = 0;
  // Of the pass work: a looping body's arithmetic between two of its fetches
  // (Counters::loop_dependent_instructions), which a lane runs after one fetch returns and before
  // it issues the next, so that it adds to the pass's bottleneck instead of overlapping it
  // (profiles with measured latencies: Profile::fetch_latency_clocks).
  double fetch_wait_ms = 0;
  // Looping passes (Counters::loop_*): of the pass work, the lanes already out of the loop while
  // their batch iterates; of the arithmetic, the loop/break overhead (Profile).
  double loop_idle_ms = 0;
  double loop_overhead_ms = 0;
  double latency_ms = 0;  // looping passes' longest lanes (not part of the three above)
  double total_ms = 0;
  // Each unit's whole demand, overlapped or not (how close the other bottlenecks are).
  double arithmetic_demand_ms = 0, texture_demand_ms = 0, memory_demand_ms = 0;

  // (name, ms) pairs in the order above, for tables and JSON.
  std::vector<std::pair<std::string, double>> items() const;
};

// Whether a frame has a price on `profile`: a looping frame needs loops of steps_per_pass
// iterations there (the statistics' predicted_ms is null elsewhere, the CLI's and bench_gl's).
inline bool prices(const vgpu::Profile& profile, bool looping, int steps_per_pass) {
  return !looping || profile.max_loop_iterations >= steps_per_pass;
}

// A frame's fixed costs from its counters, as predict prices them: per pass, program loads (the
// program bytes over the bus, bus_ms, plus program_load_us each) and query read-backs.
struct FixedCosts {
  double per_pass_ms = 0, program_load_ms = 0, bus_ms = 0, readback_ms = 0;
  // What predict's total adds of them, in its order (program_load_ms holds bus_ms).
  double total_ms() const { return per_pass_ms + program_load_ms + readback_ms; }
};
FixedCosts fixed_costs(const vgpu::Counters& totals, const vgpu::Profile& profile,
                       const CostParams& params);

// The price of a frame `scale` times larger in pixels than the one priced in `b` (a probe's full
// frame, --accel auto: host/trace/stream/accel_choice.h), every term of b.total_ms: the costs
// that follow the pass count (per pass, program loads, read-backs) and the looping passes'
// longest lanes (latency: one lane's chain, which does not grow with the pixel count) as
// counted, the fragment work and downloads times `scale`. At scale 1 this is b.total_ms. (Whether
// a pass outgrows the L2 at that size is the profile's to say: price b on one whose l2_bytes is
// divided by `scale`.)
double full_frame_ms(const CostBreakdown& b, double scale);

// The price of a frame's passes so far, from its running totals after each pass (the pass: the
// difference from the totals before it), each pass priced as predict() prices it, at `scale`
// (full_frame_ms). Later passes only add to it, so a frame whose
// running price passes a bound is priced over that bound at its end (a clear between two passes
// is priced with the pass after it, at most what predict() gives it). That holds where predict()
// prices the frame pass by pass, from its records (RenderOptions::keep_pass_records, as the
// probes keep them); from per-program averages predict() may price it lower. --accel auto stops
// a probe once its running price passes what could still be picked.
class RunningPrice {
 public:
  RunningPrice(const vgpu::Profile& profile, double scale);
  // Called after each pass with the frame's totals so far: the price so far.
  double add(const vgpu::Counters& totals);

 private:
  vgpu::Profile profile_;
  CostParams params_;
  double scale_;
  vgpu::Counters last_{};
  CostBreakdown work_;  // the passes' work so far, unscaled
};

// Uses stats.passes (one record per pass) when it holds every pass, else each program's totals
// spread evenly over its passes.
CostBreakdown predict(const vgpu::FrameStats& stats, const vgpu::Profile& profile);
CostBreakdown predict(const vgpu::FrameStats& stats, const vgpu::Profile& profile,
                      const CostParams& params);

// A moving scene's update between two frames (issue 23, --frames): the static textures uploaded
// again cross the profile's host-to-GPU bus at Profile::bus_mbps, the figure program uploads use
// (AGP 8x, 2112 MB/s, for gf5700 and r300; PCI Express for gf6600, rtx4090, h200 and h100); the
// structure's build is host work, charged as the host measured it (no 2004 CPU is modeled).
struct UpdateCost {
  double upload_ms = 0;  // uploaded bytes / bus_mbps
  double build_ms = 0;   // host, as measured
  double total_ms = 0;   // upload_ms + build_ms (the host builds, then uploads)
};
UpdateCost predict_update(uint64_t uploaded_bytes, double build_ms, const vgpu::Profile& profile);

// A few lines: the predicted total and its breakdown, for the CLI.
std::string describe(const CostBreakdown& cost, const vgpu::Profile& profile);

// What-if transforms of a frame's statistics, predicted by the same model (docs/studies/table1.md).
// Multiple render targets: two kernels that always run back to back become one pass writing
// both targets. The merged pass shades each fragment once, does both programs' operations and
// fetches except the inputs both read (shared_fetches own texels, shared_bytes each fragment),
// writes both targets, and is one program load instead of two.
struct MergedPair {
  std::string first, second;  // kernel names, as in the statistics
  int shared_fetches = 0;     // own-texel fetches both programs make of the same texture
  int shared_bytes = 0;       // their bytes per fragment
};
// The pairs of the paper's pipeline: intersecciones + proximoTriangulo (both read the voxel
// state), traversal + actualizarVoxel (the second reads the first's output, the traversal state).
const std::vector<MergedPair>& mrt_pairs();
vgpu::FrameStats with_merged_passes(const vgpu::FrameStats& stats,
                                    const std::vector<MergedPair>& pairs);
// Programs kept resident: each is loaded once, on first use, instead of at every switch.
vgpu::FrameStats with_resident_programs(const vgpu::FrameStats& stats);
// The named scenarios: "mrt", "resident programs", "mrt + resident programs".
std::vector<std::pair<std::string, vgpu::FrameStats>> what_ifs(const vgpu::FrameStats& stats);

}  // namespace host
