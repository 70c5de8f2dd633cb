// Batch walks: an emulator shortcut, not modeled hardware. A host loop whose passes read the
// textures they change only at each fragment's own texel (the stream tracer's grid walk) gives
// every fragment the same results whichever fragments run beside it. So the emulator may run
// eight neighbouring fragments through the whole loop, pass after pass, with their texels in
// registers (Slot), instead of every pass over the whole target; the host then replays the
// pass sequence so the statistics come out as if each pass had run (Gpu::replay_next).
//
// run_batch() runs one program on one batch: fetches of resident units come from their slots,
// other units are read from the texture as usual, the outputs go to the target slots, and
// fragments that do not run keep their previous values (the passthrough unit's), exactly as
// Gpu::draw() under a work mask.
#pragma once

#include <cstdint>

#include "vgpu/fragment.h"
#include "vgpu/program.h"
#include "vgpu/texture.h"

namespace vgpu {

// A batch: W neighbouring fragments of one row.
inline constexpr int kBatchWidth = 8;

// What a pass did, summed over the batches of a walk: what Gpu::draw() needs to charge the pass
// without running it.
struct PassTally {
  uint64_t ran = 0;           // fragments that ran the program (the work mask's non-zero ones)
  uint64_t killed = 0;        // of those, discarded by the program
  uint64_t lanes_idle = 0;    // lanes idle in the program's branches, among those that ran
  uint64_t flagged_idle = 0;  // fragments that ran idle in some branch (kBranchIdle)
  // Idle fragments of the 8x4 and of the 32x32 tiles that hold a fragment taking a branch (for
  // the batch counters: FrameStats idle_in_batch32 and idle_in_batch1024).
  uint64_t idle_near_took8x4 = 0, idle_near_took32x32 = 0;
  double host_ms = 0;  // host time charged to the pass (a share of the walk's)
  PassTally& operator+=(const PassTally& o) {
    ran += o.ran;
    killed += o.killed;
    lanes_idle += o.lanes_idle;
    flagged_idle += o.flagged_idle;
    idle_near_took8x4 += o.idle_near_took8x4;
    idle_near_took32x32 += o.idle_near_took32x32;
    host_ms += o.host_ms;
    return *this;
  }
};

// One texture's texels at a batch's fragments, channel-major; channels the texture lacks hold
// (0, 0, 0, 1), as a fetch reads them.
struct Slot {
  alignas(32) float v[4][kBatchWidth];
  const Texture* texture = nullptr;
  // The batch's own texels from the texture (lanes past `n` repeat lane 0).
  void load(const Texture& t, int x0, int y, int n);
  // Back to the texture, lanes [0, n), through `data` (the texture's storage: the caller bumped
  // its version once for the walk).
  void store(const Texture& t, float* data, int x0, int y, int n) const;
};

// An output: the slot holding the target's texels, and the slot the program's idle fragments
// copy (its passthrough unit's), or null for a program whose idle fragments are discarded.
// `noutputs` may be less than the program's outputs: the rest are not kept (a query's counter).
struct BatchOutput {
  Slot* slot = nullptr;
  const Slot* idle_source = nullptr;
};

// Lanes as bits (lane i: bit i).
struct BatchRun {
  uint8_t killed = 0;  // ran and discarded
  uint8_t took = 0;    // ran and took every branch it met (kBranchTook)
  uint8_t idle = 0;    // ran and sat idle in some branch (kBranchIdle)
  uint64_t lanes_idle = 0;
};

// Runs p on the lanes `live` of the batch at (x0 + i, y), computing in `precision` (fp32, fp24 or
// fp16, as Gpu::precision_of says), with the fragment processor's branching (`dynamic`). units[u]
// is what unit u holds: a texture in memory, fetched at any coordinates, or, where `lanes` is
// set (to a Slot's v), the batch's own texels, fetched only there.
BatchRun run_batch(const Program& p, Format precision, bool dynamic, const BoundTexture* units,
                   const BatchOutput* outputs, int noutputs, uint8_t live, int x0, int y);

}  // namespace vgpu
