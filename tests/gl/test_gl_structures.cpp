// The BVH, two-level grid and kd-tree walks (--accel bvh, grid2, kdtree) on the GL device
// against the vgpu: multipass, fused (--mrt on) and looping frames of a bundled scene give the
// same passes, query counts, hit ids, depths and image (on llvmpipe bit for bit,
// tests/gl/gl_compare.h), written once for every structure; adaptive and undersampled frames
// walking the BVH (adaptive) and the kd-tree (undersampled); and the bunny's two-level grid on a
// driver's texture limit.
#include <doctest/doctest.h>

#include <algorithm>
#include <string>
#include <utility>

#include "host/accel/accel.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/stream/stream_tracer.h"
#include "tests/gl/gl_compare.h"
#include "tests/support/structures.h"

namespace {

// What differs between the structures: the kind, and the programs' names ("bvh step", ...).
struct Bvh {
  static constexpr host::AccelKind kind = host::AccelKind::bvh;
  static constexpr const char* prefix = "bvh";
};
struct Grid2 {
  static constexpr host::AccelKind kind = host::AccelKind::grid2;
  static constexpr const char* prefix = "grid2";
};
struct KdTree {
  static constexpr host::AccelKind kind = host::AccelKind::kdtree;
  static constexpr const char* prefix = "kd";
};

struct Frame {
  host::RenderResult result;
  std::string device;
};

enum class Variant { multipass, mrt, looping };

// How a frame samples its pixels: one ray through each (the default), adaptive sampling up to
// `spp` rays (--aa adaptive --spp N), or undersampling on a lattice of every `undersample`-th
// pixel (--aa undersample:K).
struct Sampling {
  int spp = 1;
  bool adaptive = false;
  int undersample = 0;
  bool primary_only = false;  // --bounces 0 --shadows off: the walk of the primary rays alone
};

Frame render(host::AccelKind kind, const std::string& scene_name, const std::string& device,
             int size, Variant v, const std::string& profile = "gf6600", Sampling sampling = {},
             bool xy = false) {
  host::RenderOptions opt;
  if (xy) opt.addressing = host::RenderOptions::Addressing::xy;
  opt.width = opt.height = size;
  opt.spp = sampling.spp;
  opt.adaptive = sampling.adaptive;
  opt.undersample = sampling.undersample;
  if (sampling.primary_only) {
    opt.bounces = 0;
    opt.shadows = false;
  }
  opt.device = device;
  opt.threads = 2;
  opt.keep_pass_records = true;
  if (v != Variant::multipass) opt.profile = profile;
  opt.mrt = v == Variant::mrt;
  opt.looping = v == Variant::looping;
  opt.steps_per_pass = 16;
  // As the CLI builds them: the structure, and a one-voxel grid for the scene box (the paper's
  // grid is built beside them, and not walked here).
  host::Scene scene = host::load_scene(host::resolve_scene(scene_name));
  const host::Camera cam = host::scene_camera(scene);
  const test_support::Structures s = test_support::build_structures(kind, std::move(scene), cam);
  host::StreamTracer tracer(s.scene, s.accel(), opt);
  return {tracer.render(s.camera), tracer.device().description()};
}

}  // namespace

TYPE_TO_STRING_AS("bvh", Bvh);
TYPE_TO_STRING_AS("grid2", Grid2);
TYPE_TO_STRING_AS("kdtree", KdTree);

TEST_CASE_TEMPLATE("frames on the GL device give the vgpu's queries, hit ids, depths and image", T,
                   Bvh, Grid2, KdTree) {
  const std::string prefix = std::string(T::prefix) + " ";
  for (const Variant v : {Variant::multipass, Variant::mrt, Variant::looping}) {
    CAPTURE(int(v));
    const Frame vf = render(T::kind, "bunny-low", "vgpu", 48, v);
    const Frame gf = render(T::kind, "bunny-low", "gl", 48, v);
    const host::RenderResult &a = vf.result, &b = gf.result;
    REQUIRE(a.stats.passes.size() == b.stats.passes.size());
    size_t walk_passes = 0;
    for (size_t i = 0; i < a.stats.passes.size(); ++i) {
      CAPTURE(i);
      REQUIRE(a.stats.passes[i].program == b.stats.passes[i].program);
      CHECK(a.stats.passes[i].query_result == b.stats.passes[i].query_result);
      walk_passes += a.stats.passes[i].program.rfind(prefix, 0) == 0;
    }
    CHECK(walk_passes > 0);
    CHECK(a.rays_unfinished == 0);
    CHECK(b.rays_unfinished == 0);
    const auto hit =
        std::count_if(a.hit_id.begin(), a.hit_id.end(), [](float id) { return id >= 0; });
    CHECK(hit * 20 >= std::ptrdiff_t(a.hit_id.size()));
    const std::string depth_kernel = prefix + (v == Variant::looping ? "looping traversal"
                                               : v == Variant::mrt ? "intersections + next triangle"
                                                                   : "intersections");
    gltest::check_same_frame(gf.device, depth_kernel, a.hit_id, b.hit_id, a.depth, b.depth, a.rgb,
                             b.rgb);
  }
}

TEST_CASE_TEMPLATE(
    "frames addressed by (x, y) on the GL device give the vgpu's queries, hit ids, depths and "
    "image",
    T, Grid2, KdTree) {
  // --addressing xy (docs/studies/scale.md): the kernels' second address channel, the carry into
  // the row and the list starts read again from the leaf's or sub-cell's texel, as GLSL.
  for (const Variant v : {Variant::multipass, Variant::looping}) {
    CAPTURE(int(v));
    const Frame vf = render(T::kind, "bunny-low", "vgpu", 32, v, "gf6600", {}, true);
    const Frame gf = render(T::kind, "bunny-low", "gl", 32, v, "gf6600", {}, true);
    const host::RenderResult &a = vf.result, &b = gf.result;
    REQUIRE(a.stats.passes.size() == b.stats.passes.size());
    for (size_t i = 0; i < a.stats.passes.size(); ++i) {
      CAPTURE(i);
      REQUIRE(a.stats.passes[i].program == b.stats.passes[i].program);
      CHECK(a.stats.passes[i].query_result == b.stats.passes[i].query_result);
    }
    CHECK(a.rays_unfinished == 0);
    const std::string prefix = std::string(T::prefix) + " ";
    gltest::check_same_frame(
        gf.device, prefix + (v == Variant::looping ? "looping traversal" : "intersections"),
        a.hit_id, b.hit_id, a.depth, b.depth, a.rgb, b.rgb);
  }
}

namespace {

// A sampled frame walking the structure of `kind` on both devices: the same passes, query counts
// (adaptive at 4 rays a pixel: marcarPixeles marks the pixels for the 2 x 2 level from the
// centre frame's colours and surfaces on the GL device's own textures, and so decides every
// later pass's work and query; undersampling: marcarHuecos picks the gaps to trace from the
// lattice's colours and surfaces, rellenarHuecos blends the rest), rays per pixel, hit ids and
// image. Primary rays only (no bounces, no shadows): a multipass walk of the BVH takes about a
// thousand passes a sample frame, each a draw and a query on llvmpipe.
void check_sampled_frames(host::AccelKind kind, const std::string& prefix, const std::string& scene,
                          const Sampling& sampling, int size) {
  const Frame vf = render(kind, scene, "vgpu", size, Variant::multipass, "", sampling);
  const Frame gf = render(kind, scene, "gl", size, Variant::multipass, "", sampling);
  const host::RenderResult &a = vf.result, &b = gf.result;
  REQUIRE(a.stats.passes.size() == b.stats.passes.size());
  int marks = 0, walk_passes = 0;
  for (size_t i = 0; i < a.stats.passes.size(); ++i) {
    CAPTURE(i);
    REQUIRE(a.stats.passes[i].program == b.stats.passes[i].program);
    CHECK(a.stats.passes[i].query_result == b.stats.passes[i].query_result);
    // (adaptive: the default criterion, the budget, whose marks cortarPuntajes cuts)
    marks += a.stats.passes[i].program == (sampling.adaptive ? "cut scores" : "mark gaps");
    walk_passes += a.stats.passes[i].program.rfind(prefix + " ", 0) == 0;
  }
  CHECK(marks == 1);
  CHECK(walk_passes > 0);
  CHECK(b.rays_per_pixel == a.rays_per_pixel);
  // Not a frame where nothing was refined, or everything traced.
  const auto& n = a.rays_per_pixel;
  if (sampling.adaptive) {
    CHECK(std::count(n.begin(), n.end(), 1u) > 0);
    CHECK(std::count(n.begin(), n.end(), 1u + 4u) > 0);
  } else {
    // The lattice holds every second column and row and the last: some gaps are traced
    // beyond it, others filled.
    const std::ptrdiff_t side = size / 2 + (size % 2 == 0 ? 1 : 0);
    CHECK(std::count(n.begin(), n.end(), 0u) > 0);
    CHECK(std::count(n.begin(), n.end(), 1u) > side * side);
  }
  gltest::check_same_frame(gf.device, prefix + " intersections", a.hit_id, b.hit_id, a.depth,
                           b.depth, a.rgb, b.rgb);
}

}  // namespace

TEST_CASE(
    "adaptive frames walking the BVH on the GL device give the vgpu's queries, rays per pixel, "
    "hit ids and image") {
  check_sampled_frames(host::AccelKind::bvh, "bvh", "bunny-low", {4, true, 0, true}, 32);
}

TEST_CASE(
    "undersampled frames walking the kd-tree on the GL device give the vgpu's queries, rays per "
    "pixel, hit ids and image") {
  check_sampled_frames(host::AccelKind::kdtree, "kd", "classic", {1, false, 2, true}, 32);
}

TEST_CASE("the bunny's two-level grid fits a GL driver whose textures stop at 16384 texels") {
  // 96,334 sub-cells: laid out in one row as long as the profile allows, they took a 32768 x 3
  // texture, which llvmpipe (16384) refused; host/trace/passes.cpp's entry_texture lays them
  // out about square. On the h200 profile (32768 texels a side) as bench_gl's looping frames.
  const auto kind = host::AccelKind::grid2;
  const Frame vf = render(kind, "bunny", "vgpu", 24, Variant::looping, "h200");
  const Frame gf = render(kind, "bunny", "gl", 24, Variant::looping, "h200");
  const host::RenderResult &a = vf.result, &b = gf.result;
  CHECK(a.rays_unfinished == 0);
  CHECK(b.rays_unfinished == 0);
  gltest::check_same_frame(gf.device, "grid2 looping traversal", a.hit_id, b.hit_id, a.depth,
                           b.depth, a.rgb, b.rgb);
}
