// Statistics arithmetic and their table form (the JSON form is the report room's:
// host/report/counters_json.h).
#include "vgpu/stats.h"

#include <algorithm>
#include <cstdio>

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
                  "fetches and %s operations; %s operations between fetches\n",
                  p.name.c_str(), p.loop_budget, human(c.loop_batch_iterations).c_str(),
                  human(c.loop_lane_slots).c_str(), human(c.loop_iterations).c_str(),
                  human(c.loop_lanes_idle).c_str(),
                  100.0 * double(c.loop_lanes_idle) / double(c.loop_lane_slots),
                  human(c.loop_span_iterations).c_str(), human(c.loop_span_fetches).c_str(),
                  human(c.loop_span_operations).c_str(),
                  human(c.loop_dependent_instructions).c_str());
    out += line;
  }
  return out;
}

}  // namespace vgpu
