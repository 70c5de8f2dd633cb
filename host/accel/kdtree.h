// A kd-tree for the stream tracer (an extension: "adaptive subdivision" in the paper's future
// work), walked by kd-restart (Foley & Sugerman, "KD-Tree Acceleration Structures for a GPU
// Raytracer", Graphics Hardware 2005): no stack; a ray descends from the root to the first leaf
// its segment [tmin, tmax] reaches, tests that leaf's triangles (a hit counts only inside the
// leaf's segment), and if none is hit restarts from the root with tmin moved to the leaf's exit.
// Built on the host with the surface area heuristic over the triangles' bounding boxes clipped
// to each node (Wald & Havran 2006's events: sorted once, each node's taken in order from its
// parent's, KdEvents); a triangle overlapping both sides of a plane goes to both.
//
// Node i of the layout, depth first:
//   inner node: axis 0, 1 or 2 and the split position; its left child (below the plane) is node
//               i + 1, its right child `right`;
//   leaf:       axis 3; its triangles are a list in `lists`, closed by -1 (lists[0] = -1 is the
//               empty leaves' list).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "host/scene/scene.h"

namespace host {

// How a node finds its events in order: `presorted` sorts the triangles' box ends once per axis
// at the root and hands each child its parent's lists filtered, work linear in each node's
// triangles after that one sort; `per_node` sorts each node's events again (a log factor more),
// the reference the tests hold the other to. Both build the same tree, to the bit.
enum class KdEvents { presorted, per_node };

struct KdSpec {
  double node_cost = 1.0;      // SAH: a node step (about two passes of the multipass walk)
  double triangle_cost = 1.5;  // SAH: a triangle test (about three: test, next entry, query)
  double empty_bonus = 0.2;    // SAH: a split with an empty side costs this much less
  int max_depth = 0;           // 0: 8 + 1.3 log2(triangles), Havran's rule of thumb
  KdEvents events = KdEvents::presorted;
};

struct KdNode {
  float split = 0;
  int32_t axis = 3;    // 0, 1, 2; 3 for a leaf
  int32_t right = -1;  // inner: index of the right child
  int32_t leaf = 0;    // leaf: index of its first list entry in KdTree::lists
  int32_t count = 0;   // leaf: triangles in its list
};

struct KdTree {
  glm::vec3 lo{0.0f}, hi{0.0f};  // the root's box: the padded scene box (Scene::box)
  std::vector<KdNode> nodes;     // depth first; nodes[0] is the root
  std::vector<int32_t> lists;    // lists[0] = -1; each leaf's list closed by -1
  int depth = 0, leaves = 0, empty_leaves = 0, max_leaf = 0;
  double sah_cost = 0;
  double build_ms = 0;
  uint64_t references() const;
};

// Builds the tree inside the box [lo, hi] (the padded scene box, Scene::box). Deterministic.
// Throws std::invalid_argument for a vertex that is not finite (the glTF loader refuses those
// first; a scene built in code may not).
KdTree build_kdtree(const Scene& scene, glm::vec3 lo, glm::vec3 hi, const KdSpec& spec = {});

// Whether two trees are the same: every node's fields (a split's bits: -0 and +0 differ), the
// lists, the depth, leaf counts and SAH cost (build_ms aside).
bool same_tree(const KdTree& a, const KdTree& b);

// "kd-tree: 12,345 nodes, depth 21, 6,173 leaves (1,020 empty) of at most 9 triangles"
std::string describe(const KdTree& kd);

}  // namespace host
