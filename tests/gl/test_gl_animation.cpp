// A moving scene on the GL device (issue 23): a tracer made for hop's first frame, then updated
// frame after frame on the same device (static textures rewritten and uploaded again, the BVH
// refitted or the grid rebuilt), gives the vgpu's queries, hit ids, depths and image on every
// frame (on llvmpipe bit for bit, tests/gl/gl_compare.h).
#include <doctest/doctest.h>

#include <memory>
#include <string>
#include <vector>

#include "host/accel/accel.h"
#include "host/accel/bvh.h"
#include "host/accel/grid.h"
#include "host/scene/animation.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/stream_tracer.h"
#include "tests/gl/gl_compare.h"

namespace {

struct Sequence {
  std::vector<host::RenderResult> frames;
  std::string device;
};

// hop at 0, 0.7 and 1.4 s on `device`, one tracer updated between frames as the CLI does it.
Sequence play(const std::string& device, host::AccelKind kind) {
  const host::AnimatedScene a(host::resolve_scene("hop"));
  host::RenderOptions opt;
  opt.width = 40;
  opt.height = 32;
  opt.device = device;
  opt.threads = 2;
  opt.keep_pass_records = true;
  host::Scene scene = a.at(0, 0.0);
  const bool bvh_kind = kind == host::AccelKind::bvh;
  const std::unique_ptr<host::Accel> accel = host::make_accel(kind, scene, {});
  host::StreamTracer tracer(scene, *accel, opt);
  Sequence s;
  s.device = tracer.device().description();
  for (const double t : {0.0, 0.7, 1.4}) {
    if (t > 0) {
      scene = a.at(0, t);
      (void)accel->update(scene, bvh_kind ? "refit" : "rebuild");  // --update refit for the BVH
      (void)tracer.update(scene, *accel);
    }
    s.frames.push_back(tracer.render(host::scene_camera(scene, 1.25f)));  // hop's own camera
  }
  return s;
}

}  // namespace

TEST_CASE("hop's frames on the GL device, refitted or rebuilt between frames, are the vgpu's") {
  for (const host::AccelKind kind : {host::AccelKind::bvh, host::AccelKind::grid}) {
    CAPTURE(int(kind));
    const Sequence v = play("vgpu", kind), g = play("gl", kind);
    REQUIRE(v.frames.size() == 3);
    REQUIRE(g.frames.size() == 3);
    for (size_t f = 0; f < v.frames.size(); ++f) {
      CAPTURE(f);
      const host::RenderResult &a = v.frames[f], &b = g.frames[f];
      REQUIRE(a.stats.passes.size() == b.stats.passes.size());
      for (size_t i = 0; i < a.stats.passes.size(); ++i) {
        CAPTURE(i);
        REQUIRE(a.stats.passes[i].program == b.stats.passes[i].program);
        CHECK(a.stats.passes[i].query_result == b.stats.passes[i].query_result);
      }
      CHECK(a.rays_unfinished == 0);
      gltest::check_same_frame(g.device,
                               kind == host::AccelKind::bvh ? "bvh intersections" : "intersections",
                               a.hit_id, b.hit_id, a.depth, b.depth, a.rgb, b.rgb);
    }
    // The frames differ: the scene moved.
    CHECK(v.frames[0].hit_id != v.frames[2].hit_id);
  }
}
