// The looping variant (--kernels looping) on the GL device: its program printed as one GLSL
// loop (vgpu/record.h RecLoop, vgpu/glsl.cpp), and whole frames against the vgpu's.
#include <doctest/doctest.h>

#include <string>

#include "host/accel/grid.h"
#include "host/image/image_io.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/stream_tracer.h"
#include "tests/gl/gl_compare.h"

namespace {

struct Frame {
  host::RenderResult result;
  std::string device;  // the device's description
};

Frame render(const std::string& scene_name, const std::string& device, int size) {
  const host::Scene scene = host::load_scene(host::resolve_scene(scene_name), host::with_images());
  host::RenderOptions opt;
  opt.width = opt.height = size;
  opt.device = device;
  opt.threads = 2;
  opt.profile = "gf6600";
  opt.looping = true;
  opt.steps_per_pass = 16;
  opt.keep_pass_records = true;
  const host::Grid grid =
      host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile(opt.profile)));
  const host::Camera cam = host::scene_camera(scene);
  host::StreamTracer tracer(scene, grid, opt);
  return {tracer.render(cam), tracer.device().description()};
}

}  // namespace

TEST_CASE("the looping program prints as one GLSL loop with its budget and a break") {
  vgpu::KernelProgram<kernels::LoopingTraversal> p;
  p.kernel.steps = 24;
  const vgpu::GlslProgram g = vgpu::to_glsl(p);
  CAPTURE(g.source);
  CHECK(g.source.find("for (int it = 0; it < 24; ++it) {") != std::string::npos);
  CHECK(g.source.find(") break;") != std::string::npos);
  for (int o = 0; o < 3; ++o)
    CHECK(g.source.find("layout(location = " + std::to_string(o) + ") out vec4 out" +
                        std::to_string(o) + ";") != std::string::npos);
  // Ten units: the five ray-state textures, the three vertex textures, pointers and lists.
  CHECK(g.units.size() == 10);
  // The body appears once: as many fetches in the text as the counting run makes.
  size_t fetches = 0;
  for (size_t at = 0; (at = g.source.find("= texelFetch(", at)) != std::string::npos; ++at)
    ++fetches;
  CHECK(fetches == size_t(p.analyze().fetches.total()));
}

TEST_CASE("looping frames on the GL device give the vgpu's queries, hit ids, depths and image") {
  for (const std::string name : {"sphere", "bunny-refl"}) {
    CAPTURE(name);
    const Frame vf = render(name, "vgpu", 64), gf = render(name, "gl", 64);
    const host::RenderResult &v = vf.result, &g = gf.result;
    REQUIRE(v.stats.passes.size() == g.stats.passes.size());
    size_t loops = 0;
    for (size_t i = 0; i < v.stats.passes.size(); ++i) {
      CAPTURE(i);
      REQUIRE(v.stats.passes[i].program == g.stats.passes[i].program);
      CHECK(v.stats.passes[i].query_result == g.stats.passes[i].query_result);
      loops += v.stats.passes[i].program == "looping traversal";
    }
    CHECK(loops > 1);
    gltest::check_same_frame(gf.device, "looping traversal", v.hit_id, g.hit_id, v.depth, g.depth,
                             v.rgb, g.rgb);
  }
}
