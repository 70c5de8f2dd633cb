// Tests for host/grid (uniform grid construction) and host/reference (voxel walks and
// brute-force hits used as references by the tracer tests).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <random>
#include <set>
#include <stdexcept>
#include <vector>

#include "host/accel/grid.h"
#include "tests/support/reference.h"

namespace {

using host::Grid;
using host::Scene;

struct Tri {
  glm::vec3 a, b, c;
};

Scene make_scene(const std::vector<Tri>& tris) {
  Scene s;
  for (const Tri& t : tris) {
    s.add_flat_triangle(t.a, t.b, t.c, 0, uint32_t(s.id.size()));
  }
  s.materials.resize(1);
  s.input_triangles = uint32_t(tris.size());
  return s;
}

// A grid over [0, 4]³ with unit voxels unless told otherwise: voxel planes at integers.
Grid box_grid(const Scene& s, glm::ivec3 res = glm::ivec3(4), glm::vec3 hi = glm::vec3(4.0f)) {
  return host::build_grid_in_box(s, glm::vec3(0.0f), hi, res);
}

// Voxels listing triangle `t`.
std::set<size_t> voxels_of(const Grid& g, uint32_t t) {
  std::set<size_t> out;
  for (size_t v = 0; v < g.voxels(); ++v) {
    auto list = g.triangles_in(v);
    if (std::find(list.begin(), list.end(), t) != list.end()) out.insert(v);
  }
  return out;
}

// Voxels the exact test accepts, checked over every voxel of the grid (no candidate culling).
std::set<size_t> voxels_by_exhaustive_test(const Grid& g, const Scene& s, uint32_t t) {
  const glm::dvec3 tri[3] = {glm::dvec3(s.p0[t]), glm::dvec3(s.p1[t]), glm::dvec3(s.p2[t])};
  std::set<size_t> out;
  for (int z = 0; z < g.res.z; ++z)
    for (int y = 0; y < g.res.y; ++y)
      for (int x = 0; x < g.res.x; ++x) {
        glm::dvec3 lo, hi;
        g.voxel_box({x, y, z}, lo, hi);
        if (host::triangle_box_overlap(tri, lo, hi)) out.insert(g.index(x, y, z));
      }
  return out;
}

// Points on triangle t on a barycentric lattice with `n` steps per edge.
std::vector<glm::dvec3> samples_on(const Scene& s, uint32_t t, int n) {
  const glm::dvec3 a(s.p0[t]), b(s.p1[t]), c(s.p2[t]);
  std::vector<glm::dvec3> out;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; i + j <= n; ++j) {
      const double u = double(i) / n, v = double(j) / n;
      out.push_back(a + u * (b - a) + v * (c - a));
    }
  return out;
}

// The listed voxels of triangle t against a dense sampling: every voxel holding a sample is
// listed (a sample on a plane counts for the voxels on both sides), and every listed voxel lies
// within `tol` (world units, per axis) of some sample.
void check_against_samples(const Grid& g, const Scene& s, uint32_t t, int n, double tol) {
  const std::set<size_t> listed = voxels_of(g, t);
  std::vector<char> near(g.voxels(), 0);  // voxels within tol of a sample
  std::set<size_t> sampled;               // voxels holding a sample, both sides of a plane
  for (const glm::dvec3& p : samples_on(s, t, n)) {
    const glm::ivec3 lo = g.voxel_of(p - glm::dvec3(tol)), hi = g.voxel_of(p + glm::dvec3(tol));
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) near[g.index(x, y, z)] = 1;
    bool inside = true;
    for (int a = 0; a < 3; ++a)
      inside = inside && p[a] >= g.boundary(a, 0) && p[a] <= g.boundary(a, g.res[a]);
    if (!inside) continue;
    const glm::ivec3 v = g.voxel_of(p);
    sampled.insert(g.index(v));
    for (int a = 0; a < 3; ++a) {
      if (v[a] > 0 && p[a] == g.boundary(a, v[a])) {
        glm::ivec3 below = v;
        --below[a];
        sampled.insert(g.index(below));
      }
    }
  }
  std::vector<size_t> unlisted, untouched;
  std::set_difference(sampled.begin(), sampled.end(), listed.begin(), listed.end(),
                      std::back_inserter(unlisted));
  for (size_t v : listed)
    if (!near[v]) untouched.push_back(v);
  CHECK(unlisted.empty());
  CHECK(untouched.empty());
}

// Sutherland–Hodgman: clip the triangle by the six closed half-spaces of the box; they overlap
// iff something is left. An independent check of the separating-axis test.
bool overlap_by_clipping(const glm::dvec3 tri[3], glm::dvec3 lo, glm::dvec3 hi) {
  std::vector<glm::dvec3> poly(tri, tri + 3);
  for (int a = 0; a < 3 && !poly.empty(); ++a) {
    for (int side = 0; side < 2 && !poly.empty(); ++side) {
      auto inside = [&](const glm::dvec3& p) { return side ? p[a] <= hi[a] : p[a] >= lo[a]; };
      const double plane = side ? hi[a] : lo[a];
      std::vector<glm::dvec3> out;
      for (size_t i = 0; i < poly.size(); ++i) {
        const glm::dvec3 p = poly[i], q = poly[(i + 1) % poly.size()];
        if (inside(p)) out.push_back(p);
        if (inside(p) != inside(q)) out.push_back(p + (q - p) * ((plane - p[a]) / (q[a] - p[a])));
      }
      poly = out;
    }
  }
  return !poly.empty();
}

Scene random_scene(size_t n, uint32_t seed, float size = 0.3f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(0.0f, 10.0f), off(-size, size);
  std::vector<Tri> tris;
  while (tris.size() < n) {
    const glm::vec3 c(pos(rng), pos(rng), pos(rng));
    Tri t{c + glm::vec3(off(rng), off(rng), off(rng)), c + glm::vec3(off(rng), off(rng), off(rng)),
          c + glm::vec3(off(rng), off(rng), off(rng))};
    if (glm::length(glm::cross(t.b - t.a, t.c - t.a)) > 1e-6f) tris.push_back(t);
  }
  return make_scene(tris);
}

}  // namespace

// ---- Grid specs ----

TEST_CASE("Grid specs auto, N and AxBxC are parsed") {
  CHECK(host::parse_grid_spec("auto").automatic());
  CHECK(host::parse_grid_spec("16").res == glm::ivec3(16));
  CHECK(host::parse_grid_spec("1").res == glm::ivec3(1));
  CHECK(host::parse_grid_spec("512").res == glm::ivec3(512));
  CHECK(host::parse_grid_spec("8x4x2").res == glm::ivec3(8, 4, 2));
  CHECK(host::parse_grid_spec("3X5X7").res == glm::ivec3(3, 5, 7));
  CHECK(host::parse_grid_spec("007").res == glm::ivec3(7));
  CHECK_FALSE(host::parse_grid_spec("15x15x15").automatic());
}

TEST_CASE("Malformed grid specs are rejected with a message naming the text") {
  for (const char* bad : {"",    "0",       "513",   "8x0x8", "8x8x513",
                          "4x4", "4x4x4x4", "-4",    "+4",    " 4",
                          "4 ",  "x",       "4xx4",  "x4x4",  "4x4x",
                          "abc", "Auto",    "autox", "1.5",   "99999999999999999999"}) {
    CAPTURE(bad);
    CHECK_THROWS_AS(host::parse_grid_spec(bad), std::invalid_argument);
  }
  try {
    host::parse_grid_spec("600");
    FAIL("no exception");
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    CHECK(what.find("'600'") != std::string::npos);
    CHECK(what.find("512") != std::string::npos);
  }
}

TEST_CASE("A resolution outside 1..512 is refused by the builder") {
  const Scene s = make_scene({{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}});
  host::GridSpec spec;
  spec.res = {4, 0, 4};
  CHECK_THROWS_AS(host::build_grid(s, spec), std::invalid_argument);
  spec.res = {4, 513, 4};
  CHECK_THROWS_AS(host::build_grid(s, spec), std::invalid_argument);
}

// ---- Automatic resolution ----

TEST_CASE(
    "Automatic resolution follows the bounds' aspect ratio at about density voxels per triangle") {
  host::Bounds b;
  b.extend({0, 0, 0});
  b.extend({4, 2, 1});
  const glm::ivec3 r = host::auto_resolution(b, 1000, 4.0);  // 4000 voxels wanted
  CHECK(r.x == 2 * r.y);
  CHECK(r.y == 2 * r.z);
  CHECK(r == glm::ivec3(32, 16, 8));  // extent · cbrt(4000 / 8) = extent · 7.94 → 31.7, 15.9, 7.9
  const double cells = double(r.x) * r.y * r.z;
  CHECK(cells == doctest::Approx(4000).epsilon(0.1));

  host::Bounds cube;
  cube.extend({-1, -1, -1});
  cube.extend({1, 1, 1});
  CHECK(host::auto_resolution(cube, 848, 4.0) == glm::ivec3(15));  // the paper's Fig. 1 grid
  CHECK(host::auto_resolution(cube, 848) == glm::ivec3(15));       // default density
}

TEST_CASE("Automatic resolution clamps every axis to 1..128") {
  host::Bounds cube;
  cube.extend({0, 0, 0});
  cube.extend({1, 1, 1});
  CHECK(host::auto_resolution(cube, 100000000) == glm::ivec3(128));
  CHECK(host::auto_resolution(cube, 1) == glm::ivec3(2));  // cbrt(4) = 1.59
  CHECK(host::auto_resolution(cube, 0) == glm::ivec3(1));
  CHECK(host::auto_resolution(host::Bounds{}, 10) == glm::ivec3(1));

  host::Bounds needle;  // 1000:1:1 → the thin axes stay at one voxel
  needle.extend({0, 0, 0});
  needle.extend({1000, 1, 1});
  const glm::ivec3 r = host::auto_resolution(needle, 10, 4.0);
  CHECK(r == glm::ivec3(40, 1, 1));  // the whole 40-voxel budget goes along x
}

TEST_CASE("Automatic resolution gives a flat scene one voxel across and the budget in its plane") {
  host::Bounds flat;
  flat.extend({0, 0, 5});
  flat.extend({2, 1, 5});
  const glm::ivec3 r = host::auto_resolution(flat, 200, 4.0);  // 800 voxels in a 2:1 plane
  CHECK(r == glm::ivec3(40, 20, 1));
}

// ---- Bounds ----

TEST_CASE("Grid bounds are the scene bounds padded on every side, even along a flat axis") {
  const Scene flat = make_scene({{{0, 0, 3}, {10, 0, 3}, {0, 5, 3}}});
  const Grid g = host::build_grid(flat, host::parse_grid_spec("4"));
  const host::Bounds b = flat.bounds();
  for (int a = 0; a < 3; ++a) {
    CHECK(g.lo[a] < b.lo[a]);
    CHECK(g.hi[a] > b.hi[a]);
    CHECK(g.cell[a] > 0.0f);
  }
  const double diag = std::sqrt(125.0);
  CHECK(double(g.hi.z) - double(g.lo.z) ==
        doctest::Approx(2 * host::kScenePadRelative * diag).epsilon(0.01));
  CHECK(voxels_of(g, 0).size() > 0);
}

TEST_CASE("Grid padding survives float rounding for a small scene far from the origin") {
  const glm::vec3 o(1.0e6f, -2.0e6f, 3.0e6f);
  const Scene s = make_scene({{o, o + glm::vec3(1, 0, 0), o + glm::vec3(0, 1, 0.5f)}});
  const Grid g = host::build_grid(s, host::parse_grid_spec("auto"));
  const host::Bounds b = s.bounds();
  for (int a = 0; a < 3; ++a) {
    CHECK(g.lo[a] < b.lo[a]);
    CHECK(g.hi[a] > b.hi[a]);
  }
  CHECK(g.references() >= 1);
}

// ---- Triangle/voxel overlap ----

TEST_CASE("The triangle-box test agrees with clipping the triangle against the box") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coord(-1.5, 1.5);
  int overlaps = 0;
  for (int i = 0; i < 20000; ++i) {
    const glm::dvec3 tri[3] = {{coord(rng), coord(rng), coord(rng)},
                               {coord(rng), coord(rng), coord(rng)},
                               {coord(rng), coord(rng), coord(rng)}};
    const glm::dvec3 lo(-0.5, -0.3, -0.4), hi(0.5, 0.2, 0.6);
    const bool sat = host::triangle_box_overlap(tri, lo, hi);
    CHECK(sat == overlap_by_clipping(tri, lo, hi));
    overlaps += sat;
  }
  CHECK(overlaps > 2000);  // both outcomes well represented
  CHECK(overlaps < 18000);
}

TEST_CASE("A single triangle is listed in exactly the voxels it overlaps") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> coord(0.1f, 7.9f);
  for (int i = 0; i < 40; ++i) {
    const Scene s = make_scene({{{coord(rng), coord(rng), coord(rng)},
                                 {coord(rng), coord(rng), coord(rng)},
                                 {coord(rng), coord(rng), coord(rng)}}});
    const Grid g = box_grid(s, {8, 7, 6}, glm::vec3(8.0f));
    CAPTURE(i);
    CHECK(voxels_of(g, 0) == voxels_by_exhaustive_test(g, s, 0));
    // Samples 1/200 of the longest edge apart: a listed voxel is within about a spacing of one.
    const double edge = std::max({glm::length(s.p1[0] - s.p0[0]), glm::length(s.p2[0] - s.p0[0]),
                                  glm::length(s.p2[0] - s.p1[0])});
    check_against_samples(g, s, 0, 200, 2.0 * edge / 200);
  }
}

TEST_CASE("A triangle spanning the whole grid diagonal is listed along the whole diagonal") {
  const Scene s = make_scene({{{0, 0, 0}, {4, 4, 4}, {4, 0, 0}}});
  const Grid g = box_grid(s);
  const std::set<size_t> listed = voxels_of(g, 0);
  CHECK(listed == voxels_by_exhaustive_test(g, s, 0));
  for (int i = 0; i < 4; ++i) CHECK(listed.count(g.index(i, i, i)) == 1);
  CHECK(listed.count(g.index(0, 3, 3)) == 0);  // in its plane y = z but past the edge x = y
  check_against_samples(g, s, 0, 400, 0.03);
}

TEST_CASE("A triangle lying exactly in a voxel face is listed in both voxels") {
  // In the plane z = 2 between voxel layers z = 1 and z = 2, inside column (1, 1).
  const Scene s = make_scene({{{1.2f, 1.2f, 2}, {1.8f, 1.2f, 2}, {1.2f, 1.8f, 2}}});
  const Grid g = box_grid(s);
  CHECK(voxels_of(g, 0) == std::set<size_t>{g.index(1, 1, 1), g.index(1, 1, 2)});
}

TEST_CASE("A triangle touching a voxel edge with one vertex is listed in all four voxels") {
  // Vertex on the edge x = 2, y = 2 (along z); the rest in voxel (1, 1, 1) and above.
  const Scene s = make_scene({{{2, 2, 1.5f}, {1.5f, 1.2f, 1.5f}, {1.2f, 1.5f, 1.6f}}});
  const Grid g = box_grid(s);
  CHECK(voxels_of(g, 0) ==
        std::set<size_t>{g.index(1, 1, 1), g.index(2, 1, 1), g.index(1, 2, 1), g.index(2, 2, 1)});
}

TEST_CASE("A thin sliver triangle is listed in every voxel along its length") {
  const Scene s = make_scene({{{0.1f, 0.5f, 0.5f}, {3.9f, 3.5f, 2.5f}, {3.9f, 3.5001f, 2.5f}}});
  const Grid g = box_grid(s);
  const std::set<size_t> listed = voxels_of(g, 0);
  CHECK(listed == voxels_by_exhaustive_test(g, s, 0));
  // The sliver is almost a segment: it must cover the voxels the segment walks through.
  for (const glm::ivec3& v :
       host::voxel_walk_reference(g, glm::dvec3(s.p0[0]), glm::dvec3(s.p1[0] - s.p0[0]))) {
    CHECK(listed.count(g.index(v)) == 1);
  }
  check_against_samples(g, s, 0, 600, 0.02);
}

TEST_CASE("A large axis-aligned quad is listed in exactly the voxel layers it lies in") {
  const Tri a{{0, 0, 2.5f}, {4, 0, 2.5f}, {4, 4, 2.5f}},
      b{{0, 0, 2.5f}, {4, 4, 2.5f}, {0, 4, 2.5f}};
  const Tri c{{0, 0, 1}, {4, 0, 1}, {4, 4, 1}}, d{{0, 0, 1}, {4, 4, 1}, {0, 4, 1}};
  const Scene s = make_scene({a, b, c, d});
  const Grid g = box_grid(s);
  std::set<size_t> layer2, layers01;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      layer2.insert(g.index(x, y, 2));
      layers01.insert(g.index(x, y, 0));
      layers01.insert(g.index(x, y, 1));
    }
  for (uint32_t t : {0u, 1u}) {
    const std::set<size_t> listed = voxels_of(g, t);
    CHECK(listed == voxels_by_exhaustive_test(g, s, t));
    for (size_t v : listed) CHECK(layer2.count(v) == 1);
  }
  std::set<size_t> quad;  // the two halves together cover the whole layer
  for (uint32_t t : {0u, 1u})
    for (size_t v : voxels_of(g, t)) quad.insert(v);
  CHECK(quad == layer2);
  std::set<size_t> quad_on_plane;  // in the plane z = 1: layers 0 and 1
  for (uint32_t t : {2u, 3u})
    for (size_t v : voxels_of(g, t)) quad_on_plane.insert(v);
  CHECK(quad_on_plane == layers01);
}

TEST_CASE("Bounding-box insertion would over-list a diagonal triangle") {
  const Scene s = make_scene({{{0.1f, 0.1f, 0.1f}, {3.9f, 0.2f, 3.9f}, {0.2f, 3.9f, 3.8f}}});
  const Grid g = box_grid(s);
  const size_t exact = voxels_of(g, 0).size();
  CHECK(exact == voxels_by_exhaustive_test(g, s, 0).size());
  CHECK(exact < 64);  // the bounding box covers all 4 × 4 × 4 voxels
  CHECK(exact >= 16);
}

// ---- CSR layout ----

TEST_CASE("Voxels are numbered x fastest, then y, then z") {
  Grid g;
  g.res = {5, 3, 2};
  CHECK(g.voxels() == 30);
  CHECK(g.index(0, 0, 0) == 0);
  CHECK(g.index(1, 0, 0) == 1);
  CHECK(g.index(0, 1, 0) == 5);
  CHECK(g.index(0, 0, 1) == 15);
  CHECK(g.index(4, 2, 1) == 29);
}

TEST_CASE("The CSR voxel lists are consistent and list every triangle") {
  const Scene s = random_scene(3000, 3, 0.8f);
  const Grid g = host::build_grid(s, host::parse_grid_spec("auto"));
  REQUIRE(g.start.size() == g.voxels() + 1);
  CHECK(g.start.front() == 0);
  CHECK(g.start.back() == g.tris.size());
  CHECK(g.references() == g.tris.size());
  CHECK(g.memory_bytes() == (g.start.size() + g.tris.size()) * 4);
  CHECK(g.build_ms >= 0.0);
  std::vector<int> seen(s.triangle_count(), 0);
  for (size_t v = 0; v < g.voxels(); ++v) {
    REQUIRE(g.start[v] <= g.start[v + 1]);
    auto list = g.triangles_in(v);
    CHECK(std::is_sorted(list.begin(), list.end()));
    CHECK(std::adjacent_find(list.begin(), list.end()) == list.end());  // no duplicates
    for (uint32_t t : list) {
      REQUIRE(t < s.triangle_count());
      ++seen[t];
    }
  }
  CHECK(std::count(seen.begin(), seen.end(), 0) == 0);
  // Spot-check the exact lists against the exhaustive test.
  for (uint32_t t = 0; t < s.triangle_count(); t += 97)
    CHECK(voxels_of(g, t) == voxels_by_exhaustive_test(g, s, t));
}

TEST_CASE("The grid is the same for any thread count") {
  const Scene s = random_scene(20000, 5);  // 4 ranges of 4096+
  const Grid one = host::build_grid(s, host::parse_grid_spec("auto"), 1);
  for (unsigned threads : {2u, 3u, 4u}) {
    const Grid many = host::build_grid(s, host::parse_grid_spec("auto"), threads);
    CAPTURE(threads);
    CHECK(many.res == one.res);
    CHECK(many.lo == one.lo);
    CHECK(many.start == one.start);
    CHECK(many.tris == one.tris);
  }
}

TEST_CASE("A scene without triangles gives one empty voxel") {
  const Grid g = host::build_grid(Scene{}, host::parse_grid_spec("auto"));
  CHECK(g.res == glm::ivec3(1));
  CHECK(g.start == std::vector<uint32_t>{0, 0});
  CHECK(g.references() == 0);
}

// ---- Reference voxel walk ----

namespace {
Grid unit_grid(glm::ivec3 res = glm::ivec3(4)) {  // voxel planes at the integers
  Grid g;
  g.lo = glm::vec3(0.0f);
  g.res = res;
  g.cell = glm::vec3(1.0f);
  g.hi = glm::vec3(res);
  return g;
}
using Walk = std::vector<glm::ivec3>;
}  // namespace

TEST_CASE("An axis-parallel ray walks a straight row of voxels") {
  const Grid g = unit_grid();
  CHECK(host::voxel_walk_reference(g, {-1, 1.5, 2.5}, {1, 0, 0}) ==
        Walk{{0, 1, 2}, {1, 1, 2}, {2, 1, 2}, {3, 1, 2}});
  CHECK(host::voxel_walk_reference(g, {0.5, 0.5, 10}, {0, 0, -2}) ==
        Walk{{0, 0, 3}, {0, 0, 2}, {0, 0, 1}, {0, 0, 0}});
  CHECK(host::voxel_walk_reference(g, {2.5, 3.5, 0.5}, {0, -1, 0}) ==
        Walk{{2, 3, 0}, {2, 2, 0}, {2, 1, 0}, {2, 0, 0}});  // starts inside
}

TEST_CASE("A ray lying in a voxel plane walks the voxels on its positive side") {
  const Grid g = unit_grid();
  CHECK(host::voxel_walk_reference(g, {-1, 2, 0.5}, {1, 0, 0}) ==
        Walk{{0, 2, 0}, {1, 2, 0}, {2, 2, 0}, {3, 2, 0}});
  CHECK(host::voxel_walk_reference(g, {-1, 4, 0.5}, {1, 0, 0}) ==  // on the grid's top face
        Walk{{0, 3, 0}, {1, 3, 0}, {2, 3, 0}, {3, 3, 0}});
}

TEST_CASE("A diagonal ray walks one voxel per plane crossing") {
  const Grid g = unit_grid();
  // Crosses x planes at t = 0.5, 1.5, 2.5, y planes at t = 1, 3, and leaves at x = 4, t = 3.5.
  CHECK(host::voxel_walk_reference(g, {0.5, 0.5, 0.5}, {1, 0.5, 0}) ==
        Walk{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {2, 1, 0}, {3, 1, 0}, {3, 2, 0}});
}

TEST_CASE("A ray through a voxel edge steps diagonally past the side voxels") {
  const Grid g = unit_grid();
  CHECK(host::voxel_walk_reference(g, {0.5, 0.5, 1.5}, {1, 1, 0}) ==
        Walk{{0, 0, 1}, {1, 1, 1}, {2, 2, 1}, {3, 3, 1}});
}

TEST_CASE("A ray through voxel corners steps diagonally in all three axes") {
  const Grid g = unit_grid();
  CHECK(host::voxel_walk_reference(g, {-1, -1, -1}, {1, 1, 1}) ==
        Walk{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}});
  CHECK(host::voxel_walk_reference(g, {4, 0, 4}, {-1, 1, -1}) ==
        Walk{{3, 0, 3}, {2, 1, 2}, {1, 2, 1}, {0, 3, 0}});
}

TEST_CASE("Rays that miss the grid walk no voxels") {
  const Grid g = unit_grid();
  CHECK(host::voxel_walk_reference(g, {-1, 5, 0.5}, {1, 0, 0}).empty());     // parallel, outside
  CHECK(host::voxel_walk_reference(g, {-1, 0.5, 0.5}, {-1, 0, 0}).empty());  // pointing away
  CHECK(host::voxel_walk_reference(g, {6, 5, 0.5}, {-1, 0.2, 0}).empty());   // passes beside
  CHECK(host::voxel_walk_reference(g, {5, 5, 2}, {1, -1, 0}).empty());       // grazes one edge
  CHECK(host::voxel_walk_reference(g, {1, 1, 1}, {0, 0, 0}).empty());        // no direction
}

TEST_CASE("The reference voxel walk matches a dense march along random rays") {
  const Grid g = unit_grid({5, 4, 3});
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int walked = 0;
  for (int i = 0; i < 300; ++i) {
    // From around the grid towards a point in or near it; some start inside, some miss.
    const glm::dvec3 origin(2.5 + 6 * u(rng), 2 + 6 * u(rng), 1.5 + 6 * u(rng));
    const glm::dvec3 target(2.5 + 3 * u(rng), 2 + 2.5 * u(rng), 1.5 + 2 * u(rng));
    const glm::dvec3 dir = (target - origin) * (0.5 + 0.5 * std::abs(u(rng)));
    const Walk walk = host::voxel_walk_reference(g, origin, dir);
    // Voxels of points every 2e-3 world units along the ray: a subsequence of the exact walk
    // (a voxel whose chord is shorter than the step may be skipped, rarely).
    Walk march;
    const double step = 2e-3 / glm::length(dir);
    for (double t = 0; t < 30 / glm::length(dir); t += step) {
      const glm::dvec3 p = origin + t * dir;
      if (p.x < 0 || p.y < 0 || p.z < 0 || p.x >= 5 || p.y >= 4 || p.z >= 3) continue;
      const glm::ivec3 v = g.voxel_of(p);
      if (march.empty() || march.back() != v) march.push_back(v);
    }
    CAPTURE(i);
    size_t k = 0;
    for (const glm::ivec3& v : march) {
      while (k < walk.size() && walk[k] != v) ++k;
      CHECK(k < walk.size());
    }
    CHECK(walk.size() <= march.size() + 2);
    walked += !walk.empty();
  }
  CHECK(walked > 200);
}

// ---- Brute-force hits ----

TEST_CASE("Brute force finds the nearer of two triangles at the known t") {
  // Two parallel triangles facing +z at z = -2 (index 0) and z = -1 (index 1).
  const Scene s = make_scene(
      {{{-1, -1, -2}, {1, -1, -2}, {0, 1, -2}}, {{-1, -1, -1}, {1, -1, -1}, {0, 1, -1}}});
  const host::RefHit hit = host::brute_force_hit(s, {0, 0, 1}, {0, 0, -1});
  CHECK(hit.tri == 1);
  CHECK(hit.t == doctest::Approx(2.0));
  // hit (0, 0, -1) = (1-u-v)·(-1,-1) + u·(1,-1) + v·(0,1) → u = 0.25, v = 0.5
  CHECK(hit.u == doctest::Approx(0.25));
  CHECK(hit.v == doctest::Approx(0.5));

  const host::RefHit scaled = host::brute_force_hit(s, {0, 0, 1}, {0, 0, -2});
  CHECK(scaled.t == doctest::Approx(1.0));  // t in units of |dir|

  const host::RefHit beyond = host::brute_force_hit(s, {0, 0, 1}, {0, 0, -1}, 2.5);
  CHECK(beyond.tri == 0);
  CHECK(beyond.t == doctest::Approx(3.0));

  const host::RefHit back = host::brute_force_hit(s, {0, 0, -5}, {0, 0, 1});  // two-sided
  CHECK(back.tri == 0);
  CHECK(back.t == doctest::Approx(3.0));
}

TEST_CASE("Brute force misses give triangle -1") {
  const Scene s = make_scene({{{-1, -1, -2}, {1, -1, -2}, {0, 1, -2}}});
  CHECK(host::brute_force_hit(s, {0, 0, 1}, {0, 0, 1}).tri == -1);   // behind the origin
  CHECK(host::brute_force_hit(s, {5, 0, 1}, {0, 0, -1}).tri == -1);  // beside
  CHECK(host::brute_force_hit(s, {0, 0, -2}, {1, 0, 0}).tri == -1);  // in the plane
  CHECK(host::brute_force_hit(Scene{}, {0, 0, 0}, {1, 0, 0}).tri == -1);
}

TEST_CASE("Brute force breaks ties in t by the lowest triangle index") {
  // Two triangles sharing the edge x = 0 in the plane z = 0; the ray hits the shared edge.
  const Scene s = make_scene({{{0, -1, 0}, {1, 0, 0}, {0, 1, 0}},
                              {{0, -1, 0}, {0, 1, 0}, {-1, 0, 0}},
                              {{0, -1, 0}, {0, 1, 0}, {-1, 0, 0}}});
  CHECK(host::brute_force_hit(s, {0, 0, 1}, {0, 0, -1}).tri == 0);
  const Scene twins =
      make_scene({{{0, -1, 0}, {0, 1, 0}, {-1, 0, 0}}, {{-1, 0, 0}, {0, -1, 0}, {0, 1, 0}}});
  CHECK(host::brute_force_hit(twins, {-0.2, 0, 1}, {0, 0, -1}).tri == 0);
}

TEST_CASE("The brute-force image equals per-pixel brute-force hits") {
  const Scene s = random_scene(200, 17, 1.0f);
  const glm::dvec3 origin(5, 5, -10);
  auto dir_of = [](int x, int y) { return glm::dvec3((x - 16) / 20.0, (y - 12) / 20.0, 1.0); };
  const std::vector<host::RefHit> image = host::brute_force_image(s, dir_of, origin, 32, 24);
  REQUIRE(image.size() == 32 * 24);
  int hits = 0;
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 32; ++x) {
      const host::RefHit a = image[size_t(y) * 32 + x],
                         b = host::brute_force_hit(s, origin, dir_of(x, y));
      CHECK(a.tri == b.tri);
      CHECK(a.t == b.t);
      hits += a.tri >= 0;
    }
  CHECK(hits > 20);
}
