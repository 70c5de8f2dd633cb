// Kernels of one's own in the frame (issue 48) on the GL device: the same C++ functors, printed
// as GLSL from their recordings, give the GL device's frame what the project's kernels give it
// where they compute the same thing, and the emulator's frame bit for bit where they do not.
#include <doctest/doctest.h>

#include "host/accel/grid.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/stream_tracer.h"
#include "host/trace/user_stage.h"
#include "tests/gl/gl_compare.h"
#include "tests/support/bits.h"
#include "tests/support/user_stages.h"

using test_support::same_bits;

namespace {

host::RenderResult render(const host::Scene& scene, const std::string& device, bool own, bool toon,
                          int spp, std::string* name = nullptr) {
  host::RenderOptions opt;
  opt.width = 24;
  opt.height = 16;
  opt.spp = spp;
  opt.threads = 2;
  opt.device = device;
  if (own && toon) {
    opt.user.shader = host::user_stage<test_support::Toon>();
    opt.user.camera = host::user_stage<test_support::Fisheye>();
  } else if (own) {
    opt.user.shader = host::user_stage<test_support::ShaderFromStage>();
    opt.user.camera = host::user_stage<test_support::CameraFromStage>();
  }
  const host::Grid grid =
      host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile(opt.profile)));
  host::StreamTracer tracer(scene, grid, opt);
  if (name) *name = tracer.device().description();
  return tracer.render(host::scene_camera(scene, float(opt.width) / float(opt.height)));
}

}  // namespace

TEST_CASE("a shader and a camera of one's own that compute the project's give its GL frame") {
  const host::Scene scene = host::load_scene(host::resolve_scene("classic"));
  for (const int spp : {1, 4}) {
    CAPTURE(spp);
    const host::RenderResult ours = render(scene, "gl", false, false, spp);
    const host::RenderResult theirs = render(scene, "gl", true, false, spp);
    CHECK(same_bits(ours.rgb, theirs.rgb));
    CHECK(same_bits(ours.hit_id, theirs.hit_id));
    CHECK(ours.stats.totals.passes == theirs.stats.totals.passes);
    CHECK(theirs.stats.find("shader from stage") != nullptr);
  }
}

TEST_CASE("a toon shader and a fisheye camera give the emulator's frame on the GL device") {
  const host::Scene scene = host::load_scene(host::resolve_scene("bunny"));
  std::string gl_name;
  const host::RenderResult emu = render(scene, "vgpu", true, true, 1);
  const host::RenderResult gl = render(scene, "gl", true, true, 1, &gl_name);
  REQUIRE(gl.stats.find("toon") != nullptr);
  CHECK(gl.stats.find("toon")->counters.passes == emu.stats.find("toon")->counters.passes);
  gltest::check_same_frame(gl_name, "toon and fisheye", emu.hit_id, gl.hit_id, emu.depth, gl.depth,
                           emu.rgb, gl.rgb);
}
