// Multiple render targets executed (--mrt on, kernels/fused.h): the fused pipeline gives the
// multipass pipeline's images, hit ids and depths bit for bit, on every bundled scene and every
// stability case, with the passes and program loads the structure predicts; a profile with one
// output refuses it, naming the fused program.
#include <doctest/doctest.h>

#include <cstring>
#include <string>
#include <vector>

#include "host/accel/grid.h"
#include "host/image/image_io.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/mrt.h"
#include "host/trace/stream/stream_tracer.h"
#include "stability_cases.h"
#include "tests/support/bits.h"

using test_support::same_bits;

namespace {

uint64_t passes_of(const vgpu::FrameStats& s, const std::string& program) {
  const auto* p = s.find(program);
  return p ? p->counters.passes : 0;
}

// Traces that walked the grid at all, in a multipass run with pass records: each has exactly
// one actualizarVoxel pass right after its entry pass (init or reset traversal) and the
// rayosEnGrilla query between them. That first actualizarVoxel is the one --mrt on keeps.
uint64_t walking_traces(const vgpu::FrameStats& s) {
  uint64_t n = 0;
  for (size_t i = 2; i < s.passes.size(); ++i)
    n += s.passes[i].program == "update voxel" && (s.passes[i - 2].program == "init traversal" ||
                                                   s.passes[i - 2].program == "reset traversal");
  return n;
}

// The multipass and the fused run of one frame: equal images, AOVs and ray counts; passes and
// program loads fewer by what the structure predicts; queries, read-backs and every query
// count unchanged.
void check_fused_matches(const host::RenderResult& off, const host::RenderResult& on, int pixels) {
  CHECK(same_bits(off.hit_id, on.hit_id));
  CHECK(same_bits(off.depth, on.depth));
  CHECK(same_bits(off.rgb, on.rgb));
  CHECK(off.iterations == on.iterations);
  CHECK(off.rays_traced == on.rays_traced);
  CHECK(off.rays_unfinished == on.rays_unfinished);
  const vgpu::FrameStats &a = off.stats, &b = on.stats;
  // Each intersecciones + proximoTriangulo pair is one fused pass, each traversal step one
  // fused traversal + actualizarVoxel pass, and of the actualizarVoxel passes only each
  // trace's first is left.
  const uint64_t k = passes_of(a, "intersections"), steps = passes_of(a, "traversal");
  const uint64_t traces = walking_traces(a);
  CHECK(passes_of(a, "next triangle") == k);
  CHECK(passes_of(a, "update voxel") == steps);
  CHECK(passes_of(b, "intersections + next triangle") == k);
  CHECK(passes_of(b, "traversal + update voxel") == steps);
  CHECK(passes_of(b, "update voxel") == traces);
  for (const char* gone : {"intersections", "next triangle", "traversal"})
    CHECK(passes_of(b, gone) == 0);
  const uint64_t saved = k + steps - traces;
  CHECK(b.totals.passes == a.totals.passes - saved);
  // Every pass loads a program in both pipelines (no two passes in a row share one), but for
  // the ray streams' passes (glass): their prefix-sum passes run one program several times in
  // a row, and the count of those repeats is the same in both pipelines.
  const uint64_t repeats = a.totals.passes - a.totals.program_loads;
  CHECK(repeats == b.totals.passes - b.totals.program_loads);
  if (passes_of(a, "stream scan") == 0) CHECK(repeats == 0);
  CHECK(b.totals.program_loads == a.totals.program_loads - saved);
  // Every pass shades every pixel (no masks): the saved passes' fragments are saved.
  CHECK(b.totals.fragments_shaded == a.totals.fragments_shaded - saved * uint64_t(pixels));
  // The host still steers by the same queries: read-backs do not change.
  CHECK(b.totals.query_readbacks == a.totals.query_readbacks);
  std::vector<int64_t> qa, qb;
  for (const auto& p : a.passes)
    if (p.query_result >= 0) qa.push_back(p.query_result);
  for (const auto& p : b.passes)
    if (p.query_result >= 0) qb.push_back(p.query_result);
  CHECK(qa == qb);
}

host::RenderResult render(const host::Scene& scene, const host::Grid& grid, const host::Camera& cam,
                          host::RenderOptions opt, bool mrt) {
  opt.mrt = mrt;
  opt.keep_pass_records = true;
  host::StreamTracer tracer(scene, grid, opt);
  return tracer.render(cam);
}

}  // namespace

TEST_CASE("every bundled scene at 64x64 gives identical hit ids, depths and images with mrt on" * doctest::test_suite("sweep")) {
  for (const auto& [bound_name, bound_path] : host::list_scenes()) {
    // Named copies: clang 14 cannot capture a structured binding (CAPTURE, INFO).
    const auto& name = bound_name;
    const auto& path = bound_path;
    CAPTURE(name);
    const host::Scene scene = host::load_scene(path, host::with_images());
    host::RenderOptions opt;
    opt.width = opt.height = 64;
    opt.profile = "gf6600";
    opt.threads = 2;
    const host::Grid grid =
        host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile(opt.profile)));
    const host::Camera cam = host::scene_camera(scene);
    const host::RenderResult off = render(scene, grid, cam, opt, false);
    const host::RenderResult on = render(scene, grid, cam, opt, true);
    MESSAGE(name << ": passes " << off.stats.totals.passes << " -> " << on.stats.totals.passes
                 << ", program loads " << off.stats.totals.program_loads << " -> "
                 << on.stats.totals.program_loads << ", read-backs "
                 << off.stats.totals.query_readbacks << " -> " << on.stats.totals.query_readbacks);
    check_fused_matches(off, on, 64 * 64);
  }
}

TEST_CASE("every stability case gives identical hit ids and depths with mrt on at fp32 and fp16") {
  for (const stability::Case& c : stability::cases()) {
    for (vgpu::Format f : {vgpu::Format::fp32, vgpu::Format::fp16}) {
      CAPTURE(c.name);
      CAPTURE(vgpu::format_name(f));
      const host::Grid grid = stability::grid_of(c);
      host::RenderOptions opt = stability::options_of(c, f);
      opt.profile = "gf6600";
      opt.lanes = 1;
      const host::RenderResult off = render(c.scene, grid, c.camera, opt, false);
      const host::RenderResult on = render(c.scene, grid, c.camera, opt, true);
      check_fused_matches(off, on, c.width * c.height);
    }
  }
}

TEST_CASE("fused passes are bit-identical for 1 and 3 threads, 1 and 8 lanes, shortcut and masks") {
  const host::Scene scene = host::load_scene(host::resolve_scene("bunny-refl"));
  host::RenderOptions opt;
  opt.width = 72;  // 72x64 = 4608 fragments: passes are split over threads from 4096 on
  opt.height = 64;
  opt.profile = "gf6600";
  opt.threads = 1;
  opt.lanes = 1;
  const host::Grid grid =
      host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile(opt.profile)));
  const host::Camera cam = *scene.camera;
  const host::RenderResult ref = render(scene, grid, cam, opt, true);
  auto same = [&](const host::RenderResult& r) {
    CHECK(same_bits(ref.rgb, r.rgb));
    CHECK(same_bits(ref.hit_id, r.hit_id));
    CHECK(same_bits(ref.depth, r.depth));
  };
  opt.threads = 3;
  opt.lanes = 8;
  const host::RenderResult wide = render(scene, grid, cam, opt, true);
  same(wide);
  CHECK(wide.stats.totals.same_counts(ref.stats.totals));
  opt.host_shortcut = false;
  const host::RenderResult slow = render(scene, grid, cam, opt, true);
  same(slow);
  CHECK(slow.stats.totals.same_counts(ref.stats.totals));
  opt.host_shortcut = true;
  opt.masks = true;
  const host::RenderResult masked = render(scene, grid, cam, opt, true);
  same(masked);
  CHECK(masked.stats.totals.fragments_masked > 0);
  CHECK(masked.stats.totals.passes == ref.stats.totals.passes);
}

TEST_CASE("mrt on a profile with one output is refused, naming the fused program and the limit") {
  const host::Scene scene = host::load_scene(host::resolve_scene("bunny-low"));
  const host::Grid grid = host::build_grid(scene, host::GridSpec{glm::ivec3(4)});
  host::RenderOptions opt;
  opt.width = opt.height = 8;
  opt.profile = "gf5700";
  opt.mrt = true;
  CHECK_THROWS_WITH_AS(host::StreamTracer(scene, grid, opt),
                       "--mrt on: program 'intersections + next triangle' writes 2 outputs; "
                       "profile gf5700 allows 1 (no multiple render targets)",
                       vgpu::Error);
  // Each profile with more than one output runs it; the fused programs compute in one format.
  for (const vgpu::Profile& p : vgpu::profiles()) {
    CAPTURE(p.name);
    const std::string why = host::mrt_refusal(p, host::Formats::all(vgpu::Format::fp32));
    CHECK(why.empty() == (p.max_outputs >= 2));
  }
  host::Formats mixed = host::Formats::all(vgpu::Format::fp32);
  mixed.set(host::Group::hits, vgpu::Format::fp16, vgpu::Format::fp16);
  const std::string why = host::mrt_refusal(vgpu::profile("gf6600"), mixed);
  CHECK(why.find("'intersections + next triangle'") != std::string::npos);
  CHECK(why.find("hits (fp16) and voxel (fp32)") != std::string::npos);
}
