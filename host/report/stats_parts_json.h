// The statistics JSON's objects that other rooms hand up as typed structs: each writer puts one
// struct's fields under the keys docs/cli.md ("The statistics JSON") gives, in that order. The
// rooms count (host/accel: AccelStats; host/model: Formats; host/trace: StreamStats,
// CompactStats); only the report room writes JSON (frame_stats_json, stats_json.h, assembles
// these with the rest of a frame's object).
#pragma once

#include <nlohmann/json.hpp>

#include "host/accel/accel_stats.h"
#include "host/model/formats.h"
#include "host/trace/render_options.h"

namespace host {

// The structure's own fields of the "accel" object (what follows "structure"): grid {voxels,
// references, build_ms}; grid2 {coarse, crowded_cells, sub_cells, list_entries, references,
// max_list, build_ms}; bvh {nodes, leaves, depth, max_leaf, references, sah_cost, build_ms};
// kdtree {nodes, leaves, empty_leaves, depth, max_leaf, references, sah_cost, build_ms}.
nlohmann::ordered_json accel_stats_json(const AccelStats& s);

// "formats": {"rays": {"texels": "fp32", "arithmetic": "fp32", "why": "..."}, ...}, one entry
// per group in kGroups' order.
nlohmann::ordered_json formats_json(const Formats& f);

// "streams" (glass's ray streams): {levels [{rays, chunks, reflected, refracted,
// total_internal}], split, compaction, copies, gather, shadow_glass (each {passes, bytes}),
// shadow_rays_continued}.
nlohmann::ordered_json streams_json(const StreamStats& s);

// "compact" (the sampling modes' dense streams): {packs, frames, live_rays, slots, pixels, scan,
// compaction, gather (each {passes, bytes})}.
nlohmann::ordered_json compact_json(const CompactStats& s);

}  // namespace host
