// --accel auto (host/trace/stream/accel_choice.h): probe frames priced by the cost model.
#include "host/trace/stream/accel_choice.h"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "host/model/cost_model.h"
#include "host/trace/stream/stream_tracer.h"
#include "kernels/kernels.h"

namespace host {

WalkWork walk_work(const vgpu::FrameStats& stats, uint64_t rays_traced) {
  WalkWork w;
  auto useful = [&](const char* name) -> uint64_t {
    const vgpu::FrameStats::ProgramTotals* p = stats.find(name);
    if (!p) return 0;
    const vgpu::Counters& c = p->counters;
    return c.fragments_shaded - std::min(c.lanes_idle, c.fragments_shaded);
  };
  using namespace kernels;
  w.voxel_steps = useful(Traversal::name) + useful(TraverseUpdate::name) + useful(Grid2Step::name) +
                  useful(Grid2StepLoad::name);
  w.nodes_visited = useful(BvhStep::name) + useful(BvhStepLoad::name) + useful(KdStep::name) +
                    useful(KdStepLoad::name);
  w.triangle_tests = useful(Intersections::name) + useful(IntersectNext::name) +
                     useful(BvhIntersections::name) + useful(BvhIntersectNext::name) +
                     useful(KdIntersections::name) + useful(KdIntersectNext::name) +
                     useful(Grid2Intersections::name) + useful(Grid2IntersectNext::name);
  if (stats.find(KdLoadLeaf::name)) {
    const uint64_t leaves = useful(KdLoadLeaf::name);
    w.restarts = leaves >= rays_traced ? int64_t(leaves - rays_traced) : 0;
  }
  for (const char* name :
       {LoopingTraversal::name, BvhLooping::name, KdLooping::name, Grid2Looping::name})
    if (const vgpu::FrameStats::ProgramTotals* p = stats.find(name))
      w.loop_iterations += p->counters.loop_iterations;
  return w;
}

namespace {

// The price of a candidate: the full frame predicted from its probe's cost breakdown, every term
// of the model's total (CostBreakdown::total_ms). The costs that follow the pass count (per pass,
// program loads, read-backs) and the looping passes' longest lanes (latency: one lane's chain,
// which does not grow with the pixel count) as measured; the fragment work scaled by `scale`,
// the full frame's pixels over the probe's. At scale 1 this is the probe's total_ms.
double full_frame_ms(const CostBreakdown& b, double scale) {
  return b.per_pass_ms + b.program_load_ms + b.readback_ms + b.latency_ms +
         scale * (b.arithmetic_ms + b.texture_ms + b.memory_ms + b.download_ms);
}

}  // namespace

AccelChoice choose_accel(const Scene& scene, const std::vector<AccelCandidate>& candidates,
                         const RenderOptions& options, const Camera& camera) {
  const auto t0 = std::chrono::steady_clock::now();
  AccelChoice c;
  RenderOptions probe = options;
  probe.width = std::min(options.width, std::max(16, options.width / 4));
  probe.height = std::min(options.height, std::max(16, options.height / 4));
  probe.observer = nullptr;
  probe.progress = nullptr;
  probe.trace_pixel.reset();
  probe.trace_out = nullptr;
  probe.keep_pass_records = true;
  c.probe_width = probe.width;
  c.probe_height = probe.height;
  const double scale =
      double(options.width) * double(options.height) / (double(probe.width) * double(probe.height));
  const vgpu::Profile& profile = vgpu::profile(options.profile);
  std::string refused;
  double best = 0;
  bool any = false;
  for (const AccelCandidate& cand : candidates) {
    const Accel& accel = *cand.accel;
    const AccelKind kind = accel.kind();
    const std::string name(accel.name());
    probe.formats = cand.formats;
    try {
      StreamTracer tracer(scene, accel, probe);
      const RenderResult r = tracer.render(camera);
      const CostBreakdown b = predict(r.stats, profile);
      const double ms = full_frame_ms(b, scale);
      c.predicted_ms[name] = ms;
      c.probe_passes[name] = r.stats.totals.passes;
      if (!any || ms < best) {
        best = ms;
        c.kind = kind;
        any = true;
      }
    } catch (const vgpu::Error& e) {
      refused += (refused.empty() ? "" : "; ") + name + ": " + e.what();
    }
  }
  if (!any) throw vgpu::Error("--accel auto: no structure fits: " + refused);
  // The grid unless another is predicted clearly cheaper (kAutoGridMargin).
  const auto grid = c.predicted_ms.find(std::string(accel_name(AccelKind::grid)));
  bool kept = false;
  if (c.kind != AccelKind::grid && grid != c.predicted_ms.end() &&
      best > (1.0 - kAutoGridMargin) * grid->second) {
    c.kind = AccelKind::grid;
    best = grid->second;
    kept = true;
  }
  std::string others;
  for (const auto& [name, ms] : c.predicted_ms)
    if (name != accel_name(c.kind)) {
      char part[96];
      std::snprintf(part, sizeof part, "%s%s %.1f ms (%.2fx)", others.empty() ? "" : ", ",
                    name.c_str(), ms, ms / best);
      others += part;
    }
  char line[640];
  std::snprintf(line, sizeof line, "%s predicted %.1f ms on %s against %s, from %dx%d probes%s%s%s",
                std::string(accel_name(c.kind)).c_str(), best, profile.name.c_str(),
                others.empty() ? "nothing else" : others.c_str(), probe.width, probe.height,
                kept ? " (the grid is kept unless another is predicted 10% cheaper)" : "",
                refused.empty() ? "" : "; refused: ", refused.c_str());
  c.why = line;
  c.probe_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return c;
}

}  // namespace host
