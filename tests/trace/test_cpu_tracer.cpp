// Tests for host/cpu_tracer: known-answer renders, the hit buffer against the brute-force
// reference, thread-count independence, the blend formula, and agreement with the stream tracer.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "host/accel/grid.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/cpu/cpu_tracer.h"
#include "host/trace/stream/stream_tracer.h"
#include "tests/support/reference.h"

namespace {

using host::Camera;
using host::CpuStats;
using host::RenderOptions;
using host::RenderResult;
using host::Scene;
using kernels::ShadingModel;

struct Tri {
  glm::vec3 a, b, c;
  uint32_t material = 0;
};

// Flat-shaded triangles, ids 0, 1, 2, ... in order.
Scene make_scene(const std::vector<Tri>& tris, std::vector<host::Material> materials,
                 std::vector<host::PointLight> lights) {
  Scene s;
  for (const Tri& t : tris) {
    s.add_flat_triangle(t.a, t.b, t.c, t.material, uint32_t(s.id.size()));
  }
  s.materials = std::move(materials);
  s.lights = std::move(lights);
  s.input_triangles = uint32_t(tris.size());
  return s;
}

// Two triangles: the square [x0, x1] x [y0, y1] in the plane z.
void add_quad_z(std::vector<Tri>& tris, float x0, float x1, float y0, float y1, float z,
                uint32_t material) {
  tris.push_back({{x0, y0, z}, {x1, y0, z}, {x1, y1, z}, material});
  tris.push_back({{x0, y0, z}, {x1, y1, z}, {x0, y1, z}, material});
}

// At the origin, looking down -Z, +Y up.
Camera origin_camera() {
  Camera c;
  c.position = glm::vec3(0.0f);
  c.forward = glm::vec3(0, 0, -1);
  c.up = glm::vec3(0, 1, 0);
  c.yfov = 0.8f;
  return c;
}

RenderOptions small_options(int w, int h, ShadingModel model, int bounces, bool shadows) {
  RenderOptions o;
  o.width = w;
  o.height = h;
  o.shading = model;
  o.bounces = bounces;
  o.shadows = shadows;
  return o;
}

glm::dvec3 pixel_rgb(const RenderResult& r, int x, int y) {
  const size_t i = (size_t(y) * size_t(r.width) + size_t(x)) * 3;
  return {r.rgb[i], r.rgb[i + 1], r.rgb[i + 2]};
}

double grid_diagonal(const host::Grid& g) {
  return glm::length(glm::dvec3(g.hi) - glm::dvec3(g.lo));
}

// How far the CPU and stream renders of one scene agree.
struct Agreement {
  double hit_id = 0;       // fraction of pixels with the same primary hit id (or both missing)
  double colour = 0;       // fraction of pixels whose channels all differ by at most 2/255
  double colour_half = 0;  // the same within 1/2 of an 8-bit step (0.5/255)
  double max_diff = 0;     // largest channel difference, linear units
  double mean_diff = 0;    // mean over pixels of the largest channel difference
  uint64_t cpu_rays = 0, stream_rays = 0;  // rays entering the grid (RenderResult::rays_traced)
};

Agreement compare_with_stream(const std::string& file, const RenderOptions& opt) {
  const Scene scene = host::load_scene(file);
  const host::Grid grid = host::build_grid(scene, host::GridSpec{});
  const Camera cam = host::scene_camera(scene, float(opt.width) / float(opt.height));
  const RenderResult cpu = host::render_cpu(scene, grid, cam, opt);
  host::StreamTracer stream_tracer(scene, grid, opt);
  const RenderResult gpu = stream_tracer.render(cam);
  REQUIRE(cpu.hit_id.size() == gpu.hit_id.size());
  REQUIRE(cpu.rgb.size() == gpu.rgb.size());
  const size_t n = cpu.hit_id.size();
  size_t same_id = 0, close = 0, close_half = 0;
  Agreement a;
  for (size_t i = 0; i < n; ++i) {
    same_id += cpu.hit_id[i] == gpu.hit_id[i];
    double d = 0;
    for (int c = 0; c < 3; ++c)
      d = std::max(d, double(std::abs(cpu.rgb[i * 3 + c] - gpu.rgb[i * 3 + c])));
    close += d <= 2.0 / 255.0;
    close_half += d <= 0.5 / 255.0;
    a.max_diff = std::max(a.max_diff, d);
    a.mean_diff += d / double(n);
  }
  a.hit_id = double(same_id) / double(n);
  a.colour = double(close) / double(n);
  a.colour_half = double(close_half) / double(n);
  a.cpu_rays = cpu.rays_traced;
  a.stream_rays = gpu.rays_traced;
  MESSAGE(scene.name << " " << opt.width << "x" << opt.height << " bounces=" << opt.bounces
                     << ": hit ids agree on " << 100.0 * a.hit_id << "% of pixels, colours within "
                     << "2/255 on " << 100.0 * a.colour << "% (within 0.5/255 on "
                     << 100.0 * a.colour_half << "%); largest difference " << a.max_diff * 255.0
                     << "/255, mean " << a.mean_diff * 255.0 << "/255; rays traced: CPU "
                     << a.cpu_rays << ", stream " << a.stream_rays);
  return a;
}

}  // namespace

TEST_CASE("The double-precision primary rays follow the camera contract") {
  Camera cam;
  cam.position = glm::vec3(1, 2, 3);
  cam.forward = glm::normalize(glm::vec3(0.3f, -0.2f, -1.0f));
  cam.up =
      glm::normalize(glm::vec3(0, 1, 0) - glm::dot(glm::vec3(0, 1, 0), cam.forward) * cam.forward);
  cam.yfov = 0.7f;
  for (int y = 0; y < 7; ++y)
    for (int x = 0; x < 11; ++x) {
      const glm::dvec3 d = host::cpu_primary_dir(cam, 11, 7, x, y);
      const glm::vec3 f = host::primary_dir(cam, 11, 7, float(x), float(y));
      CHECK(glm::length(d) == doctest::Approx(1.0).epsilon(1e-15));
      CHECK(glm::length(d - glm::dvec3(f)) < 1e-6);
    }
}

TEST_CASE(
    "A large quad facing the camera, lit from the eye, gives the hand-computed diffuse colour") {
  // Quad at z = -5, kd = (0.8, 0.6, 0.4), white light at the eye: for a primary ray d the light
  // direction is -d, so colour = kd (0.1 + n.l) with n.l = -d.z, in every pixel.
  std::vector<Tri> tris;
  add_quad_z(tris, -50, 50, -50, 50, -5, 0);
  const Scene scene =
      make_scene(tris, {{glm::vec3(0.8f, 0.6f, 0.4f), 0.0f}}, {{glm::vec3(0.0f), glm::vec3(1.0f)}});
  const host::Grid grid = host::build_grid(scene, host::GridSpec{});
  const Camera cam = origin_camera();
  const glm::dvec3 kd(glm::vec3(0.8f, 0.6f, 0.4f));
  const double ambient = double(kernels::Shader{}.ambient.x);
  CHECK(ambient == doctest::Approx(0.1));

  const RenderResult diffuse =
      host::render_cpu(scene, grid, cam, small_options(9, 9, ShadingModel::diffuse, 2, true));
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 9; ++x) {
      const glm::dvec3 d = host::cpu_primary_dir(cam, 9, 9, x, y);
      const glm::dvec3 expect = kd * (ambient - d.z);
      const glm::dvec3 got = pixel_rgb(diffuse, x, y);
      for (int c = 0; c < 3; ++c) CHECK(got[c] == doctest::Approx(expect[c]).epsilon(1e-6));
    }
  CHECK(diffuse.iterations == 1);  // reflect 0: no reflected ray

  // The centre pixel looks straight down the axis: n.l = 1 and the mirrored light direction
  // meets the eye, so the highlight is the full ks = 0.5.
  const RenderResult phong =
      host::render_cpu(scene, grid, cam, small_options(9, 9, ShadingModel::phong, 0, true));
  const glm::dvec3 centre = pixel_rgb(phong, 4, 4);
  for (int c = 0; c < 3; ++c)
    CHECK(centre[c] == doctest::Approx(kd[c] * (ambient + 1.0) + 0.5).epsilon(1e-6));

  // Attenuation: the lit terms over 1 + (5 / atten_dist)^2, atten_dist = half the grid diagonal.
  const RenderResult atten =
      host::render_cpu(scene, grid, cam, small_options(9, 9, ShadingModel::phong_atten, 0, true));
  const double q = 5.0 / (0.5 * grid_diagonal(grid));
  const glm::dvec3 centre_atten = pixel_rgb(atten, 4, 4);
  for (int c = 0; c < 3; ++c)
    CHECK(centre_atten[c] ==
          doctest::Approx(kd[c] * ambient + (kd[c] + 0.5) / (1.0 + q * q)).epsilon(1e-6));
}

TEST_CASE(
    "A ray hitting a triangle reports its depth and input id; a ray missing it reports none") {
  // A right triangle at z = -3 with legs along x and y from (-1, -1) and hypotenuse x + y = 0.5.
  Scene scene = make_scene({{{-1, -1, -3}, {1.5f, -1, -3}, {-1, 1.5f, -3}}},
                           {{glm::vec3(0.5f), 0.0f}}, {{glm::vec3(0, 0, 2), glm::vec3(1.0f)}});
  scene.id[0] = 42;
  const host::Grid grid = host::build_grid(scene, host::GridSpec{});
  const Camera cam = origin_camera();
  CpuStats stats;
  const RenderResult r = host::render_cpu(
      scene, grid, cam, small_options(5, 5, ShadingModel::diffuse, 0, false), &stats);
  // Centre pixel: straight down -Z, depth 3.
  CHECK(r.hit_id[2 * 5 + 2] == 42.0f);
  CHECK(r.depth[2 * 5 + 2] == doctest::Approx(3.0).epsilon(1e-7));
  // Pixel (3, 3) meets the plane at about (0.51, -0.51): inside; depth 3 / -d.z.
  const glm::dvec3 d33 = host::cpu_primary_dir(cam, 5, 5, 3, 3);
  CHECK(r.hit_id[3 * 5 + 3] == 42.0f);
  CHECK(r.depth[3 * 5 + 3] == doctest::Approx(3.0 / -d33.z).epsilon(1e-7));
  // Pixel (0, 0) meets it at about (-1.01, 1.01): outside, left of x = -1.
  CHECK(r.hit_id[0] == -1.0f);
  CHECK(r.depth[0] == 0.0f);
  CHECK(pixel_rgb(r, 0, 0) == glm::dvec3(0.0));
  // One primary ray per pixel, no shadow or reflected rays; every one enters the grid box or not.
  CHECK(stats.rays == 25);
  CHECK(r.rays_traced <= 25);
  CHECK(stats.voxel_steps > 0);
  CHECK(stats.triangle_tests > 0);
}

TEST_CASE("The hit buffer equals the brute-force reference on a small hand-made scene") {
  // 60 random triangles in [-2, 2]^3, seen from z = 6, against several grid resolutions.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> centre(-2.0f, 2.0f), corner(-0.8f, 0.8f);
  // Each vector's components drawn z, y, x, in sequence: the order GCC evaluated the arguments
  // of glm::vec3(d(rng), d(rng), d(rng)) when the test was written (the language leaves it open,
  // and clang draws x first, which gives another scene).
  const auto draw = [&](std::uniform_real_distribution<float>& d) {
    const float z = d(rng), y = d(rng), x = d(rng);
    return glm::vec3(x, y, z);
  };
  std::vector<Tri> tris;
  for (int i = 0; i < 60; ++i) {
    const glm::vec3 c = draw(centre);
    const glm::vec3 a = c + draw(corner);
    const glm::vec3 b = c + draw(corner);
    tris.push_back({a, b, c + draw(corner), 0});
  }
  const Scene scene =
      make_scene(tris, {{glm::vec3(0.7f), 0.0f}}, {{glm::vec3(3, 5, 6), glm::vec3(1.0f)}});
  Camera cam = origin_camera();
  cam.position = glm::vec3(0.2f, 0.1f, 6.0f);
  const int W = 64, H = 48;
  const std::vector<host::RefHit> ref = host::brute_force_image(
      scene, [&](int x, int y) { return host::cpu_primary_dir(cam, W, H, x, y); },
      glm::dvec3(cam.position), W, H);

  for (const glm::ivec3 res : {glm::ivec3(0), glm::ivec3(1), glm::ivec3(7, 3, 5), glm::ivec3(16)}) {
    CAPTURE(res.x);
    CAPTURE(res.y);
    CAPTURE(res.z);
    const host::Grid grid = host::build_grid(scene, host::GridSpec{res});
    const RenderResult r =
        host::render_cpu(scene, grid, cam, small_options(W, H, ShadingModel::diffuse, 0, false));
    int compared = 0, hits = 0;
    for (int i = 0; i < W * H; ++i) {
      const host::RefHit& h = ref[size_t(i)];
      if (h.tri >= 0 && std::min({h.u, h.v, 1.0 - h.u - h.v}) < 1e-6) continue;  // on an edge
      ++compared;
      CAPTURE(i);
      if (h.tri < 0) {
        CHECK(r.hit_id[size_t(i)] == -1.0f);
        continue;
      }
      ++hits;
      CHECK(r.hit_id[size_t(i)] == float(scene.id[size_t(h.tri)]));
      CHECK(r.depth[size_t(i)] == doctest::Approx(h.t).epsilon(1e-6));
    }
    CHECK(compared >= W * H - 10);
    CHECK(hits > W * H / 4);  // the scene covers a good part of the frame
  }
}

TEST_CASE("The output is bit-identical for 1 and 3 threads") {
  const Scene scene = host::load_scene(VGPU_SCENES_DIR "/bunny-refl.gltf");
  const host::Grid grid = host::build_grid(scene, host::GridSpec{});
  REQUIRE(scene.camera);
  RenderOptions opt = small_options(40, 36, ShadingModel::phong, 2, true);
  opt.threads = 1;
  CpuStats s1, s3;
  const RenderResult r1 = host::render_cpu(scene, grid, *scene.camera, opt, &s1);
  opt.threads = 3;
  const RenderResult r3 = host::render_cpu(scene, grid, *scene.camera, opt, &s3);
  CHECK(r1.rgb == r3.rgb);
  CHECK(r1.depth == r3.depth);
  CHECK(r1.hit_id == r3.hit_id);
  CHECK(r1.iterations == r3.iterations);
  CHECK(r1.rays_traced == r3.rays_traced);
  CHECK(s1.rays == s3.rays);
  CHECK(s1.voxel_steps == s3.voxel_steps);
  CHECK(s1.triangle_tests == s3.triangle_tests);
  CHECK(r1.iterations == 3);  // the reflective floor and walls send rays on
}

TEST_CASE(
    "Two facing mirrors blend as the geometric series, truncated by bounces and the weight cut") {
  // Mirrors at z = -1 and z = +1, reflect 0.5, kd 0.4; the eye at the origin looks down -Z and
  // a white light sits on the axis at z = 0.5. The single pixel's ray runs along the axis and
  // bounces between the mirrors; every surface it meets has n.l = 1, so C = kd (0.1 + 1) and the
  // i-th surface (0-based) adds 0.5^i (1 - 0.5) C.
  std::vector<Tri> tris;
  add_quad_z(tris, -5, 5, -5, 5, -1, 0);
  add_quad_z(tris, -5, 5, -5, 5, 1, 0);
  const Scene scene =
      make_scene(tris, {{glm::vec3(0.4f), 0.5f}}, {{glm::vec3(0, 0, 0.5f), glm::vec3(1.0f)}});
  const host::Grid grid = host::build_grid(scene, host::GridSpec{});
  const Camera cam = origin_camera();
  const double C = double(0.4f) * (double(kernels::Shader{}.ambient.x) + 1.0);

  CpuStats stats;
  const RenderResult r2 = host::render_cpu(
      scene, grid, cam, small_options(1, 1, ShadingModel::diffuse, 2, true), &stats);
  CHECK(r2.iterations == 3);
  CHECK(pixel_rgb(r2, 0, 0).x == doctest::Approx(0.5 * C * (1 + 0.5 + 0.25)).epsilon(1e-6));
  CHECK(r2.depth[0] == doctest::Approx(1.0).epsilon(1e-7));
  CHECK(stats.rays == 6);  // three surfaces, one shadow ray each
  CHECK(r2.rays_traced == 6);

  // Many bounces: the weight after surface i is 0.5^(i+1), cut below 1/512 = 0.5^9, so ten
  // surfaces contribute: sum_{i<10} 0.5^(i+1) C = (1 - 2^-10) C.
  const RenderResult r20 =
      host::render_cpu(scene, grid, cam, small_options(1, 1, ShadingModel::diffuse, 20, true));
  CHECK(r20.iterations == 10);
  CHECK(pixel_rgb(r20, 0, 0).x == doctest::Approx((1.0 - std::ldexp(1.0, -10)) * C).epsilon(1e-6));
}

TEST_CASE("The CPU and stream tracers agree on the bunny at 64x64 with phong and shadows") {
  const Agreement a = compare_with_stream(VGPU_SCENES_DIR "/bunny.gltf",
                                          small_options(64, 64, ShadingModel::phong, 0, true));
  CHECK(a.hit_id >= 0.995);
  CHECK(a.colour >= 0.99);
}

TEST_CASE("The CPU and stream tracers agree on the reflective bunny scene with two bounces") {
  // Measured (fp32 profiles gf5700, gf6600, rtx4090 alike): hit ids agree on 100% of pixels,
  // every pixel within 0.5/255 (largest 0.075/255, mean 0.0125/255), the same 16426 rays traced;
  // 100% also at 128x128 and 256x256. Both tracers run the same algorithm, so they part only
  // where fp32 rounding moves a ray across a triangle edge or a voxel face; a reflected ray that
  // does so lands on another surface and can change its pixel by far more than 2/255. The
  // thresholds allow 4 such pixels of 4096 (0.1%), and 1% of pixels off by more than half an
  // 8-bit step: a real divergence (a kernel rule, an offset or a constant not matching)
  // breaks them at once.
  const Agreement a = compare_with_stream(VGPU_SCENES_DIR "/bunny-refl.gltf",
                                          small_options(64, 64, ShadingModel::phong, 2, true));
  CHECK(a.hit_id >= 0.999);
  CHECK(a.colour >= 0.999);
  CHECK(a.colour_half >= 0.99);
  CHECK(double(a.cpu_rays) == doctest::Approx(double(a.stream_rays)).epsilon(0.001));
}
