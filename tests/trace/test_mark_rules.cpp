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
