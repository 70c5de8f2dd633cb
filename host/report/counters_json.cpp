// The virtual GPU's counters as JSON (host/report/counters_json.h).

// GCC 12 reports false positives inside nlohmann_json's templates.
#if defined(__GNUC__) && !defined(__clang__)  // GCC's warnings; clang has neither
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wrestrict"
#endif
#include "host/report/counters_json.h"

namespace host {

nlohmann::ordered_json counters_json(const vgpu::Counters& c, bool device_timed) {
  nlohmann::ordered_json j;
  for (const auto& [name, field] : vgpu::kCounterFields) j[name] = c.*field;
  j["host_ms"] = c.host_ms;
  j["device_ms"] = device_timed ? nlohmann::ordered_json(c.device_ms) : nlohmann::ordered_json();
  return j;
}

nlohmann::ordered_json frame_counters_json(const vgpu::FrameStats& s) {
  nlohmann::ordered_json j;
  j["totals"] = counters_json(s.totals, s.device_timed);
  auto progs = nlohmann::ordered_json::array();
  for (const vgpu::FrameStats::ProgramTotals& p : s.programs) {
    nlohmann::ordered_json e;
    e["name"] = p.name;
    e["paper_name"] = p.paper_name;
    // The static count has its own key: the counters' "instructions" (executed) follow.
    e["static_instructions"] = p.instructions;
    const nlohmann::ordered_json c = counters_json(p.counters, s.device_timed);  // items() needs it
    for (auto& [k, v] : c.items()) e[k] = v;
    if (p.loop_budget > 0) {  // a looping program: its loop per iteration
      e["loop_budget"] = p.loop_budget;
      e["loop_body_instructions"] = p.loop_body_instructions;
      e["loop_active_per_iteration"] = p.loop_active;
      e["loop_idle_per_iteration"] = p.loop_idle;
    }
    progs.push_back(e);
  }
  j["programs"] = progs;
  j["downloads"] = s.downloads;
  j["download_bytes"] = s.download_bytes;
  return j;
}

}  // namespace host
