// Tests for host/accel/kdtree (the SAH kd-tree walked by kd-restart): the layout the kernels read
// (depth first, left child i + 1, lists closed by -1), and the invariant the walk's correctness
// rests on: every triangle whose bounding box meets a leaf's box (the root box cut by the split
// planes above the leaf) is in that leaf's list.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "host/accel/grid.h"
#include "host/accel/kdtree.h"
#include "host/image/image_io.h"
#include "host/scene/gltf_loader.h"

namespace {

using host::KdNode;
using host::KdTree;
using host::same_tree;
using host::Scene;

Scene make_scene(const std::vector<std::array<glm::vec3, 3>>& tris) {
  Scene s;
  for (const auto& t : tris) s.add_flat_triangle(t[0], t[1], t[2], 0, uint32_t(s.id.size()));
  s.materials.resize(1);
  s.input_triangles = uint32_t(tris.size());
  return s;
}

// n small random triangles in [0, 10]^3, with a few large ones across the box.
Scene random_scene(unsigned seed, int n) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(0.0f, 10.0f), off(-0.6f, 0.6f), big(-4.0f, 4.0f);
  std::vector<std::array<glm::vec3, 3>> tris;
  for (int i = 0; i < n; ++i) {
    const glm::vec3 c(pos(rng), pos(rng), pos(rng));
    auto& d = i % 25 == 0 ? big : off;
    tris.push_back({c + glm::vec3(d(rng), d(rng), d(rng)), c + glm::vec3(d(rng), d(rng), d(rng)),
                    c + glm::vec3(d(rng), d(rng), d(rng))});
  }
  return make_scene(tris);
}

struct Leaf {
  int node;
  int depth;
  glm::dvec3 lo, hi;
};

// Every leaf with its box, derived from the split planes from the root box down, walking the
// layout as the kernels do (left = i + 1, right = node.right).
std::vector<Leaf> leaves_of(const KdTree& kd) {
  std::vector<Leaf> out;
  struct Item {
    int node, depth;
    glm::dvec3 lo, hi;
  };
  std::vector<Item> stack{{0, 0, glm::dvec3(kd.lo), glm::dvec3(kd.hi)}};
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    if (it.node < 0 || size_t(it.node) >= kd.nodes.size()) FAIL("node " << it.node << " reached");
    const KdNode& n = kd.nodes[size_t(it.node)];
    if (n.axis == 3) {
      out.push_back({it.node, it.depth, it.lo, it.hi});
      continue;
    }
    if (n.axis < 0 || n.axis > 2) FAIL("node " << it.node << ": axis " << n.axis);
    Item l = {it.node + 1, it.depth + 1, it.lo, it.hi}, r = {n.right, it.depth + 1, it.lo, it.hi};
    l.hi[n.axis] = double(n.split);
    r.lo[n.axis] = double(n.split);
    stack.push_back(r);
    stack.push_back(l);
  }
  return out;
}

std::vector<int> list_of(const KdTree& kd, const KdNode& n) {
  std::vector<int> out;
  for (size_t k = size_t(n.leaf); k < kd.lists.size() && kd.lists[k] >= 0; ++k)
    out.push_back(kd.lists[k]);
  return out;
}

// The structural checks: layout, lists, depth, and the overlap invariant.
void check_tree(const Scene& s, const KdTree& kd, int max_depth) {
  REQUIRE_FALSE(kd.nodes.empty());
  REQUIRE_FALSE(kd.lists.empty());
  CHECK(kd.lists[0] == -1);
  // Inner nodes: the right child after the left subtree (at least node i + 1), inside the
  // layout; the plane inside the root box.
  for (size_t i = 0; i < kd.nodes.size(); ++i) {
    const KdNode& n = kd.nodes[i];
    if (n.axis != 3 &&
        !(n.axis >= 0 && n.axis <= 2 && n.right > int(i) + 1 && size_t(n.right) < kd.nodes.size() &&
          n.split > kd.lo[n.axis] && n.split < kd.hi[n.axis]))
      FAIL("inner node " << i << ": axis " << n.axis << ", right " << n.right << ", split "
                         << n.split);
  }
  const std::vector<Leaf> leaves = leaves_of(kd);
  // Every node is reached exactly once from the root: the layout is a tree.
  std::vector<int> seen(kd.nodes.size(), 0);
  CHECK(leaves.size() == size_t(kd.leaves));
  CHECK(2 * leaves.size() - 1 == kd.nodes.size());
  int deepest = 0, empty = 0, longest = 0;
  uint64_t refs = 0;
  size_t missing = 0, extra = 0, bad_ids = 0, twice = 0;
  for (const Leaf& leaf : leaves) {
    ++seen[size_t(leaf.node)];
    deepest = std::max(deepest, leaf.depth);
    const KdNode& n = kd.nodes[size_t(leaf.node)];
    if (n.leaf < 0 || size_t(n.leaf) >= kd.lists.size()) {
      FAIL_CHECK("leaf " << leaf.node << " points past the lists: " << n.leaf);
      continue;
    }
    const std::vector<int> list = list_of(kd, n);
    // Closed by -1 right after its count entries (an empty leaf points at lists[0]).
    const bool closed = size_t(n.leaf) + list.size() < kd.lists.size();
    if (!closed || list.size() != size_t(n.count) || (list.empty() && n.leaf != 0))
      FAIL_CHECK("leaf " << leaf.node << ": list at " << n.leaf << " of " << list.size()
                         << " entries, count " << n.count << (closed ? "" : ", not closed"));
    empty += list.empty();
    longest = std::max(longest, int(list.size()));
    refs += list.size();
    std::vector<char> in(s.triangle_count(), 0);
    for (int t : list) {
      if (t < 0 || size_t(t) >= s.triangle_count()) {
        ++bad_ids;
        continue;
      }
      twice += in[size_t(t)];
      in[size_t(t)] = 1;
    }
    for (size_t t = 0; t < s.triangle_count(); ++t) {
      const glm::dvec3 a(s.p0[t]), b(s.p1[t]), c(s.p2[t]);
      const glm::dvec3 lo = glm::min(a, glm::min(b, c)), hi = glm::max(a, glm::max(b, c));
      bool meets = true;
      for (int ax = 0; ax < 3; ++ax)
        meets = meets && lo[ax] <= leaf.hi[ax] && hi[ax] >= leaf.lo[ax];
      if (meets && !in[t]) ++missing;
      if (!meets && in[t]) ++extra;
    }
  }
  CHECK_MESSAGE(missing == 0, missing << " (leaf, triangle) overlaps missing from the lists");
  CHECK(bad_ids == 0);
  CHECK_MESSAGE(twice == 0, twice << " triangles listed twice in one leaf");
  CHECK_MESSAGE(extra == 0, extra << " listed triangles outside their leaf's box");
  size_t unreached = 0;
  for (size_t i = 0; i < kd.nodes.size(); ++i) unreached += kd.nodes[i].axis == 3 && seen[i] != 1;
  CHECK(unreached == 0);
  CHECK(deepest <= max_depth);
  CHECK(kd.depth == deepest + 1);  // levels: the root alone is depth 1
  CHECK(kd.empty_leaves == empty);
  CHECK(kd.max_leaf == longest);
  CHECK(kd.references() == refs);
}

// Havran's rule, written out: 8 + 1.3 log2(triangles), rounded.
int default_max_depth(size_t triangles) {
  return int(std::lround(8.0 + 1.3 * std::log2(double(std::max<size_t>(triangles, 1)))));
}

}  // namespace

TEST_CASE(
    "every triangle whose box meets a kd leaf's box is in that leaf's list, on random scenes") {
  for (unsigned seed : {1u, 2u, 3u}) {
    CAPTURE(seed);
    const Scene s = random_scene(seed, 300);
    const KdTree kd = host::build_kdtree(s, glm::vec3(-4.5f), glm::vec3(14.5f));
    CHECK(kd.leaves > 20);  // the SAH did split
    check_tree(s, kd, default_max_depth(s.triangle_count()));
  }
}

TEST_CASE("every bundled scene's kd-tree lists each triangle in every leaf its box meets" * doctest::test_suite("sweep")) {
  const auto scenes = host::list_scenes();
  REQUIRE(scenes.size() >= 8);
  for (const auto& [bound_name, bound_path] : scenes) {
    // Named copies: clang 14 cannot capture a structured binding (CAPTURE, INFO).
    const auto& name = bound_name;
    const auto& path = bound_path;
    CAPTURE(std::string(name));
    const Scene s = host::load_scene(path, host::with_images());
    const host::Grid box = host::build_grid(s, host::GridSpec{glm::ivec3(1)});
    const KdTree kd = host::build_kdtree(s, box.lo, box.hi);
    CHECK(kd.leaves > 1);
    check_tree(s, kd, default_max_depth(s.triangle_count()));
  }
}

TEST_CASE("a kd-tree never grows deeper than the maximum depth it is given") {
  const Scene s = random_scene(7, 400);
  for (int depth : {1, 3, 6}) {
    CAPTURE(depth);
    host::KdSpec spec;
    spec.max_depth = depth;
    const KdTree kd = host::build_kdtree(s, glm::vec3(-4.5f), glm::vec3(14.5f), spec);
    CHECK(kd.depth == depth + 1);  // 400 triangles: the SAH wants to go deeper everywhere
    check_tree(s, kd, depth);
  }
}

TEST_CASE("the kd-tree build is deterministic") {
  const Scene s = random_scene(11, 300);
  const KdTree a = host::build_kdtree(s, glm::vec3(-4.5f), glm::vec3(14.5f));
  const KdTree b = host::build_kdtree(s, glm::vec3(-4.5f), glm::vec3(14.5f));
  CHECK(same_tree(a, b));
  const Scene bunny = host::load_scene(host::resolve_scene("bunny-low"));
  const host::Grid box = host::build_grid(bunny, host::GridSpec{glm::ivec3(1)});
  CHECK(same_tree(host::build_kdtree(bunny, box.lo, box.hi),
                  host::build_kdtree(bunny, box.lo, box.hi)));
}

TEST_CASE("the kd-tree from events sorted once is the tree that sorts every node's, to the bit") {
  auto both = [](const Scene& s, glm::vec3 lo, glm::vec3 hi, host::KdSpec spec = {}) {
    spec.events = host::KdEvents::presorted;
    const KdTree fast = host::build_kdtree(s, lo, hi, spec);
    spec.events = host::KdEvents::per_node;
    const KdTree reference = host::build_kdtree(s, lo, hi, spec);
    CHECK(fast.nodes.size() > 1);
    CHECK(same_tree(fast, reference));
    CHECK(fast.empty_leaves == reference.empty_leaves);
    CHECK(fast.max_leaf == reference.max_leaf);
  };
  for (unsigned seed : {1u, 5u, 9u}) {
    CAPTURE(seed);
    both(random_scene(seed, 300), glm::vec3(-4.5f), glm::vec3(14.5f));
  }
  // Triangles sharing box ends (a grid of axis-aligned quads): many events at one position.
  std::vector<std::array<glm::vec3, 3>> quads;
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j) {
      const glm::vec3 o(float(i), float(j), float((i + j) % 3));
      quads.push_back({o, o + glm::vec3(1, 0, 0), o + glm::vec3(0, 1, 0)});
      quads.push_back({o + glm::vec3(1, 0, 0), o + glm::vec3(1, 1, 0), o + glm::vec3(0, 1, 0)});
    }
  const Scene tiles = make_scene(quads);
  both(tiles, glm::vec3(-0.5f), glm::vec3(13.5f));
  host::KdSpec shallow;
  shallow.max_depth = 4;
  both(tiles, glm::vec3(-0.5f), glm::vec3(13.5f), shallow);
  // Many boxes in x in [-1.5, -0.5] and a few starting at x = -0 or +0: the SAH cuts at x = 0,
  // duplicating the few; one sign stored whichever of their events a sort puts first.
  std::vector<std::array<glm::vec3, 3>> signed_zero;
  for (int i = 0; i < 48; ++i) {
    const float y = float(i % 8), z = float(i / 8 % 6);
    if (i % 6 == 0) {
      const float x0 = i % 12 ? -0.0f : 0.0f;
      signed_zero.push_back(
          {glm::vec3(x0, y, z), glm::vec3(1.0f, y + 0.5f, z), glm::vec3(1.0f, y, z + 0.5f)});
    } else {
      signed_zero.push_back({glm::vec3(-1.5f, y, z), glm::vec3(-0.5f, y + 0.5f, z),
                             glm::vec3(-0.5f, y, z + 0.5f)});
    }
  }
  const Scene zeros = make_scene(signed_zero);
  both(zeros, glm::vec3(-1.5f), glm::vec3(8.5f));
  const KdTree split_at_zero = host::build_kdtree(zeros, glm::vec3(-1.5f), glm::vec3(8.5f));
  CHECK(std::any_of(split_at_zero.nodes.begin(), split_at_zero.nodes.end(),
                    [](const KdNode& n) { return n.axis == 0 && n.split == 0.0f; }));
  CHECK(std::none_of(split_at_zero.nodes.begin(), split_at_zero.nodes.end(),
                     [](const KdNode& n) { return n.axis < 3 && std::signbit(n.split); }));
  for (const char* name : {"bunny-low", "teapot"}) {
    CAPTURE(std::string(name));
    const Scene s = host::load_scene(host::resolve_scene(name));
    const host::Grid box = host::build_grid(s, host::GridSpec{glm::ivec3(1)});
    both(s, box.lo, box.hi);
  }
}

TEST_CASE("a kd-tree over a vertex that is not finite is refused, naming its triangle") {
  std::vector<std::array<glm::vec3, 3>> tris = {
      {glm::vec3(0, 0, 0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0)},
      {glm::vec3(2, 0, 0), glm::vec3(3, std::nanf(""), 0), glm::vec3(2, 1, 0)}};
  const Scene s = make_scene(tris);
  CHECK_THROWS_WITH_AS(host::build_kdtree(s, glm::vec3(-1.0f), glm::vec3(4.0f)),
                       "kd-tree: triangle 1 has a vertex that is not finite",
                       std::invalid_argument);
}

TEST_CASE("an empty scene's kd-tree is one empty leaf pointing at the shared empty list") {
  const Scene s;
  const KdTree kd = host::build_kdtree(s, glm::vec3(0.0f), glm::vec3(1.0f));
  REQUIRE(kd.nodes.size() == 1);
  CHECK(kd.nodes[0].axis == 3);
  CHECK(kd.nodes[0].leaf == 0);
  CHECK(kd.nodes[0].count == 0);
  CHECK(kd.lists == std::vector<int32_t>{-1});
  CHECK(kd.leaves == 1);
  CHECK(kd.empty_leaves == 1);
  CHECK(kd.depth == 1);
  CHECK(kd.max_leaf == 0);
  CHECK(kd.references() == 0);
}

TEST_CASE("two clusters far apart along x are split on x between them") {
  // Two clusters of 8 small triangles each, one in x in [0, 1], the other in [9, 10], both in
  // y, z in [0, 1]; box [-0.5, 10.5] x [-0.5, 1.5]^2. The root's cheapest plane is a face of one
  // cluster's boxes on x, in [1, 9]; below it every triangle of the first cluster, above it
  // every one of the second (a cluster's triangles touching the plane go to both sides).
  std::vector<std::array<glm::vec3, 3>> tris;
  for (float x0 : {0.0f, 9.0f})
    for (int k = 0; k < 8; ++k) {
      const float x = x0 + 0.125f * float(k);
      tris.push_back({glm::vec3(x, 0, 0), glm::vec3(x + 0.125f, 1, 0), glm::vec3(x, 0, 1)});
    }
  const Scene s = make_scene(tris);
  const KdTree kd = host::build_kdtree(s, glm::vec3(-0.5f), glm::vec3(10.5f, 1.5f, 1.5f));
  REQUIRE(kd.nodes.size() >= 3);
  const KdNode& root = kd.nodes[0];
  CHECK(root.axis == 0);
  CHECK(root.split >= 1.0f);
  CHECK(root.split <= 9.0f);
  // Which triangles lie on each side of the root: every leaf under the left child lists only
  // the first cluster, every leaf under the right only the second (with the plane's toucher).
  check_tree(s, kd, default_max_depth(s.triangle_count()));
  for (const Leaf& leaf : leaves_of(kd)) {
    const bool left = leaf.hi.x <= double(root.split);
    for (int t : list_of(kd, kd.nodes[size_t(leaf.node)])) {
      CAPTURE(t);
      CAPTURE(leaf.node);
      const bool first = t < 8;
      if (left) CHECK(first);
      if (!left && first) CHECK(s.p1[size_t(t)].x >= root.split);  // touches the plane
    }
  }
}

TEST_CASE("two triangles far apart along x stay one leaf: each candidate plane touches one box") {
  // A documented limit of the build, not a wish: candidate planes are the triangles' box faces
  // and a box touching a plane goes to both sides, so with one triangle at x in [0, 1] and one
  // at [9, 10] every plane keeps one of them on both sides. Box [-0.5, 10.5] x [-0.5, 1.5]^2,
  // area(w) = 8 w + 8: the best plane (x = 1 or x = 9) costs 1 + 1.5 (20 * 1 + 84 * 2) / 96 =
  // 3.94 against the leaf's 1.5 * 2 = 3.
  const Scene s = make_scene({{glm::vec3(0, 0, 0), glm::vec3(1, 1, 0), glm::vec3(0, 0, 1)},
                              {glm::vec3(9, 0, 0), glm::vec3(10, 1, 0), glm::vec3(9, 0, 1)}});
  const KdTree kd = host::build_kdtree(s, glm::vec3(-0.5f), glm::vec3(10.5f, 1.5f, 1.5f));
  REQUIRE(kd.nodes.size() == 1);
  CHECK(kd.nodes[0].axis == 3);
  CHECK(kd.nodes[0].count == 2);
  CHECK(kd.sah_cost == doctest::Approx(3.0));
  CHECK(kd.lists == std::vector<int32_t>{-1, 0, 1, -1});
}
