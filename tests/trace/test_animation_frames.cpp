// Frames of a moving scene (issue 23): a frame of tests/data/gltf/animated.gltf at a time T
// against the same scene with T's transforms applied to its vertices by hand, and a stream tracer
// updated between frames (static textures rewritten and uploaded again on the same device),
// walking the grid or a BVH, against a tracer made for that frame; a file's two animations
// played together against the same scene posed by hand.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>

#include "host/accel/accel.h"
#include "host/accel/grid.h"
#include "host/accel/grid2.h"
#include "host/scene/animation.h"
#include "host/scene/camera.h"
#include "host/trace/stream/stream_tracer.h"

using host::RenderOptions;
using host::RenderResult;
using host::Scene;

namespace {

std::string data_path(const std::string& name) {
  return std::string(VGPU_TEST_DATA) + "/gltf/" + name;
}

// The whole pipeline (2 bounces, shadow rays, phong), one thread, a small image.
RenderOptions options() {
  RenderOptions opt;
  opt.width = 64;
  opt.height = 48;
  opt.threads = 1;
  return opt;
}

RenderResult render(const Scene& scene, const host::Grid& grid, const host::Camera& cam) {
  host::StreamTracer tracer(scene, grid, options());
  return tracer.render(cam);
}

// `m` applied to triangles [first, last) of `s`: corners as points, normals by the inverse
// transpose, renormalised (world space in, world space out).
void transform(Scene& s, size_t first, size_t last, const glm::dmat4& m) {
  const glm::dmat3 nm = glm::transpose(glm::inverse(glm::dmat3(m)));
  for (size_t i = first; i < last; ++i) {
    for (auto* p : {&s.p0[i], &s.p1[i], &s.p2[i]})
      *p = glm::vec3(m * glm::dvec4(glm::dvec3(*p), 1));
    for (auto* n : {&s.n0[i], &s.n1[i], &s.n2[i]})
      *n = glm::vec3(glm::normalize(nm * glm::dvec3(*n)));
  }
}

int differing(const std::vector<float>& a, const std::vector<float>& b) {
  int n = 0;
  for (size_t i = 0; i < a.size(); ++i) n += a[i] != b[i];
  return n;
}

float max_difference(const std::vector<float>& a, const std::vector<float>& b) {
  REQUIRE(a.size() == b.size());
  float m = 0.0f;
  for (size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(a[i] - b[i]));
  return m;
}

}  // namespace

TEST_CASE("a frame at time T hits what the scene with T's transforms applied by hand hits") {
  const host::AnimatedScene a(data_path("animated.gltf"));
  const Scene& rest = a.rest();
  const double pi = std::numbers::pi;
  const glm::dmat4 I(1.0);
  // At rest the body (triangles 2-13) sits at (0, 0.5, 0), its child the head (14-25) 1 above
  // it at half size. At 2 s of "move" the body is halfway to (2, 0.5, 0), an eighth of a turn
  // about +Y, and the head (STEP at 2 s) is at a quarter size.
  const glm::dmat4 body_rest = glm::translate(I, {0, 0.5, 0});
  const glm::dmat4 head_rest =
      body_rest * glm::scale(glm::translate(I, {0, 1, 0}), glm::dvec3(0.5));
  const glm::dmat4 body = glm::rotate(glm::translate(I, {1, 0.5, 0}), pi / 4, {0, 1, 0});
  const glm::dmat4 head = body * glm::scale(glm::translate(I, {0, 1, 0}), glm::dvec3(0.25));
  Scene by_hand = rest;
  transform(by_hand, 2, 14, body * glm::inverse(body_rest));
  transform(by_hand, 14, 26, head * glm::inverse(head_rest));

  const Scene posed = a.at(0, 2.0);
  REQUIRE(posed.camera);
  const host::Camera cam = *posed.camera;
  const host::Grid grid_posed = host::build_grid(posed, {});
  const host::Grid grid_hand = host::build_grid(by_hand, {});
  CHECK(grid_posed.res == grid_hand.res);
  const RenderResult r_posed = render(posed, grid_posed, cam);
  const RenderResult r_hand = render(by_hand, grid_hand, cam);
  // The same triangle hit in every pixel, at the same distance.
  CHECK(differing(r_posed.hit_id, r_hand.hit_id) == 0);
  int far = 0;
  for (size_t i = 0; i < r_posed.depth.size(); ++i)
    far += std::abs(r_posed.depth[i] - r_hand.depth[i]) > 1e-5f * std::max(1.0f, r_hand.depth[i]);
  CHECK(far == 0);
  // The posed normals are the hand-made ones, and so the colours agree (the corners differ in
  // the last bits of float, which moves a colour by far less than 1e-4).
  for (size_t i = 0; i < posed.triangle_count(); ++i) {
    CAPTURE(i);
    CHECK(glm::all(glm::epsilonEqual(posed.n0[i], by_hand.n0[i], 1e-6f)));
    CHECK(glm::all(glm::epsilonEqual(posed.n1[i], by_hand.n1[i], 1e-6f)));
    CHECK(glm::all(glm::epsilonEqual(posed.n2[i], by_hand.n2[i], 1e-6f)));
  }
  CHECK(max_difference(r_posed.rgb, r_hand.rgb) < 1e-4f);
  // And the frame did move: the rest scene's hits differ in many pixels.
  const RenderResult r_rest = render(rest, host::build_grid(rest, {}), cam);
  CHECK(differing(r_rest.hit_id, r_posed.hit_id) > 50);
  // The body's triangles are hit somewhere in both frames.
  auto hits_body = [](const RenderResult& r) {
    return std::any_of(r.hit_id.begin(), r.hit_id.end(),
                       [](float id) { return id >= 2 && id < 14; });
  };
  CHECK(hits_body(r_posed));
  CHECK(hits_body(r_rest));
}

TEST_CASE("a tracer updated between frames renders what a tracer made for the frame renders") {
  const host::AnimatedScene a(data_path("animated.gltf"));
  const Scene first = a.at(0, 0.0);
  const host::Camera cam = *first.camera;
  const host::Grid grid_first = host::build_grid(first, {});
  host::StreamTracer tracer(first, grid_first, options());
  (void)tracer.render(cam);
  // Frame two, with the first frame's grid resolution (as the CLI keeps it).
  const Scene second = a.at(0, 2.0);
  const host::Grid grid_second = host::build_grid(second, {grid_first.res});
  const host::StreamTracer::Upload up = tracer.update(second, grid_second);
  const RenderResult updated = tracer.render(cam);
  const RenderResult fresh = render(second, grid_second, cam);
  CHECK(differing(updated.rgb, fresh.rgb) == 0);
  CHECK(differing(updated.hit_id, fresh.hit_id) == 0);
  CHECK(differing(updated.depth, fresh.depth) == 0);
  CHECK(updated.stats.totals.passes == fresh.stats.totals.passes);
  CHECK(updated.stats.totals.bytes_read == fresh.stats.totals.bytes_read);
  // What moved was uploaded again, whole textures: the vertices, normals and grid; the colours
  // did not change.
  const auto& names = up.textures;
  auto uploaded = [&](const char* name) {
    return std::find(names.begin(), names.end(), name) != names.end();
  };
  for (const char* name :
       {"vertices0", "vertices2", "normals1", "triangle lists", "voxel pointers"})
    CHECK_MESSAGE(uploaded(name), name);
  CHECK_FALSE(uploaded("colors"));
  CHECK(up.bytes > 0);
  CHECK(up.bytes < tracer.static_bytes());
  // The same frame again: nothing changed, nothing sent.
  const host::StreamTracer::Upload again = tracer.update(second, grid_second);
  CHECK(again.bytes == 0);
  CHECK(again.textures.empty());

  // More triangles than the scene's textures hold: new textures, the same image as a new tracer.
  Scene grown = second;
  for (size_t i = 0; i < 30; ++i) {
    const float x = -3.5f + 0.25f * float(i);
    grown.add_flat_triangle({x, 0.2f, 1.0f}, {x + 0.2f, 0.2f, 1.0f}, {x + 0.1f, 0.6f, 1.0f}, 0,
                            100 + uint32_t(i));
  }
  const host::Grid grid_grown = host::build_grid(grown, {grid_first.res});
  const host::StreamTracer::Upload up_grown = tracer.update(grown, grid_grown);
  CHECK(std::find(up_grown.textures.begin(), up_grown.textures.end(), "colors") !=
        up_grown.textures.end());
  const RenderResult grown_updated = tracer.render(cam);
  const RenderResult grown_fresh = render(grown, grid_grown, cam);
  CHECK(differing(grown_updated.rgb, grown_fresh.rgb) == 0);
  CHECK(differing(grown_updated.hit_id, grown_fresh.hit_id) == 0);
  CHECK(std::count(grown_fresh.hit_id.begin(), grown_fresh.hit_id.end(), 110.0f) > 0);
}

TEST_CASE(
    "a tracer walking a BVH, a kd-tree or a two-level grid, updated between frames, renders what "
    "a new one renders") {
  const host::AnimatedScene a(data_path("animated.gltf"));
  const Scene first = a.at(0, 0.0), second = a.at(0, 2.0);
  const host::Camera cam = *first.camera;
  for (const host::AccelKind kind :
       {host::AccelKind::bvh, host::AccelKind::kdtree, host::AccelKind::grid2}) {
    CAPTURE(std::string(host::accel_name(kind)));
    // The structure in its scene box, as the CLI builds it: for the first frame, then updated
    // for the second (Accel::update, as the CLI's later frames); a fresh one for the second.
    const std::unique_ptr<host::Accel> accel = host::make_accel(kind, first, {});
    host::StreamTracer tracer(first, *accel, options());
    (void)tracer.render(cam);
    (void)accel->update(second, "rebuild");
    const std::unique_ptr<host::Accel> accel2 = host::make_accel(kind, second, {});
    const host::StreamTracer::Upload up = tracer.update(second, *accel);
    const RenderResult updated = tracer.render(cam);
    host::StreamTracer fresh_tracer(second, *accel2, options());
    const RenderResult fresh = fresh_tracer.render(cam);
    CHECK(differing(updated.rgb, fresh.rgb) == 0);
    CHECK(differing(updated.hit_id, fresh.hit_id) == 0);
    CHECK(differing(updated.depth, fresh.depth) == 0);
    CHECK(updated.stats.totals.passes == fresh.stats.totals.passes);
    const char* nodes = kind == host::AccelKind::bvh      ? "bvh nodes lo"
                        : kind == host::AccelKind::kdtree ? "kd nodes"
                                                          : "grid2 lists";
    for (const char* name : {"vertices0", nodes})
      CHECK_MESSAGE(std::find(up.textures.begin(), up.textures.end(), name) != up.textures.end(),
                    name);
    // The same frame walked through the grid hits the same triangles in every pixel (the
    // structures agree; 0 differences, as the walk tests ask, not the 0.5% allowed before).
    const RenderResult grid_frame = render(second, host::build_grid(second, {}), cam);
    CHECK(differing(updated.hit_id, grid_frame.hit_id) == 0);
    // A tracer made for another structure is not handed a grid.
    CHECK_THROWS_AS(tracer.update(second, host::build_grid(second, {})), std::invalid_argument);
  }
}

TEST_CASE("every animation played together renders what the scene posed by hand renders") {
  // two_animations.gltf (tests/data/gltf/make_cases.py): "rise" lifts the outer cube, "spin"
  // turns its child; _at_1s is the same scene with both nodes' transforms set by hand to their
  // values at 1 s (tests/scene/test_animation.cpp checks the triangles). The two renders are the
  // same bits; "rise" alone (the first animation, what a file played before issue 34) is not.
  const host::AnimatedScene a(data_path("two_animations.gltf"));
  const Scene both = a.at(a.all(), 1.0), rise_only = a.at(size_t(0), 1.0);
  const Scene by_hand = host::load_scene(data_path("two_animations_at_1s.gltf"));
  const host::Camera cam = *both.camera;
  const RenderResult r = render(both, host::build_grid(both, {}), cam);
  const RenderResult want = render(by_hand, host::build_grid(by_hand, {}), cam);
  CHECK(differing(r.rgb, want.rgb) == 0);
  CHECK(differing(r.hit_id, want.hit_id) == 0);
  CHECK(differing(r.depth, want.depth) == 0);
  const RenderResult half = render(rise_only, host::build_grid(rise_only, {}), cam);
  CHECK(differing(half.rgb, want.rgb) > 0);
}

TEST_CASE(
    "a frame of leaning file normals, turned and stretched, is shaded as the same scene posed by "
    "hand") {
  // tests/data/gltf/animated_normals.gltf at 1 s: its quad turned an eighth about +Z and
  // stretched to scale (2, 1, 1); its normals lean away from the face, so the shading shows
  // whether they were posed by the inverse transpose (tests/scene/test_animation.cpp works one
  // corner in numbers).
  const host::AnimatedScene a(data_path("animated_normals.gltf"));
  const Scene& rest = a.rest();
  const glm::dmat4 m = glm::scale(glm::rotate(glm::dmat4(1.0), std::numbers::pi / 4, {0, 0, 1}),
                                  glm::dvec3(2, 1, 1));
  Scene by_hand = rest;
  transform(by_hand, 0, rest.triangle_count(), m);
  const Scene posed = a.at(0, 1.0);
  for (size_t i = 0; i < posed.triangle_count(); ++i) {
    CHECK(glm::all(glm::epsilonEqual(posed.n0[i], by_hand.n0[i], 1e-6f)));
    CHECK(glm::all(glm::epsilonEqual(posed.n1[i], by_hand.n1[i], 1e-6f)));
    CHECK(glm::all(glm::epsilonEqual(posed.n2[i], by_hand.n2[i], 1e-6f)));
  }
  const host::Camera cam = *posed.camera;
  const RenderResult r_posed = render(posed, host::build_grid(posed, {}), cam);
  const RenderResult r_hand = render(by_hand, host::build_grid(by_hand, {}), cam);
  CHECK(differing(r_posed.hit_id, r_hand.hit_id) == 0);
  const long quad_pixels =
      std::count_if(r_posed.hit_id.begin(), r_posed.hit_id.end(), [](float id) { return id >= 0; });
  CHECK(quad_pixels > 500);
  CHECK(max_difference(r_posed.rgb, r_hand.rgb) < 1e-4f);
  // The check can tell: the same posed corners with the rest normals (not turned, not
  // stretched) shade most of the quad differently.
  Scene unposed_normals = posed;
  unposed_normals.n0 = rest.n0;
  unposed_normals.n1 = rest.n1;
  unposed_normals.n2 = rest.n2;
  const RenderResult r_wrong = render(unposed_normals, host::build_grid(unposed_normals, {}), cam);
  CHECK(differing(r_wrong.rgb, r_posed.rgb) > quad_pixels);
}
