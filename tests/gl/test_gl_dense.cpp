// Sampling that saves time (issue 35) on the GL device: the sampling modes' dense streams, drawn
// over the rows they fill, give the GL device's own gated frames' images bit for bit (the same
// GLSL on the same rays), and the vgpu's.
#include <doctest/doctest.h>

#include "host/accel/grid.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/stream_tracer.h"
#include "tests/gl/gl_compare.h"
#include "tests/support/bits.h"

using test_support::same_bits;

TEST_CASE(
    "dense streams on the GL device give its gated frames' image, depths and hit ids bit for bit, "
    "adaptive and undersampled") {
  const host::Scene scene = host::load_scene(host::resolve_scene("classic"));
  const host::Camera cam = host::scene_camera(scene);
  for (const int mode : {0, 1}) {
    CAPTURE(mode);  // 0: adaptive up to 16 samples; 1: undersampling, K = 2
    host::RenderResult frames[3];
    std::string gl_name;
    for (int k = 0; k < 3; ++k) {
      host::RenderOptions opt;
      opt.width = 24;
      opt.height = 16;
      opt.spp = mode == 0 ? 16 : 1;
      opt.adaptive = mode == 0;
      opt.undersample = mode == 0 ? 0 : 2;
      opt.device = k < 2 ? "gl" : "vgpu";
      opt.compact = k != 0;  // the GL device gated, then dense; the vgpu dense
      opt.threads = 2;
      const host::Grid grid =
          host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile(opt.profile)));
      host::StreamTracer tracer(scene, grid, opt);
      frames[k] = tracer.render(cam);
      if (k == 1) gl_name = tracer.device().description();
    }
    CHECK_FALSE(frames[0].compact.on);
    REQUIRE(frames[1].compact.on);
    CHECK(frames[1].compact.slots < frames[1].compact.pixels);
    CHECK(same_bits(frames[0].rgb, frames[1].rgb));
    CHECK(same_bits(frames[0].depth, frames[1].depth));
    CHECK(same_bits(frames[0].hit_id, frames[1].hit_id));
    CHECK(frames[1].rays_per_pixel == frames[2].rays_per_pixel);
    gltest::check_same_frame(gl_name, "intersections", frames[2].hit_id, frames[1].hit_id,
                             frames[2].depth, frames[1].depth, frames[2].rgb, frames[1].rgb);
  }
}

TEST_CASE(
    "adaptive frames on the GL device after the second make no texture and print no GLSL: they "
    "keep the jitter table and the programs' uniform sets of those before, and give their image") {
  const host::Scene scene = host::load_scene(host::resolve_scene("classic"));
  const host::Camera cam = host::scene_camera(scene);
  host::RenderOptions opt;
  opt.width = 24;
  opt.height = 16;
  opt.spp = 16;
  opt.adaptive = true;
  opt.device = "gl";
  opt.threads = 2;
  const host::Grid grid =
      host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile(opt.profile)));
  host::StreamTracer tracer(scene, grid, opt);
  auto* gl = dynamic_cast<gl::GlDevice*>(&tracer.device());
  REQUIRE(gl);
  // The first frame grows the jitter table level by level; the second draws its first level's
  // rays with the grown table's width, a uniform set the first did not have.
  const host::RenderResult first = tracer.render(cam);
  REQUIRE(first.compact.on);
  CHECK(first.compact.packs >= 2);  // levels of more than one sample count
  tracer.render(cam);
  const gl::GlDevice::HostTimes before = gl->host_times();
  const host::RenderResult third = tracer.render(cam);
  const gl::GlDevice::HostTimes& after = gl->host_times();
  CHECK(after.textures_made == before.textures_made);
  CHECK(after.framebuffers_made == before.framebuffers_made);
  CHECK(after.variants_printed == before.variants_printed);
  CHECK(after.variants_reused > before.variants_reused);
  CHECK(same_bits(first.rgb, third.rgb));
  CHECK(first.rays_per_pixel == third.rays_per_pixel);
}
