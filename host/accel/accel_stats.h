// What each acceleration structure tells of itself after its build: its own statistics, as
// plain fields (Accel::stats() hands them up; the report room writes them as the statistics'
// "accel" object, host/report/stats_json.h, and docs/cli.md describes the keys).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <variant>

namespace host {

// The paper's uniform grid.
struct GridStats {
  glm::ivec3 voxels{0};     // voxels per axis
  uint64_t references = 0;  // (voxel, triangle) pairs
  double build_ms = 0;
};

// The two-level grid.
struct Grid2Stats {
  glm::ivec3 coarse{0};       // the coarse grid's voxels per axis
  int crowded_cells = 0;      // coarse cells with a sub-grid of more than one cell
  uint64_t sub_cells = 0;     // cells of every sub-grid
  uint64_t list_entries = 0;  // entries of the triangle lists
  uint64_t references = 0;    // (sub-cell, triangle) pairs
  int max_list = 0;           // longest sub-cell list
  double build_ms = 0;
};

// The BVH.
struct BvhStats {
  uint64_t nodes = 0;
  int leaves = 0;
  int depth = 0;            // longest root-to-leaf path, in nodes
  int max_leaf = 0;         // most triangles in one leaf
  uint64_t references = 0;  // triangle entries over all leaves
  double sah_cost = 0;      // expected node visits + triangle tests of a ray hitting the root
  double build_ms = 0;
};

// The kd-tree.
struct KdTreeStats {
  uint64_t nodes = 0;
  int leaves = 0;
  int empty_leaves = 0;
  int depth = 0;
  int max_leaf = 0;
  uint64_t references = 0;
  double sah_cost = 0;
  double build_ms = 0;
};

// One structure's statistics: the alternative of its kind.
using AccelStats = std::variant<GridStats, Grid2Stats, BvhStats, KdTreeStats>;

}  // namespace host
