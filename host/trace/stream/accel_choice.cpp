// --accel auto (host/trace/stream/accel_choice.h): probe frames priced by the cost model.
#include "host/trace/stream/accel_choice.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <optional>

#include "host/model/cost_model.h"
#include "host/trace/stream/stream_tracer.h"
#include "host/trace/structures.h"
#include "host/trace/validate.h"
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
  // Every structure's walk kernels (its row's, host/trace/structures.h): a frame runs one's.
  for (const WalkRow& row : walk_rows()) {
    const WalkKernels& k = row.kernels;
    for (const char* name : k.steps) (k.tree ? w.nodes_visited : w.voxel_steps) += useful(name);
    for (const char* name : k.tests) w.triangle_tests += useful(name);
    if (const vgpu::FrameStats::ProgramTotals* p = stats.find(k.looping))
      w.loop_iterations += p->counters.loop_iterations;
  }
  if (stats.find(kernels::KdLoadLeaf::name)) {
    const uint64_t leaves = useful(kernels::KdLoadLeaf::name);
    w.restarts = leaves >= rays_traced ? int64_t(leaves - rays_traced) : 0;
  }
  return w;
}

namespace {

// The options of a probe frame: 1/`divisor` of the size in x and y (at least 16x16), quiet.
RenderOptions probe_options(const RenderOptions& options, int divisor = 4) {
  RenderOptions probe = options;
  probe.width = std::min(options.width, std::max(16, options.width / divisor));
  probe.height = std::min(options.height, std::max(16, options.height / divisor));
  probe.observer = nullptr;
  probe.progress = nullptr;
  probe.trace_pixel.reset();
  probe.trace_out = nullptr;
  probe.keep_pass_records = true;
  return probe;
}

// The full frame's pixels over the probe's.
double probe_scale(const RenderOptions& options, const RenderOptions& probe) {
  return double(options.width) * double(options.height) /
         (double(probe.width) * double(probe.height));
}

// A probe's price so far (RunningPrice, on the profile it is priced on, at its scale) can only
// grow, so a probe whose price so far passes `ms` is priced over `ms` whatever else it does.
std::function<bool(const vgpu::Counters&)> over(double ms, const vgpu::Profile& profile,
                                                double scale) {
  return [=, price = std::make_shared<RunningPrice>(profile, scale)](const vgpu::Counters& t) {
    // (By more than rounding: the running price adds a clear's bytes within a pass, predict after
    // the passes, so the two may differ in their last bits; a probe priced at `ms` runs on.)
    return price->add(t) > ms * (1 + 1e-12);
  };
}

// The profile a probe is priced on: its L2 divided by `scale`, so that a probe's pass spills
// where the same pass of the full frame would (a footprint taken to grow with the pixels, as the
// ray-state textures do; a scene's own textures do not, so a large scene's is overstated).
vgpu::Profile full_frame_profile(const vgpu::Profile& profile, double scale) {
  vgpu::Profile p = profile;
  p.l2_bytes /= scale;
  return p;
}

// One candidate's probe: its full-frame price (every term, full_frame_ms) and passes; throws
// vgpu::Error where the profile's limits refuse it, vgpu::BudgetError where `stop` stops it
// (the emulator's probes).
std::pair<double, uint64_t> probe_price(const Scene& scene, const AccelCandidate& cand,
                                        RenderOptions probe, const RenderOptions& options,
                                        const Camera& camera, const vgpu::Profile& profile,
                                        std::function<bool(const vgpu::Counters&)> stop = {}) {
  probe.formats = cand.formats;
  probe.stop_when = std::move(stop);
  StreamTracer tracer(scene, *cand.accel, probe);
  const RenderResult r = tracer.render(camera);
  const double scale = probe_scale(options, probe);
  return {full_frame_ms(predict(r.stats, full_frame_profile(profile, scale)), scale),
          r.stats.totals.passes};
}

}  // namespace

AccelChoice choose_accel(const Scene& scene, const std::vector<AccelCandidate>& candidates,
                         const RenderOptions& options, const Camera& camera, bool stop_early) {
  const auto t0 = std::chrono::steady_clock::now();
  AccelChoice c;
  const RenderOptions probe = probe_options(options, 4);
  c.probe_width = probe.width;
  c.probe_height = probe.height;
  const vgpu::Profile& profile = vgpu::profile(options.profile);
  auto name_of = [](const AccelCandidate* cand) { return std::string(cand->accel->name()); };
  // A probe stops once its price so far passes `ms` (over); its price is then only
  // known to be over that: kept just over `ms`, the candidate listed in `stopped`.
  const bool emulated = options.device == "vgpu";
  auto budget = [&](double ms, const RenderOptions& size) {
    const double scale = probe_scale(options, size);
    return stop_early && emulated ? over(ms, full_frame_profile(profile, scale), scale)
                                  : std::function<bool(const vgpu::Counters&)>{};
  };
  auto stop = [&](const std::string& name, double ms) {  // strictly over: not a tie, not in band
    c.stopped.push_back(name);
    return std::nextafter(ms, std::numeric_limits<double>::infinity());
  };
  // The first round: every candidate at a quarter of the size. Once one is priced, a probe past
  // the band of the cheapest so far cannot be in the band of the cheapest: it stops there.
  std::string refused;
  std::vector<const AccelCandidate*> priced;
  double cheapest = 0;
  for (const AccelCandidate& cand : candidates) {
    const std::string name = name_of(&cand);
    const double bound = (1.0 + kAutoProbeBand) * cheapest;
    try {
      const auto [ms, passes] = probe_price(scene, cand, probe, options, camera, profile,
                                            priced.empty() ? nullptr : budget(bound, probe));
      c.coarse_ms[name] = c.predicted_ms[name] = ms;
      c.probe_passes[name] = passes;
      cheapest = priced.empty() ? ms : std::min(cheapest, ms);
      priced.push_back(&cand);
    } catch (const vgpu::BudgetError&) {
      c.coarse_ms[name] = c.predicted_ms[name] = stop(name, bound);
    } catch (const vgpu::Error& e) {
      refused += (refused.empty() ? "" : "; ") + name + ": " + e.what();
    }
  }
  if (priced.empty()) throw vgpu::Error("--accel auto: no structure fits: " + refused);
  // The second round: those within kAutoProbeBand of the cheapest, at half the size (where that
  // is larger than the first probes; at the first probes' size their prices stand), the cheapest
  // first: a probe past the cheapest second price so far cannot be the pick, and stops there.
  const RenderOptions fine = probe_options(options, 2);
  const bool larger = fine.width > probe.width || fine.height > probe.height;
  if (larger) {
    c.refine_width = fine.width;
    c.refine_height = fine.height;
  }
  std::vector<const AccelCandidate*> band;
  for (const AccelCandidate* cand : priced)
    if (c.coarse_ms.at(name_of(cand)) <= (1.0 + kAutoProbeBand) * cheapest) band.push_back(cand);
  const size_t probed_again = larger && band.size() > 1 ? band.size() : 0;
  if (probed_again) {
    std::vector<const AccelCandidate*> order = band, kept;
    std::stable_sort(order.begin(), order.end(), [&](const auto* x, const auto* y) {
      return c.coarse_ms.at(name_of(x)) < c.coarse_ms.at(name_of(y));
    });
    double best = 0;
    for (const AccelCandidate* cand : order) {
      const std::string name = name_of(cand);
      try {
        const double ms = probe_price(scene, *cand, fine, options, camera, profile,
                                      kept.empty() ? nullptr : budget(best, fine))
                              .first;
        c.predicted_ms[name] = ms;
        best = kept.empty() ? ms : std::min(best, ms);
        kept.push_back(cand);
      } catch (const vgpu::BudgetError&) {
        c.predicted_ms[name] = stop(name, best);
      } catch (const vgpu::Error& e) {  // the larger probe outgrew a limit: the frame would too
        c.predicted_ms.erase(name);
        refused += (refused.empty() ? "" : "; ") + name + ": " + e.what();
      }
    }
    std::vector<const AccelCandidate*> still;  // in the candidates' order, for ties
    for (const AccelCandidate* cand : band) {
      const std::string name = name_of(cand);
      if (!c.predicted_ms.count(name)) continue;
      c.refined.push_back(name);
      if (std::find(kept.begin(), kept.end(), cand) != kept.end()) still.push_back(cand);
    }
    band = still;
    if (band.empty())  // every one refused: the cheapest of the others, at their first price
      for (const AccelCandidate* cand : priced)
        if (c.predicted_ms.count(name_of(cand))) band.push_back(cand);
    if (band.empty()) throw vgpu::Error("--accel auto: no structure fits: " + refused);
  }
  // The cheapest of the band, a tie going to the candidate listed first.
  double best = 0;
  for (size_t i = 0; i < band.size(); ++i) {
    const double ms = c.predicted_ms.at(name_of(band[i]));
    if (i == 0 || ms < best) {
      best = ms;
      c.kind = band[i]->accel->kind();
    }
  }
  std::string others;
  for (const auto& [name, ms] : c.predicted_ms)
    if (name != accel_name(c.kind)) {
      const bool again = std::find(c.refined.begin(), c.refined.end(), name) != c.refined.end();
      const bool stopped = std::find(c.stopped.begin(), c.stopped.end(), name) != c.stopped.end();
      const char* first = again || c.refined.empty() ? "" : ", first probe";
      char part[128];
      std::snprintf(part, sizeof part, "%s%s %s%.1f ms (%.2fx%s%s)", others.empty() ? "" : ", ",
                    name.c_str(), stopped ? "over " : "", ms, ms / best,
                    stopped ? ", its probe stopped" : "", first);
      others += part;
    }
  char round2[96] = "";
  if (probed_again)
    std::snprintf(round2, sizeof round2, ", the %zu within %.0f%% again at %dx%d", probed_again,
                  100.0 * kAutoProbeBand, c.refine_width, c.refine_height);
  char line[768];
  std::snprintf(line, sizeof line, "%s predicted %.1f ms on %s against %s, from %dx%d probes%s%s%s",
                std::string(accel_name(c.kind)).c_str(), best, profile.name.c_str(),
                others.empty() ? "nothing else" : others.c_str(), probe.width, probe.height, round2,
                refused.empty() ? "" : "; refused: ", refused.c_str());
  c.why = line;
  c.probe_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return c;
}

BeamsChoice choose_beams(const Scene& scene, const Accel& accel, const RenderOptions& options,
                         const Camera& camera, std::string_view engine) {
  const auto t0 = std::chrono::steady_clock::now();
  BeamsChoice c;
  const vgpu::Profile& profile = vgpu::profile(options.profile);
  // Where --beams on would be refused, off, saying why (no probe runs).
  RenderOptions with = options;
  with.beams = true;
  std::string refused;
  // The GL device runs the emulator's passes and counts the same statistics, so its probes are
  // priced alike; the CPU tracer has no passes for the cost model to price.
  if (engine == "cpu")
    refused = "the cost model prices passes, and the cpu engine runs none";
  else if (const std::vector<Refusal> r = validate(with, profile); !r.empty())
    refused = r.front().why;
  if (!refused.empty()) {
    c.why = "off: " + refused;
    return c;
  }
  // The probes: the frame's primary trace at its full size, without and with beams. Smaller
  // probes mislead here (glass and sphere were predicted cheaper with beams from 64x64 probes,
  // and are dearer at 256x256): a multipass walk runs as many passes as its slowest ray,
  // and which rays are slowest changes with the image's size and the tiles' footprint. Beams
  // change the primary trace alone, so the rest of the frame is left out of both.
  RenderOptions probe = probe_options(options);
  probe.width = options.width;
  probe.height = options.height;
  probe.bounces = 0;
  probe.shadows = false;
  probe.spp = 1;
  probe.adaptive = false;
  probe.undersample = 0;
  c.probed = true;
  c.probe_width = probe.width;
  c.probe_height = probe.height;
  for (const bool on : {true, false}) {  // on first: a structure refusing beams renders nothing
    probe.beams = on;
    std::optional<StreamTracer> tracer;
    try {
      tracer.emplace(scene, accel, probe);
    } catch (const vgpu::LimitError& e) {
      // A refusal the structure makes once built (beams need linear addresses: its indices
      // outgrew them, docs/studies/scale.md): off, saying why.
      if (!on) throw;
      c.on = false;
      c.probed = false;
      c.why = std::string("off: ") + e.what();
      c.probe_ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      return c;
    }
    const RenderResult r = tracer->render(camera);
    const CostBreakdown b = predict(r.stats, profile);
    (on ? c.on_ms : c.off_ms) = b.total_ms;
    c.probe_model_ms += b.total_ms;
  }
  c.on = c.on_ms < (1.0 - kAutoBeamsMargin) * c.off_ms;
  char line[320];
  std::snprintf(line, sizeof line,
                "%s: primary rays %.1f ms with beams (%.2fx), %.1f ms without, predicted on %s "
                "from %dx%d probes (on only where at least %.0f%% cheaper)",
                c.on ? "on" : "off", c.on_ms, c.on_ms / c.off_ms, c.off_ms, profile.name.c_str(),
                probe.width, probe.height, 100.0 * kAutoBeamsMargin);
  c.why = line;
  c.probe_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return c;
}

}  // namespace host
