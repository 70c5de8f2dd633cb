// The walks of the other structures (--accel bvh, kdtree, grid2: host/trace/walks/) held against
// the paper's grid walk and against themselves, each case written once for every structure it
// applies to (doctest registers one test per structure, named "...<kdtree>"): the same primary
// hit ids as the grid on every bundled scene and every stability case, ties apart (a ray through
// an edge two triangles share, or a vertex, hits both at the same t and either answer is right);
// batch walks, --mrt on and looping against pass by pass; the CPU tracer's walk in double
// against its grid walk and against the stream tracer's. Then the cases of one structure alone:
// the kd-tree's and the two-level grid's work counters against the CPU tracer's, --accel auto
// and the two-level grid on an uneven scene, and the formats refused for the two-level grid.
// The BVH's own cases are in test_bvh_walk.cpp.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "host/accel/accel.h"
#include "host/model/cost_model.h"
#include "host/model/formats.h"
#include "host/report/counters_json.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/cpu/cpu_tracer.h"
#include "host/trace/stream/accel_choice.h"
#include "host/trace/stream/stream_tracer.h"
#include "host/trace/walks/grid_walk.h"
#include "stability_cases.h"
#include "tests/support/bits.h"
#include "tests/support/hit_compare.h"
#include "tests/support/stats_json.h"
#include "tests/support/structures.h"

using test_support::check_ties;
using test_support::compare_ids;
using test_support::same_bits;
using test_support::Structures;

namespace {

// What differs between the structures in these cases: the kind, the programs each walk runs,
// and what the stability cases measured.
struct Bvh {
  static constexpr host::AccelKind kind = host::AccelKind::bvh;
  static constexpr const char* step = "bvh step";
  static constexpr const char* step_load = "bvh step + load leaf";
  static constexpr const char* intersect_next = "bvh intersections + next triangle";
};
struct KdTree {
  static constexpr host::AccelKind kind = host::AccelKind::kdtree;
  static constexpr const char* step = kernels::KdStep::name;
  static constexpr const char* step_load = kernels::KdStepLoad::name;
  static constexpr const char* intersect_next = kernels::KdIntersectNext::name;
  static constexpr const char* looping = kernels::KdLooping::name;
  // Ties on the stability case of the triangle fan (see the stability case below).
  static constexpr int fan_ties = 0;
};
struct Grid2 {
  static constexpr host::AccelKind kind = host::AccelKind::grid2;
  static constexpr const char* step = kernels::Grid2Step::name;
  static constexpr const char* step_load = kernels::Grid2StepLoad::name;
  static constexpr const char* intersect_next = kernels::Grid2IntersectNext::name;
  static constexpr const char* looping = kernels::Grid2Looping::name;
  static constexpr int fan_ties = 3;
};

host::RenderOptions options(int w, int h, const std::string& profile = "gf5700") {
  host::RenderOptions opt;
  opt.width = w;
  opt.height = h;
  opt.profile = profile;
  opt.threads = 2;
  opt.bounces = 0;
  opt.shadows = false;
  return opt;
}

host::RenderResult stream(const host::Scene& scene, const host::Accel& accel,
                          const host::Camera& cam, const host::RenderOptions& opt) {
  host::StreamTracer tracer(scene, accel, opt);
  return tracer.render(cam);
}

// Every structure built for a scene on a profile, as --accel auto's candidates.
struct Candidates {
  std::vector<std::unique_ptr<host::Accel>> built;
  std::vector<host::AccelCandidate> candidates;
  Candidates(const host::Scene& scene, const vgpu::Profile& p) {
    const host::AccelParams params{host::grid_spec_for({}, scene, p)};
    for (host::AccelKind k : host::kAccelKinds) {
      built.push_back(host::make_accel(k, scene, params));
      candidates.push_back({built.back().get(), host::resolve({}, scene, *built.back(), p)});
    }
  }
};

uint64_t passes_of(const host::RenderResult& r, const char* program) {
  const auto* p = r.stats.find(program);
  return p ? p->counters.passes : 0;
}

}  // namespace

TYPE_TO_STRING_AS("bvh", Bvh);
TYPE_TO_STRING_AS("kdtree", KdTree);
TYPE_TO_STRING_AS("grid2", Grid2);

TEST_CASE_TEMPLATE("the walk gives the grid walk's hit ids on every bundled scene, ties apart" *
                       doctest::test_suite("sweep"),
                   T, KdTree, Grid2) {
  const auto scenes = host::list_scenes();
  REQUIRE(scenes.size() >= 8);
  int ties = 0, crowded = 0;
  for (const auto& [bound_name, bound_path] : scenes) {
    // Named copies: clang 14 cannot capture a structured binding (CAPTURE, INFO).
    const auto& name = bound_name;
    CAPTURE(std::string(name));
    const Structures s = test_support::bundled_structures(T::kind, name, 48, 48);
    if (const host::Grid2* g2 = s.accel().grid2()) crowded += g2->crowded;
    const host::RenderOptions opt = options(48, 48);
    const host::RenderResult g = stream(s.scene, s.grid_accel(), s.camera, opt);
    const host::RenderResult k = stream(s.scene, s.accel(), s.camera, opt);
    CHECK(k.rays_unfinished == 0);
    CHECK(k.rays_traced == g.rays_traced);
    ties += check_ties(compare_ids(g, k));
  }
  if (T::kind == host::AccelKind::grid2) CHECK(crowded > 0);  // the walk descends somewhere
  // None at 48x48 over the bundled scenes: the structures' lists and the grid's both keep
  // triangles in id order and a tie inside one leaf, cell or voxel keeps the first tested, so
  // only a shared edge on a boundary that one structure cuts and the other does not could decide
  // otherwise. Counted, so a change that brings some shows here.
  CHECK(ties == 0);
}

TEST_CASE_TEMPLATE("the walk gives the grid walk's hit ids on every stability case", T, KdTree,
                   Grid2) {
  int ties = 0;
  for (const stability::Case& c : stability::cases()) {
    CAPTURE(c.name);
    // The grid in the case's box; a kd-tree in the same box, a two-level grid over the scene's.
    const Structures s = test_support::structures_in_box(T::kind, c.scene, c.camera,
                                                         stability::grid_of(c), c.lo, c.hi);
    const host::RenderOptions opt = stability::options_of(c, vgpu::Format::fp32);
    const host::RenderResult g = stream(s.scene, s.grid_accel(), s.camera, opt);
    const host::RenderResult k = stream(s.scene, s.accel(), s.camera, opt);
    CHECK(k.rays_unfinished == 0);
    const int t = check_ties(compare_ids(g, k));
    test_support::check_ties_in_double(s.scene, s.camera, c.width, c.height, g, k);
    // Measured: ties only on the fan and only with the two-level grid, where 3 pixels' rays run
    // through a spoke that two coplanar triangles share: both accept the ray at the same t and
    // the first tested keeps it; the grid's voxels and the sub-cells cut the spoke at other
    // places, so a ray meets the pair in other cells or one of them first (the BVH's leaves
    // give 10 such pixels). The kd-tree's leaves give none.
    const bool fan = c.name == "a triangle fan has no cracks at its spokes and centre";
    CHECK(t == (fan ? T::fan_ties : 0));
    ties += t;
    // And every pixel the case demands is right.
    for (size_t i = 0; i < c.expected.size(); ++i) {
      CAPTURE(i);
      CHECK(stability::accepts(c, c.expected[i], int(std::lround(k.hit_id[i]))));
    }
  }
  CHECK(ties == T::fan_ties);
}

TEST_CASE_TEMPLATE(
    "the walk in batches gives the frame of pass by pass at 1 and 2 threads, masks on/off" *
        doctest::test_suite("sweep"),
    T, KdTree, Grid2) {
  for (const char* name : {"bunny-refl", "classic"}) {
    const Structures s = test_support::bundled_structures(T::kind, name, 40, 36);
    for (int threads : {1, 2})
      for (bool masks : {false, true}) {
        CAPTURE(std::string(name));
        CAPTURE(threads);
        CAPTURE(masks);
        host::RenderOptions opt = options(40, 36);
        opt.threads = threads;
        opt.masks = masks;
        opt.bounces = 2;
        opt.shadows = true;
        opt.batch_walk = false;
        const host::RenderResult p = stream(s.scene, s.accel(), s.camera, opt);
        opt.batch_walk = true;
        const host::RenderResult b = stream(s.scene, s.accel(), s.camera, opt);
        CHECK_FALSE(p.batch_walk);
        CHECK(b.batch_walk);
        CHECK(same_bits(p.rgb, b.rgb));
        CHECK(same_bits(p.depth, b.depth));
        CHECK(same_bits(p.hit_id, b.hit_id));
        CHECK(p.iterations == b.iterations);
        CHECK(p.rays_traced == b.rays_traced);
        CHECK(p.rays_unfinished == b.rays_unfinished);
        CHECK(p.stats.totals.same_counts(b.stats.totals));
        CHECK(test_support::without_times(host::frame_counters_json(p.stats)) ==
              test_support::without_times(host::frame_counters_json(b.stats)));
        CHECK(p.stats.find(T::step) != nullptr);
        CHECK((p.stats.totals.fragments_masked > 0) == masks);
      }
  }
}

TEST_CASE_TEMPLATE("the walk with mrt on gives the multipass images, depths and hit ids on gf6600",
                   T, Bvh, KdTree, Grid2) {
  for (const char* name : {"bunny-refl", "classic", "teapot"}) {
    CAPTURE(std::string(name));
    const Structures s = test_support::bundled_structures(T::kind, name, 48, 48, "gf6600");
    host::RenderOptions opt = options(48, 48, "gf6600");
    opt.bounces = 2;
    opt.shadows = true;
    const host::RenderResult m = stream(s.scene, s.accel(), s.camera, opt);
    opt.mrt = true;
    const host::RenderResult f = stream(s.scene, s.accel(), s.camera, opt);
    CHECK(same_bits(m.rgb, f.rgb));
    CHECK(same_bits(m.depth, f.depth));
    CHECK(same_bits(m.hit_id, f.hit_id));
    CHECK(m.rays_traced == f.rays_traced);
    CHECK(passes_of(f, T::step_load) > 0);
    CHECK(passes_of(f, T::intersect_next) > 0);
    CHECK(f.stats.find(T::step) == nullptr);
    if (T::kind == host::AccelKind::kdtree) {
      // The fused step loads leaves unseen: no restart count.
      CHECK(host::walk_work(f.stats, f.rays_traced).restarts == -1);
      CHECK(host::walk_work(m.stats, m.rays_traced).restarts >= 0);
    }
    CHECK(f.stats.totals.passes < m.stats.totals.passes);
  }
}

TEST_CASE_TEMPLATE("the looping walk gives the multipass hit ids and depths", T, KdTree, Grid2) {
  for (const char* name : {"bunny", "classic", "sphere"}) {
    CAPTURE(std::string(name));
    const Structures s = test_support::bundled_structures(T::kind, name, 48, 48, "gf6600");
    host::RenderOptions opt = options(48, 48, "gf6600");
    const host::RenderResult m = stream(s.scene, s.accel(), s.camera, opt);
    opt.looping = true;
    const host::RenderResult l = stream(s.scene, s.accel(), s.camera, opt);
    CHECK(l.rays_unfinished == 0);
    CHECK(same_bits(m.hit_id, l.hit_id));
    CHECK(same_bits(m.depth, l.depth));
    CHECK(l.stats.find(T::looping) != nullptr);
    CHECK(l.stats.find(T::step) == nullptr);
  }
}

TEST_CASE_TEMPLATE(
    "past a lowered linear limit the walk addresses by (x, y) and gives the linear frame's images "
    "and passes",
    T, KdTree, Grid2) {
  // The boundary of automatic addressing on a small structure: with the limit just below its
  // largest index the walk goes by (x, y), at it the walk stays linear; by (x, y) every variant
  // (multipass, --mrt on, looping) renders the linear frame's image, depths and hit ids, and the
  // multipass ones in the same passes (the same states, addressed otherwise).
  const Structures s = test_support::bundled_structures(T::kind, "bunny-refl", 32, 32, "gf6600");
  uint64_t largest = 0;  // the structure's largest linear index
  if (T::kind == host::AccelKind::kdtree)
    largest = std::max<uint64_t>(s.accel().kd()->nodes.size(), s.accel().kd()->lists.size()) - 1;
  else
    largest = std::max<uint64_t>({s.g2().sub_cells(), s.g2().lists.size()}) - 1;
  for (const char* variant : {"multipass", "mrt", "looping"}) {
    CAPTURE(std::string(variant));
    host::RenderOptions opt = options(32, 32, "gf6600");
    opt.bounces = 1;
    opt.shadows = true;
    opt.mrt = std::string(variant) == "mrt";
    opt.looping = std::string(variant) == "looping";
    opt.linear_address_limit = largest;
    host::StreamTracer at_limit(s.scene, s.accel(), opt);
    CHECK_FALSE(at_limit.addresses_by_xy());
    const host::RenderResult linear = at_limit.render(s.camera);
    opt.linear_address_limit = largest - 1;
    host::StreamTracer past(s.scene, s.accel(), opt);
    CHECK(past.addresses_by_xy());
    const host::RenderResult xy = past.render(s.camera);
    CHECK(xy.rays_unfinished == 0);
    CHECK(same_bits(linear.rgb, xy.rgb));
    CHECK(same_bits(linear.depth, xy.depth));
    CHECK(same_bits(linear.hit_id, xy.hit_id));
    CHECK(linear.rays_traced == xy.rays_traced);
    if (!opt.looping) CHECK(linear.stats.totals.passes == xy.stats.totals.passes);
    // Forced: --addressing xy on the same frame.
    opt.linear_address_limit = 0;
    opt.addressing = host::RenderOptions::Addressing::xy;
    host::StreamTracer forced(s.scene, s.accel(), opt);
    CHECK(forced.addresses_by_xy());
    CHECK(same_bits(forced.render(s.camera).hit_id, linear.hit_id));
  }
}

TEST_CASE_TEMPLATE("addressed by (x, y) the walk refuses beams over tiles in one line", T, KdTree,
                   Grid2) {
  const Structures s = test_support::bundled_structures(T::kind, "bunny", 16, 16, "gf6600");
  host::RenderOptions opt = options(16, 16, "gf6600");
  opt.beams = true;
  opt.addressing = host::RenderOptions::Addressing::xy;
  CHECK_THROWS_WITH_AS(host::StreamTracer(s.scene, s.accel(), opt),
                       doctest::Contains("addressed by (x, y); beams over tiles"),
                       vgpu::LimitError);
}

TEST_CASE_TEMPLATE("the CPU tracer's walk gives its grid walk's hit ids, ties apart", T, KdTree,
                   Grid2) {
  int ties = 0;
  for (const auto& [bound_name, bound_path] : host::list_scenes()) {
    // Named copies: clang 14 cannot capture a structured binding (CAPTURE, INFO).
    const auto& name = bound_name;
    CAPTURE(std::string(name));
    const Structures s = test_support::bundled_structures(T::kind, name, 48, 48);
    const host::RenderOptions opt = options(48, 48);
    host::CpuStats ks;
    const host::RenderResult g = host::render_cpu(s.scene, s.grid_accel(), s.camera, opt);
    const host::RenderResult k = host::render_cpu(s.scene, s.accel(), s.camera, opt, &ks);
    // The kd-restart descends nodes; the two-level walk steps through cells.
    CHECK((T::kind == host::AccelKind::kdtree ? ks.nodes_visited : ks.voxel_steps) > 0);
    ties += check_ties(compare_ids(g, k));
  }
  CHECK(ties == 0);  // none at 48x48; counted so that a change bringing some shows here
}

TEST_CASE_TEMPLATE("the stream tracer's walk gives the CPU tracer's hit ids, ties apart", T, KdTree,
                   Grid2) {
  int ties = 0;
  for (const auto& [bound_name, bound_path] : host::list_scenes()) {
    // Named copies: clang 14 cannot capture a structured binding (CAPTURE, INFO).
    const auto& name = bound_name;
    CAPTURE(std::string(name));
    const Structures s = test_support::bundled_structures(T::kind, name, 48, 48);
    const host::RenderOptions opt = options(48, 48);
    const host::RenderResult c = host::render_cpu(s.scene, s.accel(), s.camera, opt);
    const host::RenderResult k = stream(s.scene, s.accel(), s.camera, opt);
    CHECK(c.rays_traced == k.rays_traced);
    ties += check_ties(compare_ids(c, k));
  }
  CHECK(ties == 0);  // none at 48x48; counted so that a change bringing some shows here
}

// Cases of the kd-tree alone.

TEST_CASE("the kd walk's triangle tests and node steps match the CPU tracer's primary-ray counts") {
  // Primary rays only (no bounces, no shadows). Each triangle test of interseccionesKd is one of
  // the CPU walk's tests. recorridoKd takes one step per node descended (the CPU's nodes_visited
  // counts those, leaves included) and one more at each leaf tested (ending or restarting the
  // ray): steps = nodes_visited + restarts + rays entering the box.
  for (const char* name : {"bunny", "classic", "teapot"}) {
    CAPTURE(std::string(name));
    const Structures s = test_support::bundled_structures(host::AccelKind::kdtree, name, 48, 48);
    const host::RenderOptions opt = options(48, 48);
    host::CpuStats cs;
    const host::RenderResult c = host::render_cpu(s.scene, s.accel(), s.camera, opt, &cs);
    const host::RenderResult k = stream(s.scene, s.accel(), s.camera, opt);
    const host::WalkWork w = host::walk_work(k.stats, k.rays_traced);
    REQUIRE(c.hit_id == k.hit_id);  // the same walks: no tie decided otherwise
    CHECK(w.triangle_tests == cs.triangle_tests);
    CHECK(w.nodes_visited == cs.nodes_visited + cs.restarts + c.rays_traced);
    // The stream walk's restarts, from cargarHojaKd's loads, are the CPU walk's.
    CHECK(cs.restarts > 0);
    CHECK(w.restarts == int64_t(cs.restarts));
    CHECK(w.voxel_steps == 0);
    CHECK(w.loop_iterations == 0);
  }
}

TEST_CASE("accel auto picks the BVH or the kd-tree for a small bunny on a huge floor") {
  // scripts/uneven_scenes.py's stadium, small: bunny-low with its camera, on a two-triangle floor
  // 270 times its width. The grid spends almost every voxel on empty floor.
  host::Scene scene = host::load_scene(host::resolve_scene("bunny-low"));
  const int w = 64, h = 64;
  const host::Camera cam = host::scene_camera(scene, float(w) / float(h));
  const host::Bounds b = scene.bounds();
  const float half = 135.0f * (b.hi.x - b.lo.x), y = b.lo.y;
  const uint32_t id = scene.input_triangles;
  scene.add_flat_triangle({-half, y, -half}, {half, y, half}, {half, y, -half}, 0, id);
  scene.add_flat_triangle({-half, y, -half}, {-half, y, half}, {half, y, half}, 0, id + 1);
  scene.input_triangles = id + 2;
  const std::string profile = "gf6600";
  const vgpu::Profile& p = vgpu::profile(profile);
  const host::AccelParams params{host::grid_spec_for({}, scene, p)};
  const host::FormatRequest fr;
  std::vector<std::unique_ptr<host::Accel>> built;
  std::vector<host::AccelCandidate> cands;
  for (host::AccelKind k : {host::AccelKind::grid, host::AccelKind::bvh, host::AccelKind::kdtree}) {
    built.push_back(host::make_accel(k, scene, params));
    cands.push_back({built.back().get(), host::resolve(fr, scene, *built.back(), p)});
  }
  host::RenderOptions opt = options(w, h, profile);
  // Every probe to its end (stopped probes: "accel auto's stopped probes never change ...").
  const host::AccelChoice c = host::choose_accel(scene, cands, opt, cam, false);
  CHECK(c.kind != host::AccelKind::grid);
  REQUIRE(c.predicted_ms.size() == 3);
  for (const char* k : {"grid", "bvh", "kdtree"}) {
    CAPTURE(k);
    REQUIRE(c.predicted_ms.count(k) == 1);
    CHECK(c.predicted_ms.at(k) > 0);
    CHECK(c.probe_passes.count(k) == 1);
  }
  CHECK(c.predicted_ms.at("grid") > c.predicted_ms.at(std::string(host::accel_name(c.kind))));
  CHECK(c.probe_width == 16);
  CHECK(c.probe_height == 16);
  CHECK(c.why.find(std::string(host::accel_name(c.kind))) == 0);
}

TEST_CASE(
    "accel auto prices each structure at the model's total for its frame and picks the "
    "cheapest") {
  // A 16x16 frame: the probe is the whole frame (scale 1), so each candidate's price must be the
  // cost model's total_ms of that structure's frame, every term of it; the looping kernels on
  // the h200 profile have a longest-lane (latency) term, which a price without it misses. On
  // the teapot that term reorders the structures: without it the two-level grid looks 12%
  // cheaper than the grid and is picked; with it the grid is the cheapest.
  const host::Scene scene = host::load_scene(host::resolve_scene("teapot"));
  const int w = 16, h = 16;
  const host::Camera cam = host::scene_camera(scene, float(w) / float(h));
  const std::string profile = "h200";
  const vgpu::Profile& p = vgpu::profile(profile);
  const Candidates all(scene, p);
  const std::vector<host::AccelCandidate>& cands = all.candidates;
  host::RenderOptions opt;
  opt.width = w;
  opt.height = h;
  opt.profile = profile;
  opt.looping = true;
  opt.threads = 2;
  const host::AccelChoice c = host::choose_accel(scene, cands, opt, cam, false);  // every price
  REQUIRE(c.probe_width == w);
  REQUIRE(c.probe_height == h);
  REQUIRE(c.predicted_ms.size() == cands.size());
  // Each structure's frame, rendered with the options the CLI passes, priced by the model.
  std::map<std::string, double> total;
  double latency = 0;
  for (const host::AccelCandidate& cand : cands) {
    const std::string name(cand.accel->name());
    CAPTURE(name);
    host::RenderOptions frame = opt;
    frame.formats = cand.formats;
    // The model's finer input, as the probe keeps it: each pass's bottleneck on its own. Without
    // the records (the CLI's predicted_ms, unless --report) each program's passes are averaged,
    // which here prices the frames 0.1% lower.
    frame.keep_pass_records = true;
    const host::CostBreakdown b = host::predict(stream(scene, *cand.accel, cam, frame).stats, p);
    total[name] = b.total_ms;
    latency += b.latency_ms;
    REQUIRE(c.predicted_ms.count(name) == 1);
    CHECK(c.predicted_ms.at(name) == doctest::Approx(b.total_ms).epsilon(1e-12));
  }
  CHECK(latency > 0);  // the term the price must not leave out is there
  // The pick: the cheapest total (a probe the size of the frame has nothing to refine).
  auto cheapest = std::min_element(
      total.begin(), total.end(), [](const auto& x, const auto& y) { return x.second < y.second; });
  const std::string want = cheapest->first;
  CHECK(c.refined.empty());
  CHECK(c.refine_width == 0);
  CHECK(std::string(host::accel_name(c.kind)) == want);
  CHECK(want == "grid");  // the teapot's case (above): the grid, by more than a tie
  CHECK(total.at("grid2") > total.at("grid"));
}

TEST_CASE(
    "accel auto probes every structure priced within its band of the cheapest again at half the "
    "size, and takes the cheapest of those") {
  // The bunny's primary rays on gf6600 at 96x96: first probes of 24x24, second of 48x48. Each
  // price is the probe's full-frame extrapolation (its fixed terms as counted, its fragment work
  // times the pixel ratio), recomputed here from renders of those sizes.
  const host::Scene scene = host::load_scene(host::resolve_scene("bunny"));
  const int w = 96, h = 96;
  const host::Camera cam = host::scene_camera(scene, float(w) / float(h));
  const std::string profile = "gf6600";
  const vgpu::Profile& p = vgpu::profile(profile);
  const Candidates all(scene, p);
  const std::vector<host::AccelCandidate>& cands = all.candidates;
  host::RenderOptions opt = options(w, h, profile);
  opt.bounces = 0;
  opt.shadows = false;
  const host::AccelChoice c = host::choose_accel(scene, cands, opt, cam);
  CHECK(c.probe_width == 24);
  CHECK(c.refine_width == 48);
  auto price = [&](const host::AccelCandidate& cand, int size) {
    host::RenderOptions frame = opt;
    frame.width = frame.height = size;
    frame.formats = cand.formats;
    frame.keep_pass_records = true;
    const host::CostBreakdown b = host::predict(stream(scene, *cand.accel, cam, frame).stats, p);
    const double scale = double(w * h) / double(size * size);
    return b.per_pass_ms + b.program_load_ms + b.readback_ms + b.latency_ms +
           scale * (b.arithmetic_ms + b.texture_ms + b.memory_ms + b.download_ms);
  };
  auto listed = [](const std::vector<std::string>& v, const std::string& name) {
    return std::find(v.begin(), v.end(), name) != v.end();
  };
  // A probe stopped in the first round (stopped, not refined) is priced over what it passed.
  double cheapest = 1e300;
  for (const host::AccelCandidate& cand : cands) {
    const std::string name(cand.accel->name());
    CAPTURE(name);
    REQUIRE(c.coarse_ms.count(name) == 1);
    const double full = price(cand, 24);
    if (listed(c.stopped, name) && !listed(c.refined, name)) {
      CHECK(full > c.coarse_ms.at(name));
      continue;
    }
    CHECK(c.coarse_ms.at(name) == doctest::Approx(full).epsilon(1e-9));
    cheapest = std::min(cheapest, full);
  }
  // The band from the whole first prices; the pick the cheapest whole second price in it.
  std::vector<std::string> band;
  std::string want;
  double want_ms = 0;
  for (const host::AccelCandidate& cand : cands) {
    const std::string name(cand.accel->name());
    CAPTURE(name);
    const double coarse = price(cand, 24);
    if (coarse > (1.0 + host::kAutoProbeBand) * cheapest) {
      CHECK(c.predicted_ms.at(name) == c.coarse_ms.at(name));  // priced once
      continue;
    }
    band.push_back(name);
    const double full = price(cand, 48);
    if (listed(c.stopped, name))
      CHECK(full > c.predicted_ms.at(name));
    else
      CHECK(c.predicted_ms.at(name) == doctest::Approx(full).epsilon(1e-9));
    if (want.empty() || full < want_ms) {
      want = name;
      want_ms = full;
    }
  }
  CHECK(c.refined == band);
  CHECK(band.size() == 3);  // grid, grid2 and the BVH within 20%; the kd-tree far off
  CHECK(std::string(host::accel_name(c.kind)) == want);
  // The kd-tree's probe (thousands of passes at 160 us each) stops in the first round; run to
  // their ends, the probes give the same pick, band and prices elsewhere.
  CHECK(listed(c.stopped, "kdtree"));
  const host::AccelChoice whole = host::choose_accel(scene, cands, opt, cam, false);
  CHECK(whole.stopped.empty());
  CHECK(whole.kind == c.kind);
  CHECK(whole.refined == c.refined);
  for (const auto& [name, ms] : whole.predicted_ms)
    if (!listed(c.stopped, name)) CHECK(c.predicted_ms.at(name) == ms);
}

TEST_CASE("accel auto judges a probe's passes against the L2 at the full frame's size") {
  // The bunny's primary rays, looping, on h100 at 1024x1024: the frame's passes outgrow the
  // 50 MB L2, its quarter-size probes' (256x256) alone do not. A probe's price must spill where
  // the frame would: its footprint is judged against a sixteenth of the L2 (the first round's
  // prices; the second round's, at half the size, against a quarter, as
  // full_frame_profile divides by the pixel ratio of either).
  const host::Scene scene = host::load_scene(host::resolve_scene("bunny"));
  const host::Camera cam = host::scene_camera(scene, 1.0f);
  const vgpu::Profile& p = vgpu::profile("h100");
  const Candidates all(scene, p);
  host::RenderOptions opt = options(1024, 1024, "h100");
  opt.looping = true;
  const host::AccelChoice c = host::choose_accel(scene, all.candidates, opt, cam, false);
  REQUIRE(c.probe_width == 256);
  int spilled = 0;
  for (const host::AccelCandidate& cand : all.candidates) {
    const std::string name(cand.accel->name());
    CAPTURE(name);
    host::RenderOptions probe = opt;
    probe.width = probe.height = 256;
    probe.formats = cand.formats;
    probe.keep_pass_records = true;
    const vgpu::FrameStats stats = stream(scene, *cand.accel, cam, probe).stats;
    CHECK(host::predict(stats, p).l2_spill_ms == 0.0);  // the probe alone fits
    vgpu::Profile full = p;
    full.l2_bytes /= 16;
    const host::CostBreakdown b = host::predict(stats, full);
    spilled += b.l2_spill_ms > 0;
    const double price = b.per_pass_ms + b.program_load_ms + b.readback_ms + b.latency_ms +
                         16 * (b.arithmetic_ms + b.texture_ms + b.memory_ms + b.download_ms);
    CHECK(c.coarse_ms.at(name) == doctest::Approx(price).epsilon(1e-9));
  }
  CHECK(spilled == 4);  // every structure's frame spills
}

TEST_CASE("a frame's running price rises pass by pass to at most its price, within a tenth of it") {
  // Every structure's frame of two scenes (one bounce, shadows) at 40x40 on four profiles, both
  // walks where the profile loops: the running price after every pass (RunningPrice, at scale 1
  // and at 16 on the profile with 1/16 of the L2, as a probe is priced) never falls, and at the
  // end it is at most the frame's fixed costs, longest lanes and 1 or 16 times its pass work as
  // predict prices them (a clear is priced with the pass after it, at most that), and at least
  // nine tenths of it.
  for (const char* name : {"bunny", "classic"}) {
    const host::Scene scene = host::load_scene(host::resolve_scene(name));
    const host::Camera cam = host::scene_camera(scene, 1.0f);
    for (const char* profile_name : {"gf5700", "gf6600", "h200", "h100"})
      for (const bool looping : {false, true}) {
        if (looping && std::string(profile_name) == "gf5700") continue;  // fp30: no loops
        const vgpu::Profile& profile = vgpu::profile(profile_name);
        vgpu::Profile small_l2 = profile;
        small_l2.l2_bytes /= 16;
        const Candidates all(scene, profile);
        for (const host::AccelCandidate& cand : all.candidates) {
          CAPTURE(name);
          CAPTURE(profile_name);
          CAPTURE(looping);
          CAPTURE(std::string(cand.accel->name()));
          host::RenderOptions opt = options(40, 40, profile_name);
          opt.looping = looping;
          opt.bounces = 1;
          opt.shadows = true;
          opt.formats = cand.formats;
          opt.keep_pass_records = true;
          host::RunningPrice at1(profile, 1.0), at16(small_l2, 16.0);
          std::vector<double> run1, run16;
          opt.stop_when = [&](const vgpu::Counters& t) {
            run1.push_back(at1.add(t));
            run16.push_back(at16.add(t));
            return false;
          };
          const host::RenderResult r = stream(scene, *cand.accel, cam, opt);
          REQUIRE(run1.size() == r.stats.totals.passes);
          CHECK(std::is_sorted(run1.begin(), run1.end()));
          CHECK(std::is_sorted(run16.begin(), run16.end()));
          const host::CostBreakdown b = host::predict(r.stats, profile);
          const host::CostBreakdown b16 = host::predict(r.stats, small_l2);
          const double fixed = b.per_pass_ms + b.program_load_ms + b.readback_ms + b.latency_ms;
          const double whole = fixed + b.arithmetic_ms + b.texture_ms + b.memory_ms;
          const double whole16 =
              fixed + 16.0 * (b16.arithmetic_ms + b16.texture_ms + b16.memory_ms);
          CHECK(run1.back() <= whole * (1 + 1e-12));
          CHECK(run16.back() <= whole16 * (1 + 1e-12));
          CHECK(run1.back() >= 0.9 * whole);
          CHECK(run16.back() >= 0.9 * whole16);
        }
      }
  }
}

TEST_CASE("accel auto's stopped probes never change its pick, its band or the others' prices") {
  // Three scenes' primary rays at 96x96 on three profiles, both walks where the profile loops:
  // the choice with stopped probes against the same choice with every probe run to its end.
  auto listed = [](const std::vector<std::string>& v, const std::string& name) {
    return std::find(v.begin(), v.end(), name) != v.end();
  };
  size_t first_round = 0, second_round = 0;  // probes stopped in each round, over the cases
  for (const char* name : {"bunny", "classic", "teapot"}) {
    const host::Scene scene = host::load_scene(host::resolve_scene(name));
    const host::Camera cam = host::scene_camera(scene, 1.0f);
    for (const char* profile : {"gf5700", "gf6600", "h200"})
      for (const bool looping : {false, true}) {
        if (looping && std::string(profile) == "gf5700") continue;  // fp30: no loops
        CAPTURE(name);
        CAPTURE(profile);
        CAPTURE(looping);
        const Candidates all(scene, vgpu::profile(profile));
        host::RenderOptions opt = options(96, 96, profile);
        opt.looping = looping;
        const host::AccelChoice c = host::choose_accel(scene, all.candidates, opt, cam);
        const host::AccelChoice whole = host::choose_accel(scene, all.candidates, opt, cam, false);
        CHECK(whole.stopped.empty());
        CHECK(c.kind == whole.kind);
        CHECK(c.refined == whole.refined);
        for (const auto& entry : whole.predicted_ms) {
          const std::string& k = entry.first;  // not a structured binding: CAPTURE's lambda
          const double ms = entry.second;
          CAPTURE(k);
          if (!listed(c.stopped, k)) {
            CHECK(c.predicted_ms.at(k) == ms);
            CHECK(c.coarse_ms.at(k) == whole.coarse_ms.at(k));
          } else {
            CHECK(ms > c.predicted_ms.at(k));  // over what it was known to pass
            ++(listed(c.refined, k) ? second_round : first_round);
          }
        }
      }
  }
  CHECK(first_round > 0);
  CHECK(second_round > 0);
}

// Cases of the two-level grid alone.

TEST_CASE(
    "the grid2 walk's triangle tests and cell steps match the CPU tracer's primary-ray counts") {
  // Primary rays only. Each triangle test of interseccionesGrilla2 is one of the CPU walk's
  // tests; recorridoGrilla2 takes one step per sub-cell visited (the last one ends the ray),
  // which the CPU walk counts as voxel steps.
  for (const char* name : {"bunny", "classic", "teapot"}) {
    CAPTURE(std::string(name));
    const Structures s = test_support::bundled_structures(host::AccelKind::grid2, name, 48, 48);
    const host::RenderOptions opt = options(48, 48);
    host::CpuStats cs;
    const host::RenderResult c = host::render_cpu(s.scene, s.accel(), s.camera, opt, &cs);
    const host::RenderResult k = stream(s.scene, s.accel(), s.camera, opt);
    const host::WalkWork w = host::walk_work(k.stats);
    REQUIRE(c.hit_id == k.hit_id);  // the same walks: no tie decided otherwise
    CHECK(w.triangle_tests == cs.triangle_tests);
    CHECK(w.voxel_steps == cs.voxel_steps);
    CHECK(w.nodes_visited == 0);
    CHECK(w.loop_iterations == 0);
    CHECK(w.restarts == -1);
  }
}

TEST_CASE(
    "with the light among the objects, the grid walks end shadow rays at the light as the CPU "
    "walk does") {
  // classic with its light moved between the spheres and the camera (inside the grid's box):
  // a shadow ray that reaches the light unblocked has voxels left behind it. The CPU walk ends
  // it at the first voxel that begins past the light (t_enter - slack >= tmax); the stream walk
  // must take the same steps, shadow rays included (a walk that went on to the box's face would
  // count more). Triangle tests differ by design for shadow rays (the CPU walk stops at the first
  // hit it meets, the pass tests the whole voxel), so only the steps are compared.
  for (const host::AccelKind kind : {host::AccelKind::grid, host::AccelKind::grid2}) {
    CAPTURE(host::accel_name(kind));
    host::Scene scene = host::load_scene(host::resolve_scene("classic"), host::with_images());
    REQUIRE(scene.lights.size() == 1);
    scene.lights[0].position = {-2.0f, 1.2f, 2.5f};
    const host::Bounds box = scene.bounds();
    REQUIRE(glm::all(glm::lessThan(box.lo, scene.lights[0].position)));
    REQUIRE(glm::all(glm::lessThan(scene.lights[0].position, box.hi)));
    const host::Camera cam = host::scene_camera(scene, 1.0f);
    const Structures s = test_support::build_structures(kind, std::move(scene), cam);
    host::RenderOptions opt = options(48, 48);
    opt.shadows = true;
    host::CpuStats cs;
    const host::RenderResult c = host::render_cpu(s.scene, s.accel(), s.camera, opt, &cs);
    const host::RenderResult k = stream(s.scene, s.accel(), s.camera, opt);
    REQUIRE(c.hit_id == k.hit_id);
    CHECK(host::walk_work(k.stats).voxel_steps == cs.voxel_steps);
    // Against the same frame without shadows, the shadow rays took steps of their own.
    opt.shadows = false;
    host::CpuStats primary;
    host::render_cpu(s.scene, s.accel(), s.camera, opt, &primary);
    CHECK(cs.voxel_steps > primary.voxel_steps);
  }
}

TEST_CASE("the two-level grid puts a small bunny on a huge floor in sub-grids of its own") {
  // scripts/uneven_scenes.py's stadium, small: bunny-low on a two-triangle floor 270 times its
  // width. The uniform grid gives the bunny a handful of voxels; the two-level grid's crowded
  // cells cut it finely, and its walk tests far fewer triangles.
  host::Scene scene = host::load_scene(host::resolve_scene("bunny-low"));
  const int w = 48, h = 48;
  const host::Camera cam = host::scene_camera(scene, float(w) / float(h));
  const host::Bounds b = scene.bounds();
  const float half = 135.0f * (b.hi.x - b.lo.x), y = b.lo.y;
  const uint32_t id = scene.input_triangles;
  scene.add_flat_triangle({-half, y, -half}, {half, y, half}, {half, y, -half}, 0, id);
  scene.add_flat_triangle({-half, y, -half}, {-half, y, half}, {half, y, half}, 0, id + 1);
  scene.input_triangles = id + 2;
  const Structures s =
      test_support::build_structures(host::AccelKind::grid2, std::move(scene), cam);
  CHECK(s.g2().crowded > 0);
  const host::RenderOptions opt = options(w, h);
  const host::RenderResult g = stream(s.scene, s.grid_accel(), s.camera, opt);
  const host::RenderResult k = stream(s.scene, s.accel(), s.camera, opt);
  check_ties(compare_ids(g, k));
  CHECK(host::walk_work(k.stats).triangle_tests * 4 < host::walk_work(g.stats).triangle_tests);
  CHECK(k.stats.totals.passes < g.stats.totals.passes);
}

TEST_CASE("a format that cannot address the two-level grid's sub-cells or lists is refused") {
  // The bunny's two-level grid has more sub-cells than fp16 (1023) or fp24 (65535) address
  // exactly: a sub-cell index that rounds would send the walk to another cell. Refused at
  // initialization, naming the group, the count and the limit, and the format that holds it.
  const Structures s = test_support::bundled_structures(host::AccelKind::grid2, "bunny", 32, 32);
  REQUIRE(s.g2().sub_cells() > 65536);
  host::RenderOptions opt = options(32, 32);
  const std::string reach = "two-level grid: sub-cell indices reach " +
                            std::to_string(s.g2().sub_cells() - 1) + "; the traversal group's ";
  for (const vgpu::Format f : {vgpu::Format::fp16, vgpu::Format::fp24}) {
    CAPTURE(vgpu::format_name(f));
    opt.formats = host::Formats::all(vgpu::Format::fp32);
    opt.formats.set(host::Group::traversal, f, vgpu::Format::fp32);
    const std::string what = reach + std::string(vgpu::format_name(f)) +
                             " addresses texels exactly only to " +
                             std::to_string(host::exact_addresses(f)) + " (give it fp32";
    CHECK_THROWS_WITH_AS(host::StreamTracer(s.scene, s.accel(), opt),
                         doctest::Contains(what.c_str()), vgpu::Error);
  }
  opt.formats = host::Formats::all(vgpu::Format::fp32);
  opt.formats.set(host::Group::voxel, vgpu::Format::fp16, vgpu::Format::fp16);
  const std::string lists = "two-level grid: list positions reach " +
                            std::to_string(s.g2().lists.size() - 1) + "; the voxel group's fp16";
  CHECK_THROWS_WITH_AS(host::StreamTracer(s.scene, s.accel(), opt),
                       doctest::Contains(lists.c_str()), vgpu::Error);
  // By (x, y) the traversal group still carries a sub-cell's offset in its sub-grid and the
  // packed sub-grid resolution (x + 1024 y): fp16 holds neither exactly.
  opt.formats = host::Formats::all(vgpu::Format::fp32);
  opt.formats.set(host::Group::traversal, vgpu::Format::fp16, vgpu::Format::fp16);
  opt.addressing = host::RenderOptions::Addressing::xy;
  CHECK_THROWS_WITH_AS(host::StreamTracer(s.scene, s.accel(), opt),
                       doctest::Contains("; the traversal group's fp16 addresses texels exactly"),
                       vgpu::LimitError);
}
