// A bounding volume hierarchy for the stream tracer (an extension: the paper names "bounding
// volumes" as future work). Built on the host with the surface area heuristic over binned
// centroids (Wald 2007), then laid out depth first with, per node, the index to jump to when
// the ray misses it or is done with it (its "escape"): the stackless walk of Thrane & Simonsen
// (2005) that needs no stack and no parent pointer, one node per step.
//
// Node i of the layout:
//   inner node: its left child is node i + 1, its right child follows the left's subtree;
//   leaf:       its triangles are a list in `lists`, closed by -1 (as the grid's voxel lists);
//   escape:     the node after i's subtree in depth-first order, -1 after the last.
// Boxes are padded by kBoxPadOfDiagonal of the scene's diagonal on every side, so that a ray
// grazing a triangle's bounding box in float arithmetic still enters it.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "host/scene/scene.h"

namespace host {

inline constexpr double kBoxPadOfDiagonal = 1e-5;

struct BvhSpec {
  int max_leaf = 4;  // triangles a leaf may hold before the SAH must split it (if it can)
  int bins = 16;     // SAH bins per axis
};

struct BvhNode {
  glm::vec3 lo{0.0f}, hi{0.0f};  // padded box, world space
  int32_t escape = -1;           // next node when this one is missed or done; -1: the walk ends
  int32_t leaf = -1;             // leaf: index of its first list entry in Bvh::lists; inner: -1
  int32_t count = 0;             // leaf: triangles in its list
};

struct Bvh {
  std::vector<BvhNode> nodes;  // depth first; nodes[0] is the root
  std::vector<int32_t> lists;  // lists[0] = -1 (shared by empty leaves); each leaf's closed by -1
  int depth = 0;               // longest root-to-leaf path, in nodes
  int leaves = 0;
  int max_leaf = 0;     // most triangles in one leaf
  double sah_cost = 0;  // expected node visits + triangle tests of a ray hitting the root
  double build_ms = 0;
  uint64_t references() const;  // triangle entries over all leaves
};

// Builds the hierarchy over the scene's triangles (internal ids). Deterministic. An empty scene
// gives one empty leaf.
Bvh build_bvh(const Scene& scene, const BvhSpec& spec = {});

// Refits the hierarchy to the scene's current vertices (the same triangles, moved): every box
// is recomputed bottom up from its triangles (leaves) or children (inner nodes), padded as the
// build pads, keeping the topology, the layout and the lists. Updates sah_cost (which grows as
// the triangles of a node move apart: the refitted tree's quality) and build_ms (the refit's
// time). Throws std::invalid_argument if the scene's triangle count differs from the build's.
void refit_bvh(Bvh& bvh, const Scene& scene);

// "bvh: 12,345 nodes, depth 21, 6,173 leaves of at most 4 triangles"
std::string describe(const Bvh& bvh);

}  // namespace host
