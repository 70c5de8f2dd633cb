// --beams auto for a GL frame (host/trace/stream/accel_choice.h, choose_beams): the probes run
// on the GL device, which counts the statistics the cost model prices as the emulator does, so a
// GL frame's choice is the emulator frame's, to the bit.
#include <doctest/doctest.h>

#include <memory>

#include "host/accel/accel.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/accel_choice.h"

TEST_CASE(
    "beams auto decides a GL frame from the emulator's probes, as it decides the emulator's") {
  const host::Scene scene = host::load_scene(host::resolve_scene("bunny-low"));
  host::RenderOptions opt;
  opt.width = opt.height = 32;
  opt.profile = "gf6600";
  opt.threads = 2;
  opt.bounces = 0;
  opt.shadows = false;
  const auto accel = host::make_accel(
      host::AccelKind::grid, scene,
      host::AccelParams{host::grid_spec_for({}, scene, vgpu::profile(opt.profile))});
  const host::Camera cam = host::scene_camera(scene);
  const host::BeamsChoice emulated = host::choose_beams(scene, *accel, opt, cam, "stream");
  opt.device = "gl";
  const host::BeamsChoice gl = host::choose_beams(scene, *accel, opt, cam, "gl");
  CHECK(gl.probed);
  CHECK(gl.on == emulated.on);
  CHECK(gl.off_ms == emulated.off_ms);
  CHECK(gl.on_ms == emulated.on_ms);
  CHECK(gl.on);  // the low bunny at 32x32: 0.90x with beams (tests/trace/test_beams_auto.cpp)
}
