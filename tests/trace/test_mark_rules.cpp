// cpu_adaptive_levels (bench_mark_rules' data): every pixel's centre ray and adaptive levels, as
// if every pixel were refined, must be the colours, keys and ray counts the renders themselves
// give, or the rules tried offline from it would be measured against another tracer.
#include <doctest/doctest.h>

#include <vector>

#include "host/accel/grid.h"
#include "host/image/image_io.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/cpu/cpu_tracer.h"
#include "host/trace/sampling.h"

namespace {

// bunny-refl (mirrors, shadows) at 12 x 12: small, with reflected keys and shadow rays to count.
struct Case {
  host::Scene scene = host::load_scene(host::resolve_scene("bunny-refl"), host::with_images());
  host::Grid grid = host::build_grid(scene, host::GridSpec{glm::ivec3(8, 8, 8)});
  host::Camera camera = host::scene_camera(scene, 1.0f);
  host::RenderOptions opt;
  Case() {
    opt.width = opt.height = 12;
    opt.profile = "gf6600";
    opt.spp = 16;
    opt.threads = 2;
  }
  host::RenderResult render(int spp) const {
    host::RenderOptions o = opt;
    o.spp = spp;
    return host::render_cpu(scene, grid, camera, o);
  }
};

// Which of the side x side strata each offset lies in, counted.
std::vector<int> strata(const std::vector<std::vector<glm::vec2>>& levels, int side) {
  std::vector<int> count(size_t(side * side), 0);
  for (const auto& level : levels)
    for (const glm::vec2 o : level) ++count[size_t(int(o.y * side) * side + int(o.x * side))];
  return count;
}

uint64_t sum(const std::vector<uint32_t>& v) {
  uint64_t s = 0;
  for (const uint32_t x : v) s += x;
  return s;
}

}  // namespace

TEST_CASE(
    "every pixel's adaptive levels are the CPU tracer's 1, 4 and 16 sample images bit for bit, "
    "with the rays each traced") {
  const Case c;
  const host::CpuAdaptiveLevels lv =
      host::cpu_adaptive_levels(c.scene, host::GridAccel(c.grid), c.camera, c.opt);
  REQUIRE(lv.sides == std::vector<int>{2, 4});
  REQUIRE(lv.level.size() == 2);
  REQUIRE(lv.level_rays.size() == 2);
  const host::RenderResult one = c.render(1), four = c.render(4), sixteen = c.render(16);
  CHECK(lv.centre == one.rgb);
  CHECK(lv.depth == one.depth);
  CHECK(lv.level[0] == four.rgb);
  CHECK(lv.level[1] == sixteen.rgb);
  CHECK(sum(lv.centre_rays) == one.rays_traced);
  CHECK(sum(lv.level_rays[0]) == four.rays_traced);
  CHECK(sum(lv.level_rays[1]) == sixteen.rays_traced);
  // Each level's rays are at least one per sample where the centre ray entered the grid.
  for (size_t i = 0; i < lv.centre_rays.size(); ++i)
    if (lv.centre_rays[i] > 0) CHECK(lv.level_rays[1][i] >= 1u);
}

TEST_CASE(
    "every pixel's surface keys are the materials its centre ray and that ray's reflected ray "
    "hit, -1 for none") {
  const Case c;
  const host::GridAccel accel(c.grid);
  const host::CpuAdaptiveLevels lv = host::cpu_adaptive_levels(c.scene, accel, c.camera, c.opt);
  int reflected = 0;
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 12; ++x) {
      CAPTURE(x);
      CAPTURE(y);
      const size_t i = size_t(y) * 12 + size_t(x);
      const std::vector<host::CpuRay> tree =
          host::cpu_ray_tree(c.scene, accel, c.opt, glm::dvec3(c.camera.position),
                             host::cpu_primary_dir(c.camera, 12, 12, x, y));
      REQUIRE(!tree.empty());
      const auto material = [&](int64_t tri) {
        return tri < 0 ? -1 : int(c.scene.material[size_t(tri)]);
      };
      CHECK(lv.key[i] == material(tree[0].hit));
      int want = -1;
      for (const host::CpuRay& r : tree)
        if (r.depth == 1 && r.kind == host::CpuRayKind::reflected) {
          want = material(r.hit);
          break;
        }
      CHECK(lv.reflected_key[i] == want);
      reflected += want >= 0;
    }
  CHECK(reflected > 0);  // the case has mirrors that see something
}

TEST_CASE(
    "levels that keep their samples add one sample to each stratum the samples before leave "
    "empty, and stop where the side does not double") {
  const uint64_t seed = 7;
  const std::vector<std::vector<glm::vec2>> k16 = host::kept_level_samples(16, seed);
  REQUIRE(k16.size() == 2);
  REQUIRE(k16[0].size() == 4);
  for (int k = 0; k < 4; ++k) CHECK(k16[0][size_t(k)] == host::sample_offset(4, k, seed));
  CHECK(k16[1].size() == 12);
  CHECK(strata({k16[0]}, 2) == std::vector<int>(4, 1));
  CHECK(strata(k16, 4) == std::vector<int>(16, 1));  // the 4 kept and the 12 new: one each
  for (const glm::vec2 o : k16[1]) {
    // Each new sample is its stratum's sample_offset(16, stratum).
    const int stratum = int(o.y * 4) * 4 + int(o.x * 4);
    CHECK(o == host::sample_offset(16, stratum, seed));
  }
  const std::vector<std::vector<glm::vec2>> k64 = host::kept_level_samples(64, seed);
  REQUIRE(k64.size() == 3);
  CHECK(k64[2].size() == 48);
  CHECK(strata(k64, 8) == std::vector<int>(64, 1));
  CHECK(host::kept_level_samples(9, seed).size() == 1);  // 2 x 2, then 3 x 3: not kept
}

TEST_CASE("a level that keeps the 2 x 2 samples traces only the 12 new ones") {
  // One white wall facing the camera, diffuse, no shadows or mirrors: every sample is one ray
  // that enters the grid, and the colour barely changes across a pixel.
  host::Scene scene;
  scene.name = "wall";
  scene.materials = {{{1.0f, 1.0f, 1.0f}, 0.0f}};
  scene.add_flat_triangle({-4, -4, 0}, {4, -4, 0}, {4, 4, 0}, 0, 0);
  scene.add_flat_triangle({-4, -4, 0}, {4, 4, 0}, {-4, 4, 0}, 0, 1);
  scene.input_triangles = 2;
  scene.lights = {{{0, 0, 1000}, {1, 1, 1}}};
  const host::Grid grid = host::build_grid(scene, host::GridSpec{glm::ivec3(2, 2, 1)});
  host::Camera camera;
  camera.position = {0, 0, 4};
  camera.forward = {0, 0, -1};
  camera.up = {0, 1, 0};
  camera.yfov = 0.5f;
  host::RenderOptions opt;
  opt.width = opt.height = 4;
  opt.bounces = 0;
  opt.shadows = false;
  opt.shading = kernels::ShadingModel::diffuse;
  opt.spp = 16;
  const host::CpuAdaptiveLevels lv =
      host::cpu_adaptive_levels(scene, host::GridAccel(grid), camera, opt);
  REQUIRE(lv.kept.size() == 2);
  CHECK(lv.kept[0].empty());
  REQUIRE(lv.kept[1].size() == 16 * 3);
  REQUIRE(lv.kept_rays[1].size() == 16);
  for (size_t i = 0; i < 16; ++i) {
    CAPTURE(i);
    CHECK(lv.centre_rays[i] == 1u);
    CHECK(lv.level_rays[0][i] == 4u);
    CHECK(lv.level_rays[1][i] == 16u);
    CHECK(lv.kept_rays[1][i] == 12u);
    for (int c = 0; c < 3; ++c) {
      // The mean of 16 samples, one to a stratum, on a nearly flat colour: the 4 x 4 level's.
      CHECK(lv.kept[1][i * 3 + size_t(c)] > 0.1f);
      CHECK(lv.kept[1][i * 3 + size_t(c)] ==
            doctest::Approx(lv.level[1][i * 3 + size_t(c)]).epsilon(1e-4));
    }
  }
}
