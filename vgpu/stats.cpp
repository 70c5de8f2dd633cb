// Statistics arithmetic and their JSON and table forms.
#include "vgpu/stats.h"

// GCC 12 reports false positives inside nlohmann_json's templates.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wrestrict"

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>

namespace vgpu {

Counters& Counters::operator+=(const Counters& o) {
  for (const auto& [name, field] : kCounterFields) this->*field += o.*field;
  host_ms += o.host_ms;
  device_ms += o.device_ms;
  return *this;
}

bool Counters::same_counts(const Counters& o) const {
  for (const auto& [name, field] : kCounterFields)
    if (this->*field != o.*field) return false;
  return true;
}

nlohmann::ordered_json to_json(const Counters& c, bool device_timed) {
  nlohmann::ordered_json j;
  for (const auto& [name, field] : kCounterFields) j[name] = c.*field;
  j["host_ms"] = c.host_ms;
  j["device_ms"] = device_timed ? nlohmann::ordered_json(c.device_ms) : nlohmann::ordered_json();
  return j;
}

FrameStats::ProgramTotals& FrameStats::program(const std::string& name,
                                               const std::string& paper_name, int instructions) {
  for (ProgramTotals& p : programs)
    if (p.name == name) return p;
  programs.push_back({name, paper_name, instructions, {}, {}, {}, 0, 0});
  return programs.back();
}

const FrameStats::ProgramTotals* FrameStats::find(const std::string& name) const {
  for (const ProgramTotals& p : programs)
    if (p.name == name) return &p;
  return nullptr;
}

void FrameStats::clear() {
  passes.clear();
  programs.clear();
  totals = {};
  downloads = download_bytes = 0;
}

nlohmann::ordered_json FrameStats::json() const {
  nlohmann::ordered_json j;
  j["totals"] = vgpu::to_json(totals, device_timed);
  auto progs = nlohmann::ordered_json::array();
  for (const ProgramTotals& p : programs) {
    nlohmann::ordered_json e;
    e["name"] = p.name;
    e["paper_name"] = p.paper_name;
    // The static count has its own key: the counters' "instructions" (executed) follow.
    e["static_instructions"] = p.instructions;
    const nlohmann::ordered_json c = vgpu::to_json(p.counters, device_timed);  // items() needs it
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
  j["downloads"] = downloads;
  j["download_bytes"] = download_bytes;
  return j;
}

std::string FrameStats::to_json(int indent) const {
  return json().dump(indent);
}

static std::string human(uint64_t v) {
  char buf[32];
  if (v >= 10'000'000'000ull)
    std::snprintf(buf, sizeof buf, "%.1fG", v / 1e9);
  else if (v >= 10'000'000ull)
    std::snprintf(buf, sizeof buf, "%.1fM", v / 1e6);
  else if (v >= 100'000ull)
    std::snprintf(buf, sizeof buf, "%.1fk", v / 1e3);
  else
    std::snprintf(buf, sizeof buf, "%llu", static_cast<unsigned long long>(v));
  return buf;
}

std::string FrameStats::to_table() const {
  std::string out;
  char line[512];
  // Name columns as wide as the longest name (fused programs have long ones), at least 24 / 22.
  int nw = 24, pw = 22;
  for (const ProgramTotals& p : programs) {
    nw = std::max(nw, int(p.name.size()));
    pw = std::max(pw, int(p.paper_name.size()));
  }
  std::snprintf(line, sizeof line, "%-*s %-*s %7s %9s %9s %9s %9s %9s %9s %6s %6s %9s%s\n", nw,
                "kernel", pw, "paper name", "passes", "launched", "shaded", "discarded", "fetches",
                "read B", "written B", "loads", "reads", "host ms",
                device_timed ? "    gpu ms" : "");
  out += line;
  auto row = [&](const std::string& n, const std::string& pn, const Counters& c) {
    std::snprintf(line, sizeof line, "%-*s %-*s %7s %9s %9s %9s %9s %9s %9s %6s %6s %9.2f", nw,
                  n.c_str(), pw, pn.c_str(), human(c.passes).c_str(),
                  human(c.fragments_launched).c_str(), human(c.fragments_shaded).c_str(),
                  human(c.fragments_discarded).c_str(), human(c.texture_fetches).c_str(),
                  human(c.bytes_read).c_str(), human(c.bytes_written).c_str(),
                  human(c.program_loads).c_str(), human(c.query_readbacks).c_str(), c.host_ms);
    out += line;
    if (device_timed) {
      std::snprintf(line, sizeof line, " %9.2f", c.device_ms);
      out += line;
    }
    out += "\n";
  };
  for (const ProgramTotals& p : programs) row(p.name, p.paper_name, p.counters);
  row("total", "", totals);
  for (const ProgramTotals& p : programs) {
    const Counters& c = p.counters;
    if (c.loop_lane_slots == 0) continue;
    std::snprintf(line, sizeof line,
                  "%s: loop of %d iterations a pass, %s batch iterations, %s lane slots, %s "
                  "active, %s idle (%.1f%%); longest lanes %s iterations, waiting through %s "
                  "fetches and %s operations\n",
                  p.name.c_str(), p.loop_budget, human(c.loop_batch_iterations).c_str(),
                  human(c.loop_lane_slots).c_str(), human(c.loop_iterations).c_str(),
                  human(c.loop_lanes_idle).c_str(),
                  100.0 * double(c.loop_lanes_idle) / double(c.loop_lane_slots),
                  human(c.loop_span_iterations).c_str(), human(c.loop_span_fetches).c_str(),
                  human(c.loop_span_operations).c_str());
    out += line;
  }
  return out;
}

}  // namespace vgpu
