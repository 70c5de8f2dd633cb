// A frame's statistics JSON as tests compare it: everything but the wall-clock times and the
// process's peak memory.
#pragma once

#include <nlohmann/json.hpp>

namespace test_support {

// A statistics JSON without its wall-clock fields (every "*_ms" key, at any depth) and the
// process's memory (peak_rss_bytes and the memory model's object, whose terms are the process's
// and the threads'): two runs of the same frame agree on everything else.
inline nlohmann::ordered_json without_times(const nlohmann::ordered_json& j) {
  if (j.is_object()) {
    nlohmann::ordered_json out = nlohmann::ordered_json::object();
    for (auto& [k, v] : j.items())
      if (!(k.size() > 3 && k.compare(k.size() - 3, 3, "_ms") == 0) && k != "peak_rss_bytes" &&
          k != "memory")
        out[k] = without_times(v);
    return out;
  }
  if (j.is_array()) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (auto& v : j) out.push_back(without_times(v));
    return out;
  }
  return j;
}

}  // namespace test_support
