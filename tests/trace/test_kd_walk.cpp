// The kd-tree walk (--accel kdtree, host/trace/walks/kd_walk.h) against the grid's: the same primary
// hit ids on every bundled scene and every stability case (but for ties: a ray through an edge
// two triangles share, or a vertex, hits both at the same t and either answer is right), the
// same coverage; batch walks, --mrt on and looping against pass by pass; the CPU tracer's
// kd-restart in double against its grid walk and against the stream tracer's kd walk; the
// walk's work counters against the CPU tracer's; and --accel auto on an uneven scene.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "host/accel/accel.h"
#include "host/accel/grid.h"
#include "host/image/image_io.h"
#include "host/model/formats.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/accel_choice.h"
#include "host/trace/cpu/cpu_tracer.h"
#include "host/trace/walks/grid_walk.h"
#include "host/trace/stream/stream_tracer.h"
#include "stability_cases.h"

namespace {

// A statistics JSON without its wall-clock fields (every "*_ms" key).
nlohmann::ordered_json without_times(const nlohmann::ordered_json& j) {
  if (j.is_object()) {
    nlohmann::ordered_json out = nlohmann::ordered_json::object();
    for (auto& [k, v] : j.items())
      if (!(k.size() > 3 && k.compare(k.size() - 3, 3, "_ms") == 0)) out[k] = without_times(v);
    return out;
  }
  if (j.is_array()) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (auto& v : j) out.push_back(without_times(v));
    return out;
  }
  return j;
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

// One scene with its grid (the paper's), its one-voxel box grid and its kd-tree in that box.
struct Structures {
  host::Scene scene;
  host::Grid grid, box;
  host::KdTree kd;
  host::Camera camera;
  Structures(host::Scene s, const host::Camera& cam, const std::string& profile = "gf5700")
      : scene(std::move(s)),
        grid(host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile(profile)))),
        box(host::build_grid(scene, host::GridSpec{glm::ivec3(1)})),
        kd(host::build_kdtree(scene, box.lo, box.hi)),
        camera(cam) {}
  // A stability case: the grid in the case's box, the kd-tree in the same box.
  explicit Structures(const stability::Case& c)
      : scene(c.scene),
        grid(stability::grid_of(c)),
        box(host::build_grid_in_box(c.scene, c.lo, c.hi, glm::ivec3(1), 1)),
        kd(host::build_kdtree(c.scene, c.lo, c.hi)),
        camera(c.camera) {}
  host::Accel grid_accel() const { return {host::AccelKind::grid, &grid, nullptr, nullptr}; }
  host::Accel kd_accel() const { return {host::AccelKind::kdtree, &box, nullptr, &kd}; }
};

Structures bundled(const std::string& name, int w, int h, const std::string& profile = "gf5700") {
  host::Scene s = host::load_scene(host::resolve_scene(name), host::with_images());
  const host::Camera cam = host::scene_camera(s, float(w) / float(h));
  return Structures(std::move(s), cam, profile);
}

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

// Two hit buffers compared pixel by pixel: pixels whose ids differ, and of those the ties
// (both hit, at depths within 1e-5 relative: the same point on two triangles); coverage
// (hit or miss) differences apart.
struct IdDiff {
  int differ = 0, ties = 0, coverage = 0;
  std::string first;  // the first difference that is no tie
};
IdDiff compare_ids(const host::RenderResult& a, const host::RenderResult& b) {
  IdDiff d;
  REQUIRE(a.hit_id.size() == b.hit_id.size());
  for (size_t i = 0; i < a.hit_id.size(); ++i) {
    const int x = int(std::lround(a.hit_id[i])), y = int(std::lround(b.hit_id[i]));
    if ((x >= 0) != (y >= 0)) ++d.coverage;
    if (x == y) continue;
    ++d.differ;
    const float da = a.depth[i], db = b.depth[i];
    if (x >= 0 && y >= 0 && std::abs(da - db) <= 1e-5f * std::max(std::abs(da), 1.0f))
      ++d.ties;
    else if (d.first.empty())
      d.first = "pixel " + std::to_string(i) + ": " + std::to_string(x) + " at " +
                std::to_string(da) + " vs " + std::to_string(y) + " at " + std::to_string(db);
  }
  return d;
}

// A render's tie count, checked: every difference a tie, no coverage difference.
int check_ties(const IdDiff& d) {
  CHECK(d.coverage == 0);
  CHECK_MESSAGE(d.differ == d.ties, "a difference that is no tie: ", d.first);
  return d.ties;
}

}  // namespace

TEST_CASE("the kd-tree walk gives the grid walk's hit ids on every bundled scene, ties apart") {
  const auto scenes = host::list_scenes();
  REQUIRE(scenes.size() >= 8);
  int ties = 0;
  for (const auto& [name, path] : scenes) {
    CAPTURE(std::string(name));
    const Structures s = bundled(name, 48, 48);
    const host::RenderOptions opt = options(48, 48);
    const host::RenderResult g = stream(s.scene, s.grid_accel(), s.camera, opt);
    const host::RenderResult k = stream(s.scene, s.kd_accel(), s.camera, opt);
    CHECK(k.rays_unfinished == 0);
    CHECK(k.rays_traced == g.rays_traced);
    ties += check_ties(compare_ids(g, k));
  }
  // None at 48x48 over the bundled scenes: the tree's and the grid's lists both keep triangles in
  // id order and a tie inside one leaf or voxel keeps the first tested, so only a shared edge
  // on a leaf's or voxel's boundary could decide otherwise. Counted, so a change that brings
  // some shows here.
  CHECK(ties == 0);
}

TEST_CASE("the kd-tree walk gives the grid walk's hit ids on every stability case") {
  int ties = 0;
  for (const stability::Case& c : stability::cases()) {
    CAPTURE(c.name);
    const Structures s(c);
    const host::RenderOptions opt = stability::options_of(c, vgpu::Format::fp32);
    const host::RenderResult g = stream(s.scene, s.grid_accel(), s.camera, opt);
    const host::RenderResult k = stream(s.scene, s.kd_accel(), s.camera, opt);
    CHECK(k.rays_unfinished == 0);
    ties += check_ties(compare_ids(g, k));
    // And every pixel the case demands is right.
    for (size_t i = 0; i < c.expected.size(); ++i) {
      CAPTURE(i);
      CHECK(stability::accepts(c, c.expected[i], int(std::lround(k.hit_id[i]))));
    }
  }
  CHECK(ties == 0);  // none on these cases (their expected answers avoid edges, by design)
}

TEST_CASE(
    "the kd walk in batches gives the frame of pass by pass at 1 and 2 threads, masks on/off") {
  for (const char* name : {"bunny-refl", "classic"}) {
    const Structures s = bundled(name, 40, 36);
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
        const host::RenderResult p = stream(s.scene, s.kd_accel(), s.camera, opt);
        opt.batch_walk = true;
        const host::RenderResult b = stream(s.scene, s.kd_accel(), s.camera, opt);
        CHECK_FALSE(p.batch_walk);
        CHECK(b.batch_walk);
        CHECK(same_bits(p.rgb, b.rgb));
        CHECK(same_bits(p.depth, b.depth));
        CHECK(same_bits(p.hit_id, b.hit_id));
        CHECK(p.iterations == b.iterations);
        CHECK(p.rays_traced == b.rays_traced);
        CHECK(p.rays_unfinished == b.rays_unfinished);
        CHECK(p.stats.totals.same_counts(b.stats.totals));
        CHECK(without_times(p.stats.json()) == without_times(b.stats.json()));
        CHECK(p.stats.find(kernels::KdStep::name) != nullptr);
        CHECK((p.stats.totals.fragments_masked > 0) == masks);
      }
  }
}

TEST_CASE("the kd walk with mrt on gives the multipass images, depths and hit ids") {
  for (const char* name : {"bunny-refl", "classic", "teapot"}) {
    CAPTURE(std::string(name));
    const Structures s = bundled(name, 48, 48, "gf6600");
    host::RenderOptions opt = options(48, 48, "gf6600");
    opt.bounces = 2;
    opt.shadows = true;
    const host::RenderResult m = stream(s.scene, s.kd_accel(), s.camera, opt);
    opt.mrt = true;
    const host::RenderResult f = stream(s.scene, s.kd_accel(), s.camera, opt);
    CHECK(same_bits(m.rgb, f.rgb));
    CHECK(same_bits(m.depth, f.depth));
    CHECK(same_bits(m.hit_id, f.hit_id));
    CHECK(m.rays_traced == f.rays_traced);
    CHECK(f.stats.find(kernels::KdStepLoad::name) != nullptr);
    CHECK(f.stats.find(kernels::KdIntersectNext::name) != nullptr);
    CHECK(f.stats.find(kernels::KdStep::name) == nullptr);
    // The fused step loads leaves unseen: no restart count.
    CHECK(host::walk_work(f.stats, f.rays_traced).restarts == -1);
    CHECK(host::walk_work(m.stats, m.rays_traced).restarts >= 0);
    CHECK(f.stats.totals.passes < m.stats.totals.passes);
  }
}

TEST_CASE("the looping kd walk gives the multipass hit ids and depths") {
  for (const char* name : {"bunny", "classic", "sphere"}) {
    CAPTURE(std::string(name));
    const Structures s = bundled(name, 48, 48, "gf6600");
    host::RenderOptions opt = options(48, 48, "gf6600");
    const host::RenderResult m = stream(s.scene, s.kd_accel(), s.camera, opt);
    opt.looping = true;
    const host::RenderResult l = stream(s.scene, s.kd_accel(), s.camera, opt);
    CHECK(l.rays_unfinished == 0);
    CHECK(same_bits(m.hit_id, l.hit_id));
    CHECK(same_bits(m.depth, l.depth));
    CHECK(l.stats.find(kernels::KdLooping::name) != nullptr);
    CHECK(l.stats.find(kernels::KdStep::name) == nullptr);
  }
}

TEST_CASE("the CPU tracer's kd-restart gives its grid walk's hit ids, ties apart") {
  int ties = 0;
  for (const auto& [name, path] : host::list_scenes()) {
    CAPTURE(std::string(name));
    const Structures s = bundled(name, 48, 48);
    const host::RenderOptions opt = options(48, 48);
    host::CpuStats ks;
    const host::RenderResult g = host::render_cpu(s.scene, s.grid_accel(), s.camera, opt);
    const host::RenderResult k = host::render_cpu(s.scene, s.kd_accel(), s.camera, opt, &ks);
    CHECK(ks.nodes_visited > 0);
    ties += check_ties(compare_ids(g, k));
  }
  CHECK(ties == 0);  // none at 48x48; counted so that a change bringing some shows here
}

TEST_CASE("the stream tracer's kd walk gives the CPU tracer's kd-restart hit ids, ties apart") {
  int ties = 0;
  for (const auto& [name, path] : host::list_scenes()) {
    CAPTURE(std::string(name));
    const Structures s = bundled(name, 48, 48);
    const host::RenderOptions opt = options(48, 48);
    const host::RenderResult c = host::render_cpu(s.scene, s.kd_accel(), s.camera, opt);
    const host::RenderResult k = stream(s.scene, s.kd_accel(), s.camera, opt);
    CHECK(c.rays_traced == k.rays_traced);
    ties += check_ties(compare_ids(c, k));
  }
  CHECK(ties == 0);  // none at 48x48; counted so that a change bringing some shows here
}

TEST_CASE("the kd walk's triangle tests and node steps match the CPU tracer's primary-ray counts") {
  // Primary rays only (no bounces, no shadows). Each triangle test of interseccionesKd is one of
  // the CPU walk's tests. recorridoKd takes one step per node descended (the CPU's nodes_visited
  // counts those, leaves included) and one more at each leaf tested (ending or restarting the
  // ray): steps = nodes_visited + restarts + rays entering the box.
  for (const char* name : {"bunny", "classic", "teapot"}) {
    CAPTURE(std::string(name));
    const Structures s = bundled(name, 48, 48);
    const host::RenderOptions opt = options(48, 48);
    host::CpuStats cs;
    const host::RenderResult c = host::render_cpu(s.scene, s.kd_accel(), s.camera, opt, &cs);
    const host::RenderResult k = stream(s.scene, s.kd_accel(), s.camera, opt);
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
  const host::Grid grid = host::build_grid(scene, host::grid_spec_for({}, scene, p));
  const host::Grid box = host::build_grid(scene, host::GridSpec{glm::ivec3(1)});
  const host::Bvh bvh = host::build_bvh(scene);
  const host::KdTree kd = host::build_kdtree(scene, box.lo, box.hi);
  const host::FormatRequest fr;
  std::vector<host::AccelCandidate> cands = {
      {{host::AccelKind::grid, &grid, nullptr, nullptr}, host::resolve(fr, scene, grid, p)},
      {{host::AccelKind::bvh, &box, &bvh, nullptr},
       host::resolve(fr, scene, box, p, bvh.lists.size())},
      {{host::AccelKind::kdtree, &box, nullptr, &kd},
       host::resolve(fr, scene, box, p, kd.lists.size())}};
  host::RenderOptions opt = options(w, h, profile);
  const host::AccelChoice c = host::choose_accel(scene, cands, opt, cam);
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
