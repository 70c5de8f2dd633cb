// Tests for host/accel/bvh (the SAH-binned BVH and its depth-first layout with escape indices):
// the layout's invariants on every bundled scene and on tiny hand-made scenes, checked by
// walking the layout here (children found from the layout rule alone: the left child of inner
// node i is i + 1, the right child is the left child's escape), and a few cases whose nodes are
// known in advance.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "host/accel/accel.h"
#include "host/accel/bvh.h"
#include "host/image/image_io.h"
#include "host/scene/gltf_loader.h"

namespace {

using host::Bvh;
using host::BvhNode;
using host::Scene;

struct Tri {
  glm::vec3 a, b, c;
};

Scene make_scene(const std::vector<Tri>& tris) {
  Scene s;
  for (const Tri& t : tris) s.add_flat_triangle(t.a, t.b, t.c, 0, uint32_t(s.id.size()));
  s.materials.resize(1);
  s.input_triangles = uint32_t(tris.size());
  return s;
}

// n small triangles at random places in [0, 10]^3 (fixed seed).
Scene random_scene(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(0.0f, 10.0f), off(-0.3f, 0.3f);
  std::vector<Tri> tris;
  for (int i = 0; i < n; ++i) {
    const glm::vec3 c(pos(rng), pos(rng), pos(rng));
    tris.push_back({c + glm::vec3(off(rng), off(rng), off(rng)),
                    c + glm::vec3(off(rng), off(rng), off(rng)),
                    c + glm::vec3(off(rng), off(rng), off(rng))});
  }
  return make_scene(tris);
}

bool contains(const BvhNode& outer, const BvhNode& inner) {
  for (int a = 0; a < 3; ++a)
    if (!(outer.lo[a] <= inner.lo[a] && inner.hi[a] <= outer.hi[a])) return false;
  return true;
}

bool contains(const BvhNode& n, const glm::vec3& p) {
  for (int a = 0; a < 3; ++a)
    if (!(n.lo[a] <= p[a] && p[a] <= n.hi[a])) return false;
  return true;
}

bool is_leaf(const BvhNode& n) {
  return n.leaf >= 0;
}

// Every invariant of the layout; `splittable`: no two triangles share a centroid, so the SAH can
// always split a list longer than spec.max_leaf.
void check_invariants(const Scene& s, const Bvh& bvh, const host::BvhSpec& spec, bool splittable) {
  const size_t n = s.triangle_count();
  const int32_t count = int32_t(bvh.nodes.size());
  REQUIRE(count >= 1);
  REQUIRE_FALSE(bvh.lists.empty());
  CHECK(bvh.lists[0] == -1);
  CHECK(size_t(count) == 2 * size_t(bvh.leaves) - 1);
  std::vector<int> seen(n, 0);
  int leaves = 0, max_leaf = 0;
  size_t list_entries = 1;  // lists[0]
  for (int32_t i = 0; i < count; ++i) {
    const BvhNode& node = bvh.nodes[size_t(i)];
    CAPTURE(i);
    // Escapes point forward, or end the walk.
    CHECK((node.escape == -1 || (node.escape > i && node.escape <= count - 1)));
    if (is_leaf(node)) {
      ++leaves;
      max_leaf = std::max(max_leaf, int(node.count));
      CHECK(node.count >= 0);
      REQUIRE(size_t(node.leaf) + size_t(node.count) < bvh.lists.size());
      if (node.count == 0) CHECK(node.leaf == 0);  // the shared empty list
      if (node.count > 0) list_entries += size_t(node.count) + 1;
      for (int32_t k = 0; k < node.count; ++k) {
        const int32_t t = bvh.lists[size_t(node.leaf + k)];
        REQUIRE(t >= 0);
        REQUIRE(size_t(t) < n);
        ++seen[size_t(t)];
        // The leaf's (padded) box holds its triangle's corners.
        CHECK(contains(node, s.p0[size_t(t)]));
        CHECK(contains(node, s.p1[size_t(t)]));
        CHECK(contains(node, s.p2[size_t(t)]));
      }
      CHECK(bvh.lists[size_t(node.leaf + node.count)] == -1);  // closed by -1
    } else {
      CHECK(node.count == 0);
      // Left child i + 1, right child the left's escape; the right's escape is the parent's.
      REQUIRE(i + 1 < count);
      const BvhNode& left = bvh.nodes[size_t(i + 1)];
      REQUIRE(left.escape > i + 1);
      const BvhNode& right = bvh.nodes[size_t(left.escape)];
      CHECK(right.escape == node.escape);
      CHECK(contains(node, left));
      CHECK(contains(node, right));
    }
  }
  CHECK(bvh.nodes[0].escape == -1);
  CHECK(leaves == bvh.leaves);
  CHECK(max_leaf == bvh.max_leaf);
  CHECK(list_entries == bvh.lists.size());  // no stray entries
  CHECK(bvh.references() == n);
  for (size_t t = 0; t < n; ++t) {
    CAPTURE(t);
    CHECK(seen[t] == 1);  // every triangle referenced exactly once
  }
  if (splittable) CHECK(bvh.max_leaf <= spec.max_leaf);
  CHECK(bvh.depth >= 1);
  CHECK(bvh.depth <= 65);
  CHECK(bvh.sah_cost >= 1.0);
}

// The depth-first order: a walk that always enters visits every node once, in index order.
void check_full_walk(const Bvh& bvh) {
  std::vector<int32_t> order;
  for (int32_t i = 0;
       i >= 0 && i < int32_t(bvh.nodes.size()) && order.size() <= bvh.nodes.size();) {
    order.push_back(i);
    i = is_leaf(bvh.nodes[size_t(i)]) ? bvh.nodes[size_t(i)].escape : i + 1;
  }
  REQUIRE(order.size() == bvh.nodes.size());
  for (size_t k = 0; k < order.size(); ++k) CHECK(order[k] == int32_t(k));
}

bool same(const Bvh& a, const Bvh& b) {
  if (a.nodes.size() != b.nodes.size() || a.lists != b.lists || a.depth != b.depth ||
      a.leaves != b.leaves || a.max_leaf != b.max_leaf || a.sah_cost != b.sah_cost)
    return false;
  for (size_t i = 0; i < a.nodes.size(); ++i) {
    const BvhNode &x = a.nodes[i], &y = b.nodes[i];
    if (x.lo != y.lo || x.hi != y.hi || x.escape != y.escape || x.leaf != y.leaf ||
        x.count != y.count)
      return false;
  }
  return true;
}

}  // namespace

TEST_CASE(
    "the BVH of every bundled scene keeps the layout's invariants and builds the same twice" * doctest::test_suite("sweep")) {
  const auto scenes = host::list_scenes();
  REQUIRE(scenes.size() >= 8);
  for (const auto& [bound_name, bound_path] : scenes) {
    // Named copies: clang 14 cannot capture a structured binding (CAPTURE, INFO).
    const auto& name = bound_name;
    const auto& path = bound_path;
    CAPTURE(name);
    const Scene s = host::load_scene(path, host::with_images());
    const Bvh a = host::build_bvh(s), b = host::build_bvh(s);
    // Bundled meshes may hold triangles sharing a centroid: max_leaf checked where it must hold.
    check_invariants(s, a, {}, false);
    CHECK(a.max_leaf <= host::BvhSpec{}.max_leaf);
    check_full_walk(a);
    CHECK(same(a, b));
    CHECK(a.leaves > 1);
  }
}

TEST_CASE("random small scenes keep the invariants for leaf sizes 1, 2, 4 and 8 and 2 to 64 bins") {
  for (int n : {1, 2, 3, 5, 17, 100, 333})
    for (const host::BvhSpec spec :
         {host::BvhSpec{1, 16}, host::BvhSpec{2, 2}, host::BvhSpec{4, 16}, host::BvhSpec{8, 64}}) {
      CAPTURE(n);
      CAPTURE(spec.max_leaf);
      CAPTURE(spec.bins);
      const Scene s = random_scene(n, unsigned(n) * 7u + 1u);
      const Bvh bvh = host::build_bvh(s, spec);
      check_invariants(s, bvh, spec, true);
      check_full_walk(bvh);
      CHECK(same(bvh, host::build_bvh(s, spec)));
    }
}

TEST_CASE("triangles sharing one centroid are halved into leaves of at most max_leaf") {
  // Ten copies of one triangle: no plane separates their centroids, the builder halves lists.
  std::vector<Tri> tris(10, Tri{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const Scene s = make_scene(tris);
  const Bvh bvh = host::build_bvh(s);
  check_invariants(s, bvh, {}, true);
  check_full_walk(bvh);
  CHECK(bvh.max_leaf <= 4);
  CHECK(bvh.leaves >= 3);
}

TEST_CASE("an empty scene gives one empty leaf that ends the walk") {
  const Scene s = make_scene({});
  const Bvh bvh = host::build_bvh(s);
  REQUIRE(bvh.nodes.size() == 1);
  CHECK(bvh.nodes[0].escape == -1);
  CHECK(bvh.nodes[0].leaf == 0);
  CHECK(bvh.nodes[0].count == 0);
  CHECK(bvh.lists == std::vector<int32_t>{-1});
  CHECK(bvh.leaves == 1);
  CHECK(bvh.depth == 1);
  CHECK(bvh.max_leaf == 0);
  CHECK(bvh.references() == 0);
  check_invariants(s, bvh, {}, true);
}

TEST_CASE("one triangle gives one leaf whose box is its own, padded") {
  const Scene s = make_scene({{{0, 0, 0}, {4, 0, 0}, {0, 3, 0}}});
  const Bvh bvh = host::build_bvh(s);
  REQUIRE(bvh.nodes.size() == 1);
  const BvhNode& n = bvh.nodes[0];
  CHECK(n.escape == -1);
  CHECK(n.leaf == 1);
  CHECK(n.count == 1);
  CHECK(bvh.lists == std::vector<int32_t>{-1, 0, -1});
  // Padded by 1e-5 of the scene's diagonal (5) on every side, the flat z axis too.
  const float pad = float(host::kBoxPadOfDiagonal * 5.0);
  CHECK(n.lo == glm::vec3(-pad));
  CHECK(n.hi == glm::vec3(4.0f + pad, 3.0f + pad, pad));
  CHECK(n.lo.z < 0.0f);
  CHECK(n.hi.z > 0.0f);
}

TEST_CASE("two far-apart triangles give a root and two leaves with the expected escapes") {
  // Triangle 0 near x = 100, triangle 1 near the origin: the SAH splits on x (the two leaves'
  // area is far below the root's), the lower centroid going left.
  const Scene s = make_scene({{{100, 0, 0}, {101, 0, 0}, {100, 1, 0}},  //
                              {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}});
  const Bvh bvh = host::build_bvh(s);
  REQUIRE(bvh.nodes.size() == 3);
  const BvhNode &root = bvh.nodes[0], &left = bvh.nodes[1], &right = bvh.nodes[2];
  CHECK(root.leaf == -1);
  CHECK(root.escape == -1);
  CHECK(left.escape == 2);
  CHECK(right.escape == -1);
  CHECK(left.leaf == 1);
  CHECK(left.count == 1);
  CHECK(right.leaf == 3);
  CHECK(right.count == 1);
  CHECK(bvh.lists == std::vector<int32_t>{-1, 1, -1, 0, -1});
  CHECK(bvh.leaves == 2);
  CHECK(bvh.depth == 2);
  CHECK(bvh.max_leaf == 1);
  CHECK(left.hi.x < 2.0f);
  CHECK(right.lo.x > 99.0f);
  check_invariants(s, bvh, {}, true);
}

TEST_CASE(
    "the SAH cost of two far-apart triangles is worked by hand, and grows by the hand-worked "
    "ratio when a refit brings them together") {
  // A leaf of one triangle costs a visit and a test: 2. Unpadded boxes, area 2 (xy + yz + zx):
  // each triangle's [0, 1]^2 x {0}: 2; the root's [0, 101] x [0, 1] x {0}: 202. The root:
  // 1 + (2 x 2 + 2 x 2) / 202 = 1 + 8/202.
  Scene s = make_scene({{{100, 0, 0}, {101, 0, 0}, {100, 1, 0}},  //
                        {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}});
  Bvh bvh = host::build_bvh(s);
  REQUIRE(bvh.nodes.size() == 3);
  CHECK(bvh.sah_cost == doctest::Approx(1.0 + 8.0 / 202.0).epsilon(1e-12));
  // Triangle 0 moved to x = 0.5: the leaves keep their areas, the root's box shrinks to
  // [0, 1.5] x [0, 1]: area 3, cost 1 + 8/3, 3.5 times the build's (past --update auto's 1.25).
  for (auto* p : {&s.p0[0], &s.p1[0], &s.p2[0]}) p->x -= 99.5f;
  host::refit_bvh(bvh, s);
  CHECK(bvh.sah_cost == doctest::Approx(1.0 + 8.0 / 3.0).epsilon(1e-12));
  CHECK(bvh.sah_cost / (1.0 + 8.0 / 202.0) > 3.5);
}

TEST_CASE(
    "--update auto refits while the refitted SAH cost stays within 1.25 times the last build's "
    "and rebuilds past it, as two triangles move through each other") {
  // Triangle 1 stays at [0, 1] x [0, 1] (z = 0); triangle 0, the same shape at [d, d + 1],
  // comes in from d = 100 and passes through it. While the two leaves hold one triangle each
  // (boxes of area 2, cost 2), the root's box is [0, d + 1] x [0, 1] x {0}, of area 2(d + 1),
  // and the tree costs 1 + 8 / (2(d + 1)). Auto compares that with the LAST BUILD's cost (not
  // the last refit's) and rebuilds once it passes kRefitLimit = 1.25 times it.
  REQUIRE(host::BvhAccel::kRefitLimit == 1.25);
  Scene s = make_scene({{{100, 0, 0}, {101, 0, 0}, {100, 1, 0}},  //
                        {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}});
  const auto accel = host::make_accel(host::AccelKind::bvh, s, {});
  auto cost_at = [](double d) { return 1.0 + 8.0 / (2.0 * (d + 1.0)); };
  REQUIRE(accel->bvh() != nullptr);
  CHECK(accel->bvh()->sah_cost == doctest::Approx(cost_at(100)).epsilon(1e-12));  // 1.0396
  double d_now = 100;
  auto move_to = [&](double d) {
    for (auto* p : {&s.p0[0], &s.p1[0], &s.p2[0]}) p->x += float(d - d_now);
    d_now = d;
    return accel->update(s, "auto");
  };
  struct Frame {
    double d;            // triangle 0's left edge
    const char* action;  // what auto must do
    double cost;         // the tree's SAH cost afterwards, by hand
  };
  // Built at d = 100 (1.0396): d = 30: 1.1290, 1.086 times the build's: refit. d = 14: 1.2667,
  // 1.218 times: refit (the ratio is just under the limit). d = 11: 1.3333, 1.2825 times: rebuild
  // (a rule comparing with the last refit's 1.2667 sees 1.053 and refits); the build splits the
  // two again (a split's 1 + 4/24 beats a leaf's 2 tests), at the same cost. d = 9: 1.4, 1.05
  // times the new build's: refit (a rule still comparing with the first build's sees 1.347 and
  // rebuilds). d = 0.5, the triangles overlapping: the refit's root has area 3 and costs
  // 1 + 8/3 = 3.667, 2.75 times the build's: rebuild, and the build now keeps both triangles
  // in one leaf (a split's 1 + 4/3 loses to a leaf's 2): 1 visit + 2 tests = 3.
  const Frame frames[] = {{30, "refit", cost_at(30)},
                          {14, "refit", cost_at(14)},
                          {11, "rebuild", cost_at(11)},
                          {9, "refit", cost_at(9)},
                          {0.5, "rebuild", 3.0}};
  for (const Frame& f : frames) {
    CAPTURE(f.d);
    CHECK(move_to(f.d) == std::string(f.action));
    CHECK(accel->bvh()->sah_cost == doctest::Approx(f.cost).epsilon(1e-6));
    check_invariants(s, *accel->bvh(), {}, false);
  }
  CHECK(accel->bvh()->nodes.size() == 1);  // the last build: one leaf of both triangles
  // The two ratios either side of the limit, from the hand-worked costs.
  CHECK(cost_at(14) / cost_at(100) < 1.25);
  CHECK(cost_at(11) / cost_at(100) > 1.25);
}

TEST_CASE("a refitted BVH keeps every invariant: its boxes hold the moved triangles") {
  for (int n : {2, 17, 333}) {
    CAPTURE(n);
    Scene s = random_scene(n, unsigned(n) * 7u + 1u);
    Bvh bvh = host::build_bvh(s);
    // Refitting an unmoved scene reproduces the build, boxes and cost.
    Bvh same_scene = bvh;
    host::refit_bvh(same_scene, s);
    CHECK(same(same_scene, bvh));
    // Every triangle moved by its own random offset (up to 5 on each axis): the topology stays,
    // the boxes must follow.
    std::mt19937 rng{unsigned(n)};
    std::uniform_real_distribution<float> off(-5.0f, 5.0f);
    for (size_t t = 0; t < s.triangle_count(); ++t) {
      const glm::vec3 d(off(rng), off(rng), off(rng));
      s.p0[t] += d;
      s.p1[t] += d;
      s.p2[t] += d;
    }
    host::refit_bvh(bvh, s);
    check_invariants(s, bvh, {}, true);
    check_full_walk(bvh);
    // The same topology, and no better than a build for the moved scene.
    const Bvh rebuilt = host::build_bvh(s);
    CHECK(bvh.lists == same_scene.lists);
    CHECK(bvh.nodes.size() == same_scene.nodes.size());
    if (n > 2) CHECK(bvh.sah_cost > rebuilt.sah_cost);
  }
}

TEST_CASE("describe names nodes, depth, leaves and the largest leaf") {
  const Scene s = make_scene({{{100, 0, 0}, {101, 0, 0}, {100, 1, 0}},  //
                              {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}});
  CHECK(host::describe(host::build_bvh(s)) ==
        "bvh: 3 nodes, depth 2, 2 leaves of at most 1 triangles");
}

TEST_CASE("acceleration structure names are parsed, and an unknown one is refused naming the set") {
  CHECK(host::parse_accel_kind("grid") == host::AccelKind::grid);
  CHECK(host::parse_accel_kind("bvh") == host::AccelKind::bvh);
  CHECK(host::parse_accel_kind("kdtree") == host::AccelKind::kdtree);
  CHECK(host::accel_name(host::AccelKind::grid) == "grid");
  CHECK(host::accel_name(host::AccelKind::bvh) == "bvh");
  // Only the names it accepts are offered ("auto" is the CLI's, which builds each structure).
  for (const std::string text : {"magic", "auto", "BVH", ""}) {
    CAPTURE(text);
    CHECK_THROWS_WITH_AS(
        host::parse_accel_kind(text),
        ("unknown acceleration structure '" + text + "' (known: grid, grid2, bvh, kdtree)").c_str(),
        std::invalid_argument);
  }
}
