// Statistics: everything the virtual GPU does is counted, per pass, per program and per frame.
// Counters are plain integers summed per thread, so they are identical for any thread count.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace vgpu {

struct Counters {
  uint64_t passes = 0;               // render-to-texture passes (draws)
  uint64_t fragments_launched = 0;   // fragments in the drawn rectangles
  uint64_t fragments_shaded = 0;     // fragments the program ran on (launched minus masked)
  uint64_t fragments_masked = 0;     // skipped by the early-z/stencil mask before shading
  uint64_t fragments_discarded = 0;  // shaded, then killed (no write, not counted by a query)
  // Shaded fragments idle in a branch: each f.branch() block a shaded fragment does not take
  // counts it once (a work-masked idle fragment, once per branch of the program). Lanes issued
  // without a live fragment (partial batches, masked fragments) are not counted.
  uint64_t lanes_idle = 0;
  // Shaded fragments idle in the program's branch that sit in a batch with no shaded fragment
  // taking it: what dynamic branching skips at a granularity of 32 (8x4 pixel tiles, a warp) or
  // 1024 (32x32 tiles, NV4x) fragments. Tiles are aligned to the drawn rectangle's corner.
  uint64_t idle_in_batch32 = 0;
  uint64_t idle_in_batch1024 = 0;
  uint64_t instructions = 0;     // fragment-program instructions executed (shaded x static count)
  uint64_t texture_fetches = 0;  // texels fetched through texture units
  // Of instructions: the arithmetic (all but the fetches) run at fp24 or at fp16; the rest of
  // the arithmetic ran at fp32. The cost model charges each at the profile's rate for it.
  uint64_t alu_fp24 = 0;
  uint64_t alu_fp16 = 0;
  uint64_t bytes_read = 0;     // bytes fetched through texture units
  uint64_t bytes_written = 0;  // bytes written to render targets
  // The bytes a pass can touch, the cost model's cache footprint: of each texture it fetches
  // from, the bytes it fetched or the whole texture, whichever is less (a texture bound to two
  // units once), plus its targets' texels under the drawn rectangle.
  uint64_t footprint_bytes = 0;
  uint64_t program_loads = 0;    // binds of a program different from the last one
  uint64_t program_bytes = 0;    // bytes of program code uploaded by those loads
  uint64_t clears = 0;           // render-target clears (glClear: no fragment program)
  uint64_t queries = 0;          // occlusion queries issued
  uint64_t query_readbacks = 0;  // query results read back by the host (a CPU-GPU sync)
  double host_ms = 0;            // host wall time (the only counter that varies run to run)
  // Time the passes took on a real device (GL timer queries); 0 on the emulator, which has no
  // device time of its own (the cost model predicts one).
  double device_ms = 0;
  // Data-dependent loops (Fragments::loop), per hardware batch: branch_granularity pixels of
  // the drawn rectangle (Gpu: tiles aligned to its corner) iterate together until the last of
  // their shaded fragments leaves the loop (or the budget runs out).
  uint64_t loop_iterations = 0;        // iterations shaded fragments were active in (lane work)
  uint64_t loop_lane_slots = 0;        // per batch: shaded fragments x the batch's iterations
  uint64_t loop_lanes_idle = 0;        // slots - iterations: lanes already out of the loop
  uint64_t loop_batch_iterations = 0;  // per batch: the iterations it ran, summed
  // What the idle lanes were issued: loop_lanes_idle x the body's instructions and fetches
  // (instructions and texture_fetches count the active lanes' work: a loop body once per
  // iteration a fragment was active in).
  uint64_t loop_idle_instructions = 0;
  uint64_t loop_idle_fetches = 0;
  // The pass's longest lane: per pass, the most iterations one shaded fragment ran, summed over
  // passes; and that many iterations of the body's longest chain of dependent operations
  // (Program::Analysis::loop: its fetches and its other operations), what one lane waits for
  // however many lanes run beside it (the cost model's latency term).
  uint64_t loop_span_iterations = 0;
  uint64_t loop_span_fetches = 0;
  uint64_t loop_span_operations = 0;
  // The body's operations that wait on a fetch of their own iteration and feed another of its
  // fetches (an address computed from a fetched texel), once per active iteration: arithmetic
  // a lane cannot overlap with its own fetches (Program::Analysis, vgpu/span.h).
  uint64_t loop_dependent_instructions = 0;

  Counters& operator+=(const Counters& o);
  // Every integer counter equal (host_ms excluded).
  bool same_counts(const Counters& o) const;
};

// Every integer counter and its name, in the JSON's order: the one list that sums, comparisons,
// the JSON forms and the cost model's transforms walk (host_ms is not a count).
inline constexpr std::pair<const char*, uint64_t Counters::*> kCounterFields[] = {
    {"passes", &Counters::passes},
    {"fragments_launched", &Counters::fragments_launched},
    {"fragments_shaded", &Counters::fragments_shaded},
    {"fragments_masked", &Counters::fragments_masked},
    {"fragments_discarded", &Counters::fragments_discarded},
    {"lanes_idle", &Counters::lanes_idle},
    {"idle_in_batch32", &Counters::idle_in_batch32},
    {"idle_in_batch1024", &Counters::idle_in_batch1024},
    {"instructions", &Counters::instructions},
    {"texture_fetches", &Counters::texture_fetches},
    {"alu_fp24", &Counters::alu_fp24},
    {"alu_fp16", &Counters::alu_fp16},
    {"bytes_read", &Counters::bytes_read},
    {"bytes_written", &Counters::bytes_written},
    {"footprint_bytes", &Counters::footprint_bytes},
    {"program_loads", &Counters::program_loads},
    {"program_bytes", &Counters::program_bytes},
    {"clears", &Counters::clears},
    {"queries", &Counters::queries},
    {"query_readbacks", &Counters::query_readbacks},
    {"loop_iterations", &Counters::loop_iterations},
    {"loop_lane_slots", &Counters::loop_lane_slots},
    {"loop_lanes_idle", &Counters::loop_lanes_idle},
    {"loop_batch_iterations", &Counters::loop_batch_iterations},
    {"loop_idle_instructions", &Counters::loop_idle_instructions},
    {"loop_idle_fetches", &Counters::loop_idle_fetches},
    {"loop_span_iterations", &Counters::loop_span_iterations},
    {"loop_span_fetches", &Counters::loop_span_fetches},
    {"loop_span_operations", &Counters::loop_span_operations},
    {"loop_dependent_instructions", &Counters::loop_dependent_instructions}};

// One pass as recorded: which program, what it drew, what it cost.
struct PassRecord {
  std::string program;
  int width = 0, height = 0;  // drawn rectangle, fragments
  Counters counters;          // counters.passes == 1
  int64_t query_result = -1;  // fragments that passed, if the pass ran inside a query
  // A looping program's pass: per iteration k (index k - 1) of its budget, the lanes of the
  // batches still iterating that were active / already out of the loop (idle). Empty otherwise.
  std::vector<uint64_t> loop_active{}, loop_idle{};
};

// A frame's statistics: every pass, and per-program totals in order of first use.
struct FrameStats {
  struct ProgramTotals {
    std::string name;
    std::string paper_name;
    int instructions = 0;  // static instruction count
    Counters counters;
    // A looping program: its passes' loop_active / loop_idle summed per iteration (PassRecord).
    std::vector<uint64_t> loop_active{}, loop_idle{};
    int loop_budget = 0;             // the largest iteration budget its passes had
    int loop_body_instructions = 0;  // static instructions of one iteration
  };
  std::vector<PassRecord> passes;
  std::vector<ProgramTotals> programs;
  Counters totals;
  bool keep_pass_records = true;  // off: only per-program and frame totals (long renders)
  bool device_timed = false;      // device_ms holds measured times (the GL device)
  // Device -> host texture read-backs (the image and AOVs at the end of a frame), outside passes.
  uint64_t downloads = 0;
  uint64_t download_bytes = 0;

  ProgramTotals& program(const std::string& name, const std::string& paper_name, int instructions);
  const ProgramTotals* find(const std::string& name) const;
  void clear();

  // As JSON: host/report/counters_json.h.
  std::string to_table() const;  // human-readable, one row per program
};

}  // namespace vgpu
