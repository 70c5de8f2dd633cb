// The statistics JSON's objects from the rooms' typed statistics (stats_parts_json.h).

// GCC 12 reports false positives inside the JSON library's templates.
#if defined(__GNUC__) && !defined(__clang__)  // GCC's warnings; clang has neither
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wrestrict"
#endif
#include "host/report/stats_parts_json.h"

#include <string>
#include <variant>

namespace host {

namespace {

using Json = nlohmann::ordered_json;

Json ivec3_json(const glm::ivec3& v) {
  return {v.x, v.y, v.z};
}

// A job's passes and bytes (read + written).
Json job(uint64_t passes, uint64_t bytes) {
  return Json{{"passes", passes}, {"bytes", bytes}};
}

Json fields(const GridStats& s) {
  Json j;
  j["voxels"] = ivec3_json(s.voxels);
  j["references"] = s.references;
  j["build_ms"] = s.build_ms;
  return j;
}

Json fields(const Grid2Stats& s) {
  Json j;
  j["coarse"] = ivec3_json(s.coarse);
  j["crowded_cells"] = s.crowded_cells;
  j["sub_cells"] = s.sub_cells;
  j["list_entries"] = s.list_entries;
  j["references"] = s.references;
  j["max_list"] = s.max_list;
  j["build_ms"] = s.build_ms;
  return j;
}

Json fields(const BvhStats& s) {
  Json j;
  j["nodes"] = s.nodes;
  j["leaves"] = s.leaves;
  j["depth"] = s.depth;
  j["max_leaf"] = s.max_leaf;
  j["references"] = s.references;
  j["sah_cost"] = s.sah_cost;
  j["build_ms"] = s.build_ms;
  return j;
}

Json fields(const KdTreeStats& s) {
  Json j;
  j["nodes"] = s.nodes;
  j["leaves"] = s.leaves;
  j["empty_leaves"] = s.empty_leaves;
  j["depth"] = s.depth;
  j["max_leaf"] = s.max_leaf;
  j["references"] = s.references;
  j["sah_cost"] = s.sah_cost;
  j["build_ms"] = s.build_ms;
  return j;
}

}  // namespace

Json accel_stats_json(const AccelStats& s) {
  return std::visit([](const auto& alt) { return fields(alt); }, s);
}

Json formats_json(const Formats& f) {
  Json j = Json::object();
  for (Group g : kGroups)
    j[std::string(group_name(g))] = {
        {"texels", std::string(vgpu::format_name(f[g]))},
        {"arithmetic", std::string(vgpu::format_name(f.arithmetic(g)))},
        {"why", f.why[size_t(g)]}};
  return j;
}

Json streams_json(const StreamStats& s) {
  Json levels = Json::array();
  for (const StreamLevel& l : s.levels)
    levels.push_back({{"rays", l.rays},
                      {"chunks", l.chunks},
                      {"reflected", l.reflected},
                      {"refracted", l.refracted},
                      {"total_internal", l.total_internal}});
  return {{"levels", levels},
          {"split", job(s.split_passes, s.split_bytes)},
          {"compaction", job(s.compaction_passes, s.compaction_bytes)},
          {"copies", job(s.copy_passes, s.copy_bytes)},
          {"gather", job(s.gather_passes, s.gather_bytes)},
          {"shadow_glass", job(s.shadow_passes, s.shadow_bytes)},
          {"shadow_rays_continued", s.shadow_continued}};
}

Json compact_json(const CompactStats& s) {
  return {{"packs", s.packs},
          {"frames", s.frames},
          {"live_rays", s.live_rays},
          {"slots", s.slots},
          {"pixels", s.pixels},
          {"scan", job(s.scan_passes, s.scan_bytes)},
          {"compaction", job(s.compaction_passes, s.compaction_bytes)},
          {"gather", job(s.gather_passes, s.gather_bytes)}};
}

}  // namespace host
