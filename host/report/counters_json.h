// The virtual GPU's counters as JSON: one pass's or one program's counters, and a frame's
// totals and programs. The vgpu counts (vgpu/stats.h); the report room writes what it counted.
#pragma once

#include <nlohmann/json.hpp>

#include "vgpu/stats.h"

namespace host {

// The counters as a JSON object: every field of vgpu::kCounterFields, then host_ms, then
// device_ms (null unless the device measured it).
nlohmann::ordered_json counters_json(const vgpu::Counters& c, bool device_timed = false);

// {"totals": {...}, "programs": [{"name", "paper_name", "static_instructions", counters...}],
//  "downloads", "download_bytes"}
nlohmann::ordered_json frame_counters_json(const vgpu::FrameStats& s);

}  // namespace host
