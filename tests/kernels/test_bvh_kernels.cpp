// Kernel tests for the BVH walk (kernels/bvh.h): inicioBVH, recorridoBVH, cargarHoja,
// interseccionesBVH, their fused --mrt on forms and the looping kernel, each run as a real pass on
// hand-made texels, every channel of every output checked against values worked out here. Linked
// into test_gl too, every pass is made again on the GL device from the same texels.
//
// The hand-made hierarchy (texture layouts of kernels/bvh.h and host/trace/walks/bvh_walk.cpp),
// node textures 2 texels wide (nodes 2 to 4 sit on the second and third rows):
//   node 0  root, inner  box [0, 4]^3                     escape -1
//   node 1  inner L      box [1, 2] x [0, 1] x [0, 1]     escape 4 (past its subtree)
//   node 2  leaf A       box [1, 1.6] x [0, 1] x [0, 1]   escape 3    list at 1: {0}
//   node 3  leaf A2      box [1.6, 2] x [0, 1] x [0, 1]   escape 4    list at 6: {3}
//   node 4  leaf B       box [3, 4] x [0, 1] x [0, 1]     escape -1   list at 3: {2, 1}
// nodes lo = (box lo, escape), nodes hi = (box hi, list start; -1 for an inner node). Lists,
// 4 entries per row (B's list wraps to the second row): {-1, 0, -1, 2 | 1, -1, 3, -1}.
// Triangles 0, 1 and 2 span y, z in [0, 1] in the planes x = 1.5, 3.5 and 3.75, corners
// (x, 0, 0), (x, 1, 0), (x, 0, 1): a ray along +x through (y, z) meets one with u = y, v = z.
// Triangle 3, in x = 1.75, is the other half of that square: corners (x, 1, 1), (x, 0, 1),
// (x, 1, 0), u = 1 - y, v = 1 - z.
#include <doctest/doctest.h>

#include <iterator>
#include <vector>

#include "kernel_pass.h"

using kernels::kFar;
using kernels::kNone;
using ktest::check_same;
using ktest::scalars;
using ktest::texels;
using ktest::Texture;
using ktest::vec3s;

namespace {

struct Tree {
  Texture lo = texels("nodes lo", 2, 3,
                      {{0, 0, 0, -1}, {1, 0, 0, 4}, {1, 0, 0, 3}, {1.6f, 0, 0, 4}, {3, 0, 0, -1}});
  Texture hi = texels("nodes hi", 2, 3,
                      {{4, 4, 4, -1}, {2, 1, 1, -1}, {1.6f, 1, 1, 1}, {2, 1, 1, 6}, {4, 1, 1, 3}});
  Texture lists = scalars("bvh lists", 4, 2, {kNone, 0, kNone, 2, 1, kNone, 3, kNone});
  Texture v0 = vec3s("vertices0", 2, 2, {{1.5f, 0, 0}, {3.5f, 0, 0}, {3.75f, 0, 0}, {1.75f, 1, 1}});
  Texture v1 = vec3s("vertices1", 2, 2, {{1.5f, 1, 0}, {3.5f, 1, 0}, {3.75f, 1, 0}, {1.75f, 0, 1}});
  Texture v2 = vec3s("vertices2", 2, 2, {{1.5f, 0, 1}, {3.5f, 0, 1}, {3.75f, 0, 1}, {1.75f, 1, 0}});
};

kernels::BvhUniforms uniforms() {
  kernels::BvhUniforms u;
  u.node_width = 2;
  u.nodes = 5;
  u.list_width = 4;
  return u;
}

const glm::vec4 kPx(1, 0, 0, kFar), kMx(-1, 0, 0, kFar), kNoHit(kFar, 0, 0, kNone);
const glm::vec4 kEmpty(0, 0, 0, kNone);  // voxel state: nothing to test

// The step cases: origin, ray, traversal, intersection, and the traversal expected after one
// recorridoBVH pass.
struct StepCase {
  glm::vec4 origin, ray, trav, isect, expected;
};

const glm::vec4 kO(0.5f, 0.5f, 0.5f, 0);
const std::vector<StepCase> kStepCases = {
    // 0: the root is met: an inner node sends the ray to node + 1 (its y is cleared)
    {kO, kPx, {0, 1, 9, 9}, kNoHit, {1, kNone, 0, 0}},
    // 1: L met: on to its left child, node 2
    {kO, kPx, {1, kNone, 0, 0}, kNoHit, {2, kNone, 0, 0}},
    // 2: leaf A met: on to its escape (3), y = A's list start
    {kO, kPx, {2, kNone, 0, 0}, kNoHit, {3, 1, 0, 0}},
    // 3: leaf B met, escape -1: the node count (5), y = B's list start
    {kO, kPx, {4, kNone, 0, 0}, kNoHit, {5, 3, 0, 0}},
    // 4: L missed (the ray runs -x from x = 0.5): its escape, past its subtree
    {kO, kMx, {1, kNone, 0, 0}, kNoHit, {4, kNone, 0, 0}},
    // 5: leaf B missed, escape -1: the node count
    {kO, kMx, {4, kNone, 0, 0}, kNoHit, {5, kNone, 0, 0}},
    // 6: at the node count: the walk is done
    {kO, kPx, {5, kNone, 0, 0}, kNoHit, {kNone, kNone, 0, 0}},
    // 7: a done ray: untouched, every channel
    {kO, kPx, {kNone, kNone, 5, 6}, kNoHit, {kNone, kNone, 5, 6}},
    // 8: B's box (entered at t = 2.5) lies beyond the nearest hit so far (t = 2): missed
    {kO, kPx, {4, kNone, 0, 0}, {2, 0.25f, 0.25f, 0}, {5, kNone, 0, 0}},
    // 9: the same with tmax 2 instead of a hit
    {kO, {1, 0, 0, 2}, {4, kNone, 0, 0}, kNoHit, {5, kNone, 0, 0}},
    // 10: a hit beyond the box (t = 3) does not stop the ray entering it
    {kO, kPx, {4, kNone, 0, 0}, {3, 0.5f, 0.5f, 1}, {5, 3, 0, 0}},
    // 11: oblique, into A through its x = 1 face (t = 0.83) before leaving its y slab (1.125)
    {{0.5f, 0.1f, 0.5f, 0}, {0.6f, 0.8f, 0, kFar}, {2, kNone, 0, 0}, kNoHit, {3, 1, 0, 0}},
    // 12: oblique, leaves L's y slab (t = 0.125) before its x slab begins (t = 0.83): missed
    {{0.5f, 0.1f, 0.5f, 0}, {0.6f, -0.8f, 0, kFar}, {1, kNone, 0, 0}, kNoHit, {4, kNone, 0, 0}},
    // 13: parallel to the y slab and outside it (y = 1.5): A missed
    {{0.5f, 1.5f, 0.5f, 0}, kPx, {2, kNone, 0, 0}, kNoHit, {3, kNone, 0, 0}},
    // 14: parallel to the y slab, on its face y = 1: inside
    {{0.5f, 1, 0.5f, 0}, kPx, {2, kNone, 0, 0}, kNoHit, {3, 1, 0, 0}},
    // 15: starting inside A, going away (-x): met
    {{1.5f, 0.5f, 0.5f, 0}, kMx, {2, kNone, 0, 0}, kNoHit, {3, 1, 0, 0}},
    // 16: L behind the ray (+x from x = 2.5): missed
    {{2.5f, 0.5f, 0.5f, 0}, kPx, {1, kNone, 0, 0}, kNoHit, {4, kNone, 0, 0}},
    // 17: leaf A2 met: on to its escape (4), y = its list start (6, second row)
    {kO, kPx, {3, kNone, 0, 0}, kNoHit, {4, 6, 0, 0}},
};

struct StepTextures {
  Texture origins, rays, trav, isect;
};

StepTextures step_textures() {
  std::vector<glm::vec4> o, r, t, i;
  for (const StepCase& c : kStepCases) {
    o.push_back(c.origin);
    r.push_back(c.ray);
    t.push_back(c.trav);
    i.push_back(c.isect);
  }
  const int n = int(kStepCases.size());
  return {texels("origins", n, 1, o), texels("rays", n, 1, r), texels("traversal", n, 1, t),
          texels("intersection", n, 1, i)};
}

// The intersection cases: origin, ray, voxel state, intersection, and the intersection expected
// after one interseccionesBVH pass.
struct HitCase {
  glm::vec4 origin, ray, vs, isect, expected;
};

const glm::vec4 kOa(0.5f, 0.25f, 0.25f, 0), kOb(2.5f, 0.25f, 0.5f, 0);
const std::vector<HitCase> kHitCases = {
    // 0: triangle 0 at t = 1, u = 0.25, v = 0.25, after no hit
    {kOa, kPx, {1, 0, 0, 0}, kNoHit, {1, 0.25f, 0.25f, 0}},
    // 1: triangle 2 at t = 1.25, u = 0.25, v = 0.5
    {kOb, kPx, {3, 0, 0, 2}, kNoHit, {1.25f, 0.25f, 0.5f, 2}},
    // 2: triangle 1 at t = 1, nearer than the hit so far (triangle 2 at 1.25): replaces it
    {kOb, kPx, {4, 0, 0, 1}, {1.25f, 0.25f, 0.5f, 2}, {1, 0.25f, 0.5f, 1}},
    // 3: triangle 2 at t = 1.25, farther than the hit so far: the nearest is kept
    {kOb, kPx, {3, 0, 0, 2}, {1, 0.25f, 0.5f, 1}, {1, 0.25f, 0.5f, 1}},
    // 4: tmax 0.75 before the hit at t = 1: none
    {kOa, {1, 0, 0, 0.75f}, {1, 0, 0, 0}, kNoHit, kNoHit},
    // 5: tmax exactly at the hit (t = 1): none (t < tmax)
    {kOa, {1, 0, 0, 1}, {1, 0, 0, 0}, kNoHit, kNoHit},
    // 6: no voxel rule: a hit 101.5 units away is kept
    {{-100, 0.25f, 0.25f, 0}, kPx, {1, 0, 0, 0}, kNoHit, {101.5f, 0.25f, 0.25f, 0}},
    // 7: through the plane outside the triangle (u + v = 1.8): none
    {{0.5f, 0.9f, 0.9f, 0}, kPx, {1, 0, 0, 0}, kNoHit, kNoHit},
    // 8: nothing to test (w = -1): the intersection is kept
    {kOa, kPx, {2, 0, 0, kNone}, {3, 0.1f, 0.2f, 1}, {3, 0.1f, 0.2f, 1}},
    // 9: a hit at the same t as the one so far: the earlier one is kept
    {kOa, kPx, {1, 0, 0, 0}, {1, 0.5f, 0.5f, 7}, {1, 0.5f, 0.5f, 7}},
    // 10: the triangle behind the origin: none
    {{2.5f, 0.25f, 0.25f, 0}, kPx, {1, 0, 0, 0}, kNoHit, kNoHit},
};

struct HitTextures {
  Texture origins, rays, vs, isect;
};

HitTextures hit_textures() {
  std::vector<glm::vec4> o, r, v, i;
  for (const HitCase& c : kHitCases) {
    o.push_back(c.origin);
    r.push_back(c.ray);
    v.push_back(c.vs);
    i.push_back(c.isect);
  }
  const int n = int(kHitCases.size());
  return {texels("origins", n, 1, o), texels("rays", n, 1, r), texels("voxel state", n, 1, v),
          texels("intersection", n, 1, i)};
}

}  // namespace

TEST_CASE("bvh enter puts every ray at the root and a slot without a ray (w < 0) done") {
  const Texture rays =
      texels("rays", 4, 1, {{1, 0, 0, kFar}, {0, 1, 0, 0}, {0, 0, 1, kNone}, {1, 0, 0, -5}});
  // The target starts full of junk: every channel must be written.
  const Texture out = ktest::run(kernels::BvhEnter{}, {&rays}, 4, 1, glm::vec4(7, 8, 9, 10));
  CHECK_TEXEL(out, 0, 0, glm::vec4(0, kNone, 0, 0));
  CHECK_TEXEL(out, 1, 0, glm::vec4(0, kNone, 0, 0));  // tmax 0 is still a ray
  CHECK_TEXEL(out, 2, 0, glm::vec4(kNone, kNone, 0, 0));
  CHECK_TEXEL(out, 3, 0, glm::vec4(kNone, kNone, 0, 0));
}

TEST_CASE("bvh step enters met boxes, escapes missed ones and ends the walk past the last node") {
  const Tree tree;
  const StepTextures s = step_textures();
  kernels::BvhStep k;
  k.bvh = uniforms();
  const int n = int(kStepCases.size());
  const Texture out =
      ktest::run(k, {&s.origins, &s.rays, &s.trav, &s.isect, &tree.lo, &tree.hi}, n, 1);
  for (int i = 0; i < n; ++i) {
    CAPTURE(i);
    CHECK_TEXEL(out, i, 0, kStepCases[size_t(i)].expected);
  }
}

TEST_CASE("bvh load leaf loads the first triangle of the leaf just entered, and nothing else") {
  const Tree tree;
  kernels::BvhLoadLeaf k;
  k.bvh = uniforms();
  const Texture trav = texels("traversal", 6, 1,
                              {{2, 1, 0, 0},          // entered A: list at 1, triangle 0
                               {3, 3, 0, 0},          // entered B: list at 3, triangle 2
                               {2, kNone, 0, 0},      // entered nothing
                               {kNone, kNone, 0, 0},  // done
                               {3, 3, 0, 0},          // entered B, still testing a triangle
                               {2, 0, 0, 0}});        // the shared empty list
  const Texture vs =
      texels("voxel state", 6, 1,
             {kEmpty, kEmpty, {4, 3, 2, kNone}, {9, 8, 7, kNone}, {1, 5, 6, 0}, {5, 5, 5, kNone}});
  const Texture out = ktest::run(k, {&trav, &vs, &tree.lists}, 6, 1);
  CHECK_TEXEL(out, 0, 0, glm::vec4(1, 0, 0, 0));
  CHECK_TEXEL(out, 1, 0, glm::vec4(3, 0, 0, 2));
  CHECK_TEXEL(out, 2, 0, glm::vec4(4, 3, 2, kNone));
  CHECK_TEXEL(out, 3, 0, glm::vec4(9, 8, 7, kNone));
  CHECK_TEXEL(out, 4, 0, glm::vec4(1, 5, 6, 0));
  CHECK_TEXEL(out, 5, 0, glm::vec4(0, 0, 0, kNone));
}

TEST_CASE("bvh intersections keeps the nearest hit before tmax, with no voxel rule") {
  const Tree tree;
  const HitTextures h = hit_textures();
  kernels::BvhIntersections k;
  k.scene.width = 2;
  const int n = int(kHitCases.size());
  const Texture out =
      ktest::run(k, {&h.origins, &h.rays, &h.vs, &h.isect, &tree.v0, &tree.v1, &tree.v2}, n, 1);
  for (int i = 0; i < n; ++i) {
    CAPTURE(i);
    CHECK_TEXEL(out, i, 0, kHitCases[size_t(i)].expected);
  }
}

TEST_CASE("bvh step + load leaf equals bvh step then bvh load leaf") {
  const Tree tree;
  const StepTextures s = step_textures();
  const int n = int(kStepCases.size());
  // Nothing to test anywhere, but for case 14 (enters A while still testing triangle 2).
  std::vector<glm::vec4> vsv(size_t(n), kEmpty);
  vsv[14] = {4, 0, 0, 2};
  vsv[7] = {7, 0, 0, kNone};
  const Texture vs = texels("voxel state", n, 1, vsv);
  kernels::BvhStepLoad k;
  k.bvh = uniforms();
  const auto out = ktest::run_targets(
      k, {&s.origins, &s.rays, &s.trav, &s.isect, &vs, &tree.lo, &tree.hi, &tree.lists}, n, 1);
  for (int i = 0; i < n; ++i) {
    CAPTURE(i);
    CHECK_TEXEL(out[0], i, 0, kStepCases[size_t(i)].expected);
  }
  // Leaves entered: A (cases 2, 11, 15) loads triangle 0 at list entry 1; B (3, 10) triangle 2
  // at entry 3; A2 (17) triangle 3 at entry 6; case 14 is still testing: kept.
  for (int i = 0; i < n; ++i) {
    CAPTURE(i);
    glm::vec4 e = vsv[size_t(i)];
    if (i == 2 || i == 11 || i == 15) e = {1, 0, 0, 0};
    if (i == 3 || i == 10) e = {3, 0, 0, 2};
    if (i == 17) e = {6, 0, 0, 3};
    CHECK_TEXEL(out[1], i, 0, e);
  }
  // The two single kernels, as the multipass walk runs them.
  kernels::BvhStep ks;
  ks.bvh = k.bvh;
  kernels::BvhLoadLeaf kl;
  kl.bvh = k.bvh;
  const Texture stepped =
      ktest::run(ks, {&s.origins, &s.rays, &s.trav, &s.isect, &tree.lo, &tree.hi}, n, 1);
  check_same(out[0], stepped);
  check_same(out[1], ktest::run(kl, {&stepped, &vs, &tree.lists}, n, 1));
}

TEST_CASE("bvh intersections + next triangle equals bvh intersections then next triangle") {
  const Tree tree;
  const HitTextures h = hit_textures();
  const int n = int(kHitCases.size());
  kernels::BvhIntersectNext k;
  k.bvh = uniforms();
  k.scene.width = 2;
  const auto out = ktest::run_targets(
      k, {&h.origins, &h.rays, &h.vs, &h.isect, &tree.v0, &tree.v1, &tree.v2, &tree.lists}, n, 1);
  for (int i = 0; i < n; ++i) {
    CAPTURE(i);
    CHECK_TEXEL(out[0], i, 0, kHitCases[size_t(i)].expected);
    // The next list entry: from 1 the -1 at 2; from 3 triangle 1 at 4 (second row); from 4
    // the -1 at 5; nothing to test (case 8): kept.
    const glm::vec4 vs = kHitCases[size_t(i)].vs;
    glm::vec4 e = vs;
    if (vs.w >= 0) e = {vs.x + 1, 0, 0, vs.x == 3 ? 1.0f : kNone};
    CHECK_TEXEL(out[1], i, 0, e);
  }
  kernels::BvhIntersections ki;
  ki.scene = k.scene;
  kernels::NextTriangle kn;
  kn.lists.list_width = 4;
  check_same(
      out[0],
      ktest::run(ki, {&h.origins, &h.rays, &h.vs, &h.isect, &tree.v0, &tree.v1, &tree.v2}, n, 1));
  check_same(out[1], ktest::run(kn, {&h.vs, &tree.lists}, n, 1));
}

namespace {

// The walk's rays: 0 hits triangle 0 in A, then misses A2 and B (beyond the hit); 1 misses L
// (behind it), enters B, hits triangle 2 (t = 1.25), then triangle 1 nearer (t = 1); 2 runs -x
// and misses L and B; 3 is no ray; 4 has tmax 0.75: it enters A (at t = 0.5) but triangle 0
// (t = 1) lies past tmax; 5 passes beside triangle 0 in A and hits triangle 3 in A2 (t = 1.25,
// u = v = 0.25).
struct Walk {
  Tree tree;
  Texture origins = texels("origins", 6, 1, {kOa, kOb, kO, kO, kOa, {0.5f, 0.75f, 0.75f, 0}});
  Texture rays = texels("rays", 6, 1, {kPx, kPx, kMx, {1, 0, 0, kNone}, {1, 0, 0, 0.75f}, kPx});
  static constexpr int n = 6;
};

struct State {
  Texture trav, vs, isect;
};

State start(const Walk& w) {
  return {ktest::run(kernels::BvhEnter{}, {&w.rays}, Walk::n, 1),
          texels("voxel state", Walk::n, 1, std::vector<glm::vec4>(Walk::n, kEmpty)),
          texels("intersection", Walk::n, 1, std::vector<glm::vec4>(Walk::n, kNoHit))};
}

// The multipass walk on every fragment at once: step, load, then the leaf's triangles (at most
// 2, plus the pass that finds the list's end), `rounds` times. Kernels leave fragments with
// nothing to do as they are, so extra rounds change nothing.
State multipass(const Walk& w, int rounds) {
  State s = start(w);
  kernels::BvhStep ks;
  ks.bvh = uniforms();
  kernels::BvhLoadLeaf kl;
  kl.bvh = ks.bvh;
  kernels::BvhIntersections ki;
  ki.scene.width = 2;
  kernels::NextTriangle kn;
  kn.lists.list_width = 4;
  const Tree& t = w.tree;
  for (int r = 0; r < rounds; ++r) {
    s.trav = ktest::run(ks, {&w.origins, &w.rays, &s.trav, &s.isect, &t.lo, &t.hi}, Walk::n, 1);
    s.vs = ktest::run(kl, {&s.trav, &s.vs, &t.lists}, Walk::n, 1);
    for (int k = 0; k < 3; ++k) {
      s.isect =
          ktest::run(ki, {&w.origins, &w.rays, &s.vs, &s.isect, &t.v0, &t.v1, &t.v2}, Walk::n, 1);
      s.vs = ktest::run(kn, {&s.vs, &t.lists}, Walk::n, 1);
    }
  }
  return s;
}

// One pass of the looping kernel (three targets) on a gf6600 vgpu.
State looping_pass(vgpu::Gpu& gpu, const vgpu::KernelProgram<kernels::BvhLooping>& p, const Walk& w,
                   const State& in) {
  State o{Texture("traversal out", Walk::n, 1, 4), Texture("voxel state out", Walk::n, 1, 4),
          Texture("intersection out", Walk::n, 1, 4)};
  const Tree& t = w.tree;
  const Texture* units[] = {&w.origins, &w.rays, &in.trav, &in.vs, &in.isect, &t.v0,
                            &t.v1,      &t.v2,   &t.lo,    &t.hi,  &t.lists};
  gpu.use_program(p);
  gpu.unbind_textures();
  for (int u = 0; u < 11; ++u) gpu.bind_texture(u, *units[u]);
  const std::vector<Texture> before =
      ktest::before_pass({&o.trav, &o.vs, &o.isect});  // the GL pass starts from the same texels
  gpu.set_targets({&o.trav, &o.vs, &o.isect});
  gpu.draw();
  if (ktest::gl_check()) {
    REQUIRE(gpu.precision() == vgpu::Format::fp32);
    REQUIRE(p.precision() == vgpu::Format::fp32);
    ktest::check_on_gl(p, {std::begin(units), std::end(units)}, before, {&o.trav, &o.vs, &o.isect},
                       nullptr);
  }
  return o;
}

void check_same_state(const State& a, const State& b) {
  check_same(a.trav, b.trav);
  check_same(a.vs, b.vs);
  check_same(a.isect, b.isect);
}

}  // namespace

TEST_CASE("the multipass bvh walk on hand-made texels finds each ray's nearest hit and ends") {
  const Walk w;
  const State s = multipass(w, 6);  // at most 5 nodes, and one step to end
  for (int i = 0; i < Walk::n; ++i) CHECK_TEXEL(s.trav, i, 0, glm::vec4(kNone, kNone, 0, 0));
  CHECK_TEXEL(s.vs, 0, 0, glm::vec4(2, 0, 0, kNone));  // A's list read to its end
  CHECK_TEXEL(s.vs, 1, 0, glm::vec4(5, 0, 0, kNone));  // B's list read to its end
  CHECK_TEXEL(s.vs, 2, 0, kEmpty);
  CHECK_TEXEL(s.vs, 3, 0, kEmpty);
  CHECK_TEXEL(s.vs, 4, 0, glm::vec4(2, 0, 0, kNone));  // A's list read, its triangle refused
  CHECK_TEXEL(s.vs, 5, 0, glm::vec4(7, 0, 0, kNone));  // A2's list read to its end
  CHECK_TEXEL(s.isect, 0, 0, glm::vec4(1, 0.25f, 0.25f, 0));
  CHECK_TEXEL(s.isect, 1, 0, glm::vec4(1, 0.25f, 0.5f, 1));
  CHECK_TEXEL(s.isect, 2, 0, kNoHit);
  CHECK_TEXEL(s.isect, 3, 0, kNoHit);
  CHECK_TEXEL(s.isect, 4, 0, kNoHit);
  CHECK_TEXEL(s.isect, 5, 0, glm::vec4(1.25f, 0.25f, 0.25f, 3));
  // Five rounds are one too few for rays 0 and 5 (the root, L, A, A2, B, then the step that
  // ends the walk) and ray 4: they wait at the node count with their hits found; rays 1 and 2
  // (root, L missed, B, end) are done, 3 was never walking.
  const State short_walk = multipass(w, 5);
  CHECK_TEXEL(short_walk.trav, 0, 0, glm::vec4(5, kNone, 0, 0));
  CHECK_TEXEL(short_walk.trav, 1, 0, glm::vec4(kNone, kNone, 0, 0));
  CHECK_TEXEL(short_walk.trav, 2, 0, glm::vec4(kNone, kNone, 0, 0));
  CHECK_TEXEL(short_walk.trav, 3, 0, glm::vec4(kNone, kNone, 0, 0));
  CHECK_TEXEL(short_walk.trav, 4, 0, glm::vec4(5, kNone, 0, 0));
  CHECK_TEXEL(short_walk.trav, 5, 0, glm::vec4(5, kNone, 0, 0));
  CHECK_TEXEL(short_walk.isect, 5, 0, glm::vec4(1.25f, 0.25f, 0.25f, 3));
}

TEST_CASE("bvh looping equals the multipass walk on hand-made texels, for any step budget") {
  const Walk w;
  const State multi = multipass(w, 6);
  vgpu::Gpu gpu(vgpu::profile("gf6600"), 1, 1);
  kernels::BvhLooping k;
  k.bvh = uniforms();
  k.scene.width = 2;
  k.steps = 32;
  const vgpu::KernelProgram<kernels::BvhLooping> p(k);
  const State in = start(w);
  const State once = looping_pass(gpu, p, w, in);
  check_same_state(once, multi);
  // Another pass (more iterations) leaves finished rays as they are.
  check_same_state(looping_pass(gpu, p, w, once), multi);
  // One iteration per pass, resumed where the last stopped: ray 5 needs 8 (the root, L, A
  // entered and loaded, its triangle, A2 entered and loaded, its triangle, B missed, the end);
  // 12 passes are more than enough.
  k.steps = 1;
  const vgpu::KernelProgram<kernels::BvhLooping> p1(k);
  State s = in;
  for (int i = 0; i < 12; ++i) s = looping_pass(gpu, p1, w, s);
  check_same_state(s, multi);
  // After 2 iterations ray 1 has visited the root and missed L: it is at B, nothing loaded.
  State two = looping_pass(gpu, p1, w, looping_pass(gpu, p1, w, in));
  CHECK_TEXEL(two.trav, 1, 0, glm::vec4(4, kNone, 0, 0));
  CHECK_TEXEL(two.vs, 1, 0, kEmpty);
  CHECK_TEXEL(two.isect, 1, 0, kNoHit);
}
