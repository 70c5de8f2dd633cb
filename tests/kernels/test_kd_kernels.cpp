// Kernel tests for the kd-tree walk (kernels/kdtree.h, kd-restart): inicioKd, recorridoKd,
// interseccionesKd, the fused --mrt on forms and the looping kernel with push-down, each run as
// real passes on a hand-made tree. Expected values are worked out by hand in the comments.
//
// The tree, in the box [0, 4]^3 (node texel: split, axis or 3 for a leaf, right child, list
// start or -1), 3 texels wide so nodes 3 to 5 sit on the second row:
//   0: x = 2, right 2       (left child 1)
//   1: leaf, list at 1: {triangle 0}
//   2: y = 2, right 4       (left child 3)
//   3: leaf, empty (list 0)
//   4: leaf, list at 3: {triangle 1}
//   5: z = 3, right 7       (left child 6; nodes 5 to 7 are only stepped from, in KdStep)
// Triangle 0 lies in the plane x = 1 over y, z in [0, 4]; triangle 1 in the plane y = 3 over
// x in [2, 6], z in [0, 4].
#include <array>
#include <iterator>
#include <utility>
#include <vector>

#include "kernel_pass.h"

namespace {

using kernels::kFar;
using kernels::kNone;
using ktest::any_w_at_least;
using ktest::any_x_at_least;
using ktest::check_same;
using ktest::scalars;
using ktest::texels;
using ktest::Texture;
using ktest::vec3s;

const std::vector<glm::vec4> kNodes = {{2, 0, 2, kNone}, {0, 3, kNone, 1}, {2, 1, 4, kNone},
                                       {0, 3, kNone, 0}, {0, 3, kNone, 3}, {3, 2, 7, kNone},
                                       {0, 3, kNone, 0}, {0, 3, kNone, 0}};
const std::vector<float> kLists = {kNone, 0, kNone, 1, kNone};

kernels::KdUniforms kd_uniforms(float t_slack = 0) {
  kernels::KdUniforms u;
  u.lo = glm::vec3(0.0f);
  u.hi = glm::vec3(4.0f);
  u.node_width = 3;
  u.list_width = 4;
  u.t_slack = t_slack;
  return u;
}

struct Tree {
  Texture nodes = texels("kd nodes", 3, 3, kNodes);
  Texture lists = scalars("kd lists", 4, 2, kLists);
  Texture v0 = vec3s("vertices0", 1, 2, {{1, 0, 0}, {2, 3, 0}});
  Texture v1 = vec3s("vertices1", 1, 2, {{1, 4, 0}, {6, 3, 0}});
  Texture v2 = vec3s("vertices2", 1, 2, {{1, 0, 4}, {2, 3, 4}});
};

// Rays in one row: origin (xyz) and direction with tmax (w).
struct Rays {
  Texture origins, rays;
  int n;
  Rays(const std::vector<glm::vec3>& o, const std::vector<glm::vec4>& d) : n(int(o.size())) {
    std::vector<glm::vec4> o4;
    for (const glm::vec3& p : o) o4.emplace_back(p, 0.0f);
    origins = texels("origins", n, 1, o4);
    rays = texels("rays", n, 1, d);
  }
};

const glm::vec4 kNoHit(kFar, 0, 0, kNone);
const glm::vec4 kDone(kNone, kNone, 0, 0);

}  // namespace

TEST_CASE("kd enter gives the root and the segment inside the box, or ends the ray") {
  const Rays r({{1, 1, 1}, {-1, 1, 1}, {-1, 5, 1}, {-1, 1, 1}, {1, 1, 1}, {1, 1, 1}, {1, 5, 1}},
               {{1, 0, 0, 100},    // inside: [0, 3]
                {1, 0, 0, 100},    // outside, entering at x = 0: [1, 5]
                {1, 0, 0, 100},    // outside, passing above the box: done
                {-1, 0, 0, 100},   // outside, pointing away: done
                {1, 0, 0, 2},      // inside, tmax before the exit: [0, 2]
                {1, 0, 0, kNone},  // a dead ray (w < 0): done
                {1, 0, 0, 100}});  // parallel to y, outside the y slab: done
  kernels::KdEnter k;
  k.kd = kd_uniforms();
  const Texture out = ktest::run(k, {&r.origins, &r.rays}, r.n, 1, glm::vec4(7));
  CHECK_TEXEL(out, 0, 0, glm::vec4(0, kNone, 0, 3));
  CHECK_TEXEL(out, 1, 0, glm::vec4(0, kNone, 1, 5));
  CHECK_TEXEL(out, 2, 0, kDone);
  CHECK_TEXEL(out, 3, 0, kDone);
  CHECK_TEXEL(out, 4, 0, glm::vec4(0, kNone, 0, 2));
  CHECK_TEXEL(out, 5, 0, kDone);
  CHECK_TEXEL(out, 6, 0, kDone);
}

TEST_CASE("kd step sends a ray at an inner node to the child its segment starts in") {
  // Root: x = 2. Each ray's expected next traversal texel (node, -1, tmin, tmax) by hand.
  const Tree t;
  const Rays r({{0.5f, 1, 1},   // 0: +x, ts = 1.5 inside [0, 3.5]: left, tmax cut to 1.5
                {0.5f, 1, 1},   // 1: +x, segment [0, 1]: the plane lies beyond tmax: left only
                {3, 1, 1},      // 2: +x from x = 3, ts = -1 behind the origin: right only
                {0.5f, 1, 1},   // 3: +x, segment [2, 3.5]: the plane before tmin: right only
                {3.5f, 1, 1},   // 4: -x from x = 3.5, ts = 1.5: near is right, tmax cut to 1.5
                {2, 1, 1},      // 5: origin on the plane, +x (ts = 0): right only
                {2, 1, 1},      // 6: origin on the plane, -x (ts = -0): left only
                {0.5f, 0, 1},   // 7: +y, parallel to the plane (d.x = 0), x < 2: left only
                {3, 0, 1},      // 8: +y, parallel, x > 2: right only
                {1, 1, 0.5f},   // 9: node 5 (z = 3), +z, ts = 2.5: left (6), tmax 2.5
                {1, 1, 3.5f},   // 10: node 5, -z, ts = 0.5: right (7), tmax 0.5
                {1, 1, 0.5f}},  // 11: node 5, +z, segment [2.5, 3.5]: the plane at tmin: right
               {{1, 0, 0, 100},
                {1, 0, 0, 100},
                {1, 0, 0, 100},
                {1, 0, 0, 100},
                {-1, 0, 0, 100},
                {1, 0, 0, 100},
                {-1, 0, 0, 100},
                {0, 1, 0, 100},
                {0, 1, 0, 100},
                {0, 0, 1, 100},
                {0, 0, -1, 100},
                {0, 0, 1, 100}});
  const Texture trav = texels("traversal", r.n, 1,
                              {{0, kNone, 0, 3.5f},
                               {0, kNone, 0, 1},
                               {0, kNone, 0, 1},
                               {0, kNone, 2, 3.5f},
                               {0, kNone, 0, 3.5f},
                               {0, kNone, 0, 2},
                               {0, kNone, 0, 2},
                               {0, kNone, 0, 4},
                               {0, kNone, 0, 4},
                               {5, kNone, 0, 3.5f},
                               {5, kNone, 0, 3.5f},
                               {5, kNone, 2.5f, 3.5f}});
  const Texture isect = texels("intersection", r.n, 1, std::vector<glm::vec4>(12, kNoHit));
  kernels::KdStep k;
  k.kd = kd_uniforms();
  const Texture out = ktest::run(k, {&r.origins, &r.rays, &trav, &isect, &t.nodes}, r.n, 1);
  CHECK_TEXEL(out, 0, 0, glm::vec4(1, kNone, 0, 1.5f));
  CHECK_TEXEL(out, 1, 0, glm::vec4(1, kNone, 0, 1));
  CHECK_TEXEL(out, 2, 0, glm::vec4(2, kNone, 0, 1));
  CHECK_TEXEL(out, 3, 0, glm::vec4(2, kNone, 2, 3.5f));
  CHECK_TEXEL(out, 4, 0, glm::vec4(2, kNone, 0, 1.5f));
  CHECK_TEXEL(out, 5, 0, glm::vec4(2, kNone, 0, 2));
  CHECK_TEXEL(out, 6, 0, glm::vec4(1, kNone, 0, 2));
  CHECK_TEXEL(out, 7, 0, glm::vec4(1, kNone, 0, 4));
  CHECK_TEXEL(out, 8, 0, glm::vec4(2, kNone, 0, 4));
  CHECK_TEXEL(out, 9, 0, glm::vec4(6, kNone, 0, 2.5f));
  CHECK_TEXEL(out, 10, 0, glm::vec4(7, kNone, 0, 0.5f));
  CHECK_TEXEL(out, 11, 0, glm::vec4(7, kNone, 2.5f, 3.5f));
}

TEST_CASE(
    "kd step at a leaf hands it to the load, then ends the ray or restarts it past the leaf") {
  const Tree t;
  // All rays from (0.5, 1, 1) along +x (box exit at t = 3.5) unless told.
  const Rays r({{0.5f, 1, 1},
                {0.5f, 1, 1},
                {0.5f, 1, 1},
                {0.5f, 1, 1},
                {0.5f, 1, 1},
                {0.5f, 1, 1},
                {0.5f, 1, 1},
                {0.5f, 1, 1}},
               {{1, 0, 0, 100},
                {1, 0, 0, 100},
                {1, 0, 0, 100},
                {1, 0, 0, 100},
                {1, 0, 0, 100},
                {1, 0, 0, 2},  // tmax 2 before the box exit
                {1, 0, 0, 2},
                {1, 0, 0, 100}});
  const Texture trav = texels("traversal", r.n, 1,
                              {{1, kNone, 0, 1.5f},     // 0: leaf 1 reached: y = its list, 1
                               {3, kNone, 1.5f, 3.5f},  // 1: empty leaf 3 reached: y = 0
                               {1, 1, 0, 1.5f},         // 2: leaf 1 tested with a hit: done
                               {1, 1, 0, 1.5f},         // 3: tested, no hit: restart [1.5, 3.5]
                               {4, 3, 1.5f, 3.5f},      // 4: tested, at the box exit: done
                               {1, 1, 0, 1.5f},         // 5: no hit, tmax 2: restart [1.5, 2]
                               {4, 3, 1.5f, 2},         // 6: tested up to the ray's tmax: done
                               {kNone, 5, 6, 7}});      // 7: done: untouched
  const Texture isect = texels("intersection", r.n, 1,
                               {kNoHit,
                                kNoHit,
                                {0.5f, 0.25f, 0.125f, 0},
                                kNoHit,
                                kNoHit,
                                kNoHit,
                                kNoHit,
                                {0.5f, 0.25f, 0.125f, 0}});
  kernels::KdStep k;
  k.kd = kd_uniforms();
  const Texture out = ktest::run(k, {&r.origins, &r.rays, &trav, &isect, &t.nodes}, r.n, 1);
  CHECK_TEXEL(out, 0, 0, glm::vec4(1, 1, 0, 1.5f));
  CHECK_TEXEL(out, 1, 0, glm::vec4(3, 0, 1.5f, 3.5f));
  CHECK_TEXEL(out, 2, 0, kDone);
  CHECK_TEXEL(out, 3, 0, glm::vec4(0, kNone, 1.5f, 3.5f));
  CHECK_TEXEL(out, 4, 0, kDone);
  CHECK_TEXEL(out, 5, 0, glm::vec4(0, kNone, 1.5f, 2));
  CHECK_TEXEL(out, 6, 0, kDone);
  CHECK_TEXEL(out, 7, 0, glm::vec4(kNone, 5, 6, 7));
}

TEST_CASE("kd intersections keeps the nearest hit inside the leaf's segment widened by the slack") {
  // Triangle 0 (x = 1); rays from (0, 1, 0.5) along +x meet it at t = 1 with u = 1/4 (weight of
  // corner 1, y / 4) and v = 1/8 (corner 2, z / 4). t_slack = 0.001.
  const Tree t;
  const int n = 8;
  const Rays r(std::vector<glm::vec3>(n, {0, 1, 0.5f}),
               {{1, 0, 0, 100},
                {1, 0, 0, 100},
                {1, 0, 0, 100},
                {1, 0, 0, 100},
                {1, 0, 0, 100},
                {1, 0, 0, 100},
                {1, 0, 0, 100},
                {1, 0, 0, 0.9f}});  // the hit lies past the ray's tmax
  const Texture trav = texels("traversal", n, 1,
                              {{1, 1, 0, 1},        // 0: t at tmax: taken
                               {1, 1, 0, 0.9995f},  // 1: within the slack past tmax: taken
                               {1, 1, 0, 0.998f},   // 2: past tmax + slack: kept out
                               {1, 1, 1.0005f, 3},  // 3: within the slack before tmin: taken
                               {1, 1, 1.002f, 3},   // 4: before tmin - slack: kept out
                               {1, 1, 0, 2},        // 5: a nearer hit already: kept
                               {1, 1, 0, 2},        // 6: nothing to test (vs.w = -1)
                               {1, 1, 0, 2}});      // 7: beyond the ray's tmax
  const Texture vs = texels("voxel state", n, 1,
                            {{1, 0, 0, 0},
                             {1, 0, 0, 0},
                             {1, 0, 0, 0},
                             {1, 0, 0, 0},
                             {1, 0, 0, 0},
                             {1, 0, 0, 0},
                             {2, 0, 0, kNone},
                             {1, 0, 0, 0}});
  const glm::vec4 nearer(0.75f, 0.5f, 0.5f, 9);
  const Texture isect = texels("intersection", n, 1,
                               {kNoHit, kNoHit, kNoHit, kNoHit, kNoHit, nearer, kNoHit, kNoHit});
  kernels::KdIntersections k;
  k.kd = kd_uniforms(0.001f);
  k.scene.width = 1;
  const Texture out =
      ktest::run(k, {&r.origins, &r.rays, &trav, &vs, &isect, &t.v0, &t.v1, &t.v2}, n, 1);
  const glm::vec4 hit(1, 0.25f, 0.125f, 0);
  CHECK_TEXEL_NEAR(out, 0, 0, 1e-6, hit);
  CHECK_TEXEL_NEAR(out, 1, 0, 1e-6, hit);
  CHECK_TEXEL(out, 2, 0, kNoHit);
  CHECK_TEXEL_NEAR(out, 3, 0, 1e-6, hit);
  CHECK_TEXEL(out, 4, 0, kNoHit);
  CHECK_TEXEL(out, 5, 0, nearer);
  CHECK_TEXEL(out, 6, 0, kNoHit);
  CHECK_TEXEL(out, 7, 0, kNoHit);
}

namespace {

// Every ray of the walk tests: A (+y from (3, 0.5, 1): right at the root without a cut, cut at
// y = 2 into the empty leaf 3, restart, leaf 4: triangle 1 at t = 2.5, u = v = 1/4); B (+x from
// (0.5, 1, 0.5): leaf 1, triangle 0 at t = 0.5, u = 1/4, v = 1/8); C (-x from (3.5, 1, 1):
// right, cut at x = 2, the empty leaf 3, restart, leaf 1: triangle 0 at t = 2.5, u = v = 1/4);
// D (+z from (3, 3.5, 1): leaf 4, parallel to triangle 1: no hit); E (done before the walk).
struct Walk {
  Tree t;
  Rays r;
  Texture trav, vs, isect;
  Walk()
      : Walk(Rays{
            {{3, 0.5f, 1}, {0.5f, 1, 0.5f}, {3.5f, 1, 1}, {3, 3.5f, 1}, {1, 1, 1}},
            {{0, 1, 0, 100}, {1, 0, 0, 100}, {-1, 0, 0, 100}, {0, 0, 1, 100}, {1, 0, 0, -1}}}) {}
  explicit Walk(Rays rays)
      : r(std::move(rays)),
        vs(texels("voxel state", r.n, 1, std::vector<glm::vec4>(size_t(r.n), {0, 0, 0, kNone}))),
        isect(texels("intersection", r.n, 1, std::vector<glm::vec4>(size_t(r.n), kNoHit))) {
    kernels::KdEnter k;
    k.kd = kd_uniforms();
    trav = ktest::run(k, {&r.origins, &r.rays}, r.n, 1);
  }
};

const glm::vec4 kHitA(2.5f, 0.25f, 0.25f, 1), kHitB(0.5f, 0.25f, 0.125f, 0),
    kHitC(2.5f, 0.25f, 0.25f, 0);

struct State {
  Texture trav, vs, isect;
  int steps = 0;
};

// A leaf as a ray reaches it: the node and the segment [tmin, tmax] it is tested over.
struct LeafVisit {
  float node, tmin, tmax;
  bool operator==(const LeafVisit&) const = default;
};
using LeafSequences = std::vector<std::vector<LeafVisit>>;  // per ray, in order

// Appends to each ray's sequence the leaf its traversal state holds, if it holds one (y, the
// list position, at least 0) that is not the last one appended.
void note_leaves(const Texture& trav, LeafSequences& seq) {
  for (int i = 0; i < int(seq.size()); ++i) {
    const glm::vec4 s = ktest::at(trav, i, 0);
    if (s.x < 0 || s.y < 0) continue;
    const LeafVisit v{s.x, s.z, s.w};
    if (seq[size_t(i)].empty() || !(seq[size_t(i)].back() == v)) seq[size_t(i)].push_back(v);
  }
}

// The multipass sequence of host/trace/walks/kd_walk.cpp, single kernels: step, load, then the
// leaf's triangles one per pass (intersections, next triangle) until no ray tests, until no ray
// walks. With fused, the --mrt on forms (step + load, intersections + next triangle).
State multipass(const Walk& w, bool fused, LeafSequences* leaves = nullptr) {
  const Tree& t = w.t;
  const Rays& r = w.r;
  const kernels::KdUniforms u = kd_uniforms(0.001f);
  kernels::KdStep step;
  step.kd = u;
  kernels::KdLoadLeaf load;
  load.kd.list_width = u.list_width;
  kernels::KdIntersections isect;
  isect.kd = u;
  isect.scene.width = 1;
  kernels::NextTriangle next;
  next.lists.list_width = u.list_width;
  kernels::KdStepLoad step_load;
  step_load.kd = u;
  kernels::KdIntersectNext isect_next;
  isect_next.kd = u;
  isect_next.scene.width = 1;
  State s{w.trav, w.vs, w.isect};
  while (any_x_at_least(s.trav, r.n, 0)) {
    REQUIRE(++s.steps < 40);
    if (fused) {
      auto o = ktest::run_targets(
          step_load, {&r.origins, &r.rays, &s.trav, &s.isect, &s.vs, &t.nodes, &t.lists}, r.n, 1);
      s.trav = o[0];
      s.vs = o[1];
    } else {
      s.trav = ktest::run(step, {&r.origins, &r.rays, &s.trav, &s.isect, &t.nodes}, r.n, 1);
      s.vs = ktest::run(load, {&s.trav, &s.vs, &t.lists}, r.n, 1);
    }
    if (leaves) note_leaves(s.trav, *leaves);
    for (int k = 0; any_w_at_least(s.vs, r.n, 0); ++k) {
      REQUIRE(k < 4);
      if (fused) {
        auto o = ktest::run_targets(
            isect_next,
            {&r.origins, &r.rays, &s.trav, &s.vs, &s.isect, &t.v0, &t.v1, &t.v2, &t.lists}, r.n, 1);
        s.isect = o[0];
        s.vs = o[1];
      } else {
        s.isect = ktest::run(
            isect, {&r.origins, &r.rays, &s.trav, &s.vs, &s.isect, &t.v0, &t.v1, &t.v2}, r.n, 1);
        s.vs = ktest::run(next, {&s.vs, &t.lists}, r.n, 1);
      }
    }
  }
  return s;
}

void check_hits(const Texture& isect) {
  CHECK_TEXEL_NEAR(isect, 0, 0, 1e-6, kHitA);
  CHECK_TEXEL_NEAR(isect, 1, 0, 1e-6, kHitB);
  CHECK_TEXEL_NEAR(isect, 2, 0, 1e-6, kHitC);
  CHECK_TEXEL(isect, 3, 0, kNoHit);
  CHECK_TEXEL(isect, 4, 0, kNoHit);
}

struct LoopOut {
  explicit LoopOut(int n)
      : trav("traversal out", n, 1, 4),
        vs("voxel state out", n, 1, 4),
        isect("intersection out", n, 1, 4) {}
  Texture trav, vs, isect;
  vgpu::PassRecord rec;
};

LoopOut loop_pass(const Walk& w, const Texture& trav, const Texture& vs, const Texture& isect,
                  int steps) {
  kernels::KdLooping k;
  k.kd = kd_uniforms(0.001f);
  k.scene.width = 1;
  k.steps = steps;
  const vgpu::KernelProgram<kernels::KdLooping> p(k);
  vgpu::Gpu gpu(vgpu::profile("gf6600"), 1, 1);
  LoopOut o(w.r.n);
  gpu.use_program(p);
  gpu.unbind_textures();
  const Texture* units[] = {&w.r.origins, &w.r.rays, &trav,   &vs,        &isect,
                            &w.t.v0,      &w.t.v1,   &w.t.v2, &w.t.nodes, &w.t.lists};
  for (int u = 0; u < 10; ++u) gpu.bind_texture(u, *units[u]);
  const std::vector<Texture> before = ktest::before_pass({&o.trav, &o.vs, &o.isect});
  gpu.set_targets({&o.trav, &o.vs, &o.isect});
  o.rec = gpu.draw();
  if (ktest::gl_check()) {
    ktest::check_on_gl(p, {std::begin(units), std::end(units)}, before, {&o.trav, &o.vs, &o.isect},
                       nullptr);
  }
  return o;
}

}  // namespace

TEST_CASE("the kd walk's single passes in sequence find each ray's hit, restarts included") {
  const Walk w;
  CHECK_TEXEL(w.trav, 0, 0, glm::vec4(0, kNone, 0, 3.5f));
  CHECK_TEXEL(w.trav, 4, 0, kDone);
  const State s = multipass(w, false);
  check_hits(s.isect);
  for (int i = 0; i < 5; ++i) CHECK_TEXEL(s.trav, i, 0, kDone);
  // A: root, node 2, leaf 3 (reach, restart), root, node 2, leaf 4 (reach, done): 8 steps.
  CHECK(s.steps == 8);
}

TEST_CASE("fused kd step + load and intersections + next triangle equal the single kernels") {
  const Walk w;
  const Tree& t = w.t;
  const Rays& r = w.r;
  const kernels::KdUniforms u = kd_uniforms(0.001f);
  // One step of each form from every state of the single-kernel walk.
  kernels::KdStep step;
  step.kd = u;
  kernels::KdLoadLeaf load;
  load.kd.list_width = u.list_width;
  kernels::KdIntersections isect;
  isect.kd = u;
  isect.scene.width = 1;
  kernels::NextTriangle next;
  next.lists.list_width = u.list_width;
  kernels::KdStepLoad step_load;
  step_load.kd = u;
  kernels::KdIntersectNext isect_next;
  isect_next.kd = u;
  isect_next.scene.width = 1;
  State s{w.trav, w.vs, w.isect};
  int fused_steps = 0, fused_tests = 0;
  for (int n = 0; any_x_at_least(s.trav, r.n, 0); ++n) {
    REQUIRE(n < 40);
    CAPTURE(n);
    const auto f = ktest::run_targets(
        step_load, {&r.origins, &r.rays, &s.trav, &s.isect, &s.vs, &t.nodes, &t.lists}, r.n, 1);
    s.trav = ktest::run(step, {&r.origins, &r.rays, &s.trav, &s.isect, &t.nodes}, r.n, 1);
    s.vs = ktest::run(load, {&s.trav, &s.vs, &t.lists}, r.n, 1);
    check_same(f[0], s.trav, r.n);
    check_same(f[1], s.vs, r.n);
    ++fused_steps;
    for (int k = 0; any_w_at_least(s.vs, r.n, 0); ++k) {
      REQUIRE(k < 4);
      const auto g = ktest::run_targets(
          isect_next,
          {&r.origins, &r.rays, &s.trav, &s.vs, &s.isect, &t.v0, &t.v1, &t.v2, &t.lists}, r.n, 1);
      s.isect = ktest::run(
          isect, {&r.origins, &r.rays, &s.trav, &s.vs, &s.isect, &t.v0, &t.v1, &t.v2}, r.n, 1);
      s.vs = ktest::run(next, {&s.vs, &t.lists}, r.n, 1);
      check_same(g[0], s.isect, r.n);
      check_same(g[1], s.vs, r.n);
      ++fused_tests;
    }
  }
  check_hits(s.isect);
  CHECK(fused_steps == 8);
  CHECK(fused_tests > 0);
  // And the fused walk on its own ends in the same state.
  const State m = multipass(w, true);
  check_same(m.trav, s.trav, r.n);
  check_same(m.vs, s.vs, r.n);
  check_same(m.isect, s.isect, r.n);
}

TEST_CASE("the kd looping kernel ends in the multipass walk's hits and traversal state") {
  const Walk w;
  const State m = multipass(w, false);
  const LoopOut o = loop_pass(w, w.trav, w.vs, w.isect, 32);
  check_same(o.isect, m.isect, w.r.n);
  check_same(o.trav, m.trav, w.r.n);
  check_hits(o.isect);
  for (int i = 0; i < 5; ++i) CHECK(ktest::at(o.vs, i, 0).w == kNone);
  // Iterations (a step or a triangle each). A: root, 2 (cut), reach 3, restart at the
  // remembered node 2 (not the root), 4 (far: the plane at tmin), reach 4, triangle 1, done:
  // 8 (multipass steps from the root again: 9 with the test). B: root, reach 1, triangle 0,
  // done: 4. C: root (cut), 2, reach 3, restart at the root (the descent cut at once), 1,
  // reach 1, triangle 0, done: 8. D: root, 2, reach 4, triangle 1, done: 5. E: 0.
  CHECK(o.rec.counters.loop_iterations == 8 + 4 + 8 + 5);
}

TEST_CASE("kd looping push-down restarts at the remembered node, not the root") {
  const Walk w;
  // Four iterations: ray A has descended root -> 2 (segment whole: node 2 remembered), 2 -> 3
  // (cut at y = 2), reached the empty leaf 3, and restarted: at node 2, segment [1.5, 3.5].
  const LoopOut a = loop_pass(w, w.trav, w.vs, w.isect, 4);
  CHECK_TEXEL(a.trav, 0, 0, glm::vec4(2, kNone, 1.5f, 3.5f));
  CHECK_TEXEL(a.vs, 0, 0, glm::vec4(0, 2, 0, kNone));  // remembered node 2, no cut since
  CHECK_TEXEL(a.isect, 0, 0, kNoHit);
  // Ray C cut at the root: its remembered node stays the root, and so does its restart.
  CHECK_TEXEL(a.trav, 2, 0, glm::vec4(0, kNone, 1.5f, 3.5f));
  CHECK_TEXEL(a.vs, 2, 0, glm::vec4(0, 0, 0, kNone));
  // Resumed, the walk ends in the hits of a whole pass.
  const LoopOut b = loop_pass(w, a.trav, a.vs, a.isect, 32);
  check_hits(b.isect);
  for (int i = 0; i < 5; ++i) CHECK_TEXEL(b.trav, i, 0, kDone);
}

TEST_CASE(
    "kd-restart reaches each ray's leaves in order, over the hand-worked segments, restarting "
    "past each leaf without a hit") {
  // Eight rays, each leaf reached given as (node, tmin, tmax), worked by hand on the tree above
  // (every number a binary fraction, so the kernels' float arithmetic gives them exactly):
  //   A +y from (3, 0.5, 1): right at the root (no cut), cut at y = 2 (t = 1.5) into the empty
  //     leaf 3, restart at 1.5: the plane at tmin, far child 4 (triangle 1 at t = 2.5).
  //   B +x from (0.5, 1, 0.5): cut at x = 2 (t = 1.5), leaf 1 (triangle 0 at t = 0.5).
  //   C -x from (3.5, 1, 1): cut at x = 2 (t = 1.5), leaf 3 (empty), restart, leaf 1.
  //   D +z from (3, 3.5, 1): parallel to both planes, leaf 4 to the box's exit (t = 3); no hit.
  //   E done before the walk: no leaf.
  //   G (1, 2, 0) from (1.5, 0.5, 1): box exit at y = 4, t = 1.75. Cut at x = 2 (t = 0.5): leaf 1,
  //     where triangle 0 (x = 1) lies behind the ray; restart at 0.5: the plane at tmin, right;
  //     cut at y = 2 (t = 0.75): the empty leaf 3; restart at 0.75: leaf 4, where triangle 1
  //     (y = 3) is met at t = 1.25, at (2.75, 3, 1): u = 0.75/4, v = 1/4.
  //   P (1, 2, 0) from (2, 0.5, 1), on the plane x = 2: its direction decides, right, the plane
  //     at t = 0 cuts nothing; box exit at x = 4, t = 2, and y = 4, t = 1.75. Cut at y = 2
  //     (t = 0.75): leaf 3, restart (the root again sends it right, whole), leaf 4: triangle 1
  //     at t = 1.25, at (3.25, 3, 1): u = 1.25/4, v = 1/4.
  //   Q (-2, 0, 1) from (2, 1, 1), on the plane, pointing left: leaf 1 alone, whole (box exit
  //     at x = 0, t = 1): triangle 0 at t = 0.5, at (1, 1, 1.5): u = 1/4, v = 3/8.
  // Every leaf without a hit restarts the ray at the leaf's tmax, so each ray's next segment
  // starts where the last ended.
  const Walk w(Rays{{{3, 0.5f, 1},
                     {0.5f, 1, 0.5f},
                     {3.5f, 1, 1},
                     {3, 3.5f, 1},
                     {1, 1, 1},
                     {1.5f, 0.5f, 1},
                     {2, 0.5f, 1},
                     {2, 1, 1}},
                    {{0, 1, 0, 100},
                     {1, 0, 0, 100},
                     {-1, 0, 0, 100},
                     {0, 0, 1, 100},
                     {1, 0, 0, -1},
                     {1, 2, 0, 100},
                     {1, 2, 0, 100},
                     {-2, 0, 1, 100}}});
  const LeafSequences expected = {{{3, 0, 1.5f}, {4, 1.5f, 3.5f}},
                                  {{1, 0, 1.5f}},
                                  {{3, 0, 1.5f}, {1, 1.5f, 3.5f}},
                                  {{4, 0, 3}},
                                  {},
                                  {{1, 0, 0.5f}, {3, 0.5f, 0.75f}, {4, 0.75f, 1.75f}},
                                  {{3, 0, 0.75f}, {4, 0.75f, 1.75f}},
                                  {{1, 0, 1}}};
  const std::vector<glm::vec4> hits = {kHitA,
                                       kHitB,
                                       kHitC,
                                       kNoHit,
                                       kNoHit,
                                       {1.25f, 0.1875f, 0.25f, 1},
                                       {1.25f, 0.3125f, 0.25f, 1},
                                       {0.5f, 0.25f, 0.375f, 0}};
  auto check = [&](const LeafSequences& got, const Texture& isect) {
    for (int i = 0; i < w.r.n; ++i) {
      CAPTURE(i);
      const auto& g = got[size_t(i)];
      const auto& e = expected[size_t(i)];
      REQUIRE(g.size() == e.size());
      for (size_t k = 0; k < e.size(); ++k) {
        CAPTURE(k);
        CHECK(g[k].node == e[k].node);
        CHECK(g[k].tmin == e[k].tmin);
        CHECK(g[k].tmax == e[k].tmax);
      }
      CHECK_TEXEL_NEAR(isect, i, 0, 1e-6, hits[size_t(i)]);
    }
  };
  for (const bool fused : {false, true}) {  // the single kernels, then the --mrt on forms
    CAPTURE(fused);
    LeafSequences seq(size_t(w.r.n));
    const State s = multipass(w, fused, &seq);
    check(seq, s.isect);
  }
  // The looping kernel one iteration per pass, each pass resuming the last: the same leaves
  // over the same segments, though its restarts start at the remembered node.
  LeafSequences seq(size_t(w.r.n));
  Texture trav = w.trav, vs = w.vs, isect = w.isect;
  for (int pass = 0; any_x_at_least(trav, w.r.n, 0); ++pass) {
    REQUIRE(pass < 40);
    LoopOut o = loop_pass(w, trav, vs, isect, 1);
    trav = o.trav;
    vs = o.vs;
    isect = o.isect;
    note_leaves(trav, seq);
  }
  check(seq, isect);
}

TEST_CASE(
    "with beams, kd enter starts a ray at its tile's node, kd step restarts it there, push-down "
    "starts there, and a tile that misses ends its rays") {
  const Tree t;
  // Tiles of 2 pixels: pixels 0 and 1 in tile 0, whose beam stopped at node 2; pixels 2 and 3
  // in tile 1, whose beam stopped at node 4 and missed (z 1). The beam texel's y (the end of a
  // BVH walk) and w (the depth) are not read.
  const Texture beams = texels("kd beams", 2, 1, {{2, 7, 0, 1}, {4, 5, 1, 2}});
  const float tile = 2;
  {
    const Rays r({{3, 0.5f, 1}, {-1, 5, 1}, {1, 1, 1}, {1, 1, 1}},
                 {{0, 1, 0, 100},      // inside: [0, 3.5], at tile 0's node 2
                  {1, 0, 0, 100},      // passing above the box: done
                  {1, 0, 0, 100},      // inside, but its tile missed: done
                  {1, 0, 0, kNone}});  // a dead ray: done
    kernels::KdEnter k;
    k.kd = kd_uniforms();
    k.beam_tile = tile;
    const Texture out = ktest::run(k, {&r.origins, &r.rays, &beams}, r.n, 1, glm::vec4(7));
    CHECK_TEXEL(out, 0, 0, glm::vec4(2, kNone, 0, 3.5f));
    CHECK_TEXEL(out, 1, 0, kDone);
    CHECK_TEXEL(out, 2, 0, kDone);
    CHECK_TEXEL(out, 3, 0, kDone);
  }
  // kd step: a restart goes to the tile's node instead of the root; the other steps are kd
  // step's own.
  const Rays r({{3, 0.5f, 1}, {3, 0.5f, 1}, {3, 2.5f, 1}, {3, 2.5f, 1}},
               {{0, 1, 0, 100}, {0, 1, 0, 100}, {0, 1, 0, 1}, {0, 1, 0, 100}});
  const Texture trav = texels("traversal", r.n, 1,
                              {{3, 0, 0, 1.5f},      // 0: empty leaf 3 tested: restart at 2
                               {2, kNone, 0, 3.5f},  // 1: node 2, cut at y = 2 (t 1.5): 3
                               {4, 3, 0, 0.5f},      // 2: leaf 4 tested, tmax 1: restart at 4
                               {4, 3, 0, 1}});       // 3: leaf 4 tested with a hit: done
  const Texture isect =
      texels("intersection", r.n, 1, {kNoHit, kNoHit, kNoHit, {0.5f, 0.25f, 0.125f, 1}});
  kernels::KdStep k;
  k.kd = kd_uniforms();
  k.beam_tile = tile;
  const Texture out = ktest::run(k, {&r.origins, &r.rays, &trav, &isect, &t.nodes, &beams}, r.n, 1);
  CHECK_TEXEL(out, 0, 0, glm::vec4(2, kNone, 1.5f, 3.5f));
  CHECK_TEXEL(out, 1, 0, glm::vec4(3, kNone, 0, 1.5f));
  CHECK_TEXEL(out, 2, 0, glm::vec4(4, kNone, 0.5f, 1));
  CHECK_TEXEL(out, 3, 0, kDone);
  // The fused form restarts alike (and loads no leaf: none is reached).
  const Texture vs = texels("voxel state", r.n, 1, std::vector<glm::vec4>(4, {0, 0, 0, kNone}));
  kernels::KdStepLoad fused;
  fused.kd = kd_uniforms();
  fused.beam_tile = tile;
  const auto o = ktest::run_targets(
      fused, {&r.origins, &r.rays, &trav, &isect, &vs, &t.nodes, &t.lists, &beams}, r.n, 1);
  check_same(o[0], out, r.n);
  check_same(o[1], vs, r.n);
  // The looping kernel: the remembered node (voxel state y) starts at the tile's node where it
  // is still the root (0), and is kept where a pass already moved it. No ray walks here.
  const Texture done = texels("traversal", r.n, 1, std::vector<glm::vec4>(4, kDone));
  const Texture vs0 = texels("voxel state", r.n, 1,
                             {{0, 0, 0, kNone}, {0, 6, 1, kNone}, {0, 0, 0, kNone}, {1, 3, 0, 2}});
  kernels::KdLooping loop;
  loop.kd = kd_uniforms();
  loop.scene.width = 1;
  loop.beam_tile = tile;
  const auto l = ktest::run_targets(
      loop,
      {&r.origins, &r.rays, &done, &vs0, &isect, &t.v0, &t.v1, &t.v2, &t.nodes, &t.lists, &beams},
      r.n, 1);
  check_same(l[0], done, r.n);
  CHECK_TEXEL(l[1], 0, 0, glm::vec4(0, 2, 0, kNone));
  CHECK_TEXEL(l[1], 1, 0, glm::vec4(0, 6, 1, kNone));
  CHECK_TEXEL(l[1], 2, 0, glm::vec4(0, 4, 0, kNone));
  CHECK_TEXEL(l[1], 3, 0, glm::vec4(1, 3, 0, 2));
  check_same(l[2], isect, r.n);
}

// --- Addressed by (x, y) (KdUniforms::xy) ---------------------------------------------------
// The same tree laid out 2 texels wide, as (x, y) needs (a power of two): node i at (i mod 2,
// i div 2), its texel (split, axis, right child's column, row) or, for a leaf, (0, 3, its list
// start's column, row); list entry k at (k mod 2, k div 2). Node 6, the left child of node 5 at
// (1, 2), sits at the start of the next row: the left-child step carries into the row.
namespace {

const std::vector<glm::vec4> kNodesXy = {{2, 0, 0, 1}, {0, 3, 1, 0}, {2, 1, 0, 2}, {0, 3, 0, 0},
                                         {0, 3, 1, 1}, {3, 2, 1, 3}, {0, 3, 0, 0}, {0, 3, 0, 0}};

kernels::KdUniforms kd_uniforms_xy() {
  kernels::KdUniforms u = kd_uniforms();
  u.node_width = 2;
  u.list_width = 2;
  u.xy = 1;
  return u;
}

struct TreeXy {
  Texture nodes = texels("kd nodes", 2, 4, kNodesXy);
  Texture lists = scalars("kd lists", 2, 3, {kNone, 0, kNone, 1, kNone, 0});
};

}  // namespace

TEST_CASE("kd enter by (x, y) starts a ray at the root's column and row") {
  const Rays r({{1, 1, 1}, {-1, 5, 1}}, {{1, 0, 0, 100}, {1, 0, 0, 100}});
  kernels::KdEnter k;
  k.kd = kd_uniforms_xy();
  const Texture out = ktest::run(k, {&r.origins, &r.rays}, r.n, 1, glm::vec4(7));
  CHECK_TEXEL(out, 0, 0, glm::vec4(0, 0, 0, 3));
  CHECK_TEXEL(out, 1, 0, glm::vec4(kNone, 0, 0, 0));  // done: x -1 (y is never read)
}

TEST_CASE("kd step by (x, y) moves to children by column and row and flags a leaf reached") {
  // The traversal state: (column, plus the width 2 once the leaf was reached; row; tmin; tmax).
  const TreeXy t;
  const Rays r({{0.5f, 1, 1},   // 0: root, +x, ts = 1.5: left child, node 1 at (1, 0)
                {1, 1, 0.5f},   // 1: node 5 at (1, 2), +z, ts = 2.5: left child, node 6: (0, 3)
                {1, 1, 3.5f},   // 2: node 5, -z, ts = 0.5: right child, node 7 at (1, 3)
                {3, 2.5f, 1},   // 3: leaf 4 at (0, 2), not yet reached: flag it (x + 2)
                {3, 2.5f, 1},   // 4: leaf 4 reached and tested, no hit, segment ends at 0.5
                                //    before the box's exit 1.5: restart at the root (0, 0)
                {3, 2.5f, 1},   // 5: the same, its segment reaching the exit: done
                {3, 2.5f, 1}},  // 6: the same with a hit: done
               {{1, 0, 0, 100},
                {0, 0, 1, 100},
                {0, 0, -1, 100},
                {0, 1, 0, 100},
                {0, 1, 0, 100},
                {0, 1, 0, 100},
                {0, 1, 0, 100}});
  const Texture trav = texels("traversal", r.n, 1,
                              {{0, 0, 0, 3.5f},
                               {1, 2, 0, 3.5f},
                               {1, 2, 0, 3.5f},
                               {0, 2, 0, 1.5f},
                               {2, 2, 0, 0.5f},
                               {2, 2, 0, 1.5f},
                               {2, 2, 0, 0.5f}});
  std::vector<glm::vec4> hits(size_t(r.n), kNoHit);
  hits[6] = {0.25f, 0.1f, 0.1f, 1};
  const Texture isect = texels("intersection", r.n, 1, hits);
  kernels::KdStep k;
  k.kd = kd_uniforms_xy();
  const Texture out = ktest::run(k, {&r.origins, &r.rays, &trav, &isect, &t.nodes}, r.n, 1);
  CHECK_TEXEL(out, 0, 0, glm::vec4(1, 0, 0, 1.5f));
  CHECK_TEXEL(out, 1, 0, glm::vec4(0, 3, 0, 2.5f));
  CHECK_TEXEL(out, 2, 0, glm::vec4(1, 3, 0, 0.5f));
  CHECK_TEXEL(out, 3, 0, glm::vec4(2, 2, 0, 1.5f));
  CHECK_TEXEL(out, 4, 0, glm::vec4(0, 0, 0.5f, 1.5f));
  CHECK_TEXEL(out, 5, 0, kDone);
  CHECK_TEXEL(out, 6, 0, kDone);
}

TEST_CASE("kd load leaf by (x, y) reads the list start from the leaf's node texel") {
  const TreeXy t;
  // Rays at: leaf 4 reached (list at (1, 1): triangle 1), leaf 1 reached (list at (1, 0):
  // triangle 0), node 0 not a reached leaf (kept), leaf 4 reached with a triangle still to
  // test (kept), and a done ray (kept).
  const Texture trav =
      texels("traversal", 5, 1,
             {{2, 2, 0, 4}, {3, 0, 0, 4}, {0, 0, 0, 4}, {2, 2, 0, 4}, {kNone, 0, 0, 0}});
  const Texture vs = texels(
      "leaf state", 5, 1,
      {{0, 0, 0, kNone}, {0, 0, 0, kNone}, {0, 0, 0, kNone}, {1, 1, 0, 1}, {0, 0, 0, kNone}});
  kernels::KdLoadLeaf k;
  k.kd = kd_uniforms_xy();
  const Texture out = ktest::run(k, {&trav, &vs, &t.lists, &t.nodes}, 5, 1);
  CHECK_TEXEL(out, 0, 0, glm::vec4(1, 1, 0, 1));
  CHECK_TEXEL(out, 1, 0, glm::vec4(1, 0, 0, 0));
  CHECK_TEXEL(out, 2, 0, glm::vec4(0, 0, 0, kNone));
  CHECK_TEXEL(out, 3, 0, glm::vec4(1, 1, 0, 1));
  CHECK_TEXEL(out, 4, 0, glm::vec4(0, 0, 0, kNone));
}

TEST_CASE("next triangle by (x, y) carries a list position into the next row") {
  const TreeXy t;
  // At (1, 1) (entry 3) the next entry is (0, 2): the -1 closing the list; at (1, 0) (entry 1)
  // it is (0, 1), also a -1; at (0, 2) with nothing to test the state is kept.
  const Texture vs = texels("leaf state", 3, 1, {{1, 1, 0, 1}, {1, 0, 0, 0}, {0, 2, 0, kNone}});
  kernels::NextTriangle k;
  k.lists = kd_uniforms_xy();
  const Texture out = ktest::run(k, {&vs, &t.lists}, 3, 1);
  CHECK_TEXEL(out, 0, 0, glm::vec4(0, 2, 0, kNone));
  CHECK_TEXEL(out, 1, 0, glm::vec4(0, 1, 0, kNone));
  CHECK_TEXEL(out, 2, 0, glm::vec4(0, 2, 0, kNone));
}
