// End-to-end tests of the stream ray tracer on the virtual GPU: primary hits and depths against
// brute-force double-precision ray casting (host/reference), on a hand-built scene and on the
// bunny; and invariance of images and statistics under threads, lane widths, the emulator's host
// shortcut, early-z masks and the grid resolution.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "host/accel/grid.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/stream_tracer.h"
#include "tests/support/bits.h"
#include "tests/support/reference.h"

using host::RefHit;
using host::RenderOptions;
using host::RenderResult;
using host::Scene;

using test_support::same_bits;

namespace {

// Builds a Scene triangle by triangle: flat normals, input ids 10, 13, 16, ... (not the internal
// order, so a missing id mapping shows).
struct SceneBuilder {
  Scene s;
  void tri(glm::vec3 a, glm::vec3 b, glm::vec3 c, uint32_t material) {
    s.add_flat_triangle(a, b, c, material, 10 + 3 * uint32_t(s.id.size()));
    s.input_triangles = 10 + 3 * uint32_t(s.id.size());
  }
  void quad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, uint32_t material) {
    tri(a, b, c, material);
    tri(a, c, d, material);
  }
};

// A floor, a back wall, a floating axis-aligned quad, a tilted quad, a tilted triangle and a
// small triangle in front of the others; some surfaces reflective; one light.
Scene test_scene() {
  SceneBuilder b;
  b.s.name = "test scene";
  b.s.materials = {{{0.7f, 0.7f, 0.7f}, 0.3f},
                   {{0.2f, 0.3f, 0.8f}, 0.5f},
                   {{0.8f, 0.2f, 0.1f}, 0.0f},
                   {{0.2f, 0.8f, 0.3f}, 0.2f}};
  b.quad({-3, 0, 2}, {3, 0, 2}, {3, 0, -4}, {-3, 0, -4}, 0);                // floor y = 0
  b.quad({-3, 0, -4}, {3, 0, -4}, {3, 3, -4}, {-3, 3, -4}, 1);              // back wall z = -4
  b.quad({-1, 0.5f, -1}, {0, 0.5f, -1}, {0, 1.5f, -1}, {-1, 1.5f, -1}, 2);  // quad z = -1
  b.quad({-2.2f, 0.3f, -2.5f}, {-1.2f, 0.3f, -1.7f}, {-1.2f, 1.8f, -2.0f}, {-2.2f, 1.8f, -2.8f}, 3);
  b.tri({0.5f, 0.2f, -0.5f}, {1.8f, 0.4f, -1.5f}, {1.0f, 1.6f, -1.0f}, 3);
  b.tri({-0.3f, 1.0f, 0.5f}, {0.4f, 1.1f, 0.3f}, {0.0f, 1.7f, 0.6f}, 2);
  b.s.lights = {{{2, 5, 3}, {1, 1, 1}}};
  return b.s;
}

host::Camera test_camera() {
  host::Camera cam;
  cam.position = {0.2f, 1.5f, 5};
  cam.forward = glm::normalize(glm::vec3(0, 0.9f, -1.5f) - cam.position);
  cam.up =
      glm::normalize(glm::vec3(0, 1, 0) - glm::dot(glm::vec3(0, 1, 0), cam.forward) * cam.forward);
  cam.yfov = 0.9f;
  return cam;
}

RenderResult render(const Scene& scene, const host::Grid& grid, const host::Camera& cam,
                    RenderOptions opt) {
  host::StreamTracer tracer(scene, grid, opt);
  return tracer.render(cam);
}

RenderOptions primary_only(int w, int h) {
  RenderOptions opt;
  opt.width = w;
  opt.height = h;
  opt.bounces = 0;
  opt.shadows = false;
  opt.shading = kernels::ShadingModel::diffuse;
  opt.threads = 1;
  return opt;
}

// The whole pipeline: 2 bounces, shadow rays, phong, one thread.
RenderOptions full_pipeline(int w, int h) {
  RenderOptions opt;
  opt.width = w;
  opt.height = h;
  opt.bounces = 2;
  opt.shadows = true;
  opt.threads = 1;
  return opt;
}

// How close the ray passes to a triangle edge where that matters: the smallest |barycentric
// margin| min(u, v, 1 - u - v) over the triangles whose plane the ray crosses at 0 < t <= the
// brute-force hit (every t for a miss). Small for a hit near its triangle's edge (the hit lies in
// the triangle, margin >= 0) and for a near-miss of a triangle in front of the hit (a silhouette):
// there float and double may disagree on which triangle is hit.
double edge_margin(const Scene& s, glm::dvec3 o, glm::dvec3 d, const RefHit& hit) {
  const double tmax = hit.tri >= 0 ? hit.t * (1 + 1e-9) : std::numeric_limits<double>::infinity();
  double m = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < s.triangle_count(); ++i) {
    const glm::dvec3 p0(s.p0[i]), e1 = glm::dvec3(s.p1[i]) - p0, e2 = glm::dvec3(s.p2[i]) - p0;
    const glm::dvec3 p = glm::cross(d, e2);
    const double det = glm::dot(e1, p);
    if (det == 0) continue;
    const glm::dvec3 sv = o - p0, q = glm::cross(sv, e1);
    const double u = glm::dot(sv, p) / det, v = glm::dot(d, q) / det, t = glm::dot(e2, q) / det;
    if (t > 0 && t <= tmax) m = std::min(m, std::abs(std::min({u, v, 1 - u - v})));
  }
  return m;
}

struct Comparison {
  int pixels = 0;
  int hits = 0;               // pixels the brute force hits
  int excluded_hit_edge = 0;  // brute-force hit within `margin` of its triangle's edge
  int excluded_near = 0;      // ... or a near-missed triangle in front within `margin`
  int mismatches = 0;         // id mismatches on pixels not excluded
  int mismatches_all = 0;     // id mismatches over every pixel
  int depth_errors = 0;       // depth off by more than 1e-4 relative where the ids match
};

// The tracer's primary hits against brute_force_image over the same rays (host::primary_dir).
Comparison compare_primary(const Scene& scene, const host::Camera& cam, const RenderResult& r,
                           double margin) {
  const int W = r.width, H = r.height;
  const glm::dvec3 o(cam.position);
  auto dir = [&](int x, int y) {
    return glm::dvec3(host::primary_dir(cam, W, H, float(x), float(y)));
  };
  const std::vector<RefHit> ref = host::brute_force_image(scene, dir, o, W, H);
  Comparison c;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const size_t i = size_t(y) * W + x;
      const RefHit& h = ref[i];
      const float want = h.tri >= 0 ? float(scene.id[size_t(h.tri)]) : -1.0f;
      ++c.pixels;
      c.hits += h.tri >= 0;
      const bool match = r.hit_id[i] == want;
      c.mismatches_all += !match;
      const bool hit_edge = h.tri >= 0 && std::min({h.u, h.v, 1 - h.u - h.v}) <= margin;
      const bool near = hit_edge || edge_margin(scene, o, dir(x, y), h) <= margin;
      c.excluded_hit_edge += hit_edge;
      c.excluded_near += near;
      if (near) continue;
      if (!match) {
        ++c.mismatches;
        MESSAGE("pixel (" << x << ", " << y << "): tracer " << r.hit_id[i] << ", reference "
                          << want);
        continue;
      }
      const double depth = h.tri >= 0 ? h.t : 0.0;
      if (std::abs(r.depth[i] - depth) > 1e-4 * depth) ++c.depth_errors;
    }
  return c;
}

// Same image, depth and hit buffers bit for bit, and every integer statistic equal, in total and
// per program.
void check_identical(const RenderResult& a, const RenderResult& b) {
  CHECK(same_bits(a.rgb, b.rgb));
  CHECK(same_bits(a.depth, b.depth));
  CHECK(same_bits(a.hit_id, b.hit_id));
  CHECK(a.iterations == b.iterations);
  CHECK(a.rays_traced == b.rays_traced);
  CHECK(a.stats.totals.same_counts(b.stats.totals));
  REQUIRE(a.stats.programs.size() == b.stats.programs.size());
  for (size_t p = 0; p < a.stats.programs.size(); ++p) {
    CAPTURE(a.stats.programs[p].name);
    CHECK(a.stats.programs[p].name == b.stats.programs[p].name);
    CHECK(a.stats.programs[p].instructions == b.stats.programs[p].instructions);
    CHECK(a.stats.programs[p].counters.same_counts(b.stats.programs[p].counters));
  }
}

}  // namespace

TEST_CASE("primary hits and depths of the stream tracer match brute-force ray casting") {
  const Scene scene = test_scene();
  const host::Grid grid = host::build_grid(scene, host::GridSpec{});
  host::Camera cam = test_camera();
  SUBCASE("camera outside the grid") {}
  SUBCASE("camera inside the grid") {
    cam.position = {0.3f, 1.2f, 1.5f};
  }
  const RenderResult r = render(scene, grid, cam, primary_only(64, 48));
  const Comparison c = compare_primary(scene, cam, r, 1e-4);
  MESSAGE("hand-built scene 64x48: "
          << c.hits << " hits; excluded near an edge: " << c.excluded_hit_edge
          << " (hit margin <= 1e-4), " << c.excluded_near << " (with near-misses in front); "
          << "id mismatches: " << c.mismatches << " of the rest, " << c.mismatches_all
          << " over every pixel");
  CHECK(c.hits > c.pixels / 3);
  CHECK(c.hits < c.pixels);  // some rays miss everything
  CHECK(c.mismatches == 0);
  CHECK(c.depth_errors == 0);
  CHECK(c.excluded_near <= c.pixels / 100);
}

TEST_CASE("on the bunny the stream tracer's primary hits match brute force away from edges") {
  const Scene scene = host::load_scene(VGPU_SCENES_DIR "/bunny.gltf");
  REQUIRE(scene.camera.has_value());
  const host::Grid grid = host::build_grid(scene, host::GridSpec{});
  const RenderResult r = render(scene, grid, *scene.camera, primary_only(64, 64));
  const Comparison c = compare_primary(scene, *scene.camera, r, 1e-3);
  MESSAGE("bunny 64x64: " << c.hits << " hits; excluded (margin <= 1e-3): " << c.excluded_hit_edge
                          << " by the hit's own margin, " << c.excluded_near
                          << " with near-misses in front; id mismatches: " << c.mismatches
                          << " of the rest, " << c.mismatches_all << " over every pixel");
  CHECK(c.hits > 500);
  CHECK(c.mismatches == 0);
  CHECK(c.depth_errors == 0);
}

TEST_CASE("images and statistics are bit-identical for 1 and 3 threads and 1 and 8 lanes") {
  const Scene scene = test_scene();
  const host::Grid grid = host::build_grid(scene, host::GridSpec{});
  // 72x64 = 4608 fragments: passes are split over threads from 4096 on.
  RenderOptions opt = full_pipeline(72, 64);
  opt.lanes = 1;
  const RenderResult ref = render(scene, grid, test_camera(), opt);
  CHECK(ref.iterations == 3);
  for (auto [bound_threads, bound_lanes] : {std::pair{3, 8}, std::pair{1, 8}, std::pair{3, 1}}) {
    // Named copies: clang 14 cannot capture a structured binding (CAPTURE, INFO).
    const auto& threads = bound_threads;
    const auto& lanes = bound_lanes;
    CAPTURE(threads);
    CAPTURE(lanes);
    opt.threads = threads;
    opt.lanes = lanes;
    check_identical(ref, render(scene, grid, test_camera(), opt));
  }
}

TEST_CASE("the emulator's host shortcut changes neither the image nor any statistic") {
  const Scene scene = test_scene();
  const host::Grid grid = host::build_grid(scene, host::GridSpec{});
  RenderOptions opt = full_pipeline(40, 30);
  opt.host_shortcut = true;
  const RenderResult with = render(scene, grid, test_camera(), opt);
  opt.host_shortcut = false;
  check_identical(with, render(scene, grid, test_camera(), opt));
}

TEST_CASE("early-z masks give the same image while masking fragments that would have been shaded") {
  const Scene scene = test_scene();
  const host::Grid grid = host::build_grid(scene, host::GridSpec{});
  RenderOptions opt = full_pipeline(40, 30);
  opt.masks = false;
  const RenderResult plain = render(scene, grid, test_camera(), opt);
  opt.masks = true;
  const RenderResult masked = render(scene, grid, test_camera(), opt);
  CHECK(same_bits(plain.rgb, masked.rgb));
  CHECK(same_bits(plain.depth, masked.depth));
  CHECK(same_bits(plain.hit_id, masked.hit_id));
  CHECK(plain.stats.totals.fragments_masked == 0);
  CHECK(masked.stats.totals.fragments_masked > 0);
  CHECK(masked.stats.totals.fragments_shaded < plain.stats.totals.fragments_shaded);
  CHECK(masked.stats.totals.fragments_launched == plain.stats.totals.fragments_launched);
  CHECK(masked.stats.totals.passes == plain.stats.totals.passes);
}

TEST_CASE("grid resolutions 1x1x1, 8x8x8 and auto give the same hit buffer") {
  const Scene scene = test_scene();
  const host::Camera cam = test_camera();
  const RenderOptions opt = primary_only(64, 48);
  const RenderResult r_auto = render(scene, host::build_grid(scene, host::GridSpec{}), cam, opt);
  const host::Grid g1 = host::build_grid(scene, host::GridSpec{glm::ivec3(1)});
  const host::Grid g8 = host::build_grid(scene, host::GridSpec{glm::ivec3(8)});
  // Voxel planes at the integers: the floor y = 0 and the quad z = -1 lie in voxel faces, the
  // back wall z = -4 in the grid's outer face.
  const host::Grid g_faces =
      host::build_grid_in_box(scene, glm::vec3(-4.0f), glm::vec3(4.0f), glm::ivec3(8));
  const RenderResult r1 = render(scene, g1, cam, opt);
  const RenderResult r8 = render(scene, g8, cam, opt);
  const RenderResult r_faces = render(scene, g_faces, cam, opt);
  CHECK(same_bits(r1.hit_id, r_auto.hit_id));
  CHECK(same_bits(r8.hit_id, r_auto.hit_id));
  CHECK(same_bits(r_faces.hit_id, r_auto.hit_id));
  // One voxel: every ray is done after one traversal step; 8x8x8 walks several voxels.
  CHECK(r1.stats.find("traversal")->counters.passes == 1);
  CHECK(r8.stats.find("traversal")->counters.passes > 1);
}
