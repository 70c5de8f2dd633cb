// Glass's ray streams (issue 25) on the GL device against the vgpu: the stream passes' GLSL
// (generated from the same functors), drawn over rectangles of tall textures, give the vgpu's
// stream lengths, every pass's query count and the image; on a hand-made glass slab, on the bundled
// glass scene and on bunny-refl with --ray-streams on.
#include <doctest/doctest.h>

#include "host/accel/grid.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/stream_tracer.h"
#include "tests/gl/gl_compare.h"

namespace {

// A half-clear glass slab (z 1 to 0) before a diffuse wall (z = -2), lit from the camera's side.
host::Scene glass_slab() {
  host::Scene s;
  s.name = "glass slab";
  s.materials = {{{0.8f, 0.6f, 0.4f}, 0.2f}, {{0.9f, 0.9f, 0.9f}, 0.0f}};
  s.materials[1].transmission = 0.5f;
  s.materials[1].ior = 1.5f;
  uint32_t id = 0;
  auto quad = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, uint32_t m) {
    s.add_flat_triangle(a, b, c, m, id++);
    s.add_flat_triangle(a, c, d, m, id++);
  };
  quad({-1, -1, 1}, {1.5f, -1, 1}, {1.5f, 1, 1}, {-1, 1, 1}, 1);
  quad({-1, -1, 0}, {-1, 1, 0}, {1.5f, 1, 0}, {1.5f, -1, 0}, 1);
  quad({-6, -6, -2}, {7, -6, -2}, {7, 6, -2}, {-6, 6, -2}, 0);
  s.input_triangles = id;
  s.lights = {{{0.5f, 2, 5}, {1, 1, 1}}};
  s.camera =
      host::Camera{{0.3f, 0.4f, 5}, glm::normalize(glm::vec3(-0.1f, -0.1f, -1)), {0, 1, 0}, 0.7f};
  s.camera->up =
      glm::normalize(s.camera->up - glm::dot(s.camera->up, s.camera->forward) * s.camera->forward);
  return s;
}

void check_streams_on_gl(const host::Scene& scene) {
  host::RenderResult frames[2];
  std::string gl_name;
  for (int k = 0; k < 2; ++k) {
    host::RenderOptions opt;
    opt.width = 40;
    opt.height = 32;
    opt.device = k ? "gl" : "vgpu";
    opt.ray_streams = true;
    opt.threads = 2;
    opt.keep_pass_records = true;
    const host::Grid grid = host::build_grid(scene, host::GridSpec{});
    host::StreamTracer tracer(scene, grid, opt);
    frames[k] = tracer.render(*scene.camera);
    if (k) gl_name = tracer.device().description();
  }
  REQUIRE(frames[1].streams.on);
  // Pass by pass, the same programs and the same occlusion-query counts: the GL driver's
  // GL_SAMPLES_PASSED against the vgpu's count, among them every stream count's (contarRayos,
  // whose query gives a stream's length).
  const auto& pv = frames[0].stats.passes;
  const auto& pg = frames[1].stats.passes;
  REQUIRE(pv.size() == pg.size());
  size_t queries = 0, stream_counts = 0;
  for (size_t i = 0; i < pv.size(); ++i) {
    CAPTURE(i);
    REQUIRE(pv[i].program == pg[i].program);
    CHECK(pv[i].query_result == pg[i].query_result);
    queries += pg[i].query_result >= 0;
    stream_counts += pg[i].program == "stream count" && pg[i].query_result >= 0;
  }
  CHECK(stream_counts > 0);
  CHECK(queries == frames[1].stats.totals.query_readbacks);
  REQUIRE(frames[0].streams.levels.size() == frames[1].streams.levels.size());
  for (size_t l = 0; l < frames[0].streams.levels.size(); ++l) {
    CAPTURE(l);
    CHECK(frames[0].streams.levels[l].rays == frames[1].streams.levels[l].rays);
    CHECK(frames[0].streams.levels[l].refracted == frames[1].streams.levels[l].refracted);
    CHECK(frames[0].streams.levels[l].total_internal == frames[1].streams.levels[l].total_internal);
  }
  CHECK(frames[0].streams.shadow_continued == frames[1].streams.shadow_continued);
  gltest::check_same_frame(gl_name, "intersections", frames[0].hit_id, frames[1].hit_id,
                           frames[0].depth, frames[1].depth, frames[0].rgb, frames[1].rgb);
}

}  // namespace

TEST_CASE(
    "a glass slab's ray streams on the GL device give the vgpu's query counts, streams and "
    "image") {
  const host::Scene scene = glass_slab();
  check_streams_on_gl(scene);
}

TEST_CASE(
    "bunny-refl's reflections as ray streams on the GL device give the vgpu's query counts "
    "and image") {
  const host::Scene scene = host::load_scene(host::resolve_scene("bunny-refl"));
  REQUIRE(scene.camera.has_value());
  check_streams_on_gl(scene);
}

TEST_CASE(
    "the bundled glass scene's ray streams on the GL device give the vgpu's query counts, hits "
    "and image") {
  const host::Scene scene = host::load_scene(host::resolve_scene("glass"));
  REQUIRE(scene.camera.has_value());
  check_streams_on_gl(scene);
}
