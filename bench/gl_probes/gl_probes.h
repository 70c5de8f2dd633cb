// bench_gl's probes of the card itself, apart from the paper's frames: --latency (one fragment
// following a chain of dependent fetches or multiply-adds) and --coherence (where a warp's
// fetches go). Each times passes of its own small kernel on the GL device and returns its
// figures as JSON rows; bench_gl prints and stores them (docs/benchmarks.md).
#pragma once

#include <algorithm>
#include <chrono>
#include <nlohmann/json.hpp>
#include <vector>

#include "gl/gl_device.h"
#include "vgpu/profile.h"

namespace bench_gl_probes {

using Clock = std::chrono::steady_clock;

inline double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

inline double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// The latency probes: per chain, GPU time per iteration from two loop lengths (the difference
// removes the pass's fixed cost), in ns and in clocks of the h200 profile's boost clock.
nlohmann::ordered_json measure_latencies(gl::GlDevice& d, int runs, int warmup_ms);

// The coherence probes: GPU time of a 256x256 pass of 64 independent fetches a fragment from a
// 512x512 RGBA32F texture for four placements of the fetches, against the cost model's price
// of the emulator's pass on `card` (the same for all four).
nlohmann::ordered_json measure_coherence(gl::GlDevice& d, int runs, int warmup_ms,
                                         const vgpu::Profile& card);

}  // namespace bench_gl_probes
