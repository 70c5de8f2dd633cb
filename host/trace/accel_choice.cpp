// --accel auto (host/trace/accel_choice.h): probe frames priced by the cost model.
#include "host/trace/accel_choice.h"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "host/model/cost_model.h"
#include "host/trace/stream_tracer.h"
#include "kernels/kernels.h"

namespace host {

WalkWork walk_work(const vgpu::FrameStats& stats) {
  WalkWork w;
  auto useful = [&](const char* name) -> uint64_t {
    const vgpu::FrameStats::ProgramTotals* p = stats.find(name);
    if (!p) return 0;
    const vgpu::Counters& c = p->counters;
    return c.fragments_shaded - std::min(c.lanes_idle, c.fragments_shaded);
  };
  using namespace kernels;
  w.voxel_steps = useful(Traversal::name) + useful(TraverseUpdate::name);
  w.nodes_visited = useful(BvhStep::name) + useful(BvhStepLoad::name);
  w.triangle_tests = useful(Intersections::name) + useful(IntersectNext::name) +
                     useful(BvhIntersections::name) + useful(BvhIntersectNext::name);
  for (const char* name : {LoopingTraversal::name, BvhLooping::name})
    if (const vgpu::FrameStats::ProgramTotals* p = stats.find(name))
      w.loop_iterations += p->counters.loop_iterations;
  return w;
}

AccelChoice choose_accel(const Scene& scene, const Grid& grid, const Grid& box, const Bvh& bvh,
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
  for (const AccelKind kind : {AccelKind::grid, AccelKind::bvh}) {
    const Accel accel{kind, kind == AccelKind::grid ? &grid : &box,
                      kind == AccelKind::bvh ? &bvh : nullptr};
    const std::string name(accel_name(kind));
    try {
      StreamTracer tracer(scene, accel, probe);
      const RenderResult r = tracer.render(camera);
      const CostBreakdown b = predict(r.stats, profile);
      const double ms = b.per_pass_ms + b.program_load_ms + b.readback_ms +
                        scale * (b.arithmetic_ms + b.texture_ms + b.memory_ms + b.download_ms);
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
  char line[256];
  const std::string other = c.kind == AccelKind::grid ? "bvh" : "grid";
  if (c.predicted_ms.count(other))
    std::snprintf(line, sizeof line,
                  "%s predicted %.1f ms on %s against %s's %.1f ms (%.2fx), from %dx%d probes",
                  std::string(accel_name(c.kind)).c_str(), best, profile.name.c_str(),
                  other.c_str(), c.predicted_ms[other], c.predicted_ms[other] / best, probe.width,
                  probe.height);
  else
    std::snprintf(line, sizeof line, "%s: the only structure the profile's limits allow (%s)",
                  std::string(accel_name(c.kind)).c_str(), refused.c_str());
  c.why = line;
  c.probe_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return c;
}

}  // namespace host
