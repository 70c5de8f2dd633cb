// Kernel tests for beams over tiles through the BVH (kernels/bvh_beams.h): rayosHazBVH (one node
// of each tile's descent), the count of beams still descending, inicioHazBVH (each pixel's ray
// started at its tile's node, its walk ending at that node's escape) and recorridoBVH ending a
// walk at that end, each a real pass on hand-made texels, every output channel checked.
//
// The hierarchy (as in test_bvh_kernels.cpp; node textures 2 texels wide):
//   node 0  root, inner  box [0, 4]^3                     escape -1
//   node 1  inner L      box [1, 2] x [0, 1] x [0, 1]     escape 4
//   node 2  leaf A       box [1, 1.6] x [0, 1] x [0, 1]   escape 3
//   node 3  leaf A2      box [1.6, 2] x [0, 1] x [0, 1]   escape 4
//   node 4  leaf B       box [3, 4] x [0, 1] x [0, 1]     escape -1
// The camera looks down +z from (2.5, 0.5, -5) at an 8x2 image of 2x2 tiles. Where the tiles'
// corner rays cross the boxes (z from 0 to 1): tile 0 spans x in [1.45, 1.875] (inside L, over
// both A and A2), tiles 1 and 2 x in [2.05, 2.95] (between L and B), tile 3 x in [3.125, 3.55]
// (inside B); every tile y in [0.35, 0.65].
#include <doctest/doctest.h>

#include <vector>

#include "kernel_pass.h"

using kernels::kFar;
using kernels::kNone;
using ktest::texels;
using ktest::Texture;

namespace {

struct Tree {
  Texture lo = texels("nodes lo", 2, 3,
                      {{0, 0, 0, -1}, {1, 0, 0, 4}, {1, 0, 0, 3}, {1.6f, 0, 0, 4}, {3, 0, 0, -1}});
  Texture hi = texels("nodes hi", 2, 3,
                      {{4, 4, 4, -1}, {2, 1, 1, -1}, {1.6f, 1, 1, 1}, {2, 1, 1, 6}, {4, 1, 1, 3}});
};

kernels::BvhUniforms bvh_uniforms() {
  kernels::BvhUniforms u;
  u.node_width = 2;
  u.nodes = 5;
  u.list_width = 4;
  return u;
}

kernels::BvhBeamDescend descend(glm::vec3 eye) {
  kernels::BvhBeamDescend k;
  kernels::BeamUniforms& u = k.u.beams;
  u.camera.forward = {0, 0, 1};
  u.camera.right = {1, 0, 0};
  u.camera.up = {0, 1, 0};
  u.camera.tan_half_fov = 0.05f;
  u.camera.aspect = 4.0f;
  u.camera.width = 8;
  u.camera.height = 2;
  u.eye = eye;
  u.tile = 2;
  u.margin = 1e-3f;
  k.u.bvh = bvh_uniforms();
  return k;
}

const glm::vec3 kEye(2.5f, 0.5f, -5.0f);

}  // namespace

TEST_CASE("bvh beam descent skips the children a beam misses and stops where it cannot") {
  const Tree tree;
  const kernels::BvhBeamDescend k = descend(kEye);
  // Every beam starts at the root, descending; the target starts full of junk.
  const Texture start = texels("beams", 4, 1, std::vector<glm::vec4>(4, glm::vec4(0.0f)));
  uint64_t descending = 0;
  const Texture one = ktest::run(k, {&start, &tree.lo, &tree.hi}, 4, 1, glm::vec4(7, 8, 9, 10));
  // Tile 0: B lies wholly right of the beam: on to L, depth 1, still descending.
  CHECK_TEXEL(one, 0, 0, glm::vec4(1, 0, 0, 1));
  // Tiles 1 and 2: both of the root's children lie outside the beam: the tile misses, its
  // beam stops at the root (end: the node count).
  CHECK_TEXEL(one, 1, 0, glm::vec4(0, 5, 1, 0));
  CHECK_TEXEL(one, 2, 0, glm::vec4(0, 5, 1, 0));
  // Tile 3: L lies wholly left of the beam: on to B.
  CHECK_TEXEL(one, 3, 0, glm::vec4(4, 0, 0, 1));
  ktest::run(kernels::BvhBeamsDescending{}, {&one}, 4, 1, glm::vec4(0.0f), &descending);
  CHECK(descending == 2);
  const Texture two = ktest::run(k, {&one, &tree.lo, &tree.hi}, 4, 1, glm::vec4(7, 8, 9, 10));
  // Tile 0: its beam spans both A and A2: it stops at L, its rays' walk ending at L's escape.
  CHECK_TEXEL(two, 0, 0, glm::vec4(1, 4, 0, 1));
  CHECK_TEXEL(two, 1, 0, glm::vec4(0, 5, 1, 0));
  CHECK_TEXEL(two, 2, 0, glm::vec4(0, 5, 1, 0));
  // Tile 3: B is a leaf: it stops there; B's escape is -1, so the end is the node count.
  CHECK_TEXEL(two, 3, 0, glm::vec4(4, 5, 0, 1));
  ktest::run(kernels::BvhBeamsDescending{}, {&two}, 4, 1, glm::vec4(0.0f), &descending);
  CHECK(descending == 0);
  uint64_t missed = 0;
  ktest::run(kernels::BeamsMissed{}, {&two}, 4, 1, glm::vec4(0.0f), &missed);
  CHECK(missed == 2);
  // A third pass leaves every stopped beam as it was.
  const Texture three = ktest::run(k, {&two, &tree.lo, &tree.hi}, 4, 1, glm::vec4(7, 8, 9, 10));
  for (int t = 0; t < 4; ++t) CHECK_TEXEL(three, t, 0, ktest::at(two, t, 0));
}

TEST_CASE(
    "the looping bvh beam descent ends in one pass where the passes end, and stops at its level "
    "budget") {
  const Tree tree;
  const kernels::BvhBeamDescend one_level = descend(kEye);
  kernels::BvhBeamDescendLooping k;
  k.u = one_level.u;
  k.levels = 3;
  vgpu::Gpu gpu(ktest::gf6600(), 1, 1);  // a profile with loops
  const Texture start = texels("beams", 4, 1, std::vector<glm::vec4>(4, glm::vec4(0.0f)));
  vgpu::PassRecord rec;
  const Texture out =
      ktest::run(gpu, k, {&start, &tree.lo, &tree.hi}, 4, 1, glm::vec4(7, 8, 9, 10), nullptr, &rec);
  // The second pass's texels above: tile 0 stopped at L (depth 1), tiles 1 and 2 missed at the
  // root, tile 3 stopped at the leaf B (depth 1).
  CHECK_TEXEL(out, 0, 0, glm::vec4(1, 4, 0, 1));
  CHECK_TEXEL(out, 1, 0, glm::vec4(0, 5, 1, 0));
  CHECK_TEXEL(out, 2, 0, glm::vec4(0, 5, 1, 0));
  CHECK_TEXEL(out, 3, 0, glm::vec4(4, 5, 0, 1));
  // Iterations: tiles 0 and 3 move, then stop (2 each); tiles 1 and 2 stop at once (1 each).
  CHECK(rec.counters.loop_iterations == 2 + 1 + 1 + 2);
  // With one level of budget the loop leaves tiles 0 and 3 where the first pass leaves them.
  k.levels = 1;
  const Texture cut = ktest::run(gpu, k, {&start, &tree.lo, &tree.hi}, 4, 1, glm::vec4(7));
  CHECK_TEXEL(cut, 0, 0, glm::vec4(1, 0, 0, 1));
  CHECK_TEXEL(cut, 3, 0, glm::vec4(4, 0, 0, 1));
}

TEST_CASE("bvh beam descent misses the whole tree behind the eye") {
  const Tree tree;
  // The eye past the boxes (z = 5), looking on down +z: the root lies behind every beam.
  const kernels::BvhBeamDescend k = descend(glm::vec3(2.5f, 0.5f, 5.0f));
  const Texture start = texels("beams", 4, 1, std::vector<glm::vec4>(4, glm::vec4(0.0f)));
  const Texture out = ktest::run(k, {&start, &tree.lo, &tree.hi}, 4, 1, glm::vec4(7, 8, 9, 10));
  for (int t = 0; t < 4; ++t) CHECK_TEXEL(out, t, 0, glm::vec4(0, 5, 1, 0));
}

TEST_CASE("bvh beam enter starts each pixel's ray at its tile's node with the walk's end") {
  // The beams as the descent leaves them above: tile 0 at L (end 4), tiles 1 and 2 missed,
  // tile 3 at B (end 5).
  const Texture beams =
      texels("beams", 4, 1, {{1, 4, 0, 1}, {0, 5, 1, 0}, {0, 5, 1, 0}, {4, 5, 0, 1}});
  std::vector<glm::vec4> rays(16, glm::vec4(0, 0, 1, kFar));
  rays[1] = glm::vec4(0, 0, 1, kNone);  // pixel (1, 0), tile 0: no ray
  const Texture r = texels("rays", 8, 2, rays);
  kernels::BvhBeamEnter k;
  k.tile = 2;
  const Texture out = ktest::run(k, {&r, &beams}, 8, 2, glm::vec4(7, 8, 9, 10));
  const glm::vec4 done(kNone, kNone, 0, 0);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 8; ++x) {
      CAPTURE(x);
      CAPTURE(y);
      const int tile = x / 2;
      const glm::vec4 want = x == 1 && y == 0 ? done
                             : tile == 0      ? glm::vec4(1, kNone, 4, 0)
                             : tile == 3      ? glm::vec4(4, kNone, 5, 0)
                                              : done;
      CHECK_TEXEL(out, x, y, want);
    }
}

TEST_CASE("bvh step ends a walk at the end its traversal carries, else at the node count") {
  const Tree tree;
  const glm::vec4 o(0.5f, 0.5f, 0.5f, 0), px(1, 0, 0, kFar), none(kFar, 0, 0, kNone);
  // 0: leaf A2 met inside L's subtree (end 4): on to 4, y = its list, the end kept
  // 1: at the end (4) of L's subtree: done, though B (node 4) lies on the ray
  // 2: the same without an end (z = 0): B is walked as the full walk does
  // 3: L's subtree ended at an escape of -1 would be the node count: inside, on to B
  const Texture origins = texels("origins", 4, 1, {o, o, o, o});
  const Texture rays = texels("rays", 4, 1, {px, px, px, px});
  const Texture trav = texels("traversal", 4, 1,
                              {{3, kNone, 4, 0}, {4, kNone, 4, 0}, {4, kNone, 0, 0}, {1, 0, 5, 0}});
  const Texture isect = texels("intersection", 4, 1, {none, none, none, none});
  kernels::BvhStep k;
  k.bvh = bvh_uniforms();
  k.bvh.ends = true;
  const Texture out =
      ktest::run(k, {&origins, &rays, &trav, &isect, &tree.lo, &tree.hi}, 4, 1, glm::vec4(7));
  CHECK_TEXEL(out, 0, 0, glm::vec4(4, 6, 4, 0));
  CHECK_TEXEL(out, 1, 0, glm::vec4(kNone, kNone, 0, 0));
  CHECK_TEXEL(out, 2, 0, glm::vec4(5, 3, 0, 0));
  CHECK_TEXEL(out, 3, 0, glm::vec4(2, kNone, 5, 0));
  // Without beams (ends off) z is not read: the walk ends at the node count alone, z cleared.
  k.bvh.ends = false;
  const Texture plain =
      ktest::run(k, {&origins, &rays, &trav, &isect, &tree.lo, &tree.hi}, 4, 1, glm::vec4(7));
  CHECK_TEXEL(plain, 0, 0, glm::vec4(4, 6, 0, 0));
  CHECK_TEXEL(plain, 1, 0, glm::vec4(5, 3, 0, 0));
  CHECK_TEXEL(plain, 2, 0, glm::vec4(5, 3, 0, 0));
  CHECK_TEXEL(plain, 3, 0, glm::vec4(2, kNone, 0, 0));
}
