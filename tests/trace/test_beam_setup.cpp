// The beams' host-side set-up (host/trace/walks/grid_beams.h, bvh_beams.h) against answers the
// test works out itself: the chessboard beam distances against a brute force over hand-placed
// and random occupied voxels, the march's far bound against the box's corners, the levels of a
// hierarchy against a recursion over its children, the descent's margin and the kd-tree's nodes
// as boxes by hand. Then frames of hand-made scenes where each tile's beam must get to a voxel or
// a node the test names: a wall behind seven empty layers (every beam must cross them and each
// pixel's ray start in the last), and four triangles side by side under a hand-made BVH and
// kd-tree (each tile's beam must descend to the one leaf it sees). A beam that stops too early
// keeps the image, so the frames' bit-for-bit tests (test_beams.cpp, test_bvh_beams.cpp) cannot
// see it; these check where the beams stop.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "host/accel/accel.h"
#include "host/accel/bvh.h"
#include "host/accel/grid.h"
#include "host/accel/kdtree.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/stream_tracer.h"
#include "host/trace/walks/bvh_beams.h"
#include "host/trace/walks/grid_beams.h"
#include "tests/support/reference.h"

namespace {

// A grid of unit voxels from the origin whose voxels in `occupied` list a triangle (index 0; the
// distances look only at whether a list is empty).
host::Grid grid_with(glm::ivec3 res, const std::vector<glm::ivec3>& occupied) {
  host::Grid g;
  g.res = res;
  g.lo = glm::vec3(0.0f);
  g.cell = glm::vec3(1.0f);
  g.hi = glm::vec3(res);
  std::vector<int> listed(g.voxels(), 0);
  for (const glm::ivec3& v : occupied) listed[g.index(v)] = 1;
  g.start.assign(g.voxels() + 1, 0);
  for (size_t v = 0; v < g.voxels(); ++v) {
    g.start[v + 1] = g.start[v] + uint32_t(listed[v]);
    if (listed[v]) g.tris.push_back(0);
  }
  return g;
}

// The test's brute force: per voxel, the largest axis distance to the nearest occupied voxel,
// at most `cap` (and `cap` where none is).
std::vector<float> brute_distances(glm::ivec3 res, const std::vector<glm::ivec3>& occupied,
                                   float cap) {
  std::vector<float> d;
  for (int z = 0; z < res.z; ++z)
    for (int y = 0; y < res.y; ++y)
      for (int x = 0; x < res.x; ++x) {
        int best = 1 << 30;
        for (const glm::ivec3& o : occupied)
          best =
              std::min(best, std::max({std::abs(o.x - x), std::abs(o.y - y), std::abs(o.z - z)}));
        d.push_back(std::min(float(best), cap));
      }
  return d;
}

// The levels of a depth-first hierarchy by recursion over its children: node i's left child is
// i + 1, its right child the left child's escape; a node is a leaf where it lists triangles or
// its subtree [i, escape) is itself.
int levels_below(const host::Bvh& b, size_t i) {
  const int32_t escape = b.nodes[i].escape;
  const size_t end = escape < 0 ? b.nodes.size() : size_t(escape);
  if (b.nodes[i].count > 0 || end == i + 1) return 1;
  const size_t right = size_t(b.nodes[i + 1].escape);
  return 1 + std::max(levels_below(b, i + 1), levels_below(b, right));
}

// The same over a kd-tree's own nodes (axis 3: a leaf; the right child is named).
int kd_levels_below(const host::KdTree& kd, size_t i) {
  const host::KdNode& n = kd.nodes[i];
  if (n.axis == 3) return 1;
  return 1 + std::max(kd_levels_below(kd, i + 1), kd_levels_below(kd, size_t(n.right)));
}

host::BvhNode node(glm::vec3 lo, glm::vec3 hi, int32_t escape, int32_t leaf = -1,
                   int32_t count = 0) {
  host::BvhNode n;
  n.lo = lo;
  n.hi = hi;
  n.escape = escape;
  n.leaf = leaf;
  n.count = count;
  return n;
}

host::KdNode kd_inner(int axis, float split, int32_t right) {
  host::KdNode n;
  n.axis = axis;
  n.split = split;
  n.right = right;
  return n;
}

host::KdNode kd_leaf(int32_t leaf, int32_t count) {
  host::KdNode n;
  n.axis = 3;
  n.leaf = leaf;
  n.count = count;
  return n;
}

// Keeps a copy of the target of each pass of the named kernels as the frame's last run of that
// kernel left it.
struct KeepTargets final : host::PassObserver {
  explicit KeepTargets(std::set<std::string> names) : names_(std::move(names)) {}
  std::map<std::string, vgpu::Texture> last;
  std::map<std::string, int> runs;
  void iteration(int) override {}
  void trace_begin(TraceKind) override {}
  void trace_end() override {}
  void pass_begin(const vgpu::Stencil*) override {}
  void pass(const Pass& p) override {
    if (!names_.count(p.program.name())) return;
    last.insert_or_assign(p.program.name(), p.target);
    ++runs[p.program.name()];
  }
  void query(uint64_t, const vgpu::Stencil*, const vgpu::FrameStats&) override {}

 private:
  std::set<std::string> names_;
};

// The camera contract (host/scene/camera.h) in double: the unit primary ray through image point
// (px, py) of a w x h image.
glm::dvec3 primary(const host::Camera& cam, int w, int h, double px, double py) {
  const glm::dvec3 f(cam.forward), up(cam.up);
  const glm::dvec3 right = glm::normalize(glm::cross(f, up));
  const double t = std::tan(double(cam.yfov) / 2.0), a = double(w) / double(h);
  return glm::normalize(f + ((2.0 * px / w - 1.0) * t * a) * right +
                        ((1.0 - 2.0 * py / h) * t) * up);
}

// Where the ray from e along d leaves the box [lo, hi], which it must be inside at `at`.
double leaves_box(glm::dvec3 e, glm::dvec3 d, glm::dvec3 lo, glm::dvec3 hi, double at) {
  const std::pair<double, double> in_out = host::box_interval(e, d, lo, hi);
  const double tn = in_out.first, tf = in_out.second;
  REQUIRE(tn <= at);
  REQUIRE(tf >= at);
  return tf;
}

host::RenderOptions beam_options(int w, int h, int tile) {
  host::RenderOptions opt;
  opt.width = w;
  opt.height = h;
  opt.profile = "gf6600";
  opt.threads = 2;
  opt.bounces = 0;
  opt.shadows = false;
  opt.beams = true;
  opt.beam_tile = tile;
  return opt;
}

// Four triangles side by side in z = 0, A to D centred at x = -6, -2, 2, 6 (internal ids 0 to 3),
// each within 0.9 of its centre, seen from (0, 0, 10) down -z by a 16 x 4 image whose pixels are
// one unit wide at z = 0 (pixel x's centre at x - 7.5): each 4 x 4 tile sees one triangle, tile k
// the k-th, its corner rays passing 1.5 or more beside the others' boxes.
host::Scene four_triangles() {
  host::Scene s;
  s.materials = {host::Material{}};
  const glm::vec3 n(0, 0, 1);
  for (int k = 0; k < 4; ++k) {
    const float x = -6.0f + 4.0f * float(k);
    s.add_triangle({x - 0.9f, -0.9f, 0}, {x + 0.9f, -0.9f, 0}, {x, 0.9f, 0}, n, n, n, 0,
                   uint32_t(k));
  }
  s.lights = {{{0, 0, 10}, glm::vec3(1.0f)}};
  s.input_triangles = 4;
  return s;
}

host::Camera four_triangles_camera() {
  host::Camera cam;
  cam.position = {0, 0, 10};
  cam.forward = {0, 0, -1};
  cam.up = {0, 1, 0};
  cam.yfov = 2.0f * std::atan(0.2f);  // 16 x 4 pixels: x from -8 to 8 at z = 0
  return cam;
}

// The leaves' lists: triangle k alone in the list at 2k + 1.
const std::vector<int32_t> kFourLists = {-1, 0, -1, 1, -1, 2, -1, 3, -1};

// A box around x0..x1 over the four triangles' y and z, padded by 0.01.
host::BvhNode box_node(float x0, float x1, int32_t escape, int32_t leaf = -1, int32_t count = 0) {
  return node({x0 - 0.01f, -0.91f, -0.01f}, {x1 + 0.01f, 0.91f, 0.01f}, escape, leaf, count);
}

}  // namespace

TEST_CASE(
    "beam distances are each voxel's chessboard distance to the nearest voxel holding a triangle, "
    "as a brute force over hand-placed and random voxels finds") {
  // Hand-placed: a corner voxel, two inside, one on a face; worked by hand at a few voxels.
  const glm::ivec3 res(7, 5, 4);
  const std::vector<glm::ivec3> cells = {{1, 1, 1}, {5, 3, 2}, {6, 0, 3}, {0, 4, 0}};
  const host::Grid g = grid_with(res, cells);
  const std::vector<float> d = host::beam_distances(g);
  const std::vector<float> want = brute_distances(res, cells, 1024.0f);
  REQUIRE(d.size() == want.size());
  for (size_t v = 0; v < d.size(); ++v) {
    CAPTURE(v);
    CHECK(d[v] == want[v]);
  }
  CHECK(d[g.index(1, 1, 1)] == 0.0f);
  CHECK(d[g.index(1, 2, 1)] == 1.0f);
  CHECK(d[g.index(3, 2, 1)] == 2.0f);  // (1, 1, 1) and (5, 3, 2) are both two steps away
  CHECK(d[g.index(6, 4, 0)] == 2.0f);  // (5, 3, 2): 1, 1, 2 apart
  CHECK(d[g.index(2, 4, 3)] == 3.0f);  // (1, 1, 1), (5, 3, 2) and (0, 4, 0) all three
  // The cap, and a grid with nothing in it.
  const std::vector<float> capped = host::beam_distances(g, 1.0f);
  const std::vector<float> want_capped = brute_distances(res, cells, 1.0f);
  CHECK(capped == want_capped);
  const std::vector<float> empty = host::beam_distances(grid_with(res, {}));
  CHECK(std::all_of(empty.begin(), empty.end(), [](float k) { return k == 1024.0f; }));
  // Random grids, a few voxels in a hundred occupied.
  std::mt19937 rng(47);
  for (int run = 0; run < 6; ++run) {
    const glm::ivec3 r(3 + int(rng() % 8), 3 + int(rng() % 7), 2 + int(rng() % 6));
    std::vector<glm::ivec3> occupied;
    for (int z = 0; z < r.z; ++z)
      for (int y = 0; y < r.y; ++y)
        for (int x = 0; x < r.x; ++x)
          if (rng() % 100 < 4) occupied.push_back({x, y, z});
    CAPTURE(run);
    CHECK(host::beam_distances(grid_with(r, occupied)) == brute_distances(r, occupied, 1024.0f));
  }
  // As the march fetches them: voxel (X, Y, Z) at texel (X * res.y + Y, Z).
  const std::vector<float> texels = host::beam_distance_texels(g);
  REQUIRE(texels.size() == want.size());
  for (int z = 0; z < res.z; ++z)
    for (int y = 0; y < res.y; ++y)
      for (int x = 0; x < res.x; ++x)
        CHECK(texels[size_t(z) * 35 + size_t(x * 5 + y)] == want[g.index(x, y, z)]);
}

TEST_CASE(
    "the march's grid uniforms come from the smallest cell, and its far bound lies just past the "
    "grid box's farthest corner from the eye") {
  kernels::GridUniforms g;
  g.lo = {-1, 0, 2};
  g.cell = {2, 0.5f, 1};
  g.res = {3, 4, 5};  // the box [-1, 5] x [0, 2] x [2, 7]
  kernels::BeamUniforms u;
  host::set_beam_grid(u, g, 6);
  CHECK(u.min_cell == 0.5f);
  CHECK(u.margin == doctest::Approx(5e-4).epsilon(1e-6));
  CHECK(u.min_step == 0.25f);
  CHECK(u.tile == 6.0f);
  CHECK(u.grid.res.x == 3.0f);
  // From (1, 3, 0) the farthest corner is (5, 0, 7), neither the box's low nor its high corner:
  // sqrt(4^2 + 3^2 + 7^2) = sqrt(74).
  const double farthest = std::sqrt(74.0);
  const float far = host::beam_far(u, {1, 3, 0});
  CHECK(double(far) > farthest);
  CHECK(double(far) < farthest * 1.001);
  // From inside the box, (2, 1, 4): (-1 or 5, 0 or 2, 7), sqrt(9 + 1 + 9).
  const float inside = host::beam_far(u, {2, 1, 4});
  CHECK(double(inside) > std::sqrt(19.0));
  CHECK(double(inside) < std::sqrt(19.0) * 1.001);
}

TEST_CASE(
    "a hierarchy's levels are the nodes on its longest root-to-leaf path, as a recursion over the "
    "children counts them, for hand-made and built trees") {
  const glm::vec3 lo(0.0f), hi(1.0f);
  // Hand-made, depth first: 0 { 1 { 2, 3 { 4, 5 } }, 6 }: leaves 2 and 6 at level 3 and 2, 4
  // and 5 at level 4.
  host::Bvh b;
  b.nodes = {node(lo, hi, -1),      node(lo, hi, 6),       node(lo, hi, 3, 1, 1), node(lo, hi, 6),
             node(lo, hi, 5, 3, 1), node(lo, hi, 6, 5, 1), node(lo, hi, -1, 7, 1)};
  CHECK(host::bvh_levels(b) == 4);
  CHECK(levels_below(b, 0) == 4);
  // The deep side on the right: 0 { 1, 2 { 3 { 4, 5 }, 6 } }.
  host::Bvh r;
  r.nodes = {node(lo, hi, -1),      node(lo, hi, 2, 1, 1), node(lo, hi, -1),      node(lo, hi, 6),
             node(lo, hi, 5, 3, 1), node(lo, hi, 6, 5, 1), node(lo, hi, -1, 7, 1)};
  CHECK(host::bvh_levels(r) == 4);
  // A lone leaf; a root over an empty leaf (written as an inner node whose subtree is itself)
  // and a leaf.
  host::Bvh one;
  one.nodes = {node(lo, hi, -1, 1, 2)};
  CHECK(host::bvh_levels(one) == 1);
  host::Bvh with_empty;
  with_empty.nodes = {node(lo, hi, -1), node(lo, hi, 2), node(lo, hi, -1, 1, 1)};
  CHECK(host::bvh_levels(with_empty) == 2);
  // Built over bundled scenes, and the kd-trees' nodes as the descent reads them.
  for (const char* name : {"bunny-low", "classic", "teapot"}) {
    CAPTURE(name);
    const host::Scene scene = host::load_scene(host::resolve_scene(name));
    const host::Bvh bvh = host::build_bvh(scene);
    CHECK(host::bvh_levels(bvh) == levels_below(bvh, 0));
    const host::Bounds box = scene.box();
    const host::KdTree kd = host::build_kdtree(scene, box.lo, box.hi);
    CHECK(host::bvh_levels(host::kd_beam_nodes(kd)) == kd_levels_below(kd, 0));
  }
}

TEST_CASE("the descent's margin is a ten-thousandth of the root box's diagonal, at least of 1") {
  host::Bvh b;
  b.nodes = {node({1, 2, 3}, {4, 6, 15}, -1, 1, 1)};  // a diagonal of sqrt(9 + 16 + 144) = 13
  CHECK(host::bvh_beam_margin(b) == doctest::Approx(1.3e-3).epsilon(1e-6));
  b.nodes[0].hi = {1.1f, 2.1f, 3.1f};  // a small scene: 1e-4 of 1
  CHECK(host::bvh_beam_margin(b) == doctest::Approx(1e-4).epsilon(1e-6));
  CHECK(host::bvh_beam_margin(host::Bvh{}) == doctest::Approx(1e-4 * std::sqrt(3.0)).epsilon(1e-6));
}

TEST_CASE(
    "a kd-tree's nodes as the descent reads them: each the root box cut by the planes above it, "
    "its escape past its subtree, its leaf's list") {
  // Root box [-8, 8] x [-2, 2] x [-1, 1]; x = 0 at the root, x = -4 on the left, y = 0.5 on the
  // right over a leaf and an empty leaf.
  host::KdTree kd;
  kd.lo = {-8, -2, -1};
  kd.hi = {8, 2, 1};
  kd.nodes = {kd_inner(0, 0.0f, 4), kd_inner(0, -4.0f, 3), kd_leaf(1, 1), kd_leaf(3, 1),
              kd_inner(1, 0.5f, 6), kd_leaf(5, 2),         kd_leaf(0, 0)};
  kd.depth = 3;
  kd.leaves = 4;
  kd.max_leaf = 2;
  const host::Bvh b = host::kd_beam_nodes(kd);
  REQUIRE(b.nodes.size() == 7);
  struct Want {
    glm::vec3 lo, hi;
    int32_t escape, leaf, count;
  };
  const Want want[] = {{{-8, -2, -1}, {8, 2, 1}, -1, -1, 0}, {{-8, -2, -1}, {0, 2, 1}, 4, -1, 0},
                       {{-8, -2, -1}, {-4, 2, 1}, 3, 1, 1},  {{-4, -2, -1}, {0, 2, 1}, 4, 3, 1},
                       {{0, -2, -1}, {8, 2, 1}, -1, -1, 0},  {{0, -2, -1}, {8, 0.5f, 1}, 6, 5, 2},
                       {{0, 0.5f, -1}, {8, 2, 1}, -1, 0, 0}};
  for (size_t i = 0; i < 7; ++i) {
    CAPTURE(i);
    CHECK(b.nodes[i].lo == want[i].lo);
    CHECK(b.nodes[i].hi == want[i].hi);
    CHECK(b.nodes[i].escape == want[i].escape);
    CHECK(b.nodes[i].count == want[i].count);
    if (want[i].count > 0) CHECK(b.nodes[i].leaf == want[i].leaf);
  }
  CHECK(b.depth == 3);
  CHECK(b.leaves == 4);
  CHECK(b.max_leaf == 2);
  CHECK(host::bvh_levels(b) == 3);
}

TEST_CASE(
    "every tile's beam crosses the empty layers before a wall, in two steps from outside the grid "
    "and in one from the layer two before it, and each pixel's ray starts in the last layer at "
    "the voxel and entry its own walk reaches there") {
  // A 16 x 16 x 8 grid of unit voxels; a wall of two triangles at z = 7.5 fills layer z = 7, so
  // a voxel of layer z lies 7 - z steps from a triangle. Looking down +z from (8, 8, -8), a
  // beam first leaves the half-space in front of the grid (z < -m), then the empty cube its
  // voxel's distance 7 gives, [-6, 7) in z. From (8, 8, 5.3), in layer 5 (distance 2), the cube
  // is [4, 7) in z, 1.7 cells deep. Either way the march ends in layer 6, the last empty one,
  // where each corner ray's exit through z = 7 - m, scaled by cos(theta) and 0.9999, puts it,
  // and the next step finds no room.
  host::Scene scene;
  scene.materials = {host::Material{}};
  const glm::vec3 n(0, 0, -1);
  scene.add_triangle({-8, -8, 7.5f}, {24, -8, 7.5f}, {-8, 24, 7.5f}, n, n, n, 0, 0);
  scene.add_triangle({24, -8, 7.5f}, {24, 24, 7.5f}, {-8, 24, 7.5f}, n, n, n, 0, 1);
  scene.lights = {{{8, 8, -8}, glm::vec3(1.0f)}};
  scene.input_triangles = 2;
  const host::GridAccel grid(host::build_grid_in_box(scene, {0, 0, 0}, {16, 16, 8}, {16, 16, 8}));
  REQUIRE(grid.grid()->cell == glm::vec3(1.0f));
  const double m = 1e-3;  // the margin: a thousandth of a cell
  // Per eye: the low z face of the cube the last step leaves, a z where every corner ray is
  // inside it, the steps, and whether the pixels' points lie 0.02 or more inside their voxels
  // (from 5.3 the beam ends too near z = 7 for the test to say which way the entry rounds).
  struct Eye {
    float z;
    double cube_lo, inside;
    int steps;
    bool entries;
  };
  for (const Eye& eye : {Eye{-8.0f, -6 + m, -0.5, 2, true}, Eye{5.3f, 4 + m, 5.3, 1, false}}) {
    CAPTURE(eye.z);
    host::Camera cam;
    cam.position = {8, 8, eye.z};
    cam.forward = {0, 0, 1};
    cam.up = {0, 1, 0};
    cam.yfov = 0.45f;
    const int W = 16, H = 16, T = 4;
    host::RenderOptions opt = beam_options(W, H, T);
    KeepTargets keep({"beam march", "beam entry"});
    opt.observer = &keep;
    host::StreamTracer tracer(scene, *grid.grid(), opt);
    const host::RenderResult res = tracer.render(cam);
    REQUIRE(keep.last.count("beam march"));
    REQUIRE(keep.last.count("beam entry"));
    CHECK(keep.runs["beam march"] == eye.steps + 1);  // the steps, and the pass that finds none
    CHECK(res.beam_tiles == 16);
    CHECK(res.beam_tiles_missed == 0);
    const vgpu::Texture& beams = keep.last.at("beam march");
    const vgpu::Texture& entry = keep.last.at("beam entry");
    const glm::dvec3 e(cam.position);
    for (int ty = 0; ty < H / T; ++ty)
      for (int tx = 0; tx < W / T; ++tx) {
        CAPTURE(tx);
        CAPTURE(ty);
        // The tile's corner rays, their axis and cos(theta); where the first leaves the cube
        // (its side faces lie a cell or more beside the beam, which leaves through z = 7 - m).
        std::vector<glm::dvec3> corners;
        for (double py : {ty * T + 0.5, ty * T + T - 0.5})
          for (double px : {tx * T + 0.5, tx * T + T - 0.5})
            corners.push_back(primary(cam, W, H, px, py));
        glm::dvec3 axis(0.0);
        for (const glm::dvec3& c : corners) axis += c;
        axis = glm::normalize(axis);
        double cosw = 1.0, exit = 1e300;
        for (const glm::dvec3& c : corners) {
          cosw = std::min(cosw, glm::dot(axis, c));
          exit = std::min(exit, leaves_box(e, c, glm::dvec3(-100, -100, eye.cube_lo),
                                           glm::dvec3(100, 100, 7 - m), (eye.inside - e.z) / c.z));
        }
        const double ts = exit * cosw * 0.9999;
        // The beam got past the empty layers: its axis point lies in layer 6.
        REQUIRE(std::floor(e.z + axis.z * ts) == 6.0);
        const float* b = beams.texel(tx, ty);
        CHECK(b[0] == -1.0f);  // stopped
        CHECK(double(b[1]) == doctest::Approx(ts).epsilon(1e-5));
        CHECK(b[2] == 0.0f);  // it did not miss
        CHECK(b[3] == float(eye.steps));
        if (!eye.entries) continue;
        // Each pixel's ray starts at the voxel of layer 6 that holds its point at the tile's t
        // (none lies within 0.02 of a face here), entering it where it crosses the voxel's last
        // entry face, as the 3D-DDA would.
        for (int y = ty * T; y < ty * T + T; ++y)
          for (int x = tx * T; x < tx * T + T; ++x) {
            CAPTURE(x);
            CAPTURE(y);
            const glm::dvec3 d = primary(cam, W, H, x + 0.5, y + 0.5);
            const glm::dvec3 p = e + d * ts;
            const glm::dvec3 v = glm::floor(p);
            const glm::dvec3 depth = p - v;
            REQUIRE(std::min({depth.x, depth.y, depth.z, 1 - depth.x, 1 - depth.y, 1 - depth.z}) >
                    0.02);
            REQUIRE(v.z == 6.0);
            double te = -1e300;
            for (int a = 0; a < 3; ++a)
              te = std::max(te, ((d[a] > 0 ? v[a] : v[a] + 1) - e[a]) / d[a]);
            const float* s = entry.texel(x, y);
            CHECK(s[0] == float(v.x));
            CHECK(s[1] == float(v.y));
            CHECK(s[2] == 6.0f);
            CHECK(double(s[3]) == doctest::Approx(te).epsilon(1e-5));
          }
      }
  }
}

TEST_CASE(
    "every tile's beam descends a hand-made BVH and kd-tree to the one leaf it sees, and its rays "
    "start there") {
  const host::Scene scene = four_triangles();
  const host::Camera cam = four_triangles_camera();
  // The BVH: 0 { 1 { A, B }, 4 { C, D } }, leaves' boxes padded by 0.01.
  host::Bvh bvh;
  bvh.nodes = {box_node(-6.9f, 6.9f, -1),       box_node(-6.9f, -1.1f, 4),
               box_node(-6.9f, -5.1f, 3, 1, 1), box_node(-2.9f, -1.1f, 4, 3, 1),
               box_node(1.1f, 6.9f, -1),        box_node(1.1f, 2.9f, 6, 5, 1),
               box_node(5.1f, 6.9f, -1, 7, 1)};
  bvh.lists = kFourLists;
  bvh.depth = 3;
  bvh.leaves = 4;
  bvh.max_leaf = 1;
  // The kd-tree in [-8, 8] x [-2, 2] x [-0.5, 0.5]: x = 0, then x = -4 and x = 4.
  host::KdTree kd;
  kd.lo = {-8, -2, -0.5f};
  kd.hi = {8, 2, 0.5f};
  kd.nodes = {kd_inner(0, 0.0f, 4), kd_inner(0, -4.0f, 3), kd_leaf(1, 1), kd_leaf(3, 1),
              kd_inner(0, 4.0f, 6), kd_leaf(5, 1),         kd_leaf(7, 1)};
  kd.lists = kFourLists;
  kd.depth = 3;
  kd.leaves = 4;
  kd.max_leaf = 1;
  const host::BvhAccel bvh_accel(scene, bvh, scene.box());
  const host::KdAccel kd_accel(scene, kd);
  // Tile k sees triangle k alone: its beam must end at the leaf listing it (nodes 2, 3, 5, 6 in
  // both trees), two levels down, its rays' walk ending at that leaf's escape (7, the node count,
  // for the last).
  const float leaf[4] = {2, 3, 5, 6}, end[4] = {3, 4, 6, 7};
  for (const host::Accel* accel :
       {static_cast<const host::Accel*>(&bvh_accel), static_cast<const host::Accel*>(&kd_accel)}) {
    const bool is_bvh = accel == &bvh_accel;
    CAPTURE(is_bvh);
    host::RenderOptions opt = beam_options(16, 4, 4);
    const std::string enter = is_bvh ? "bvh beam enter" : "kd enter";
    KeepTargets keep({"bvh beam descend", enter});
    opt.observer = &keep;
    host::StreamTracer tracer(scene, *accel, opt);
    const host::RenderResult res = tracer.render(cam);
    REQUIRE(keep.last.count("bvh beam descend"));
    REQUIRE(keep.last.count(enter));
    CHECK(keep.runs["bvh beam descend"] == 3);  // one pass a level
    CHECK(res.beam_tiles == 4);
    CHECK(res.beam_tiles_missed == 0);
    const vgpu::Texture& beams = keep.last.at("bvh beam descend");
    const vgpu::Texture& start = keep.last.at(enter);
    for (int k = 0; k < 4; ++k) {
      CAPTURE(k);
      const float* b = beams.texel(k, 0);
      CHECK(b[0] == leaf[k]);
      CHECK(b[1] == end[k]);
      CHECK(b[2] == 0.0f);
      CHECK(b[3] == 2.0f);
      for (int y = 0; y < 4; ++y)
        for (int x = 4 * k; x < 4 * k + 4; ++x) {
          CAPTURE(x);
          CAPTURE(y);
          const float* s = start.texel(x, y);
          CHECK(s[0] == leaf[k]);
          if (is_bvh) CHECK(s[2] == end[k]);  // the walk's end (the kd walk restarts there)
        }
    }
    // The rays that start at those leaves hit the triangle there: pixel (4k + 1, 2)'s centre
    // looks at (x_k - 0.5, -0.5), inside triangle k.
    for (int k = 0; k < 4; ++k) {
      CAPTURE(k);
      CHECK(res.hit_id[size_t(2 * 16 + 4 * k + 1)] == float(k));
    }
  }
}
