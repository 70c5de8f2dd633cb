// The statistics JSON as a value: `vgpu-rt render`'s document (--stats-json, --stats json, the
// report's embedded copy, the Python module's stats text). Only the report room's writers put
// keys in it (stats_json.h, stats_parts_json.h, counters_json.h); the command line and the
// Python module hold it and pass it on.
#pragma once

#include <nlohmann/json.hpp>

namespace host {

using StatsJson = nlohmann::ordered_json;

}  // namespace host
