// What the Gpu's three files share (gpu.cpp, gpu_counters.cpp, gpu_workers.cpp): a row chunk's
// counts, the batch flags, eight-bytes-at-a-time mask reads and the batch counters draw() calls.
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <utility>
#include <vector>

#include "vgpu/gpu.h"

namespace vgpu {

// What one row chunk of a draw counted (run_rows fills it, draw() and replay() sum them).
struct Gpu::Chunk {
  uint64_t launched = 0, shaded = 0, masked = 0, discarded = 0, idle = 0;
  uint64_t idle_flags = 0;  // fragments flagged kIdle (for the batch counters)
  // Texel indices, ascending: the fragments that ran (DrawPlan::list_runs) and those whose
  // stencil write is 1 (DrawPlan::list_survivors).
  std::vector<uint32_t> runs, survivors;
  void reset() {
    std::vector<uint32_t> keep_runs = std::move(runs), keep_survivors = std::move(survivors);
    *this = Chunk{};
    runs = std::move(keep_runs);
    survivors = std::move(keep_survivors);
    runs.clear();
    survivors.clear();
  }
};

namespace gpu_detail {

// Batch flags per fragment: kTook took the branch, kIdle sat idle in it, 0 not shaded.
inline constexpr uint8_t kTook = kBranchTook, kIdle = kBranchIdle;

inline constexpr uint64_t kOnes = 0x0101010101010101ull, kHighs = 0x8080808080808080ull;

// The high bit of every non-zero byte of v.
constexpr uint64_t nonzero_bytes(uint64_t v) {
  return (((v & ~kHighs) + ~kHighs) | v) & kHighs;
}

// Up to eight bytes from p (n of them; the rest read as 0).
inline uint64_t load_bytes(const uint8_t* p, int n) {
  uint64_t v = 0;
  if (n >= 8) {
    std::memcpy(&v, p, 8);  // a fixed size: one load, no call
    return v;
  }
  for (int i = 0; i < n; ++i) v |= uint64_t(p[i]) << (8 * i);
  return v;
}

// The batch counters of a pass (gpu_counters.cpp, where each is described).
std::array<uint64_t, 2> idle_in_batches(const Rect& r, const uint8_t* flags, const Stencil* work,
                                        const Stencil* test, bool work_masked, uint64_t idle_flags,
                                        const uint8_t* took8, const uint8_t* took32);
std::array<uint64_t, 2> idle_in_batches_listed(int w, int h, const uint8_t* flags,
                                               const std::vector<uint32_t>& listed,
                                               bool work_masked, uint64_t idle_flags);
LoopCounts loop_batches(const Rect& r, const uint32_t* iters, uint32_t tw, const Stencil* work,
                        const Stencil* test, bool work_masked, int granularity, int budget,
                        std::vector<uint64_t>& active, std::vector<uint64_t>& idle);

}  // namespace gpu_detail
}  // namespace vgpu
