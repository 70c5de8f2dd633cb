// Numerical stability of the stream tracer at fp32 on hand-built scenes with known answers
// (tests/trace/stability_cases.h): axis-parallel rays, voxel edges and corners, triangles in voxel
// faces, closed meshes and fans without cracks, grazing hits, reflection acne, the camera inside
// the grid, misses, scenes far from the origin, very thin and very large triangles.
// Each case checks (1) the analytic expectation against brute_force_hit in double, (2) the stream
// tracer at fp32 against the expectation, pixel for pixel, with no unfinished rays, and (3) at
// fp24 and fp16, the written-down count of wrong pixels (zero where the case fits the format).
#include <doctest/doctest.h>

#include <string>
#include <tuple>

#include "stability_cases.h"
#include "tests/support/reference.h"

namespace {

const stability::Case& find_case(const std::string& name) {
  static const std::vector<stability::Case> all = stability::cases();
  for (const auto& c : all)
    if (c.name == name) return c;
  FAIL("no stability case named " << name);
  static stability::Case none;
  return none;
}

void check_case(const std::string& name) {
  const stability::Case& c = find_case(name);
  REQUIRE(c.expected.size() == size_t(c.width) * c.height);
  // (1) The analytic answer agrees with brute force in double.
  int demanded = 0;
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) {
      const int e = c.expected[size_t(y) * c.width + x];
      if (e == stability::kDontCare) continue;
      ++demanded;
      const host::RefHit h =
          host::brute_force_hit(c.scene, glm::dvec3(c.camera.position),
                                host::cpu_primary_dir(c.camera, c.width, c.height, x, y));
      const int bf = h.tri < 0 ? -1 : int(c.scene.id[size_t(h.tri)]);
      INFO(name << ": brute force at pixel (" << x << ", " << y << ")");
      CHECK(stability::accepts(c, e, bf));
    }
  CHECK(demanded > 0);
  // (2) The stream tracer at fp32 gives exactly the expected ids.
  const stability::Outcome o = stability::run(c, vgpu::Format::fp32);
  REQUIRE_MESSAGE(o.error.empty(), o.error);
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) {
      const size_t i = size_t(y) * c.width + x;
      INFO(name << ": stream fp32 at pixel (" << x << ", " << y << ") expected " << c.expected[i]
                << " got " << o.got[i]);
      CHECK(stability::accepts(c, c.expected[i], o.got[i]));
    }
  CHECK(o.wrong == 0);
  CHECK(o.colour_wrong == 0);
  CHECK(o.unfinished == 0);
}

}  // namespace

TEST_CASE("the stability cases cover each probe with demanded pixels") {
  const auto all = stability::cases();
  CHECK(all.size() >= 18);
  for (const auto& c : all) {
    int hits = 0, misses = 0;
    for (int e : c.expected) {
      hits += e >= 0 || e == stability::kAnyMesh;
      misses += e == stability::kMiss;
    }
    INFO(c.name);
    CHECK(hits + misses > 0);
  }
}

TEST_CASE("rays parallel to one axis hit an axis-aligned quad") {
  check_case("rays parallel to one axis hit an axis-aligned quad");
}
TEST_CASE("rays parallel to a coordinate plane and lying in the voxel plane y = 2 hit a wall") {
  check_case("rays parallel to a coordinate plane and lying in the voxel plane y = 2 hit a wall");
}
TEST_CASE("a ray running along a voxel edge hits the triangle below it") {
  check_case("a ray running along a voxel edge hits the triangle below it");
}
TEST_CASE("a diagonal ray through voxel corners hits the triangle behind them") {
  check_case("a diagonal ray through voxel corners hits the triangle behind them");
}
TEST_CASE("a quad lying exactly in a voxel face is hit") {
  check_case("a quad lying exactly in a voxel face is hit");
}
TEST_CASE("a triangle spanning the whole grid is hit everywhere it is seen") {
  check_case("a triangle spanning the whole grid is hit everywhere it is seen");
}
TEST_CASE("a hit just outside the current voxel is not taken before a nearer one") {
  check_case("a hit just outside the current voxel is not taken before a nearer one");
}
// These cases found a crack: both triangles sharing an edge computed u + v = 1 + 2^-23 and
// refused the ray; intersect_triangle now widens edges by kEdgeEps (kernels/common.h).
TEST_CASE("a closed octahedron has no cracks along its shared edges and vertices") {
  check_case("a closed octahedron has no cracks along its shared edges and vertices");
}
TEST_CASE("a triangle fan has no cracks at its spokes and centre") {
  check_case("a triangle fan has no cracks at its spokes and centre");
}
TEST_CASE("grazing rays hit the floor they skim") {
  check_case("grazing rays hit the floor they skim");
}
TEST_CASE("a mirror facing a red wall shows the wall, never itself") {
  check_case("a mirror facing a red wall shows the wall, never itself");
}
TEST_CASE("a camera inside a closed cube sees a wall in every pixel") {
  check_case("a camera inside a closed cube sees a wall in every pixel");
}
TEST_CASE("rays that miss the grid miss") {
  check_case("rays that miss the grid miss");
}
TEST_CASE("rays pointing away from the grid miss") {
  check_case("rays pointing away from the grid miss");
}
TEST_CASE("a scene far from the origin: a quad in a voxel face at 1e4") {
  check_case("a quad lying exactly in a voxel face is hit at 1e4");
}
TEST_CASE("a scene far from the origin: a closed octahedron at 1e4") {
  check_case("a closed octahedron has no cracks along its shared edges and vertices at 1e4");
}
TEST_CASE("a scene far from the origin: a quad in a voxel face at 1e5") {
  check_case("a quad lying exactly in a voxel face is hit at 1e5");
}
TEST_CASE("a scene far from the origin: a closed octahedron at 1e5") {
  check_case("a closed octahedron has no cracks along its shared edges and vertices at 1e5");
}
TEST_CASE("a very thin triangle is hit across its width") {
  check_case("a very thin triangle is hit across its width");
}
TEST_CASE("a very large triangle behind a small one is hit around it") {
  check_case("a very large triangle behind a small one is hit around it");
}

namespace {

// Known outcomes at reduced precision (docs/studies/stability.md): hit ids wrong at fp24 and at
// fp16, and the mirror's colour failures at fp16. Cases not listed pass at both. No case leaves
// rays unfinished. A change of the rounding rules (vgpu/format.h) or of a kernel's arithmetic moves
// these counts.
struct Known {
  const char* name;
  int fp24_wrong, fp16_wrong, fp16_colour_wrong;
};
constexpr Known kReduced[] = {
    {"a closed octahedron has no cracks along its shared edges and vertices", 3, 0, 0},
    {"a mirror facing a red wall shows the wall, never itself", 0, 0, 1},
    {"a quad lying exactly in a voxel face is hit at 1e4", 3, 28, 0},
    {"a closed octahedron has no cracks along its shared edges and vertices at 1e4", 3, 145, 0},
    {"a quad lying exactly in a voxel face is hit at 1e5", 28, 27, 0},
    {"a closed octahedron has no cracks along its shared edges and vertices at 1e5", 79, 145, 0},
    {"a very thin triangle is hit across its width", 0, 4, 0},
    {"a very large triangle behind a small one is hit around it", 0, 68, 0},
};

}  // namespace

TEST_CASE("every stability case at fp24 and fp16 gives its written-down outcome") {
  for (const stability::Case& c : stability::cases()) {
    Known k{c.name.c_str(), 0, 0, 0};
    for (const Known& r : kReduced)
      if (c.name == r.name) k = r;
    for (auto [bound_f, bound_wrong, bound_colour] :
         {std::tuple{vgpu::Format::fp24, k.fp24_wrong, 0},
          std::tuple{vgpu::Format::fp16, k.fp16_wrong, k.fp16_colour_wrong}}) {
      // Named copies: clang 14 cannot capture a structured binding (CAPTURE, INFO).
      const auto& f = bound_f;
      const auto& wrong = bound_wrong;
      const auto& colour = bound_colour;
      INFO(c.name << " at " << vgpu::format_name(f));
      const stability::Outcome o = stability::run(c, f);
      REQUIRE_MESSAGE(o.error.empty(), o.error);
      CHECK(o.wrong == wrong);
      CHECK(o.colour_wrong == colour);
      CHECK(o.unfinished == 0);
    }
  }
}
