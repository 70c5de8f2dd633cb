// Glass on the virtual GPU (issue 25): the ray streams of host/trace/stream/ray_streams.h end to
// end. A glass slab in front of a wall, seen along its axis, against Whitted's recursion in double
// written out here (every hit on the axis is at normal incidence); levels longer than one
// chunk; shadow rays through glass; the paper's reflections through the streams; and the same
// images and statistics for any thread count, lane width and walk.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "host/accel/grid.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/stream_tracer.h"
#include "tests/support/bits.h"
#include "tests/support/lane_widths.h"

using host::RenderOptions;
using host::RenderResult;
using host::Scene;

using test_support::same_bits;

namespace {

constexpr int kSize = 33;  // odd: the centre pixel's ray is the camera's axis
constexpr double kIor = 1.5;
const glm::dvec3 kWall{0.8, 0.6, 0.4}, kGlass{0.9, 0.9, 0.9};
constexpr double kAmbient = 0.1;  // the shader's default

// Camera at z = 5 looking down -z; the light at the camera. Glass slab between z = 1 (front,
// winding normal +z) and z = 0 (back, -z); a diffuse wall at z = -2. The quads' diagonals miss
// the axis.
Scene slab_scene(float transmission) {
  Scene s;
  s.name = "glass slab";
  s.materials = {{glm::vec3(kWall), 0.0f}, {glm::vec3(kGlass), 0.0f}};
  s.materials[1].transmission = transmission;
  s.materials[1].ior = float(kIor);
  uint32_t id = 0;
  auto quad = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, uint32_t m) {
    s.add_flat_triangle(a, b, c, m, id++);
    s.add_flat_triangle(a, c, d, m, id++);
  };
  quad({-4, -4, 1}, {5, -4, 1}, {5, 4, 1}, {-4, 4, 1}, 1);      // front, +z
  quad({-4, -4, 0}, {-4, 4, 0}, {5, 4, 0}, {5, -4, 0}, 1);      // back, -z
  quad({-6, -6, -2}, {7, -6, -2}, {7, 6, -2}, {-6, 6, -2}, 0);  // wall, +z
  s.input_triangles = id;
  s.lights = {{{0, 0, 5}, {1, 1, 1}}};
  return s;
}

host::Camera axis_camera() {
  host::Camera cam;
  cam.position = {0, 0, 5};
  cam.forward = {0, 0, -1};
  cam.up = {0, 1, 0};
  cam.yfov = 0.6f;
  return cam;
}

// Whitted's recursion along the axis, in double: surface s (0 front, 1 back, 2 wall) met going
// dir (-1: down -z, away from the light; +1: up) with weight w, at path depth `depth`.
double axis_colour(int channel, double t, int s, int dir, double w, int depth, int bounces) {
  const double z[3] = {1, 0, -2};
  const bool glass[3] = {true, true, false};
  const double kd = glass[s] ? kGlass[channel] : kWall[channel];
  const double ts = glass[s] ? t : 0.0;
  // Lit only from the side facing the light (+z); the shadow ray from the lifted point up to
  // the light crosses each glass surface above it (multiplied by t).
  double vis = 1;
  for (int g = 0; g < 2; ++g)
    if (z[g] > z[s] || (dir > 0 && z[g] == z[s])) vis *= t;
  const double lit = dir < 0 ? vis : 0.0;
  double c = w * (1 - ts) * kd * (kAmbient + lit);
  if (depth == bounces || !glass[s]) return c;  // the wall is no mirror (a = 0)
  const double f = std::pow((kIor - 1) / (kIor + 1), 2);
  const double wr = w * t * f, wt = w * t * (1 - f);
  auto next = [&](int from, int d) { return d < 0 ? (from < 2 ? from + 1 : -1) : from - 1; };
  if (wr >= 1.0 / 512 && next(s, -dir) >= 0)
    c += axis_colour(channel, t, next(s, -dir), -dir, wr, depth + 1, bounces);
  if (wt >= 1.0 / 512 && next(s, dir) >= 0)
    c += axis_colour(channel, t, next(s, dir), dir, wt, depth + 1, bounces);
  return c;
}

RenderOptions glass_options() {
  RenderOptions opt;
  opt.width = opt.height = kSize;
  opt.shading = kernels::ShadingModel::diffuse;
  return opt;
}

RenderResult render(const Scene& scene, RenderOptions opt) {
  const host::Grid grid = host::build_grid(scene, host::GridSpec{});
  host::StreamTracer tracer(scene, grid, opt);
  return tracer.render(axis_camera());
}

glm::dvec3 centre(const RenderResult& r) {
  const size_t i = (size_t(kSize / 2) * kSize + kSize / 2) * 3;
  return {r.rgb[i], r.rgb[i + 1], r.rgb[i + 2]};
}

}  // namespace

TEST_CASE("a clear slab passes 0.96 x 0.96 of the wall's light, and its shadow lets the light by") {
  const RenderResult r = render(slab_scene(1.0f), glass_options());
  // Front face: reflected 0.04 (back to the sky, black), refracted 0.96; back face the same;
  // the wall lit through both faces (shadow transmittance 1 x 1) plus ambient.
  const glm::dvec3 c = centre(r);
  for (int ch = 0; ch < 3; ++ch) {
    CAPTURE(ch);
    CHECK(c[ch] == doctest::Approx(0.96 * 0.96 * (kAmbient + 1.0) * kWall[ch]).epsilon(1e-5));
    CHECK(c[ch] == doctest::Approx(axis_colour(ch, 1.0, 0, -1, 1.0, 0, 2)).epsilon(1e-5));
  }
  REQUIRE(r.streams.on);
  REQUIRE(r.streams.levels.size() == 3);
  const uint64_t pixels = uint64_t(kSize) * kSize;
  CHECK(r.streams.levels[0].rays == pixels);
  CHECK(r.streams.levels[0].refracted == pixels);
  CHECK(r.streams.levels[0].reflected == pixels);  // 0.04 and more: over the cut
  CHECK(r.streams.levels[1].rays == 2 * pixels);
  CHECK(r.streams.levels[1].chunks == 2);
  CHECK(r.streams.levels[0].total_internal == 0);
  CHECK(r.streams.shadow_continued > 0);
}

TEST_CASE("a half-clear slab matches Whitted's recursion over three levels of two chunks") {
  for (int bounces : {1, 2, 3}) {
    CAPTURE(bounces);
    RenderOptions opt = glass_options();
    opt.bounces = bounces;
    const RenderResult r = render(slab_scene(0.5f), opt);
    const glm::dvec3 c = centre(r);
    for (int ch = 0; ch < 3; ++ch) {
      CAPTURE(ch);
      CHECK(c[ch] == doctest::Approx(axis_colour(ch, 0.5, 0, -1, 1.0, 0, bounces)).epsilon(1e-5));
    }
    CHECK(r.streams.levels.size() == size_t(bounces + 1));
    CHECK(r.iterations == bounces + 1);
  }
}

TEST_CASE("glass frames are bit-identical for threads, lanes, walks and masks") {
  const Scene scene = slab_scene(0.5f);
  RenderOptions opt = glass_options();
  opt.width = 72;  // 72x64: passes split over threads, six 32x32 batch-walk tiles
  opt.height = 64;
  opt.threads = 1;
  opt.lanes = 1;
  opt.batch_walk = false;
  const RenderResult ref = render(scene, opt);
  struct Variant {
    int threads, lanes;
    bool batches;
  };
  for (const Variant v : {Variant{3, 8, true}, Variant{2, 8, false}, Variant{1, 4, false}}) {
    if (!test_support::kernel_width_built(v.lanes)) continue;
    CAPTURE(v.threads);
    CAPTURE(v.lanes);
    CAPTURE(v.batches);
    opt.threads = v.threads;
    opt.lanes = v.lanes;
    opt.batch_walk = v.batches;
    const RenderResult r = render(scene, opt);
    CHECK(same_bits(ref.rgb, r.rgb));
    CHECK(same_bits(ref.hit_id, r.hit_id));
    CHECK(ref.stats.totals.same_counts(r.stats.totals));
    CHECK(ref.streams.levels.size() == r.streams.levels.size());
  }
  // Masks skip finished rays' fragments: the image stays.
  opt.masks = true;
  CHECK(same_bits(ref.rgb, render(scene, opt).rgb));
}

TEST_CASE("the paper's reflections through ray streams give the paper's image on bunny-refl") {
  const Scene scene = host::load_scene(VGPU_SCENES_DIR "/bunny-refl.gltf");
  REQUIRE(scene.camera.has_value());
  const host::Grid grid = host::build_grid(scene, host::GridSpec{});
  RenderOptions opt;
  opt.width = opt.height = 48;
  host::StreamTracer paper(scene, grid, opt);
  const RenderResult a = paper.render(*scene.camera);
  opt.ray_streams = true;
  host::StreamTracer streams(scene, grid, opt);
  const RenderResult b = streams.render(*scene.camera);
  CHECK_FALSE(a.streams.on);
  REQUIRE(b.streams.on);
  CHECK(same_bits(a.hit_id, b.hit_id));
  CHECK(same_bits(a.depth, b.depth));
  // Only the order of the additions differs: (C0 + C1) + C2 against C0 + (C1 + C2).
  double worst = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i)
    worst = std::max(worst, std::abs(double(a.rgb[i]) - double(b.rgb[i])));
  CHECK(worst < 1e-5);
  // The reflected rays the paper traces are the streams' levels 1 and 2.
  CHECK(b.streams.levels[0].refracted == 0);
  CHECK(b.streams.levels[1].rays == b.streams.levels[0].reflected);
  CHECK(b.streams.levels[1].rays > 0);
}
