// Base-colour textures through the tracers (kernels/base_color.h, host/trace/textures.h): the
// Duck-like quad's colours come from its texture, the stream tracer agrees with the CPU tracer
// for every filter, filtering costs the fetches it reads, lanes and threads change nothing, and
// an atlas past a profile's texture size is refused.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>
#include <vector>

#include "host/accel/grid.h"
#include "host/image/image_io.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"
#include "host/trace/cpu/cpu_tracer.h"
#include "host/trace/stream/stream_tracer.h"
#include "host/trace/textures.h"
#include "tests/support/lane_widths.h"

namespace {

using vgpu::Filter;

host::Scene duck_like() {
  return host::load_scene(std::string(VGPU_TEST_DATA) + "/gltf/textured.gltf", host::with_images());
}

host::RenderOptions options(Filter filter, int size = 32) {
  host::RenderOptions opt;
  opt.width = opt.height = size;
  opt.texture_filter = filter;
  opt.shading = kernels::ShadingModel::diffuse;
  opt.shadows = false;
  opt.bounces = 0;
  opt.threads = 2;
  return opt;
}

struct Frames {
  host::RenderResult stream, cpu;
};

Frames render(const host::Scene& scene, const host::RenderOptions& opt) {
  const host::Grid grid =
      host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile(opt.profile)));
  const host::Camera cam = host::scene_camera(scene, float(opt.width) / float(opt.height));
  host::StreamTracer tracer(scene, grid, opt);
  Frames f;
  f.stream = tracer.render(cam);
  f.cpu = host::render_cpu(scene, grid, cam, opt);
  return f;
}

glm::vec3 pixel(const host::RenderResult& r, int x, int y) {
  const size_t i = 3 * (size_t(y) * size_t(r.width) + size_t(x));
  return {r.rgb[i], r.rgb[i + 1], r.rgb[i + 2]};
}

float max_difference(const std::vector<float>& a, const std::vector<float>& b) {
  float m = 0;
  for (size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(a[i] - b[i]));
  return m;
}

constexpr Filter kFilters[] = {Filter::nearest, Filter::bilinear, Filter::trilinear};

}  // namespace

TEST_CASE("the Duck-like model's colours come from its texture, on both tracers and every filter") {
  const host::Scene scene = duck_like();
  for (Filter filter : kFilters) {
    CAPTURE(int(filter));
    const Frames f = render(scene, options(filter));
    for (const host::RenderResult* r : {&f.stream, &f.cpu}) {
      // The quad covers pixels 3 to 29; its quarters are red, green / blue, white. Pixels 6 and 25
      // lie within a quarter texel of the quad's edges, where every filter (clamped in s,
      // mirrored in t) reads only the corner's own texel.
      const glm::vec3 tl = pixel(*r, 6, 6), tr = pixel(*r, 25, 6), bl = pixel(*r, 6, 25),
                      br = pixel(*r, 25, 25);
      CHECK(tl.r > 0.5f);
      CHECK(tl.g < 0.02f * tl.r);
      CHECK(tl.b < 0.02f * tl.r);
      CHECK(tr.g > 0.5f);
      CHECK(tr.r < 0.02f * tr.g);
      CHECK(bl.b > 0.5f);
      CHECK(bl.r < 0.02f * bl.b);
      CHECK(br.r > 0.5f);
      CHECK(br.g == doctest::Approx(br.r));
      CHECK(br.b == doctest::Approx(br.r));
    }
    // Same filter, same chains: the emulator's fp32 within 1e-3 of the CPU tracer's doubles.
    CHECK(max_difference(f.stream.rgb, f.cpu.rgb) < 1e-3f);
    CHECK(f.stream.hit_id == f.cpu.hit_id);
  }
}

TEST_CASE(
    "the bundled textured scene renders alike on the stream and CPU tracers for every filter") {
  const host::Scene scene = host::load_scene(host::resolve_scene("textured"), host::with_images());
  REQUIRE(scene.textures.size() == 3);
  for (Filter filter : kFilters) {
    CAPTURE(int(filter));
    host::RenderOptions opt = options(filter, 64);
    opt.shading = kernels::ShadingModel::phong;
    opt.shadows = true;
    opt.bounces = 2;
    const Frames f = render(scene, opt);
    double sq = 0;
    for (size_t i = 0; i < f.stream.rgb.size(); ++i) {
      const double d = double(f.stream.rgb[i]) - double(f.cpu.rgb[i]);
      sq += d * d;
    }
    const double rms = std::sqrt(sq / double(f.stream.rgb.size()));
    CHECK(rms < 2e-3);
  }
}

TEST_CASE(
    "filtering costs fetches: bilinear 3 and trilinear 9 more per shaded fragment than nearest") {
  const host::Scene scene = duck_like();
  std::vector<double> per_fragment;
  for (Filter filter : kFilters) {
    const host::RenderOptions opt = options(filter, 16);
    const host::Grid grid =
        host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile(opt.profile)));
    host::StreamTracer tracer(scene, grid, opt);
    const host::RenderResult r = tracer.render(host::scene_camera(scene));
    const auto* shader = r.stats.find("shader");
    REQUIRE(shader != nullptr);
    REQUIRE(shader->counters.fragments_shaded > 0);
    per_fragment.push_back(double(shader->counters.texture_fetches) /
                           double(shader->counters.fragments_shaded));
  }
  // Bilinear: 4 texels for 1. Trilinear: 8 texels and two more level rectangles.
  CHECK(per_fragment[1] - per_fragment[0] == 3.0);
  CHECK(per_fragment[2] - per_fragment[0] == 9.0);
}

TEST_CASE("a textured frame is bit-identical at 1 and 8 lanes and 1 and 3 threads") {
  const host::Scene scene = duck_like();
  host::RenderOptions opt = options(Filter::trilinear, 24);
  opt.shadows = true;
  const host::Grid grid =
      host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile(opt.profile)));
  const host::Camera cam = host::scene_camera(scene);
  std::vector<std::vector<float>> images;
  for (auto [lanes, threads] : {std::pair{1, 1}, std::pair{8, 3}, std::pair{4, 2}}) {
    if (!test_support::kernel_width_built(lanes)) continue;
    opt.lanes = lanes;
    opt.threads = threads;
    host::StreamTracer tracer(scene, grid, opt);
    images.push_back(tracer.render(cam).rgb);
  }
  for (size_t i = 1; i < images.size(); ++i) CHECK(images[i] == images[0]);
}

TEST_CASE("textures whose atlas passes the profile's texture size are refused naming the limit") {
  host::Scene scene = duck_like();
  // A 2048 x 1 texture: its chain (2048 + 1024 texels wide) passes r300's 2048.
  host::SceneTexture wide;
  wide.name = "wide";
  wide.width = 2048;
  wide.height = 1;
  wide.texels.assign(2048, glm::vec4(1.0f));
  scene.textures.push_back(wide);
  host::RenderOptions opt = options(Filter::trilinear, 8);
  opt.profile = "r300";
  const host::Grid grid =
      host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile(opt.profile)));
  try {
    host::StreamTracer tracer(scene, grid, opt);
    FAIL("not refused");
  } catch (const vgpu::Error& e) {
    const std::string m = e.what();
    CHECK(m.find("atlas") != std::string::npos);
    CHECK(m.find("profile r300 holds at most 2048x2048 texels") != std::string::npos);
  }
  opt.profile = "gf5700";  // 4096: fits
  CHECK_NOTHROW(host::StreamTracer(scene, grid, opt));
}

TEST_CASE("a mip chain halves each level with a box filter down to 1x1") {
  host::SceneTexture t;
  t.width = 4;
  t.height = 2;
  for (int i = 0; i < 8; ++i) t.texels.push_back(glm::vec4(float(i)));
  const host::MipChain c = host::build_mip_chain(t);
  REQUIRE(c.levels.size() == 3);
  CHECK(c.levels[1].width == 2);
  CHECK(c.levels[1].height == 1);
  CHECK(c.levels[1].texels[0].x == (0 + 1 + 4 + 5) / 4.0f);
  CHECK(c.levels[1].texels[1].x == (2 + 3 + 6 + 7) / 4.0f);
  CHECK(c.levels[2].width == 1);
  CHECK(c.levels[2].texels[0].x == 3.5f);
}

namespace {

// A 2 x 2 quad in z = 0 facing +z, texture coordinates (0, 0) at its top-left corner (-1, 1),
// with a 64 x 64 texture (repeat) made so that each mip level's colour is known by hand:
//   red    a one-texel checker (texel (i, j): (i + j) mod 2): level 1 and every level above
//          are 0.5 everywhere;
//   green  the opposite checker: 0.5 from level 1 on, 1 - red at level 0;
//   blue   a checker of 2 x 2 blocks ((i/2 + j/2) mod 2): level 1 is the one-texel checker
//          ((i + j) mod 2), level 2 and above 0.5.
// Lit from the camera, diffuse, no reflection: a pixel is its texel times one factor shared by
// the three channels, so the channels' ratios are the texel's.
host::Scene lod_quad(const glm::vec3& light) {
  host::Scene s;
  host::Material m;
  m.color = glm::vec3(1.0f);
  m.texture = 0;
  s.materials = {m};
  host::SceneTexture t;
  t.name = "lod checkers";
  t.width = t.height = 64;
  for (int j = 0; j < 64; ++j)
    for (int i = 0; i < 64; ++i) {
      const float r = float((i + j) % 2), b = float((i / 2 + j / 2) % 2);
      t.texels.emplace_back(r, 1.0f - r, b, 1.0f);
    }
  s.textures = {t};
  const glm::vec3 n(0, 0, 1);
  s.add_triangle({-1, 1, 0}, {-1, -1, 0}, {1, 1, 0}, n, n, n, 0, 0);
  s.add_triangle({1, 1, 0}, {-1, -1, 0}, {1, -1, 0}, n, n, n, 0, 1);
  s.uv0 = {{0, 0}, {1, 0}};
  s.uv1 = {{0, 1}, {0, 1}};
  s.uv2 = {{1, 0}, {1, 1}};
  s.lights = {{light, glm::vec3(1.0f)}};
  s.input_triangles = 2;
  return s;
}

// Both tracers' frames of lod_quad seen head-on from (x, y, D), where D puts `rho` texels of
// level 0 under one pixel on the camera's axis: a pixel is D spread world units there (spread =
// 2 tan(yfov / 2) / H, the tracers' ray differential) and a world unit is 32 texels. Off the
// axis a pixel covers rho / cos(angle) texels, never fewer. 33 x 33 pixels: pixel (16, 16) is
// on the axis.
Frames lod_frames(float x, float y, double rho) {
  const float yfov = 0.5f;
  const double spread = 2.0 * std::tan(double(yfov) / 2.0) / 33.0;
  const float d = float(rho / (32.0 * spread));
  host::Camera cam;
  cam.position = {x, y, d};
  cam.yfov = yfov;
  const host::Scene scene = lod_quad(cam.position);
  host::RenderOptions opt = options(Filter::trilinear, 33);
  const host::Grid grid =
      host::build_grid(scene, host::grid_spec_for({}, scene, vgpu::profile(opt.profile)));
  host::StreamTracer tracer(scene, grid, opt);
  Frames f;
  f.stream = tracer.render(cam);
  f.cpu = host::render_cpu(scene, grid, cam, opt);
  return f;
}

}  // namespace

TEST_CASE(
    "trilinear filtering: where a pixel spans 2 texels of a frontal quad it returns level 1's "
    "constant colour, where it spans 1 level 0's texels") {
  // Two texels per pixel: level 1 (or above), where red = green = 0.5 in every pixel.
  const Frames two = lod_frames(0.0f, 0.0f, 2.0);
  // One texel per pixel, pixel centres on texel centres (the camera half a texel off the
  // quad's centre): level 0, where red and green are 0 and 1 or 1 and 0.
  const Frames one = lod_frames(1.0f / 64, -1.0f / 64, 1.0);
  for (const auto& [bound_name, bound_f2, bound_f1] :
       {std::tuple{std::string("stream"), &two.stream, &one.stream},
        std::tuple{std::string("cpu"), &two.cpu, &one.cpu}}) {
    // Named copies: clang 14 cannot capture a structured binding (CAPTURE, INFO).
    const auto& name = bound_name;
    const auto& f2 = bound_f2;
    const auto& f1 = bound_f1;
    CAPTURE(name);
    int quad = 0, level1 = 0, level0 = 0;
    for (int y = 0; y < 33; ++y)
      for (int x = 0; x < 33; ++x) {
        REQUIRE(f1->hit_id[size_t(y * 33 + x)] >= 0);  // the quad fills this frame
        const glm::vec3 q = pixel(*f1, x, y);
        level0 += std::abs(q.r - q.g) > 0.8f * (q.r + q.g);
        if (f2->hit_id[size_t(y * 33 + x)] < 0) continue;
        ++quad;
        const glm::vec3 p = pixel(*f2, x, y);
        level1 += std::abs(p.r - p.g) <= 1e-5f * (p.r + p.g) && p.r > 0.1f;
      }
    CHECK(quad > 600);  // 32 x 32 pixels, less the frame's edges
    CHECK(level1 == quad);
    CHECK(level0 == 33 * 33);
  }
}

TEST_CASE(
    "trilinear filtering: where a pixel spans 3 texels it blends levels 1 and 2 at one half") {
  // log2's fraction is taken piecewise linear (vgpu::level_of_detail): 3 / 2 - 1 = 1/2. The axis
  // pixel looks at the centre of level 1's texel (20, 13) (u = 20.5 / 32, v = 13.5 / 32), whose
  // blue is (20 + 13) mod 2 = 1; level 2's is 0.5: blue = (1 + 0.5) / 2 = 0.75 against red =
  // green = 0.5. Level 1 alone would give 1, level 2 alone 0.5, the exact log2 (fraction 0.585)
  // 0.707.
  const Frames f = lod_frames(0.28125f, 0.15625f, 3.0);
  for (const auto& [bound_name, bound_r] :
       {std::pair{std::string("stream"), &f.stream}, std::pair{std::string("cpu"), &f.cpu}}) {
    // Named copies: clang 14 cannot capture a structured binding (CAPTURE, INFO).
    const auto& name = bound_name;
    const auto& r = bound_r;
    CAPTURE(name);
    REQUIRE(r->hit_id[16 * 33 + 16] >= 0);
    const glm::vec3 p = pixel(*r, 16, 16);
    CHECK(p.r > 0.1f);
    CHECK(p.g / p.r == doctest::Approx(1.0).epsilon(1e-5));
    CHECK(p.b / p.r == doctest::Approx(1.5).epsilon(1e-4));
  }
}

TEST_CASE(
    "KHR_texture_transform's quarter turn shows the image turned clockwise: each corner of the "
    "quad shows the texel the spec's rotation brings there") {
  // tests/data/gltf/textured_rotation.gltf: the Duck-like quad (red, green / blue, white) with
  // rotation pi/2 and offset (0, 1). The extension turns the coordinates counter-clockwise,
  // "equivalent to a similar rotation of the image clockwise": the top-left corner now shows the
  // image's bottom-left texel (blue), the top-right its top-left (red), the bottom-right its
  // top-right (green), the bottom-left its bottom-right (white).
  const host::Scene scene = host::load_scene(
      std::string(VGPU_TEST_DATA) + "/gltf/textured_rotation.gltf", host::with_images());
  // The transform is applied to the corners' coordinates when the file is loaded: one filter
  // shows it as well as three.
  {
    const Frames f = render(scene, options(Filter::nearest));
    for (const host::RenderResult* r : {&f.stream, &f.cpu}) {
      // Pixels 6 and 25 lie within a quarter texel of the quad's corners (as above).
      const glm::vec3 tl = pixel(*r, 6, 6), tr = pixel(*r, 25, 6), bl = pixel(*r, 6, 25),
                      br = pixel(*r, 25, 25);
      CHECK(tl.b > 0.5f);
      CHECK(tl.r < 0.02f * tl.b);
      CHECK(tl.g < 0.02f * tl.b);
      CHECK(tr.r > 0.5f);
      CHECK(tr.g < 0.02f * tr.r);
      CHECK(tr.b < 0.02f * tr.r);
      CHECK(br.g > 0.5f);
      CHECK(br.r < 0.02f * br.g);
      CHECK(br.b < 0.02f * br.g);
      CHECK(bl.r > 0.5f);
      CHECK(bl.g == doctest::Approx(bl.r));
      CHECK(bl.b == doctest::Approx(bl.r));
    }
  }
}
