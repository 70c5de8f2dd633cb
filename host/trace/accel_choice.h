// --accel auto: which structure to walk, chosen by the cost model. Each candidate structure is
// built and a probe frame (the same options at a quarter of the size in x and y, at least 16x16)
// is rendered with it on the emulator; the cost model predicts the full frame from the probe's
// statistics on the profile asked for: the per-pass, program-load and read-back costs as
// measured (they follow the pass count, which the image size hardly changes), the fragment
// work (arithmetic, texture, memory, downloads) scaled by the pixel ratio. The cheapest wins.
#pragma once

#include <map>
#include <optional>
#include <string>

#include "host/accel/accel.h"
#include "host/scene/scene.h"
#include "host/trace/render_options.h"

namespace host {

struct AccelChoice {
  AccelKind kind = AccelKind::grid;
  int probe_width = 0, probe_height = 0;
  std::map<std::string, double> predicted_ms;  // per candidate, full frame, options.profile
  std::map<std::string, uint64_t> probe_passes;
  double probe_ms = 0;  // host wall time of the probes (builds included)
  std::string why;      // one sentence
};

// `grid` is the grid --accel grid would walk; `bvh` the BVH (built by the caller). Throws what
// StreamTracer throws for a candidate no profile limit allows only if no candidate is left.
AccelChoice choose_accel(const Scene& scene, const Grid& grid, const Grid& box, const Bvh& bvh,
                         const RenderOptions& options, const Camera& camera);

}  // namespace host
