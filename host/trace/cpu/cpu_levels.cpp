// The CPU tracer's logs for tests and benches (cpu_tracer.h): one ray's tree of rays, and every
// pixel's adaptive levels traced as if all were refined.
#include <algorithm>
#include <thread>
#include <vector>

#include "host/common/parallel.h"
#include "host/trace/cpu/cpu_core.h"
#include "host/trace/cpu/cpu_tracer.h"

namespace host {

using namespace cpu_core;

std::vector<CpuRay> cpu_ray_tree(const Scene& scene, const Accel& accel,
                                 const RenderOptions& options, const glm::dvec3& origin,
                                 const glm::dvec3& dir) {
  const Camera camera;  // only the trilinear texture footprint reads it (its pixel spread)
  Tracer tracer(scene, accel, camera, options);
  std::vector<CpuRay> rays;
  tracer.log_ = &rays;
  Counters counters;
  tracer.radiance(origin, glm::normalize(dir), 0, 1.0, nullptr, counters);
  return rays;
}

CpuAdaptiveLevels cpu_adaptive_levels(const Scene& scene, const Accel& accel, const Camera& camera,
                                      const RenderOptions& options) {
  const Tracer tracer(scene, accel, camera, options);
  CpuAdaptiveLevels out;
  const int W = std::max(options.width, 0), H = std::max(options.height, 0);
  const size_t n = size_t(W) * size_t(H);
  out.width = W;
  out.height = H;
  out.sides = adaptive_levels(options.spp);
  out.centre.assign(n * 3, 0.0f);
  out.depth.assign(n, 0.0f);
  out.key.assign(n, -1);
  out.reflected_key.assign(n, -1);
  out.centre_rays.assign(n, 0);
  out.level.assign(out.sides.size(), std::vector<float>(n * 3, 0.0f));
  out.level_rays.assign(out.sides.size(), std::vector<uint32_t>(n, 0));
  // The kept levels' samples (sampling.h): level l's set is the first l + 1 lists together.
  const size_t levels = out.sides.size();
  const std::vector<std::vector<glm::vec2>> added =
      kept_level_samples(options.spp, options.sample_seed);
  out.kept.assign(levels, {});
  out.kept_rays.assign(levels, {});
  for (size_t l = 1; l < added.size(); ++l) {
    out.kept[l].assign(n * 3, 0.0f);
    out.kept_rays[l].assign(n, 0);
  }
  RenderResult aov;  // the centre rays' depths land here
  aov.depth.assign(n, 0.0f);
  aov.hit_id.assign(n, -1.0f);
  const bool mirrors = !tracer.ray_streams();  // as adaptive(): no reflected keys in streams
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const unsigned workers = std::clamp<unsigned>(
      options.threads > 0 ? unsigned(options.threads) : cores, 1u, unsigned(std::max(H, 1)));
  std::vector<Counters> counters(workers);
  for_each_row(H, workers, [&](unsigned worker, int y) {
    Counters& c = counters[worker];
    for (int x = 0; x < W; ++x) {
      const size_t i = size_t(y) * size_t(W) + size_t(x);
      uint64_t before = c.entered;
      const glm::dvec3 centre =
          tracer.centre(x, y, aov, out.key[i], c, mirrors ? &out.reflected_key[i] : nullptr);
      out.centre_rays[i] = uint32_t(c.entered - before);
      for (int ch = 0; ch < 3; ++ch) out.centre[i * 3 + size_t(ch)] = float(centre[ch]);
      for (size_t l = 0; l < out.sides.size(); ++l) {
        // render_cpu's spp m pixel: the same offsets, summed in the same order, then divided.
        const int m = out.sides[l] * out.sides[l];
        before = c.entered;
        glm::dvec3 sum(0.0);
        for (int k = 0; k < m; ++k)
          sum += tracer.sample(x, y, sample_offset(m, k, options.sample_seed), nullptr, c);
        sum /= double(m);
        out.level_rays[l][i] = uint32_t(c.entered - before);
        for (int ch = 0; ch < 3; ++ch) out.level[l][i * 3 + size_t(ch)] = float(sum[ch]);
      }
      // The kept levels: the earlier samples traced again (their rays not counted), then the
      // new ones.
      for (size_t l = 1; l < added.size(); ++l) {
        glm::dvec3 sum(0.0);
        Counters again;
        size_t count = 0;
        for (size_t e = 0; e < l; ++e)
          for (const glm::vec2 o : added[e]) sum += tracer.sample(x, y, o, nullptr, again);
        before = c.entered;
        for (const glm::vec2 o : added[l]) sum += tracer.sample(x, y, o, nullptr, c);
        for (size_t e = 0; e <= l; ++e) count += added[e].size();
        sum /= double(count);
        out.kept_rays[l][i] = uint32_t(c.entered - before);
        for (int ch = 0; ch < 3; ++ch) out.kept[l][i * 3 + size_t(ch)] = float(sum[ch]);
      }
    }
  });
  out.depth = aov.depth;
  return out;
}

}  // namespace host
