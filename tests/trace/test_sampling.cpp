// Supersampling (--spp N, host/trace/sampling.h): where the samples lie, a known-answer edge
// pixel, and the stream tracer against the CPU tracer on the same sample positions.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "host/accel/accel.h"
#include "host/accel/bvh.h"
#include "host/accel/grid.h"
#include "host/accel/kdtree.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/cpu/cpu_tracer.h"
#include "host/trace/sampling.h"
#include "host/trace/stream/stream_tracer.h"
#include "tests/support/bits.h"

using test_support::same_bits;

namespace {

// A white square on black: x in [0, 4], y in [-2, 2] at z = 0, seen from z = 4 by a 5x1 image
// whose middle pixel the square's left edge (x = 0) cuts in half; one light far above the
// camera, diffuse shading, no shadows or reflections.
struct EdgeCase {
  host::Scene scene;
  host::Grid grid;
  host::Camera camera;
  EdgeCase() {
    scene.name = "edge";
    scene.materials = {{{1.0f, 1.0f, 1.0f}, 0.0f}};
    scene.add_flat_triangle({0, -2, 0}, {4, -2, 0}, {4, 2, 0}, 0, 0);
    scene.add_flat_triangle({0, -2, 0}, {4, 2, 0}, {0, 2, 0}, 0, 1);
    scene.input_triangles = 2;
    scene.lights = {{{0, 0, 1000}, {1, 1, 1}}};
    grid = host::build_grid(scene, host::GridSpec{glm::ivec3(4, 4, 1)});
    camera.position = {0, 0, 4};
    camera.forward = {0, 0, -1};
    camera.up = {0, 1, 0};
    // 5 pixels across 2 * 4 * tan(yfov / 2) * aspect: one pixel is 0.4 wide at z = 0, so the
    // middle pixel spans x in [-0.2, 0.2] and the edge halves it.
    camera.yfov = 2.0f * std::atan(0.05f);
  }
};

host::RenderOptions edge_options(int spp) {
  host::RenderOptions opt;
  opt.width = 5;
  opt.height = 1;
  opt.bounces = 0;
  opt.shadows = false;
  opt.shading = kernels::ShadingModel::diffuse;
  opt.profile = "gf6600";
  opt.spp = spp;
  return opt;
}

}  // namespace

TEST_CASE("sample positions take one stratum each, inside the pixel, the same every run") {
  CHECK(host::sample_offset(1, 0, 7) == glm::vec2(0.5f, 0.5f));
  for (const int spp : {4, 9, 16, 64, 256}) {
    CAPTURE(spp);
    const int n = int(std::lround(std::sqrt(double(spp))));
    std::vector<int> taken(size_t(spp), 0);
    for (int s = 0; s < spp; ++s) {
      const glm::vec2 p = host::sample_offset(spp, s, 1);
      REQUIRE(p.x >= 0.0f);
      REQUIRE(p.x < 1.0f);
      REQUIRE(p.y >= 0.0f);
      REQUIRE(p.y < 1.0f);
      ++taken[size_t(int(p.y * float(n)) * n + int(p.x * float(n)))];
      CHECK(host::sample_offset(spp, s, 1) == p);  // no hidden state
    }
    for (int k = 0; k < spp; ++k) CHECK(taken[size_t(k)] == 1);
  }
  // Another seed moves the samples within their strata.
  CHECK(host::sample_offset(16, 5, 1) != host::sample_offset(16, 5, 2));
}

TEST_CASE("sample counts other than the squares from 1 to 256 are refused, naming the count") {
  for (const int ok : {1, 4, 9, 16, 25, 100, 256}) CHECK(host::spp_refusal(ok).empty());
  CHECK(host::spp_refusal(0).find("from 1 to 256") != std::string::npos);
  CHECK(host::spp_refusal(324).find("from 1 to 256") != std::string::npos);
  CHECK(host::spp_refusal(7).find("7 samples per pixel: not a square") != std::string::npos);
  EdgeCase e;
  CHECK_THROWS_AS(host::StreamTracer(e.scene, e.grid, edge_options(8)), std::invalid_argument);
}

TEST_CASE("a pixel half covered by a white surface on black resolves to half the white") {
  EdgeCase e;
  for (const int spp : {4, 16, 64}) {
    CAPTURE(spp);
    host::StreamTracer tracer(e.scene, e.grid, edge_options(spp));
    const host::RenderResult r = tracer.render(e.camera);
    REQUIRE(r.samples == spp);
    const float white = r.rgb[3 * 3];  // pixel 3: covered by every sample
    REQUIRE(white > 0.5f);
    CHECK(r.rgb[0] == 0.0f);  // pixel 0: no sample hits
    // An even n puts exactly half the strata columns right of the edge, so exactly half the
    // samples hit; their shading varies by well under 1% across the pixel (the light is far
    // above): half the white to 1%. A sample in the wrong column would move it by 1/spp of
    // the white, 25% at spp 4.
    CHECK(std::fabs(r.rgb[2 * 3] - 0.5f * white) <= 0.01f * white);
    // The CPU tracer averages the same sample positions.
    const host::RenderResult c = host::render_cpu(e.scene, e.grid, e.camera, edge_options(spp));
    for (int i = 0; i < 5 * 3; ++i) CHECK(std::fabs(c.rgb[size_t(i)] - r.rgb[size_t(i)]) < 1e-4f);
  }
}

TEST_CASE("a supersampled frame is its sample frames, one accumulation each and one resolve") {
  EdgeCase e;
  host::StreamTracer one(e.scene, e.grid, edge_options(1));
  const host::RenderResult a = one.render(e.camera);
  host::StreamTracer four(e.scene, e.grid, edge_options(4));
  const host::RenderResult b = four.render(e.camera);
  CHECK(a.samples == 1);
  CHECK(a.first_frame_passes == a.stats.totals.passes);
  CHECK(b.first_frame_passes < b.stats.totals.passes);
  // Rays entering the grid (the square's box): the centre frame's pixels 2 (on the edge), 3 and
  // 4; each sample frame's pixels 3 and 4, and pixel 2 in the 2 of 4 frames whose sample lies
  // right of the edge.
  CHECK(a.rays_traced == 3);
  CHECK(b.rays_traced == 4 * 2 + 2);
  auto passes_of = [&b](const std::string& name) {
    for (const auto& p : b.stats.programs)
      if (p.name == name) return int(p.counters.passes);
    return 0;
  };
  CHECK(passes_of("generate rays") == 0);  // every frame's rays are jittered
  CHECK(passes_of("generate sample rays") == 4);
  CHECK(passes_of("accumulate samples") == 4);
  CHECK(passes_of("resolve samples") == 1);
}

namespace {

// The square's inside alone (one material, no edge in view), lit from close by so the diffuse
// shading changes from every pixel to the next: 8x6 pixels.
struct InsideCase : EdgeCase {
  InsideCase() {
    scene.lights = {{{2, 0, 0.6f}, {1, 1, 1}}};
    camera.position = {2, 0, 4};
  }
};

host::RenderOptions adaptive_options(int spp, float threshold) {
  host::RenderOptions opt = edge_options(spp);
  opt.width = 8;
  opt.height = 6;
  opt.adaptive = true;
  opt.aa_criterion = host::RenderOptions::AaCriterion::image;
  opt.aa_threshold = threshold;
  return opt;
}

}  // namespace

TEST_CASE("adaptive sampling that marks no pixel is the one-ray image, bit for bit") {
  InsideCase e;
  host::RenderOptions one = adaptive_options(1, 0);
  one.adaptive = false;
  const host::RenderResult a = host::StreamTracer(e.scene, e.grid, one).render(e.camera);
  const host::RenderResult b =
      host::StreamTracer(e.scene, e.grid, adaptive_options(16, 10.0f)).render(e.camera);
  CHECK(same_bits(a.rgb, b.rgb));
  CHECK(same_bits(a.hit_id, b.hit_id));
  REQUIRE(b.rays_per_pixel.size() == a.rgb.size() / 3);
  for (const uint32_t n : b.rays_per_pixel) CHECK(n == 1);
  CHECK(b.rays_traced == a.rays_traced);
}

TEST_CASE("adaptive sampling that marks every pixel is the --spp N image, bit for bit") {
  InsideCase e;
  host::RenderOptions uniform = adaptive_options(16, 0);
  uniform.adaptive = false;
  const host::RenderResult a = host::StreamTracer(e.scene, e.grid, uniform).render(e.camera);
  const host::RenderResult b =
      host::StreamTracer(e.scene, e.grid, adaptive_options(16, 0.0f)).render(e.camera);
  // Every pixel went through both levels: the centre ray, 2 x 2 samples, then 4 x 4.
  REQUIRE(b.rays_per_pixel.size() == 48);
  for (const uint32_t n : b.rays_per_pixel) CHECK(n == 1 + 4 + 16);
  CHECK(b.samples == 16);
  CHECK(same_bits(a.rgb, b.rgb));
}

TEST_CASE("adaptive sampling spends its rays on edges, and the CPU tracer marks the same pixels") {
  EdgeCase e;
  host::RenderOptions opt = adaptive_options(16, 0.05f);
  opt.width = 9;
  opt.height = 3;
  e.camera.yfov = 2.0f * std::atan(0.05f * 3.0f / 5.0f);  // 0.4 wide pixels, as before
  const host::RenderResult g = host::StreamTracer(e.scene, e.grid, opt).render(e.camera);
  const host::RenderResult c = host::render_cpu(e.scene, e.grid, e.camera, opt);
  REQUIRE(g.rays_per_pixel.size() == 27);
  CHECK(g.rays_per_pixel == c.rays_per_pixel);
  // Columns 0-3 miss, 5-8 hit, 4 is cut by the edge; its centre ray hits exactly on the edge
  // (x = 0), so its key is the square's. The keys differ between columns 3 and 4 only: both are
  // marked and refined to the last level (1 + 2x2 + 4x4 = 21 rays). Column 5 has the square's
  // key on both sides and the same colour as its neighbours (no bend), so it keeps its one ray,
  // as do all the others.
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 9; ++x) {
      CAPTURE(x);
      CAPTURE(y);
      CHECK(g.rays_per_pixel[size_t(y * 9 + x)] == (x == 3 || x == 4 ? 21u : 1u));
    }
  for (int i = 0; i < 27 * 3; ++i) CHECK(std::fabs(g.rgb[size_t(i)] - c.rgb[size_t(i)]) < 1e-4f);
}

TEST_CASE("undersampling every pixel (K = 1) is the full render, bit for bit") {
  EdgeCase e;
  host::RenderOptions full = adaptive_options(1, 0);
  full.adaptive = false;
  full.width = 9;
  full.height = 3;
  host::RenderOptions under = full;
  under.undersample = 1;
  const host::RenderResult a = host::StreamTracer(e.scene, e.grid, full).render(e.camera);
  const host::RenderResult b = host::StreamTracer(e.scene, e.grid, under).render(e.camera);
  CHECK(same_bits(a.rgb, b.rgb));
  CHECK(same_bits(a.hit_id, b.hit_id));
  CHECK(same_bits(a.depth, b.depth));
  for (const uint32_t n : b.rays_per_pixel) CHECK(n == 1);
}

TEST_CASE(
    "undersampling traces the lattice and the gaps between different surfaces, and blends "
    "the rest") {
  // One surface in view and a threshold no colour change reaches: only the lattice (every 2nd
  // pixel and the last row and column) is traced, and a pixel between two lattice pixels is
  // their mean, less the curvature correction where the lattice pixels one step further out
  // are in the image (kernels/undersample.h, FillGaps).
  InsideCase inside;
  host::RenderOptions opt = adaptive_options(1, 10.0f);
  opt.adaptive = false;
  opt.undersample = 2;
  const host::RenderResult r =
      host::StreamTracer(inside.scene, inside.grid, opt).render(inside.camera);
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 8; ++x) {
      CAPTURE(x);
      CAPTURE(y);
      const bool lattice = (x % 2 == 0 || x == 7) && (y % 2 == 0 || y == 5);
      CHECK(r.rays_per_pixel[size_t(y * 8 + x)] == (lattice ? 1u : 0u));
    }
  auto at = [&](int x, int y, int c) { return r.rgb[size_t(y * 8 + x) * 3 + size_t(c)]; };
  bool curved = false;
  for (int c = 0; c < 3; ++c) {
    CAPTURE(c);
    // (1, 2): no lattice column -2, the straight mean.
    CHECK(at(1, 2, c) == doctest::Approx(0.5f * (at(0, 2, c) + at(2, 2, c))));
    // (3, 2): between columns 2 and 4, with 0 and 6 beyond: the mean less 1/8 of the smaller
    // second difference (both within the limit, threshold / 2, and of one sign).
    const float d0 = at(0, 2, c) - 2 * at(2, 2, c) + at(4, 2, c);
    const float d1 = at(2, 2, c) - 2 * at(4, 2, c) + at(6, 2, c);
    const float bend = d0 * d1 > 0 ? (std::fabs(d0) < std::fabs(d1) ? d0 : d1) : 0.0f;
    curved = curved || std::fabs(bend) > 1e-4f;
    CHECK(at(3, 2, c) ==
          doctest::Approx(0.5f * (at(2, 2, c) + at(4, 2, c)) - bend / 8).epsilon(1e-4));
  }
  CHECK(curved);  // the light's falloff bends the shade: the correction is tested, not 0
  // Threshold 0: the shading changes across every cell, so every pixel is traced.
  host::RenderOptions all = opt;
  all.aa_threshold = 0.0f;
  const host::RenderResult t =
      host::StreamTracer(inside.scene, inside.grid, all).render(inside.camera);
  for (const uint32_t n : t.rays_per_pixel) CHECK(n == 1);
  // The edge: the cells the square's edge crosses have corners on both surfaces, so their
  // pixels are traced; the CPU tracer traces the same pixels and agrees.
  EdgeCase e;
  opt.width = 9;
  opt.height = 3;
  const host::RenderResult g = host::StreamTracer(e.scene, e.grid, opt).render(e.camera);
  const host::RenderResult c = host::render_cpu(e.scene, e.grid, e.camera, opt);
  CHECK(g.rays_per_pixel == c.rays_per_pixel);
  CHECK(g.rays_per_pixel[size_t(1 * 9 + 3)] == 1);  // between columns 2 (miss) and 4 (on edge)
  CHECK(g.rays_per_pixel[size_t(0 * 9 + 3)] == 1);  // on row 0, between (2, 0) and (4, 0)
  // On lattice column 2 (or 4) a pixel blends only that column's two lattice pixels, which
  // agree: it is not traced, though its cell's other corners lie across the edge.
  CHECK(g.rays_per_pixel[size_t(1 * 9 + 2)] == 0);
  CHECK(g.rays_per_pixel[size_t(1 * 9 + 4)] == 0);
  CHECK(g.rays_per_pixel[size_t(0 * 9 + 1)] == 0);  // all misses
  for (int i = 0; i < 27 * 3; ++i) CHECK(std::fabs(g.rgb[size_t(i)] - c.rgb[size_t(i)]) < 1e-4f);
}

TEST_CASE("the lattice along an axis agrees with on_lattice and lattice_cell at every coordinate") {
  for (int n = 1; n <= 20; ++n)
    for (int k = 1; k <= 5; ++k) {
      CAPTURE(n);
      CAPTURE(k);
      const host::LatticeAxis a = host::lattice_axis(n, k);
      REQUIRE(a.on.size() == size_t(n));
      REQUIRE(a.nearest.size() == size_t(n));
      uint64_t count = 0;
      for (int x = 0; x < n; ++x) {
        CAPTURE(x);
        // Along x of an n x 1 image, and along y of a 1 x n one.
        CHECK(bool(a.on[size_t(x)]) == host::on_lattice(x, 0, k, n, 1));
        CHECK(bool(a.on[size_t(x)]) == host::on_lattice(0, x, k, 1, n));
        const glm::ivec4 c = host::lattice_cell(x, 0, k, n, 1);
        CHECK(a.nearest[size_t(x)] == (x - c.x <= c.y - x ? c.x : c.y));
        count += host::on_lattice(x, 0, k, n, 1) ? 1 : 0;
      }
      CHECK(a.count == count);
    }
}

TEST_CASE(
    "undersampling gives a pixel it never traced the depth and surface id of its cell's nearest "
    "lattice pixel") {
  // The edge scene at 9 x 8: the last row is a lattice row off the K-spacing for K 2 and 3 (the
  // last column for K 3), and depth changes from pixel to pixel, with no symmetry about a row,
  // so a wrong corner shows.
  EdgeCase e;
  constexpr int W = 9, H = 8;
  for (const int K : {2, 3}) {
    CAPTURE(K);
    host::RenderOptions opt = adaptive_options(1, 10.0f);
    opt.adaptive = false;
    opt.undersample = K;
    opt.width = W;
    opt.height = H;
    const host::RenderResult r = host::StreamTracer(e.scene, e.grid, opt).render(e.camera);
    int untraced = 0, told_apart = 0;
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const size_t i = size_t(y * W + x);
        if (r.rays_per_pixel[i] == 1) continue;
        CAPTURE(x);
        CAPTURE(y);
        ++untraced;
        const glm::ivec4 c = host::lattice_cell(x, y, K, W, H);
        const int nx = x - c.x <= c.y - x ? c.x : c.y, ny = y - c.z <= c.w - y ? c.z : c.w;
        const size_t j = size_t(ny * W + nx);
        CHECK(same_bits(std::vector<float>{r.depth[i]}, std::vector<float>{r.depth[j]}));
        CHECK(r.hit_id[i] == r.hit_id[j]);
        // Where the cell's other corners (across x, across y, across both) all hold other
        // depths, the check above tells the nearest from each of them.
        const int ox = nx == c.x ? c.y : c.x, oy = ny == c.z ? c.w : c.z;
        int differ = 0;
        for (const size_t o : {size_t(ny * W + ox), size_t(oy * W + nx), size_t(oy * W + ox)})
          differ += o != j && r.depth[o] != r.depth[j] ? 1 : 0;
        told_apart += differ == 3 ? 1 : 0;
      }
    CHECK(untraced > 0);
    CHECK(told_apart > 0);
  }
}

TEST_CASE(
    "adaptive sampling (by either criterion) and undersampling mark the same pixels on every "
    "acceleration structure, with reflections and shadows, on both engines" *
    doctest::test_suite("sweep")) {
  // bunny-refl: a mirror floor under the bunny, two bounces, shadow rays (the CLI's defaults).
  const host::Scene scene = host::load_scene(host::resolve_scene("bunny-refl"));
  const host::Camera camera = host::scene_camera(scene);
  const host::AccelParams params{host::grid_spec_for({}, scene, vgpu::profile("gf6600"))};
  std::unique_ptr<host::Accel> accels[3] = {
      host::make_accel(host::AccelKind::grid, scene, params),
      host::make_accel(host::AccelKind::bvh, scene, params),
      host::make_accel(host::AccelKind::kdtree, scene, params)};
  for (const int mode : {0, 1, 2, 3}) {
    // 0: adaptive up to 16 samples (--aa-criterion image), 1: undersampling, K = 2, 2: adaptive
    // by the pixels' cones (--aa-criterion object: the hit distances and the mirror's reflected
    // keys), 3: by their scores within the budget (--aa-criterion budget: the search, the kept
    // level).
    CAPTURE(mode);
    host::RenderOptions opt;
    // (The budget at 12x12: its two levels and search cost the most passes under sanitizers.)
    const int size = mode == 3 ? 12 : 16;
    opt.width = opt.height = size;
    opt.profile = "gf6600";
    opt.aa_threshold = 0.1f;
    if (mode != 1) {
      opt.spp = 16;
      opt.adaptive = true;
      opt.aa_criterion = mode == 0   ? host::RenderOptions::AaCriterion::image
                         : mode == 2 ? host::RenderOptions::AaCriterion::object
                                     : host::RenderOptions::AaCriterion::budget;
      if (mode == 3) opt.aa_threshold.reset();  // the budget's floor
    } else {
      opt.undersample = 2;
    }
    std::vector<uint32_t> first;
    for (const auto& built : accels) {
      const host::Accel& a = *built;
      CAPTURE(std::string(a.name()));
      const host::RenderResult g = host::StreamTracer(scene, a, opt).render(camera);
      const host::RenderResult c = host::render_cpu(scene, a, camera, opt);
      REQUIRE(g.rays_per_pixel.size() == size_t(size * size));
      CHECK(g.rays_per_pixel == c.rays_per_pixel);
      if (first.empty()) first = g.rays_per_pixel;
      CHECK(g.rays_per_pixel == first);
      // Some pixels were refined (or traced between the lattice), not all.
      const auto most = *std::max_element(g.rays_per_pixel.begin(), g.rays_per_pixel.end());
      const auto least = *std::min_element(g.rays_per_pixel.begin(), g.rays_per_pixel.end());
      CHECK(most == (mode == 1 ? 1u : mode == 3 ? 17u : 21u));
      CHECK(least == (mode != 1 ? 1u : 0u));
      float worst = 0;
      for (size_t i = 0; i < g.rgb.size(); ++i)
        worst = std::max(worst, std::fabs(g.rgb[i] - c.rgb[i]));
      CHECK(worst < 1e-3f);
    }
  }
}

TEST_CASE(
    "the host's undersampling fill gives a quadratic shade back and a step the straight "
    "blend, and its gap test reads only the corners the fill blends") {
  // A 9x9 image; only lattice pixels (K = 2) are set, the others hold a value the fill must
  // never read.
  const int W = 9, H = 9, K = 2;
  auto image = [&](auto f) {
    std::vector<glm::dvec3> c(size_t(W * H), glm::dvec3(99.0));
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x)
        if (host::on_lattice(x, y, K, W, H)) c[size_t(y * W + x)] = f(x, y);
    return c;
  };
  // A gentle quadratic in x and y, per channel: the corrected blend is exact off the border
  // cells (second differences 2 * 0.004 * K^2 = 0.032 <= T / 2).
  const auto quad = image([](int x, int y) {
    const double v = 0.2 + 0.004 * x * x + 0.004 * y * y;
    return glm::dvec3(v, 0.5 * v, 0.25 * v);
  });
  for (const auto& [x, y] : {std::pair{3, 3}, {4, 3}, {3, 4}, {5, 5}}) {
    const glm::dvec3 f = host::undersample_fill(quad, x, y, K, W, H, 0.1);
    const double v = 0.2 + 0.004 * x * x + 0.004 * y * y;
    CHECK(f.x == doctest::Approx(v).epsilon(1e-12));
    CHECK(f.y == doctest::Approx(0.5 * v).epsilon(1e-12));
    CHECK(f.z == doctest::Approx(0.25 * v).epsilon(1e-12));
  }
  // With the limit below the second difference, the straight (bilinear) blend.
  const glm::dvec3 straight = host::undersample_fill(quad, 3, 3, K, W, H, 0.01);
  const double mean = (quad[size_t(2 * W + 2)].x + quad[size_t(2 * W + 4)].x +
                       quad[size_t(4 * W + 2)].x + quad[size_t(4 * W + 4)].x) /
                      4;
  CHECK(straight.x == doctest::Approx(mean).epsilon(1e-12));
  // A step between x = 4 and x = 6: its second differences are large at both ends of the cell
  // (4, 6), so the pixel between keeps the mean of the two.
  const auto step = image([](int x, int) { return glm::dvec3(x >= 6 ? 1.0 : 0.0); });
  CHECK(host::undersample_fill(step, 5, 4, K, W, H, 0.1).x == doctest::Approx(0.5));
  // The gap test: pixel (5, 4) on lattice row 4 blends (4, 4) and (6, 4) alone.
  std::vector<int> key(size_t(W * H), 0);
  key[size_t(2 * W + 6)] = 7;  // a corner of its cell the blend does not use
  host::GapTest t = host::undersample_gap_test(step, key, 5, 4, K, W, H);
  CHECK_FALSE(t.keys_differ);
  CHECK(t.spread == doctest::Approx(1.0));
  t = host::undersample_gap_test(step, key, 5, 3, K, W, H);  // a centre: all four corners
  CHECK(t.keys_differ);
  CHECK(t.spread == doctest::Approx(1.0));
  t = host::undersample_gap_test(quad, key, 4, 7, K, W, H);  // column 4, rows 6 and 8
  CHECK_FALSE(t.keys_differ);
  CHECK(t.spread == doctest::Approx(0.004 * (64 - 36)));
}
