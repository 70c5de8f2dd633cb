// The two-level grid walk (--accel grid2) on the GL device against the vgpu: multipass, fused
// (--mrt on) and looping frames of a bundled scene give the same passes, query counts, hit ids,
// depths and image (on llvmpipe bit for bit, tests/gl/gl_compare.h).
#include <doctest/doctest.h>

#include <algorithm>
#include <string>

#include "host/accel/accel.h"
#include "host/accel/grid.h"
#include "host/accel/grid2.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/stream_tracer.h"
#include "tests/gl/gl_compare.h"

namespace {

struct Frame {
  host::RenderResult result;
  std::string device;
};

enum class Variant { multipass, mrt, looping };

Frame render(const std::string& scene_name, const std::string& device, int size, Variant v,
             const std::string& profile = "gf6600") {
  const host::Scene scene = host::load_scene(host::resolve_scene(scene_name));
  host::RenderOptions opt;
  opt.width = opt.height = size;
  opt.device = device;
  opt.threads = 2;
  opt.keep_pass_records = true;
  if (v != Variant::multipass) opt.profile = profile;
  opt.mrt = v == Variant::mrt;
  opt.looping = v == Variant::looping;
  opt.steps_per_pass = 16;
  // As the CLI builds them: the two-level grid, and a one-voxel grid for the scene box.
  const host::Grid box = host::build_grid(scene, host::GridSpec{glm::ivec3(1)});
  const host::Grid2 g2 = host::build_grid2(scene);
  const host::Camera cam = host::scene_camera(scene);
  host::StreamTracer tracer(scene, host::Accel{host::AccelKind::grid2, &box, nullptr, nullptr, &g2},
                            opt);
  return {tracer.render(cam), tracer.device().description()};
}

}  // namespace

TEST_CASE("grid2 frames on the GL device give the vgpu's queries, hit ids, depths and image") {
  for (const Variant v : {Variant::multipass, Variant::mrt, Variant::looping}) {
    CAPTURE(int(v));
    const Frame vf = render("bunny-low", "vgpu", 48, v), gf = render("bunny-low", "gl", 48, v);
    const host::RenderResult &a = vf.result, &b = gf.result;
    REQUIRE(a.stats.passes.size() == b.stats.passes.size());
    size_t grid2_passes = 0;
    for (size_t i = 0; i < a.stats.passes.size(); ++i) {
      CAPTURE(i);
      REQUIRE(a.stats.passes[i].program == b.stats.passes[i].program);
      CHECK(a.stats.passes[i].query_result == b.stats.passes[i].query_result);
      grid2_passes += a.stats.passes[i].program.rfind("grid2 ", 0) == 0;
    }
    CHECK(grid2_passes > 0);
    CHECK(a.rays_unfinished == 0);
    CHECK(b.rays_unfinished == 0);
    const auto hit =
        std::count_if(a.hit_id.begin(), a.hit_id.end(), [](float id) { return id >= 0; });
    CHECK(hit * 20 >= std::ptrdiff_t(a.hit_id.size()));
    const char* depth_kernel = v == Variant::looping ? "grid2 looping traversal"
                               : v == Variant::mrt   ? "grid2 intersections + next triangle"
                                                     : "grid2 intersections";
    gltest::check_same_frame(gf.device, depth_kernel, a.hit_id, b.hit_id, a.depth, b.depth, a.rgb,
                             b.rgb);
  }
}

TEST_CASE("the bunny's two-level grid fits a GL driver whose textures stop at 16384 texels") {
  // 96,334 sub-cells: laid out in one row as long as the profile allows, they took a 32768 x 3
  // texture, which llvmpipe (16384) refused; host/trace/passes.cpp's entry_texture lays them
  // out about square. On the h200 profile (32768 texels a side) as bench_gl's looping frames.
  const Frame vf = render("bunny", "vgpu", 24, Variant::looping, "h200");
  const Frame gf = render("bunny", "gl", 24, Variant::looping, "h200");
  const host::RenderResult &a = vf.result, &b = gf.result;
  CHECK(a.rays_unfinished == 0);
  CHECK(b.rays_unfinished == 0);
  gltest::check_same_frame(gf.device, "grid2 looping traversal", a.hit_id, b.hit_id, a.depth,
                           b.depth, a.rgb, b.rgb);
}
