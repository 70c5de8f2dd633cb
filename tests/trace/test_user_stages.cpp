// Kernels of one's own in the frame (issue 48, host/trace/user_stage.h): a shader and a camera
// given as C++ functors or as recordings replace the project's, are counted under their own names
// as the passes they replace, and a functor that computes what the project's kernel computes
// gives its frame bit for bit. What cannot run is refused before the frame, one line each.
#include <doctest/doctest.h>

#include <memory>
#include <string>

#include "host/accel/accel.h"
#include "host/accel/grid.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/stream_tracer.h"
#include "host/trace/user_stage.h"
#include "host/trace/validate.h"
#include "tests/support/bits.h"
#include "tests/support/user_stages.h"
#include "vgpu/recorded_program.h"

using test_support::same_bits;

namespace {

host::RenderOptions small(int spp = 1) {
  host::RenderOptions opt;
  opt.width = 32;
  opt.height = 24;
  opt.spp = spp;
  opt.threads = 2;
  return opt;
}

host::RenderResult render(const host::Scene& scene, const host::RenderOptions& opt) {
  const host::Grid grid =
      host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile(opt.profile)));
  host::StreamTracer tracer(scene, grid, opt);
  return tracer.render(host::scene_camera(scene, float(opt.width) / float(opt.height)));
}

// The passes of program `name` in a frame's statistics (0: none ran).
uint64_t passes_of(const host::RenderResult& r, const std::string& name) {
  const vgpu::FrameStats::ProgramTotals* p = r.stats.find(name);
  return p ? p->counters.passes : 0;
}

}  // namespace

TEST_CASE("a shader of one's own that computes the project's shading gives its frame bit for bit") {
  const host::Scene scene = host::load_scene(host::resolve_scene("classic"));
  for (const int spp : {1, 4}) {
    CAPTURE(spp);
    const host::RenderResult ours = render(scene, small(spp));
    host::RenderOptions opt = small(spp);
    opt.user.shader = host::user_stage<test_support::ShaderFromStage>();
    const host::RenderResult theirs = render(scene, opt);
    CHECK(same_bits(ours.rgb, theirs.rgb));
    CHECK(same_bits(ours.depth, theirs.depth));
    // The same passes, the shader's under the user's name.
    CHECK(ours.stats.totals.passes == theirs.stats.totals.passes);
    CHECK(passes_of(theirs, "shader") == 0);
    CHECK(passes_of(theirs, "shader from stage") == passes_of(ours, "shader"));
    CHECK(passes_of(ours, "shader") > 0);
  }
}

TEST_CASE("a camera of one's own that computes the project's rays gives its frame bit for bit") {
  const host::Scene scene = host::load_scene(host::resolve_scene("classic"));
  for (const int spp : {1, 4}) {
    CAPTURE(spp);
    const host::RenderResult ours = render(scene, small(spp));
    host::RenderOptions opt = small(spp);
    opt.user.camera = host::user_stage<test_support::CameraFromStage>();
    const host::RenderResult theirs = render(scene, opt);
    CHECK(same_bits(ours.rgb, theirs.rgb));
    CHECK(same_bits(ours.hit_id, theirs.hit_id));
    CHECK(ours.stats.totals.passes == theirs.stats.totals.passes);
    const char* project = spp == 1 ? "generate rays" : "generate sample rays";
    CHECK(passes_of(theirs, project) == 0);
    CHECK(passes_of(theirs, "camera from stage") == passes_of(ours, project));
  }
}

TEST_CASE("a toon shader and a fisheye camera render frames of their own, counted and shaded") {
  const host::Scene scene = host::load_scene(host::resolve_scene("classic"));
  const host::RenderResult ours = render(scene, small());
  host::RenderOptions opt = small();
  opt.user.shader = host::user_stage<test_support::Toon>();
  opt.user.camera = host::user_stage<test_support::Fisheye>();
  const host::RenderResult theirs = render(scene, opt);
  CHECK(passes_of(theirs, "toon") == passes_of(ours, "shader"));
  CHECK(passes_of(theirs, "fisheye") == 1);
  CHECK_FALSE(same_bits(ours.rgb, theirs.rgb));
  // The fisheye sees the scene otherwise: other triangles at some pixels, and still hits.
  CHECK_FALSE(same_bits(ours.hit_id, theirs.hit_id));
  size_t hits = 0;
  for (const float id : theirs.hit_id) hits += id >= 0;
  CHECK(hits > theirs.hit_id.size() / 2);
  // Toon's image is not black.
  double sum = 0;
  for (const float v : theirs.rgb) sum += v;
  CHECK(sum > 0.0);
}

TEST_CASE("a recorded shader and camera take the stage's uniforms by name before each pass") {
  // A second light: the shader's uniforms change between its passes.
  host::Scene scene = host::load_scene(host::resolve_scene("classic"));
  scene.lights.push_back(scene.lights.at(0));
  scene.lights[1].position.x -= 3.0f;
  scene.lights[1].color *= glm::vec3(0.5f, 0.25f, 1.0f);
  for (const int spp : {1, 4}) {
    CAPTURE(spp);
    host::RenderOptions opt = small(spp);
    opt.user.shader = host::user_stage<test_support::Toon>();
    opt.user.camera = host::user_stage<test_support::Fisheye>();
    const host::RenderResult functors = render(scene, opt);
    auto shader_stage = host::recorded_stage(test_support::Toon{});
    auto camera_stage = host::recorded_stage(test_support::Fisheye{});
    const auto& shader = static_cast<const vgpu::RecordedProgram&>(shader_stage->program());
    const auto& camera = static_cast<const vgpu::RecordedProgram&>(camera_stage->program());
    CHECK(shader.uniform_names() ==
          std::vector<std::string>{"light_x", "light_y", "light_z", "light_r", "light_g", "light_b",
                                   "first_light", "last_light", "ambient_r", "scene_width"});
    CHECK(camera.uniform_names() ==
          std::vector<std::string>{"forward_x", "forward_y", "forward_z", "right_x", "right_y",
                                   "right_z", "up_x", "up_y", "up_z", "tan_half_fov", "aspect",
                                   "width", "height", "jitter_x", "jitter_y", "far"});
    opt.user.shader = shader_stage;
    opt.user.camera = camera_stage;
    const host::RenderResult recorded = render(scene, opt);
    CHECK(same_bits(functors.rgb, recorded.rgb));
    CHECK(same_bits(functors.hit_id, recorded.hit_id));
    CHECK(functors.stats.totals.instructions == recorded.stats.totals.instructions);
  }
}

TEST_CASE("what a kernel of one's own cannot run is refused before the frame, one line each") {
  const host::Scene scene = host::load_scene(host::resolve_scene("classic"));
  const vgpu::Profile& gf = vgpu::profile("gf5700");
  auto lines = [&](const host::RenderOptions& opt, const host::Request* q = nullptr) {
    return host::refusal_lines(host::validate(opt, gf, q, &scene));
  };
  host::RenderOptions opt = small();
  opt.user.shader = host::user_stage<test_support::Toon>();
  CHECK(lines(opt) == "");
  host::Request cpu;
  cpu.engine = "cpu";
  CHECK(lines(opt, &cpu) ==
        "shader 'toon': the cpu engine runs no kernels (a double-precision reference); a kernel "
        "of your own needs --engine stream or gl");
  // A unit the stage does not bind, and a base-colour unit on a scene without textures.
  std::shared_ptr<vgpu::RecordedProgram> bad =
      vgpu::RecordedProgram::of(vgpu::KernelProgram<test_support::Toon>{});
  opt.user.shader = std::make_shared<host::RecordedStage<kernels::ShaderStage>>(
      bad, std::vector<std::string>{"surface", "rays", "result", "colours", "normals0", "normals1",
                                    "normals2"});
  CHECK(lines(opt) ==
        "shader 'toon': unit 3 'colours' is not a texture of the shading stage (one pass per "
        "light) (it binds surface, rays, result, shadow_hits, colors, vertices0, vertices1, "
        "vertices2, normals0, normals1, normals2, origins, uvs01, uvs2, texture_table, "
        "texture_atlas)");
  opt.user.shader = std::make_shared<host::RecordedStage<kernels::ShaderStage>>(
      bad, std::vector<std::string>{"surface", "rays", "result", "texture_atlas", "normals0",
                                    "normals1", "normals2"});
  CHECK(lines(opt) ==
        "shader 'toon': unit 3 'texture_atlas' holds base-colour textures, and this scene has "
        "none");
  // A camera with beams or a gated sampling mode.
  opt = small();
  opt.user.camera = host::user_stage<test_support::Fisheye>();
  CHECK(lines(opt) == "");
  opt.beams = true;
  CHECK(lines(opt) ==
        "camera 'fisheye': --beams march the project's camera (generadorRayos) over tiles; a "
        "camera of your own needs --beams off");
  opt.beams = false;
  opt.spp = 4;
  opt.adaptive = true;
  CHECK(lines(opt) ==
        "camera 'fisheye': --aa adaptive builds on the project's camera (gated sample rays, dense "
        "streams); a camera of your own takes --spp N (its jitter as uniforms) or no --aa");
  // The tracer refuses them too (a library caller that skips validate).
  CHECK_THROWS_WITH_AS(render(scene, opt),
                       "camera 'fisheye': --aa adaptive builds on the project's camera (gated "
                       "sample rays, dense streams); a camera of your own takes --spp N (its "
                       "jitter as uniforms) or no --aa",
                       vgpu::Error);
}

TEST_CASE("frames with every kernel run as its recording are the compiled frames bit for bit") {
  // The recorded-program executor on whole frames (vgpu::Gpu::set_recorded): every structure's
  // walk, multipass and looping, supersampled; the same images, hits and passes.
  const host::Scene scene = host::load_scene(host::resolve_scene("bunny-refl"));
  const host::AccelParams params{host::grid_spec_for({}, scene, vgpu::profile("gf6600"))};
  for (const host::AccelKind kind : host::kAccelKinds)
    for (const bool looping : {false, true}) {
      CAPTURE(host::accel_name(kind));
      CAPTURE(looping);
      const std::unique_ptr<host::Accel> accel = host::make_accel(kind, scene, params);
      host::RenderResult frames[2];
      for (int recorded = 0; recorded < 2; ++recorded) {
        host::RenderOptions opt = small(looping ? 1 : 4);
        opt.profile = "gf6600";
        opt.looping = looping;
        if (recorded) opt.recorded_programs = {"all"};
        host::StreamTracer tracer(scene, *accel, opt);
        frames[recorded] =
            tracer.render(host::scene_camera(scene, float(opt.width) / float(opt.height)));
      }
      CHECK(same_bits(frames[0].rgb, frames[1].rgb));
      CHECK(same_bits(frames[0].hit_id, frames[1].hit_id));
      CHECK(frames[0].stats.totals.passes == frames[1].stats.totals.passes);
      CHECK(frames[0].stats.totals.texture_fetches == frames[1].stats.totals.texture_fetches);
    }
}
