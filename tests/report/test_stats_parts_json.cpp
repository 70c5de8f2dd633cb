// The report room's writers of the rooms' typed statistics (host/report/stats_parts_json.h):
// every field of each struct under the key docs/cli.md ("The statistics JSON") gives, keys in
// that order and nothing else. Each field holds a value no other field of its struct holds, so
// two keys swapped in a writer fail here.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "host/common/version.h"
#include "host/report/stats_json.h"
#include "host/report/stats_parts_json.h"

using Json = nlohmann::ordered_json;

namespace {

std::vector<std::string> keys(const Json& j) {
  std::vector<std::string> out;
  for (auto& [k, v] : j.items()) out.push_back(k);
  return out;
}

using Keys = std::vector<std::string>;

}  // namespace

TEST_CASE("the accel writer puts each structure's statistics under its documented keys") {
  SUBCASE("grid") {
    const Json j = host::accel_stats_json(
        host::GridStats{.voxels = {3, 4, 5}, .references = 60, .build_ms = 1.5});
    CHECK(keys(j) == Keys{"voxels", "references", "build_ms"});
    CHECK(j["voxels"] == Json{3, 4, 5});
    CHECK(j["references"] == 60);
    CHECK(j["build_ms"] == 1.5);
  }
  SUBCASE("grid2") {
    const Json j = host::accel_stats_json(host::Grid2Stats{.coarse = {6, 7, 8},
                                                           .crowded_cells = 9,
                                                           .sub_cells = 10,
                                                           .list_entries = 11,
                                                           .references = 12,
                                                           .max_list = 13,
                                                           .build_ms = 2.5});
    CHECK(keys(j) == Keys{"coarse", "crowded_cells", "sub_cells", "list_entries", "references",
                          "max_list", "build_ms"});
    CHECK(j["coarse"] == Json{6, 7, 8});
    CHECK(j["crowded_cells"] == 9);
    CHECK(j["sub_cells"] == 10);
    CHECK(j["list_entries"] == 11);
    CHECK(j["references"] == 12);
    CHECK(j["max_list"] == 13);
    CHECK(j["build_ms"] == 2.5);
  }
  SUBCASE("bvh") {
    const Json j = host::accel_stats_json(host::BvhStats{.nodes = 21,
                                                         .leaves = 22,
                                                         .depth = 23,
                                                         .max_leaf = 24,
                                                         .references = 25,
                                                         .sah_cost = 26.5,
                                                         .build_ms = 3.5});
    CHECK(keys(j) ==
          Keys{"nodes", "leaves", "depth", "max_leaf", "references", "sah_cost", "build_ms"});
    CHECK(j["nodes"] == 21);
    CHECK(j["leaves"] == 22);
    CHECK(j["depth"] == 23);
    CHECK(j["max_leaf"] == 24);
    CHECK(j["references"] == 25);
    CHECK(j["sah_cost"] == 26.5);
    CHECK(j["build_ms"] == 3.5);
  }
  SUBCASE("kdtree") {
    const Json j = host::accel_stats_json(host::KdTreeStats{.nodes = 31,
                                                            .leaves = 32,
                                                            .empty_leaves = 33,
                                                            .depth = 34,
                                                            .max_leaf = 35,
                                                            .references = 36,
                                                            .sah_cost = 37.5,
                                                            .build_ms = 4.5});
    CHECK(keys(j) == Keys{"nodes", "leaves", "empty_leaves", "depth", "max_leaf", "references",
                          "sah_cost", "build_ms"});
    CHECK(j["nodes"] == 31);
    CHECK(j["leaves"] == 32);
    CHECK(j["empty_leaves"] == 33);
    CHECK(j["depth"] == 34);
    CHECK(j["max_leaf"] == 35);
    CHECK(j["references"] == 36);
    CHECK(j["sah_cost"] == 37.5);
    CHECK(j["build_ms"] == 4.5);
  }
}

TEST_CASE(
    "the formats writer gives every group its texels, arithmetic and why, in kGroups' order") {
  host::Formats f = host::Formats::all(vgpu::Format::fp32);
  f.set(host::Group::voxel, vgpu::Format::fp16, vgpu::Format::fp24);
  f.why[size_t(host::Group::voxel)] = "the voxel's reason";
  const Json j = host::formats_json(f);
  CHECK(keys(j) == Keys{"rays", "traversal", "voxel", "hits", "colour", "queries"});
  for (auto& [group, g] : j.items()) {
    CHECK(keys(g) == Keys{"texels", "arithmetic", "why"});
    if (group == "voxel") continue;
    CHECK(g["texels"] == "fp32");
    CHECK(g["arithmetic"] == "fp32");
    CHECK(g["why"] == "");
  }
  CHECK(j["voxel"]["texels"] == "fp16");
  CHECK(j["voxel"]["arithmetic"] == "fp24");
  CHECK(j["voxel"]["why"] == "the voxel's reason");
}

TEST_CASE("the ray streams' writer puts every level's and every job's counts under their keys") {
  host::StreamStats s;
  s.on = true;
  s.levels = {{.rays = 1, .chunks = 2, .reflected = 3, .refracted = 4, .total_internal = 5},
              {.rays = 6, .chunks = 7, .reflected = 8, .refracted = 9, .total_internal = 10}};
  s.split_passes = 11, s.split_bytes = 12;
  s.compaction_passes = 13, s.compaction_bytes = 14;
  s.copy_passes = 15, s.copy_bytes = 16;
  s.gather_passes = 17, s.gather_bytes = 18;
  s.shadow_passes = 19, s.shadow_bytes = 20;
  s.shadow_continued = 21;
  const Json j = host::streams_json(s);
  CHECK(keys(j) == Keys{"levels", "split", "compaction", "copies", "gather", "shadow_glass",
                        "shadow_rays_continued"});
  REQUIRE(j["levels"].size() == 2);
  for (size_t k = 0; k < 2; ++k) {
    const Json& l = j["levels"][k];
    const uint64_t base = 5 * k;
    CHECK(keys(l) == Keys{"rays", "chunks", "reflected", "refracted", "total_internal"});
    CHECK(l["rays"] == base + 1);
    CHECK(l["chunks"] == base + 2);
    CHECK(l["reflected"] == base + 3);
    CHECK(l["refracted"] == base + 4);
    CHECK(l["total_internal"] == base + 5);
  }
  const char* jobs[] = {"split", "compaction", "copies", "gather", "shadow_glass"};
  for (int i = 0; i < 5; ++i) {
    CAPTURE(jobs[i]);
    CHECK(keys(j[jobs[i]]) == Keys{"passes", "bytes"});
    CHECK(j[jobs[i]]["passes"] == 11 + 2 * i);
    CHECK(j[jobs[i]]["bytes"] == 12 + 2 * i);
  }
  CHECK(j["shadow_rays_continued"] == 21);
}

TEST_CASE("the dense streams' writer puts every count under its key") {
  host::CompactStats c;
  c.on = true;
  c.packs = 1, c.frames = 2, c.live_rays = 3, c.slots = 4, c.pixels = 5;
  c.scan_passes = 6, c.scan_bytes = 7;
  c.compaction_passes = 8, c.compaction_bytes = 9;
  c.gather_passes = 10, c.gather_bytes = 11;
  const Json j = host::compact_json(c);
  CHECK(keys(j) ==
        Keys{"packs", "frames", "live_rays", "slots", "pixels", "scan", "compaction", "gather"});
  CHECK(j["packs"] == 1);
  CHECK(j["frames"] == 2);
  CHECK(j["live_rays"] == 3);
  CHECK(j["slots"] == 4);
  CHECK(j["pixels"] == 5);
  const char* jobs[] = {"scan", "compaction", "gather"};
  for (int i = 0; i < 3; ++i) {
    CAPTURE(jobs[i]);
    CHECK(keys(j[jobs[i]]) == Keys{"passes", "bytes"});
    CHECK(j[jobs[i]]["passes"] == 6 + 2 * i);
    CHECK(j[jobs[i]]["bytes"] == 7 + 2 * i);
  }
}

TEST_CASE("a moving scene's frame adds frame, time, animation and update; --frames wraps them") {
  Json frame = {{"scene", "hop"}};
  const Json animation = {{"name", "hop"}, {"index", 0}, {"start", 0.0}, {"end", 2.0}};
  host::add_moving_frame(frame, 2, 0.5, animation, Json{{"mode", "refit"}});
  CHECK(keys(frame) == Keys{"scene", "frame", "time", "animation", "update"});
  CHECK(frame["frame"] == 2);
  CHECK(frame["time"] == 0.5);
  CHECK(frame["animation"] == animation);
  CHECK(frame["update"]["mode"] == "refit");
  const Json doc =
      host::frames_stats_json("hop", "/scenes/hop.gltf", animation, "auto", {frame, frame, frame});
  CHECK(keys(doc) ==
        Keys{"version", "scene", "scene_path", "animation", "update", "frame_count", "frames"});
  CHECK(doc["version"] == host::version());
  CHECK(doc["scene"] == "hop");
  CHECK(doc["scene_path"] == "/scenes/hop.gltf");
  CHECK(doc["animation"] == animation);
  CHECK(doc["update"] == "auto");
  CHECK(doc["frame_count"] == 3);
  CHECK(doc["frames"] == Json{frame, frame, frame});
  CHECK(host::stats_text(doc) == doc.dump(2) + "\n");
}
