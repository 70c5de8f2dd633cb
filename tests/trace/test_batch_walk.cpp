// The batch walk (RenderOptions::batch_walk, vgpu/batch.h): the multipass grid walk run 8 pixels
// at a time through every pass, then replayed on the Gpu for the statistics, gives the images,
// depths, hit ids, ray counts and every integer statistic (totals, per program, per pass) of the
// walk run pass by pass: on every bundled scene, with --mrt on, --masks on, at fp24 and fp16,
// on targets whose width is no multiple of 8 (partial batches, partial 32x32 tiles), for 1 and 2
// threads, on every stability case, and on a crowded fan where fp16 list positions get stuck
// and the walk's triangle loop runs to its cap.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "host/accel/grid.h"
#include "host/image/image_io.h"
#include "host/report/counters_json.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/stream_tracer.h"
#include "stability_cases.h"
#include "tests/support/bits.h"
#include "tests/support/lane_widths.h"
#include "tests/support/stats_json.h"

using test_support::same_bits;

using test_support::without_times;

namespace {

using Json = nlohmann::ordered_json;

// The first pixel where two buffers differ (bits), as "i: a vs b", or "" when none does.
std::string first_difference(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size())
    return "sizes " + std::to_string(a.size()) + " vs " + std::to_string(b.size());
  for (size_t i = 0; i < a.size(); ++i)
    if (std::memcmp(&a[i], &b[i], sizeof(float)) != 0)
      return std::to_string(i) + ": " + std::to_string(a[i]) + " vs " + std::to_string(b[i]);
  return "";
}

// Every pass record as JSON: program, rectangle, every integer counter, query result, loops.
Json pass_records(const vgpu::FrameStats& s) {
  Json out = Json::array();
  for (const vgpu::PassRecord& p : s.passes)
    out.push_back({{"program", p.program},
                   {"width", p.width},
                   {"height", p.height},
                   {"counters", without_times(host::counters_json(p.counters))},
                   {"query_result", p.query_result},
                   {"loop_active", p.loop_active},
                   {"loop_idle", p.loop_idle}});
  return out;
}

// The JSON differences, shortened for a message.
std::string differences(const Json& a, const Json& b) {
  std::string d = Json::diff(a, b).dump();
  return d.size() > 1500 ? d.substr(0, 1500) + "..." : d;
}

// The batch walk against the pass-by-pass walk of one frame: everything but wall-clock time.
void check_same_frame(const host::RenderResult& passes, const host::RenderResult& batches) {
  CHECK_MESSAGE(same_bits(passes.rgb, batches.rgb), "rgb ",
                first_difference(passes.rgb, batches.rgb));
  CHECK_MESSAGE(same_bits(passes.depth, batches.depth), "depth ",
                first_difference(passes.depth, batches.depth));
  CHECK_MESSAGE(same_bits(passes.hit_id, batches.hit_id), "hit_id ",
                first_difference(passes.hit_id, batches.hit_id));
  CHECK(passes.iterations == batches.iterations);
  CHECK(passes.rays_traced == batches.rays_traced);
  CHECK(passes.rays_unfinished == batches.rays_unfinished);
  const Json a = without_times(host::frame_counters_json(passes.stats)),
             b = without_times(host::frame_counters_json(batches.stats));
  CHECK_MESSAGE(a == b, "statistics differ: ", differences(a, b));
  CHECK(passes.stats.totals.same_counts(batches.stats.totals));
  CHECK(passes.stats.keep_pass_records == batches.stats.keep_pass_records);
  REQUIRE(passes.stats.passes.size() == batches.stats.passes.size());
  if (passes.stats.keep_pass_records) {
    const Json ra = pass_records(passes.stats), rb = pass_records(batches.stats);
    for (size_t i = 0; i < ra.size(); ++i)
      if (ra[i] != rb[i]) {
        FAIL_CHECK("pass " << i << " of " << ra.size() << " differs: " << ra[i].dump() << " vs "
                           << rb[i].dump());
        break;
      }
  }
}

host::RenderResult render(const host::Scene& scene, const host::Grid& grid, const host::Camera& cam,
                          host::RenderOptions opt, bool batches) {
  opt.batch_walk = batches;
  host::StreamTracer tracer(scene, grid, opt);
  return tracer.render(cam);
}

struct Frames {
  host::RenderResult passes, batches;
};

// One frame walked pass by pass and in batches, compared.
Frames compare(const host::Scene& scene, const host::Grid& grid, const host::Camera& cam,
               const host::RenderOptions& opt) {
  Frames f{render(scene, grid, cam, opt, false), render(scene, grid, cam, opt, true)};
  // The shortcut must have run (it falls back to passes silently where it does not apply).
  CHECK_FALSE(f.passes.batch_walk);
  CHECK(f.batches.batch_walk);
  check_same_frame(f.passes, f.batches);
  return f;
}

// A bundled scene with its own grid and camera for a W x H frame.
struct Bundled {
  host::Scene scene;
  host::Grid grid;
  host::Camera camera;
  Bundled(const std::string& name, const std::string& profile, int w, int h)
      : scene(host::load_scene(host::resolve_scene(name), host::with_images())),
        grid(host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile(profile)))),
        camera(host::scene_camera(scene, float(w) / float(h))) {}
};

host::RenderOptions options(int w, int h, const std::string& profile = "gf5700") {
  host::RenderOptions opt;
  opt.width = w;
  opt.height = h;
  opt.profile = profile;
  opt.threads = 2;
  opt.bounces = 2;
  opt.shadows = true;
  return opt;
}

// The most intersection passes of one voxel step (pass records of a walk without --mrt on).
size_t longest_triangle_loop(const vgpu::FrameStats& s) {
  size_t longest = 0, run = 0;
  for (const vgpu::PassRecord& p : s.passes) {
    if (p.program == "update voxel") run = 0;
    if (p.program == "intersections") longest = std::max(longest, ++run);
  }
  return longest;
}

uint64_t passes_of(const vgpu::FrameStats& s, const std::string& program) {
  const auto* p = s.find(program);
  return p ? p->counters.passes : 0;
}

}  // namespace

TEST_CASE("every bundled scene at 48x40 gives the same frame and statistics walked in batches" * doctest::test_suite("sweep")) {
  const auto scenes = host::list_scenes();
  REQUIRE(scenes.size() >= 8);
  for (const auto& [bound_name, bound_path] : scenes) {
    // Named copies: clang 14 cannot capture a structured binding (CAPTURE, INFO).
    const auto& name = bound_name;
    Bundled b(name, "gf5700", 48, 40);
    for (int bounces : {0, 2}) {
      CAPTURE(std::string(name));
      CAPTURE(bounces);
      host::RenderOptions opt = options(48, 40);
      opt.bounces = bounces;
      const Frames f = compare(b.scene, b.grid, b.camera, opt);
      // The walk ran: rays walked the grid and tested triangles.
      CHECK(f.passes.rays_traced > 0);
      CHECK(passes_of(f.passes.stats, "intersections") > 0);
      CHECK(f.passes.stats.totals.lanes_idle > 0);
      CHECK(f.passes.stats.totals.idle_in_batch32 > 0);
      CHECK(f.passes.stats.totals.idle_in_batch1024 > 0);
    }
  }
}

TEST_CASE("mrt on gives the same frame and statistics walked in batches, with and without masks") {
  for (const char* name : {"bunny-refl", "classic"}) {
    Bundled b(name, "gf6600", 48, 40);
    for (bool masks : {false, true}) {
      CAPTURE(std::string(name));
      CAPTURE(masks);
      host::RenderOptions opt = options(48, 40, "gf6600");
      opt.mrt = true;
      opt.masks = masks;
      const Frames f = compare(b.scene, b.grid, b.camera, opt);
      CHECK(passes_of(f.passes.stats, "intersections + next triangle") > 0);
      CHECK(passes_of(f.passes.stats, "traversal + update voxel") > 0);
      CHECK(passes_of(f.passes.stats, "intersections") == 0);
      CHECK((f.passes.stats.totals.fragments_masked > 0) == masks);
    }
  }
}

TEST_CASE("masks on give the same frame and statistics walked in batches on fp30 and fp40") {
  // Idle fragments are charged as masked, and the batch counters (idle fragments in 8x4 and
  // 32x32 tiles without a taker) count only fragments that ran. fp40 (gf6600) branches
  // dynamically. Masks alone enable the batch walk too (host_shortcut off).
  for (const char* profile : {"gf5700", "gf6600"})
    for (bool shortcut : {true, false}) {
      CAPTURE(std::string(profile));
      CAPTURE(shortcut);
      Bundled b("bunny-refl", profile, 48, 40);
      host::RenderOptions opt = options(48, 40, profile);
      opt.masks = true;
      opt.host_shortcut = shortcut;
      const Frames f = compare(b.scene, b.grid, b.camera, opt);
      const vgpu::Counters& t = f.passes.stats.totals;
      CHECK(t.fragments_masked > 0);
      CHECK(t.idle_in_batch32 > 0);
    }
}

TEST_CASE("fp24 and fp16 ray state give the same frame and statistics walked in batches") {
  host::Formats mixed = host::Formats::all(vgpu::Format::fp32);
  mixed.set(host::Group::colour, vgpu::Format::fp16, vgpu::Format::fp32);
  mixed.set(host::Group::hits, vgpu::Format::fp16, vgpu::Format::fp16);
  mixed.set(host::Group::traversal, vgpu::Format::fp24, vgpu::Format::fp24);
  const std::pair<const char*, host::Formats> formats[] = {
      {"fp24", host::Formats::all(vgpu::Format::fp24)},
      {"fp16", host::Formats::all(vgpu::Format::fp16)},
      {"mixed", mixed}};
  for (const char* name : {"bunny-low", "classic"}) {
    Bundled b(name, "gf5700", 40, 32);
    for (const auto& entry : formats)
      for (bool masks : {false, true}) {
        const char* label = entry.first;  // not a binding: CAPTURE's lambda reads it (clang 14)
        const host::Formats& f = entry.second;
        if (masks && std::string(name) != "bunny-low") continue;
        CAPTURE(std::string(name));
        CAPTURE(std::string(label));
        CAPTURE(masks);
        host::RenderOptions opt = options(40, 32);
        opt.formats = f;
        opt.masks = masks;
        const Frames r = compare(b.scene, b.grid, b.camera, opt);
        // The walk's kernels computed in the reduced formats (run_batch's rounded lanes).
        const std::string l = label;
        CHECK((r.passes.stats.totals.alu_fp24 > 0) == (l != "fp16"));
        CHECK((r.passes.stats.totals.alu_fp16 > 0) == (l != "fp24"));
      }
  }
  // The R300 computes everything at fp24 whatever the formats say.
  Bundled b("sphere", "r300", 40, 32);
  const Frames r = compare(b.scene, b.grid, b.camera, options(40, 32, "r300"));
  CHECK(r.passes.stats.totals.alu_fp24 > 0);
}

TEST_CASE(
    "a 37x29 target (partial batches and 32x32 tiles) gives the same frame walked in batches") {
  for (const char* profile : {"gf5700", "gf6600"}) {
    Bundled b("classic", profile, 37, 29);
    for (bool masks : {false, true}) {
      CAPTURE(std::string(profile));
      CAPTURE(masks);
      host::RenderOptions opt = options(37, 29, profile);
      opt.masks = masks;
      opt.keep_pass_records = true;
      compare(b.scene, b.grid, b.camera, opt);
    }
  }
}

TEST_CASE("batch walks on 1 and 2 threads give the frame and statistics of pass by pass") {
  // 72x64: six 32x32 tiles for the batch walk's threads, and passes of 4608 fragments, which the
  // pass-by-pass walk splits over threads (from 4096 on).
  for (bool masks : {false, true}) {
    CAPTURE(masks);
    Bundled b("bunny-mirror", "gf6600", 72, 64);
    host::RenderOptions opt = options(72, 64, "gf6600");
    opt.masks = masks;
    opt.threads = 1;
    const host::RenderResult ref = render(b.scene, b.grid, b.camera, opt, false);
    const host::RenderResult one = render(b.scene, b.grid, b.camera, opt, true);
    opt.threads = 2;
    const host::RenderResult two = render(b.scene, b.grid, b.camera, opt, true);
    const host::RenderResult two_passes = render(b.scene, b.grid, b.camera, opt, false);
    CHECK(one.batch_walk);
    CHECK(two.batch_walk);
    check_same_frame(ref, one);
    check_same_frame(ref, two);
    check_same_frame(ref, two_passes);
    // The scalar reference (1 lane, pass by pass only) gives the same images and counts.
    opt.lanes = 1;
    const host::RenderResult scalar = render(b.scene, b.grid, b.camera, opt, true);
    CHECK_FALSE(scalar.batch_walk);
    check_same_frame(scalar, two);
  }
}

TEST_CASE("kept pass records are the same pass for pass walked in batches" * doctest::test_suite("sweep")) {
  for (const char* profile : {"gf5700", "gf6600"})
    for (bool mrt : {false, true}) {
      if (mrt && std::string(profile) == "gf5700") continue;  // one output
      for (bool masks : {false, true}) {
        CAPTURE(std::string(profile));
        CAPTURE(mrt);
        CAPTURE(masks);
        Bundled b("bunny-mirror", profile, 40, 32);
        host::RenderOptions opt = options(40, 32, profile);
        opt.mrt = mrt;
        opt.masks = masks;
        opt.keep_pass_records = true;
        const Frames f = compare(b.scene, b.grid, b.camera, opt);
        CHECK(f.batches.stats.passes.size() == f.batches.stats.totals.passes);
        CHECK(f.batches.stats.passes.size() > 100);
        // Query results steer the host: each one must be there, in the same place.
        int queries = 0;
        for (const vgpu::PassRecord& p : f.batches.stats.passes) queries += p.query_result >= 0;
        CHECK(uint64_t(queries) == f.batches.stats.totals.query_readbacks);
      }
    }
}

TEST_CASE("every stability case at fp32 and fp16 gives the same frame walked in batches") {
  // Tiny targets (1 to 17 pixels wide): batches of fewer than 8 live lanes everywhere.
  for (const stability::Case& c : stability::cases())
    for (vgpu::Format f : {vgpu::Format::fp32, vgpu::Format::fp16}) {
      CAPTURE(c.name);
      CAPTURE(vgpu::format_name(f));
      const host::Grid grid = stability::grid_of(c);
      host::RenderOptions opt = stability::options_of(c, f);
      opt.shadows = true;
      opt.keep_pass_records = true;
      compare(c.scene, grid, c.camera, opt);
    }
}

TEST_CASE(
    "the stability suite's fan crowded to 600 triangles at fp16 gives the same frame in batches" * doctest::test_suite("sweep")) {
  // The fan of tests/trace/stability_cases.h with 600 triangles round the centre vertex on the
  // voxel edge x = y = 2: the voxel lists near it hold hundreds of entries, past what fp16
  // addresses exactly, so list positions get stuck and the walk's triangle loop runs to its cap
  // (longest list + 1 passes) where fp24 steps through the list.
  const stability::Case* fan = nullptr;
  static const std::vector<stability::Case> all = stability::cases();
  for (const stability::Case& c : all)
    if (c.name == "a triangle fan has no cracks at its spokes and centre") fan = &c;
  REQUIRE(fan != nullptr);
  stability::Case c = *fan;
  stability::Builder b;
  const int n = 600;
  const double r = 1.7, pi = 3.14159265358979323846;
  const glm::vec3 ct(2, 2, 1.5f);
  for (int k = 0; k < n; ++k) {
    const double a0 = 2 * pi * k / n, a1 = 2 * pi * (k + 1) / n;
    b.tri(ct, ct + glm::vec3(float(r * std::cos(a0)), float(r * std::sin(a0)), 0),
          ct + glm::vec3(float(r * std::cos(a1)), float(r * std::sin(a1)), 0));
  }
  b.s.lights = {{{2, 2, 8}, {1, 1, 1}}};
  c.scene = b.s;
  c.width = c.height = 11;
  const host::Grid grid = stability::grid_of(c);
  size_t max_list = 0;
  for (size_t v = 0; v < grid.voxels(); ++v)
    max_list = std::max(max_list, grid.triangles_in(v).size());
  REQUIRE(max_list > 300);
  for (vgpu::Format f : {vgpu::Format::fp24, vgpu::Format::fp16}) {
    CAPTURE(vgpu::format_name(f));
    host::RenderOptions opt = stability::options_of(c, f);
    opt.shadows = true;
    opt.threads = 2;
    opt.keep_pass_records = true;
    const Frames r = compare(c.scene, grid, c.camera, opt);
    // The longest triangle loop of one voxel step: at fp16 the cap, at fp24 the list's length.
    const size_t loop = longest_triangle_loop(r.passes.stats);
    CHECK(loop == (f == vgpu::Format::fp16 ? max_list + 1 : max_list));
    // Unfinished rays (the voxel-step cap) are compared too, but no case found leaves any in
    // the multipass walk: a traversal pass moves a walking ray at least one voxel, always the
    // same way along each axis, so it leaves the grid within res.x + res.y + res.z steps, under
    // the cap of that + 2.
  }
}

TEST_CASE(
    "a frame walked pass by pass says why, decided once, and a frame in batches says nothing") {
  Bundled b("classic", "gf6600", 24, 16);
  const auto reason = [&](host::RenderOptions opt) {
    host::StreamTracer tracer(b.scene, b.grid, opt);
    const host::RenderResult r = tracer.render(b.camera);
    return std::make_pair(r.batch_walk, r.walk_reason);
  };
  host::RenderOptions opt = options(24, 16, "gf6600");
  CHECK(reason(opt) == std::make_pair(true, std::string()));
  host::RenderOptions off = opt;
  off.batch_walk = false;
  CHECK(reason(off) == std::make_pair(false, std::string("--walk passes")));
  if (test_support::kernel_width_built(4)) {
    host::RenderOptions four = opt;
    four.lanes = 4;
    CHECK(reason(four) == std::make_pair(false, std::string("--lanes 4 (a batch is 8 lanes)")));
  }
  host::RenderOptions traced = opt;
  traced.trace_pixel = glm::ivec2(3, 4);
  CHECK(reason(traced) == std::make_pair(false, std::string("--trace-pixel prints every pass")));
  host::RenderOptions bare = opt;
  bare.masks = false;
  bare.host_shortcut = false;
  CHECK(reason(bare) == std::make_pair(false, std::string("no mask skips finished rays")));
  host::RenderOptions looping = opt;
  looping.looping = true;
  CHECK(reason(looping) ==
        std::make_pair(false, std::string("looping traversal loops (--kernels looping)")));
}
