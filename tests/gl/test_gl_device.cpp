// The GL device against the vgpu on whole frames: the generated programs, every occlusion-query
// count of a frame query by query, and every bundled scene's image and hit ids. Runs on
// llvmpipe in CI (any EGL device works).
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "gl/context.h"
#include "host/accel/grid.h"
#include "host/image/image_io.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/stream_tracer.h"
#include "kernels/registry.h"
#include "tests/gl/gl_compare.h"

namespace {

struct Frame {
  host::RenderResult result;
  std::string device;
};

Frame render(const std::string& scene_name, const std::string& device, int size, bool keep_passes,
             bool mrt = false, const std::string& readback = "auto", int spp = 1,
             bool adaptive = false, int undersample = 0,
             host::RenderOptions::AaCriterion criterion = host::RenderOptions::AaCriterion::image) {
  const host::Scene scene = host::load_scene(host::resolve_scene(scene_name), host::with_images());
  host::RenderOptions opt;
  opt.width = opt.height = size;
  opt.spp = spp;
  opt.adaptive = adaptive;
  opt.undersample = undersample;
  opt.aa_criterion = criterion;
  opt.device = device;
  opt.gl_readback = readback;
  if (mrt) {  // fused two-output passes need a profile with multiple render targets
    opt.profile = "gf6600";
    opt.mrt = true;
  }
  opt.threads = 2;
  opt.keep_pass_records = keep_passes;
  const host::Grid grid =
      host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile(opt.profile)));
  const host::Camera cam = host::scene_camera(scene);
  host::StreamTracer tracer(scene, grid, opt);
  Frame f{tracer.render(cam), tracer.device().description()};
  return f;
}

// The counters the GL device takes from the driver: each pass's own GL_SAMPLES_PASSED gives
// the fragments it discarded, and so the bytes it wrote (its time, device_ms, is the driver's
// too, and differs from the emulator's by nature).
bool same_driver_counts(const vgpu::Counters& a, const vgpu::Counters& b) {
  return a.fragments_discarded == b.fragments_discarded && a.bytes_written == b.bytes_written;
}

// The counters the GL device copies from the emulator's analysis of the program
// (vgpu::pass_counters: instructions, fetches, bytes read, ... per fragment drawn): equal
// whenever the same programs draw the same rectangles from textures of the same formats,
// whatever the driver computes. lanes_idle and the batch counters are the emulator's SIMD model
// and stay 0 on the GL device.
bool same_analysis_counts(const vgpu::Counters& a, const vgpu::Counters& b) {
  for (const auto& [name, field] : vgpu::kCounterFields) {
    const std::string n = name;
    if (n == "lanes_idle" || n == "idle_in_batch32" || n == "idle_in_batch1024" ||
        n == "fragments_discarded" || n == "bytes_written")
      continue;
    if (a.*field != b.*field) return false;
  }
  return true;
}

// Per-kernel worst ulps, printed when the kernel tests ran in this process (VGPU_GL_ULPS=1).
const int kReport = [] {
  if (std::getenv("VGPU_GL_ULPS")) {
    gltest::worst_ulps();  // both maps constructed first, so they outlive the handler
    gltest::ulps_allowed("");
    std::atexit([] {
      for (const auto& [name, ulps] : gltest::worst_ulps())
        std::fprintf(stderr, "gl ulps: %-22s %6llu (allowed %d)\n", name.c_str(),
                     static_cast<unsigned long long>(ulps), gltest::ulps_allowed(name));
    });
  }
  return 0;
}();

}  // namespace

TEST_CASE(
    "every kernel's generated GLSL compiles and links on the GL device, which keeps a sampler "
    "for each unit the kernel fetches from and an output for each target") {
  gl::GlDevice& d = gltest::device();
  for (const auto& p : kernels::all_programs(kernels::Programs::with_looping)) {
    const vgpu::GlslProgram g = vgpu::to_glsl(*p);
    const std::string name = p->name();
    CAPTURE(name);
    // The driver's word: it compiles and links the text, keeps every sampler (a sampler the
    // program never reads would be dropped, its location -1) and finds each output where the
    // GLSL put it.
    gl::GlDevice::Linked l;
    REQUIRE_NOTHROW(l = d.link(*p));
    // One sampler per unit the counting run says the kernel fetches from.
    const vgpu::Program::Analysis a = p->analyze();
    int fetched = 0;
    for (int u = 0; u < vgpu::kMaxTextureUnits; ++u) fetched += a.fetches.per_unit[u] > 0;
    CHECK(int(g.units.size()) == fetched);
    CHECK(int(l.samplers.size()) == fetched);
    for (const int location : l.samplers) CHECK(location >= 0);
    REQUIRE(int(l.outputs.size()) == p->outputs());
    for (int o = 0; o < p->outputs(); ++o) CHECK(l.outputs[size_t(o)] == o);
    // Never more statements than the counting run's instructions (dead ones are dropped), and
    // a discard exactly in the programs that kill fragments. (A looping program's text also
    // copies its carried values in and out of the loop, statements the counting run does not
    // count: the bound is for the straight programs.)
    if (a.loop.loops == 0) CHECK(g.statements <= a.instructions + 1);
    CHECK((g.source.find("discard;") != std::string::npos) == p->idle_discards());
  }
}

TEST_CASE("a uniform change reuses the compiled GLSL: constants are uniforms, not text") {
  vgpu::KernelProgram<kernels::Traversal> a, b;
  b.kernel.grid.lo = {1.5f, -2.0f, 3.25f};
  b.kernel.grid.res = {7, 8, 9};
  const vgpu::GlslProgram ga = vgpu::to_glsl(a), gb = vgpu::to_glsl(b);
  CHECK(ga.source == gb.source);
  CHECK(ga.constants != gb.constants);
}

namespace {

// A pass whose output depends on a uniform: the source texel's x times `scale`.
struct ScaleBy {
  static constexpr const char* name = "scale by";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  static constexpr std::array<const char*, 1> units{"source"};
  float scale = 1;
  template <class L>
  void operator()(vgpu::Fragments<L>& f) const {
    const vgpu::Vec4<typename L::F> v = f.fetch_own(0);
    f.out(0) = {v.x * typename L::F(scale), v.y, v.z, v.w};
  }
};

// ScaleBy's 4x2 source: x channel 1..8 (row-major), then 0.5, -1 and 1.
vgpu::Texture scale_source() {
  vgpu::Texture src("scale source", 4, 2, 4);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) {
      float* t = src.texel_mut(x, y);
      t[0] = float(1 + x + 4 * y);
      t[1] = 0.5f;
      t[2] = -1.0f;
      t[3] = 1.0f;
    }
  return src;
}

// One ScaleBy pass from src into dst at p's scale, read back, every channel of every texel checked.
void draw_scaled(gl::GlDevice& d, const vgpu::KernelProgram<ScaleBy>& p, const vgpu::Texture& src,
                 vgpu::Texture& dst) {
  d.use_program(p);
  d.bind_texture(0, src);
  d.set_targets({&dst});
  d.draw();
  d.download(dst);
  const float scale = p.kernel.scale;
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) {
      CAPTURE(scale);
      CHECK(dst.texel(x, y)[0] == float(1 + x + 4 * y) * scale);
      CHECK(dst.texel(x, y)[1] == 0.5f);
      CHECK(dst.texel(x, y)[2] == -1.0f);
      CHECK(dst.texel(x, y)[3] == 1.0f);
    }
}

}  // namespace

TEST_CASE(
    "a program drawn again with uniforms it was drawn with before draws with them, from the GLSL "
    "the GL device kept for them, and a program keeps the GLSL of its last 64 uniform sets") {
  gl::GlDevice& d = gltest::device();
  const vgpu::Texture src = scale_source();
  vgpu::Texture dst("scale target", 4, 2, 4);
  d.upload(src);
  vgpu::KernelProgram<ScaleBy> p;
  auto draw = [&](float scale) {
    p.kernel.scale = scale;
    draw_scaled(d, p, src, dst);
  };
  const gl::GlDevice::HostTimes t0 = d.host_times();
  draw(2.0f);
  draw(3.0f);
  draw(2.0f);  // the first set again: its GLSL kept, its constants drawn with
  const gl::GlDevice::HostTimes t1 = d.host_times();
  CHECK(t1.variants_printed - t0.variants_printed == 2);
  CHECK(t1.variants_reused - t0.variants_reused == 1);
  CHECK(t1.programs_linked == t0.programs_linked + 1);  // one text for all: constants are uniforms
  // 64 more sets push out the oldest ones: 2 and 3 are printed again.
  for (int i = 0; i < 64; ++i) draw(4.0f + float(i));
  const gl::GlDevice::HostTimes t2 = d.host_times();
  draw(3.0f);
  draw(2.0f);
  CHECK(d.host_times().variants_printed - t2.variants_printed == 2);
  CHECK(d.host_times().variants_reused == t2.variants_reused);
}

TEST_CASE(
    "a texture that is gone, moved from or assigned over has its GL texture and the framebuffers "
    "it was a target of deleted at the GL device's next call, and passes after give every "
    "channel") {
  gl::GlDevice& d = gltest::device();
  const vgpu::Texture src = scale_source();
  d.upload(src);
  vgpu::KernelProgram<ScaleBy> p;
  p.kernel.scale = 2.0f;
  auto draw_into = [&](vgpu::Texture& dst) { draw_scaled(d, p, src, dst); };
  const size_t held = d.textures_held();
  const gl::GlDevice::HostTimes t0 = d.host_times();
  for (int i = 0; i < 3; ++i) {  // a frame's scratch target, made and dropped each time
    vgpu::Texture dst("scale target", 4, 2, 4);
    draw_into(dst);
  }
  d.upload(src);  // the next call after the last one is gone
  const gl::GlDevice::HostTimes t1 = d.host_times();
  CHECK(t1.textures_made - t0.textures_made == 3);
  CHECK(t1.textures_freed - t0.textures_freed == 3);
  CHECK(t1.framebuffers_made - t0.framebuffers_made == 3);
  CHECK(t1.framebuffers_freed - t0.framebuffers_freed == 3);
  CHECK(d.textures_held() == held);

  // A move drops the moved-from texture's id, an assignment the assigned-to texture's old one:
  // each a new texture for the device, drawn into again.
  vgpu::Texture a("moved from", 4, 2, 4);
  draw_into(a);
  vgpu::Texture b(std::move(a));
  draw_into(b);
  CHECK(d.host_times().textures_freed - t1.textures_freed == 1);
  CHECK(d.host_times().framebuffers_freed - t1.framebuffers_freed == 1);
  b = vgpu::Texture("assigned", 4, 2, 4);
  draw_into(b);
  CHECK(d.host_times().textures_freed - t1.textures_freed == 2);
  CHECK(d.host_times().framebuffers_freed - t1.framebuffers_freed == 2);
  // A move assignment between two textures the device holds drops both old ids.
  vgpu::Texture c("moved into b", 4, 2, 4);
  draw_into(c);
  b = std::move(c);
  draw_into(b);
  CHECK(d.host_times().textures_freed - t1.textures_freed == 4);
  CHECK(d.host_times().framebuffers_freed - t1.framebuffers_freed == 4);
  CHECK(d.textures_held() == held + 1);  // b's
}

TEST_CASE("the GL device refuses what it cannot do, naming it") {
  gl::GlDevice& d = gltest::device();
  vgpu::Stencil mask(4, 4);
  CHECK_THROWS_WITH_AS(d.set_stencil_test(&mask), doctest::Contains("no stencil masks"),
                       vgpu::Error);
  vgpu::Texture t("fp24 state", 4, 4, 4, vgpu::Format::fp24);
  CHECK_THROWS_WITH_AS(d.upload(t), doctest::Contains("fp24"), vgpu::Error);
  CHECK_THROWS_WITH_AS(gl::Context("99"), doctest::Contains("--gl-device 99"), gl::Unavailable);
  CHECK_THROWS_AS(gl::Context("first"), gl::Unavailable);
}

TEST_CASE(
    "every occlusion-query count and every pass's discarded fragments, as the GL driver counts "
    "them, equal the vgpu's in a bunny and a bunny-refl frame, blocking or polling for the "
    "result") {
  for (const auto& [name, wait] : {std::pair{"bunny", "block"}, std::pair{"bunny-refl", "poll"}}) {
    CAPTURE(name);
    CAPTURE(wait);
    const Frame v = render(name, "vgpu", 64, true), g = render(name, "gl", 64, true, false, wait);
    const auto& pv = v.result.stats.passes;
    const auto& pg = g.result.stats.passes;
    size_t queries = 0, discarding = 0;
    for (size_t i = 0; i < std::min(pv.size(), pg.size()); ++i) {
      CAPTURE(i);
      CAPTURE(pv[i].program);
      REQUIRE(pv[i].program == pg[i].program);
      REQUIRE(pv[i].query_result == pg[i].query_result);
      queries += pv[i].query_result >= 0;
      // The driver's own count of the pass's discards (its GL_SAMPLES_PASSED), and the rest
      // as the GL device copies it from the emulator's analysis.
      CHECK(pg[i].counters.fragments_discarded == pv[i].counters.fragments_discarded);
      CHECK(same_driver_counts(pv[i].counters, pg[i].counters));
      CHECK(same_analysis_counts(pv[i].counters, pg[i].counters));
      discarding += pg[i].counters.fragments_discarded > 0;
    }
    REQUIRE(pv.size() == pg.size());
    CHECK(queries == v.result.stats.totals.query_readbacks);
    CHECK(discarding > 0);  // passes that discard: the driver's counts are not all zero
    CHECK(same_driver_counts(v.result.stats.totals, g.result.stats.totals));
    CHECK(same_analysis_counts(v.result.stats.totals, g.result.stats.totals));
    CHECK(g.result.stats.totals.device_ms > 0);
    // The image and hit textures read back at the end: counted alike on both devices.
    CHECK(v.result.stats.downloads >= 2);
    CHECK(v.result.stats.downloads == g.result.stats.downloads);
    CHECK(v.result.stats.download_bytes == g.result.stats.download_bytes);
  }
}

TEST_CASE("the fused MRT passes on the GL device give the vgpu's query counts, hit ids and image") {
  for (const char* name : {"bunny", "bunny-refl"}) {
    CAPTURE(name);
    const Frame v = render(name, "vgpu", 64, true, true), g = render(name, "gl", 64, true, true);
    const auto& pv = v.result.stats.passes;
    const auto& pg = g.result.stats.passes;
    REQUIRE(pv.size() == pg.size());
    size_t fused = 0;
    for (size_t i = 0; i < pv.size(); ++i) {
      CAPTURE(i);
      REQUIRE(pv[i].program == pg[i].program);
      REQUIRE(pv[i].query_result == pg[i].query_result);
      fused += pv[i].program.find(" + ") != std::string::npos;
      CHECK(same_driver_counts(pv[i].counters, pg[i].counters));
      CHECK(same_analysis_counts(pv[i].counters, pg[i].counters));
    }
    CHECK(fused > 0);
    gltest::check_same_frame(g.device, "intersections + next triangle", v.result.hit_id,
                             g.result.hit_id, v.result.depth, g.result.depth, v.result.rgb,
                             g.result.rgb);
  }
}

TEST_CASE("supersampling on the GL device gives the vgpu's passes, query counts and image") {
  for (const bool adaptive : {false, true}) {
    CAPTURE(adaptive);
    const Frame v = render("classic", "vgpu", 48, true, false, "auto", 4, adaptive),
                g = render("classic", "gl", 48, true, false, "auto", 4, adaptive);
    const auto& pv = v.result.stats.passes;
    const auto& pg = g.result.stats.passes;
    REQUIRE(pv.size() == pg.size());
    int accumulations = 0;
    for (size_t i = 0; i < pv.size(); ++i) {
      CAPTURE(i);
      REQUIRE(pv[i].program == pg[i].program);
      REQUIRE(pv[i].query_result == pg[i].query_result);
      // (an adaptive level's frames trace dense streams: acumularDensos adds their samples)
      accumulations +=
          pv[i].program == "accumulate samples" || pv[i].program == "accumulate dense samples";
    }
    // Uniform: one per sample frame; adaptive: the centre frame's, then one per sample.
    CHECK(accumulations == (adaptive ? 5 : 4));
    CHECK(g.result.rays_per_pixel == v.result.rays_per_pixel);
    gltest::check_same_frame(g.device, "intersections", v.result.hit_id, g.result.hit_id,
                             v.result.depth, g.result.depth, v.result.rgb, g.result.rgb);
  }
}

TEST_CASE("adaptive sampling's second level on the GL device marks the vgpu's pixels") {
  // Up to 16 samples: marcarPixeles before the 2 x 2 level and again before the 4 x 4 level.
  const Frame v = render("classic", "vgpu", 32, true, false, "auto", 16, true),
              g = render("classic", "gl", 32, true, false, "auto", 16, true);
  const auto& pv = v.result.stats.passes;
  const auto& pg = g.result.stats.passes;
  REQUIRE(pv.size() == pg.size());
  int marks = 0;
  for (size_t i = 0; i < pv.size(); ++i) {
    CAPTURE(i);
    REQUIRE(pv[i].program == pg[i].program);
    REQUIRE(pv[i].query_result == pg[i].query_result);
    marks += pv[i].program == "mark pixels";
  }
  CHECK(marks == 2);
  // Some pixels stopped after the 2 x 2 level, some went on.
  const auto& n = v.result.rays_per_pixel;
  CHECK(std::count(n.begin(), n.end(), 1u + 4u) > 0);
  CHECK(std::count(n.begin(), n.end(), 1u + 4u + 16u) > 0);
  CHECK(g.result.rays_per_pixel == v.result.rays_per_pixel);
  gltest::check_same_frame(g.device, "intersections", v.result.hit_id, g.result.hit_id,
                           v.result.depth, g.result.depth, v.result.rgb, g.result.rgb);
}

TEST_CASE("the object criterion on the GL device keeps the vgpu's cones and marks its pixels") {
  // bunny-refl: the mirror's reflected keys (guardarReflejos) as well as the hit distances; one
  // level (4 samples), to keep the test short.
  const auto object = host::RenderOptions::AaCriterion::object;
  const Frame v = render("bunny-refl", "vgpu", 24, true, false, "auto", 4, true, 0, object),
              g = render("bunny-refl", "gl", 24, true, false, "auto", 4, true, 0, object);
  const auto& pv = v.result.stats.passes;
  const auto& pg = g.result.stats.passes;
  REQUIRE(pv.size() == pg.size());
  int cones = 0;
  for (size_t i = 0; i < pv.size(); ++i) {
    CAPTURE(i);
    REQUIRE(pv[i].program == pg[i].program);
    REQUIRE(pv[i].query_result == pg[i].query_result);
    cones += pv[i].program == "mark cones" || pv[i].program == "keep cones" ||
             pv[i].program == "keep reflected";
  }
  CHECK(cones == 3);  // keep cones, keep reflected, then mark cones before the level
  // Some pixels were refined, not all.
  const auto& n = v.result.rays_per_pixel;
  CHECK(std::count(n.begin(), n.end(), 1u + 4u) > 0);
  CHECK(std::count(n.begin(), n.end(), 1u) > 0);
  CHECK(g.result.rays_per_pixel == v.result.rays_per_pixel);
  gltest::check_same_frame(g.device, "intersections", v.result.hit_id, g.result.hit_id,
                           v.result.depth, g.result.depth, v.result.rgb, g.result.rgb);
}

TEST_CASE(
    "the budget criterion on the GL device counts the vgpu's scores at every step of its search "
    "and marks its pixels at both levels") {
  // bunny-refl, spp 16: the 2 x 2 level, then the 4 x 4 level's 12 new samples added to them.
  const auto budget = host::RenderOptions::AaCriterion::budget;
  const Frame v = render("bunny-refl", "vgpu", 16, true, false, "auto", 16, true, 0, budget),
              g = render("bunny-refl", "gl", 16, true, false, "auto", 16, true, 0, budget);
  const auto& pv = v.result.stats.passes;
  const auto& pg = g.result.stats.passes;
  REQUIRE(pv.size() == pg.size());
  uint64_t counts = 0;
  for (size_t i = 0; i < pv.size(); ++i) {
    CAPTURE(i);
    REQUIRE(pv[i].program == pg[i].program);
    REQUIRE(pv[i].query_result == pg[i].query_result);
    counts += pv[i].program == "scored hits";
  }
  REQUIRE(v.result.budget_levels.size() == 2);
  REQUIRE(g.result.budget_levels.size() == 2);
  uint64_t steps = 0;
  for (size_t l = 0; l < 2; ++l) {
    CHECK(g.result.budget_levels[l].threshold == v.result.budget_levels[l].threshold);
    CHECK(g.result.budget_levels[l].budget == v.result.budget_levels[l].budget);
    steps += v.result.budget_levels[l].steps;
  }
  CHECK(counts == steps);
  // Pixels at every stage: one ray, 1 + 4, and 1 + 4 + 12 (the kept level).
  const auto& n = v.result.rays_per_pixel;
  for (const uint32_t rays : {1u, 5u, 17u}) CHECK(std::count(n.begin(), n.end(), rays) > 0);
  CHECK(g.result.rays_per_pixel == v.result.rays_per_pixel);
  gltest::check_same_frame(g.device, "intersections", v.result.hit_id, g.result.hit_id,
                           v.result.depth, g.result.depth, v.result.rgb, g.result.rgb);
}

TEST_CASE("undersampling on the GL device traces the vgpu's pixels and gives its image") {
  const Frame v = render("classic", "vgpu", 48, true, false, "auto", 1, false, 2),
              g = render("classic", "gl", 48, true, false, "auto", 1, false, 2);
  const auto& pv = v.result.stats.passes;
  const auto& pg = g.result.stats.passes;
  REQUIRE(pv.size() == pg.size());
  for (size_t i = 0; i < pv.size(); ++i) {
    CAPTURE(i);
    REQUIRE(pv[i].program == pg[i].program);
    REQUIRE(pv[i].query_result == pg[i].query_result);
  }
  CHECK(g.result.rays_per_pixel == v.result.rays_per_pixel);
  gltest::check_same_frame(g.device, "intersections", v.result.hit_id, g.result.hit_id,
                           v.result.depth, g.result.depth, v.result.rgb, g.result.rgb);
}

TEST_CASE(
    "every bundled scene at 128x128 on the GL device matches the vgpu's hit ids, depths and "
    "colour") {
  size_t scenes = 0;
  for (const auto& [name, path] : host::list_scenes()) {
    CAPTURE(name);
    const Frame v = render(name, "vgpu", 128, false), g = render(name, "gl", 128, false);
    gltest::check_same_frame(g.device, "intersections", v.result.hit_id, g.result.hit_id,
                             v.result.depth, g.result.depth, v.result.rgb, g.result.rgb);
    // Not an empty frame: a wrong camera would compare misses alone.
    const auto hit = std::count_if(v.result.hit_id.begin(), v.result.hit_id.end(),
                                   [](float id) { return id >= 0; });
    CHECK(hit * 20 >= std::ptrdiff_t(v.result.hit_id.size()));
    ++scenes;
  }
  CHECK(scenes >= 8);
}

TEST_CASE(
    "the textured scene on the GL device matches the vgpu's image for every texture filter, "
    "and the shader's fetches as the emulator's analysis counts them") {
  const host::Scene scene = host::load_scene(host::resolve_scene("textured"), host::with_images());
  for (vgpu::Filter filter :
       {vgpu::Filter::nearest, vgpu::Filter::bilinear, vgpu::Filter::trilinear}) {
    CAPTURE(int(filter));
    host::RenderResult frames[2];
    std::string gl_name;
    for (int k = 0; k < 2; ++k) {
      host::RenderOptions opt;
      opt.width = opt.height = 96;
      opt.device = k ? "gl" : "vgpu";
      opt.texture_filter = filter;
      opt.threads = 2;
      const host::Grid grid =
          host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile(opt.profile)));
      host::StreamTracer tracer(scene, grid, opt);
      frames[k] = tracer.render(host::scene_camera(scene));
      if (k) gl_name = tracer.device().description();
      const auto* shader = frames[k].stats.find("shader");
      REQUIRE(shader != nullptr);
    }
    // The shader's fetches: the emulator's analysis of the program both devices drew (the GL
    // device copies it; no driver counts fetches), so equal counts say that the filter chose
    // the same shader on both. The driver's own figures: the frame's discards, and the image.
    CHECK(frames[0].stats.find("shader")->counters.texture_fetches ==
          frames[1].stats.find("shader")->counters.texture_fetches);
    CHECK(same_driver_counts(frames[0].stats.totals, frames[1].stats.totals));
    gltest::check_same_frame(gl_name, "intersections", frames[0].hit_id, frames[1].hit_id,
                             frames[0].depth, frames[1].depth, frames[0].rgb, frames[1].rgb);
  }
}
