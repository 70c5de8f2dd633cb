// Known answers for the CPU reference tracer's glass (docs/studies/materials.md, "Glass: the
// model"): a slab shifts a ray by the analytic amount and returns it parallel, on every structure;
// a ray tree's weights never sum above its ray's; shadow rays are dimmed by t per glass surface and
// blocked past kMaxGlassCrossings; rays are counted by kind.
#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <vector>

#include "host/accel/accel.h"
#include "host/accel/bvh.h"
#include "host/accel/grid.h"
#include "host/accel/grid2.h"
#include "host/accel/kdtree.h"
#include "host/trace/cpu/cpu_tracer.h"
#include "host/trace/diagonal.h"
#include "kernels/kernels.h"

namespace {

using host::CpuRay;
using host::CpuRayKind;
using host::Material;
using host::Scene;

// The square [x0, x1] x [y0, y1] in the plane z, its front (counter-clockwise) towards +z when
// `up`, towards -z otherwise.
void quad_z(Scene& s, float x0, float x1, float y0, float y1, float z, bool up, uint32_t mat) {
  const glm::vec3 a(x0, y0, z), b(x1, y0, z), c(x1, y1, z), d(x0, y1, z);
  const uint32_t id = uint32_t(s.id.size());
  if (up) {
    s.add_flat_triangle(a, b, c, mat, id);
    s.add_flat_triangle(a, c, d, mat, id + 1);
  } else {
    s.add_flat_triangle(a, c, b, mat, id);
    s.add_flat_triangle(a, d, c, mat, id + 1);
  }
}

// The same in the plane x, spanning y and z, its front towards +x when `up`.
void quad_x(Scene& s, float x, float y0, float y1, float z0, float z1, bool up, uint32_t mat) {
  const glm::vec3 a(x, y0, z0), b(x, y1, z0), c(x, y1, z1), d(x, y0, z1);
  const uint32_t id = uint32_t(s.id.size());
  if (up) {
    s.add_flat_triangle(a, b, c, mat, id);
    s.add_flat_triangle(a, c, d, mat, id + 1);
  } else {
    s.add_flat_triangle(a, c, b, mat, id);
    s.add_flat_triangle(a, d, c, mat, id + 1);
  }
}

// A scene with its four structures, as the CLI makes them (host::make_accel): a 4x4x4 grid, a
// BVH, a kd-tree and a two-level grid, each in the scene's box.
struct Structures {
  Scene scene;
  std::vector<std::unique_ptr<host::Accel>> accels;  // grid, bvh, kdtree, grid2
  explicit Structures(Scene s) : scene(std::move(s)) {
    const host::AccelParams params{host::GridSpec{glm::ivec3(4)}};
    for (host::AccelKind kind : {host::AccelKind::grid, host::AccelKind::bvh,
                                 host::AccelKind::kdtree, host::AccelKind::grid2})
      accels.push_back(host::make_accel(kind, scene, params));
  }
  std::vector<std::reference_wrapper<const host::Accel>> all() const {
    std::vector<std::reference_wrapper<const host::Accel>> out;
    for (const auto& a : accels) out.push_back(*a);
    return out;
  }
  const host::Accel& of(host::AccelKind kind) const {
    for (const auto& a : accels)
      if (a->kind() == kind) return *a;
    FAIL("no structure of kind " << host::accel_name(kind));
    return *accels.front();
  }
  // The tracers' ray offset ε for a structure: a fraction of its scene box's diagonal.
  static double offset(const host::Accel& a) {
    return host::kOffsetOfDiagonal * glm::length(glm::dvec3(a.box().hi) - glm::dvec3(a.box().lo));
  }
};

// A glass slab: the faces z = -2 (front up) and z = -2 - thickness (front down), clear glass of
// index eta, over an opaque grey wall at z = -6.
Scene slab_scene(double thickness, float eta) {
  Scene s;
  Material glass;
  glass.transmission = 1.0f;
  glass.ior = eta;
  glass.reflect = 0.0f;
  Material wall;
  wall.reflect = 0.0f;
  s.materials = {glass, wall};
  const float back = float(-2.0 - thickness);
  quad_z(s, -20, 20, -20, 20, -2.0f, true, 0);
  quad_z(s, -20, 20, -20, 20, back, false, 0);
  quad_z(s, -40, 40, -40, 40, -6.0f, true, 1);
  s.lights = {{glm::vec3(0, 0, 5), glm::vec3(1)}};
  s.input_triangles = uint32_t(s.id.size());
  return s;
}

host::RenderOptions options(int bounces) {
  host::RenderOptions o;
  o.width = o.height = 1;
  o.bounces = bounces;
  o.shading = kernels::ShadingModel::diffuse;
  return o;
}

}  // namespace

TEST_CASE(
    "A ray through a glass slab leaves parallel to how it entered, shifted by d sin(theta - "
    "theta_t) / cos(theta_t), on every structure") {
  const double thickness = 0.75;
  const float eta = 1.5f;
  const Structures st(slab_scene(thickness, eta));
  for (const host::Accel& accel : st.all()) {
    CAPTURE(accel.name());
    // Normal incidence, 45 degrees, Brewster's angle (tan theta = 1.5) and a steep 1.1 rad, with
    // each one's reflectance known without optics::meet: ((n - 1)/(n + 1))^2 = 0.04; 0.0502399
    // (test_optics: the s term (1 - q)^2/(1 + q)^2 with q = sqrt(3.5), the p term its square);
    // (25/169)/2 (no p term); and Fresnel's sine and tangent form in the angles themselves.
    const double pi = std::numbers::pi;
    for (const double theta : {0.0, pi / 4, std::atan(1.5), 1.1}) {
      CAPTURE(theta);
      const double q = std::sqrt(3.5), rs45 = (1 - q) / (1 + q);
      const double theta_t = std::asin(std::sin(theta) / double(eta));
      const double rs = std::sin(theta - theta_t) / std::sin(theta + theta_t);
      const double rp = std::tan(theta - theta_t) / std::tan(theta + theta_t);
      const double fresnel = theta == 0.0      ? 0.04
                             : theta == pi / 4 ? 0.5 * (rs45 * rs45 + rs45 * rs45 * rs45 * rs45)
                             : theta == 1.1    ? 0.5 * (rs * rs + rp * rp)
                                               : 25.0 / 338.0;
      const glm::dvec3 o(0.1, 0.2, 0.0);
      const glm::dvec3 d(std::sin(theta), 0.0, -std::cos(theta));
      const std::vector<CpuRay> tree = host::cpu_ray_tree(st.scene, accel, options(4), o, d);
      // The path straight through: primary, refracted in, refracted out to the wall.
      const CpuRay* out = nullptr;
      for (const CpuRay& r : tree)
        if (r.depth == 2 && r.kind == CpuRayKind::refracted) out = &r;
      REQUIRE(out != nullptr);
      REQUIRE(out->hit >= 4);  // the wall's triangles
      CHECK(glm::length(out->dir - d) < 1e-12);
      // The light left by the slab is what Fresnel let through twice: (1 - F) at each face, the
      // same F inside and out (the back face is met at theta_t from inside: Stokes).
      CHECK(out->weight == doctest::Approx((1.0 - fresnel) * (1.0 - fresnel)).epsilon(1e-12));
      // Where it lands on the wall, against the line it came in on.
      const glm::dvec3 landing = out->origin + out->dir * out->t;
      const glm::dvec3 rel = landing - o;
      const double shift = glm::length(rel - d * glm::dot(rel, d));
      const double analytic = thickness * std::sin(theta - theta_t) / std::cos(theta_t);
      // Each face's offset ε along the normal moves the path by at most ε (tan θ + tan θt) cos θ.
      const double eps = Structures::offset(accel);
      CHECK(std::abs(shift - analytic) <= 2.0 * eps);
      CHECK(shift == doctest::Approx(analytic +
                                     eps * (std::sin(theta) + std::tan(theta_t) * std::cos(theta)))
                         .epsilon(1e-9));
    }
  }
}

TEST_CASE(
    "The weights of a ray's tree: each child carries R, 1 - R or the reflectance of its parent, "
    "and they sum to the parent's exactly where no cut-off applies") {
  // Half-mirror half-glass slab (a = 0.4, t = 0.5, n = 1.7) over a wall that reflects 0.3: all
  // three shares are non-zero, and rays bounce between the faces until the 1/512 cut-off or the
  // iteration limit ends them. The faces are parallel, so every glass hit of one camera ray
  // meets its face at theta from air or at theta_t from glass, with the same Fresnel F (Stokes).
  // F by hand at normal incidence, 45 degrees and Brewster's angle (test_optics.cpp works these
  // forms out), and from Fresnel's sine and tangent form at 1.3 rad; never from optics::meet.
  Scene s = slab_scene(0.5, 1.7f);
  s.materials[0].transmission = 0.5f;
  s.materials[0].reflect = 0.4f;
  s.materials[1].reflect = 0.3f;  // the wall reflects too
  const Structures st(std::move(s));
  const double n = double(1.7f), pi = std::numbers::pi;
  const double q = std::sqrt(2 * n * n - 1), rs45 = (1 - q) / (1 + q);
  const double brewster = std::atan(n);
  auto fresnel = [&](double theta) {
    if (theta == 0.0) return (n - 1) * (n - 1) / ((n + 1) * (n + 1));
    if (theta == pi / 4) return 0.5 * (rs45 * rs45 + rs45 * rs45 * rs45 * rs45);
    if (theta == brewster) return 0.5 * std::pow((n * n - 1) / (n * n + 1), 2);  // no p term
    const double theta_t = std::asin(std::sin(theta) / n);
    const double rs = std::sin(theta - theta_t) / std::sin(theta + theta_t);
    const double rp = std::tan(theta - theta_t) / std::tan(theta + theta_t);
    return 0.5 * (rs * rs + rp * rp);
  };
  const double min_weight = kernels::ReflectedRays{}.min_weight;
  int exact_sums = 0, cut = 0;
  for (const int bounces : {0, 1, 3, 12}) {
    CAPTURE(bounces);
    for (const double theta : {0.0, pi / 4, brewster, 1.3}) {
      CAPTURE(theta);
      const double f = fresnel(theta);
      const glm::dvec3 d(std::sin(theta), 0.0, -std::cos(theta));
      const std::vector<CpuRay> tree =
          host::cpu_ray_tree(st.scene, st.all()[0], options(bounces), glm::dvec3(0.0), d);
      REQUIRE(!tree.empty());
      CHECK(tree[0].weight == 1.0);
      // The terminal weights: each hit's own shading share, each miss's background.
      double sum = 0.0;
      for (size_t i = 0; i < tree.size(); ++i) {
        const CpuRay& r = tree[i];
        CAPTURE(i);
        CHECK(r.depth <= bounces);
        sum += r.weight * r.local_share;
        // Its children are the rays one deeper that follow it before anything else at its depth.
        double children = 0.0;
        const CpuRay *reflected = nullptr, *refracted = nullptr;
        for (size_t j = i + 1; j < tree.size() && tree[j].depth > r.depth; ++j)
          if (tree[j].depth == r.depth + 1) {
            children += tree[j].weight;
            CHECK(tree[j].kind != CpuRayKind::total_internal);  // parallel faces: never total
            (tree[j].kind == CpuRayKind::refracted ? refracted : reflected) = &tree[j];
          }
        if (r.depth > 0) CHECK(r.weight >= min_weight);
        // The shares by hand: glass keeps (1 - t)(1 - a) for its shading, reflects
        // (1 - t) a + t F and refracts t (1 - F); the wall keeps 1 - a and reflects a.
        double local = 1.0, reflect = 0.0, refract = 0.0;  // a miss: the background
        if (r.hit >= 0) {
          const bool glass = st.scene.material[size_t(r.hit)] == 0;
          local = glass ? 0.5 * (1.0 - double(0.4f)) : 1.0 - double(0.3f);
          reflect = glass ? 0.5 * double(0.4f) + 0.5 * f : double(0.3f);
          refract = glass ? 0.5 * (1.0 - f) : 0.0;
        }
        CHECK(r.local_share == doctest::Approx(local).epsilon(1e-12));
        const bool deeper = r.depth < bounces;
        const bool keeps_reflected = deeper && reflect > 0 && r.weight * reflect >= min_weight;
        const bool keeps_refracted = deeper && refract > 0 && r.weight * refract >= min_weight;
        REQUIRE((reflected != nullptr) == keeps_reflected);
        REQUIRE((refracted != nullptr) == keeps_refracted);
        if (reflected)
          CHECK(reflected->weight == doctest::Approx(r.weight * reflect).epsilon(1e-12));
        if (refracted)
          CHECK(refracted->weight == doctest::Approx(r.weight * refract).epsilon(1e-12));
        if (r.hit < 0 || (keeps_reflected == (reflect > 0) && keeps_refracted == (refract > 0))) {
          // No cut-off: nothing is lost between a ray and its children.
          CHECK(children + r.weight * r.local_share == doctest::Approx(r.weight).epsilon(1e-12));
          ++exact_sums;
        } else {
          CHECK(children + r.weight * r.local_share < r.weight);
          ++cut;
        }
      }
      CHECK(sum <= 1.0 + 1e-12);
      CHECK(sum > 0.0);
      if (bounces == 0) CHECK(sum == doctest::Approx(tree[0].local_share).epsilon(1e-12));
    }
  }
  CHECK(exact_sums > 50);
  CHECK(cut > 10);
}

TEST_CASE("An opaque surface keeps the paper's shares: its reflection carries a of the weight") {
  Scene s = slab_scene(0.5, 1.5f);
  s.materials[0].transmission = 0.0f;
  s.materials[0].reflect = 0.375f;
  const Structures st(std::move(s));
  const std::vector<CpuRay> tree =
      host::cpu_ray_tree(st.scene, st.all()[0], options(2), glm::dvec3(0.0), glm::dvec3(0, 0, -1));
  REQUIRE(tree.size() == 2);  // the primary ray and its mirror reflection (which misses)
  CHECK(tree[0].local_share == 1.0 - 0.375);
  CHECK(tree[1].kind == CpuRayKind::reflected);
  CHECK(tree[1].weight == 0.375);
  CHECK(tree[1].hit == -1);
}

TEST_CASE("Past the critical angle the light inside glass is totally reflected and counted so") {
  // A ray inside a block of index 1.5 meeting its top face at 60 degrees (critical: 41.8).
  Scene s;
  Material glass;
  glass.transmission = 1.0f;
  glass.ior = 1.5f;
  s.materials = {glass};
  quad_z(s, -20, 20, -20, 20, 0.0f, true, 0);     // top face, front up (outside is above)
  quad_z(s, -20, 20, -20, 20, -10.0f, false, 0);  // bottom face, front down
  s.input_triangles = uint32_t(s.id.size());
  const Structures st(std::move(s));
  const double theta = 60.0 * std::numbers::pi / 180.0;
  const glm::dvec3 d(std::sin(theta), 0.0, std::cos(theta));  // upwards, from inside
  const std::vector<CpuRay> tree =
      host::cpu_ray_tree(st.scene, st.all()[0], options(1), glm::dvec3(0, 0, -5), d);
  REQUIRE(tree.size() == 2);
  CHECK(tree[1].kind == CpuRayKind::total_internal);
  CHECK(tree[1].weight == 1.0);  // F = 1: everything reflected, nothing refracted
  CHECK(tree[1].dir.z == doctest::Approx(-d.z).epsilon(1e-14));
  // The counters of a render agree: one frame of rays, counted per spawning iteration by kind.
  host::RenderOptions o = options(1);
  o.width = 3;
  o.height = 2;
  host::Camera cam;
  cam.position = glm::vec3(0, 0, -5);
  cam.forward = glm::vec3(glm::normalize(d));
  cam.up = glm::vec3(0, 1, 0);
  cam.yfov = 0.01f;
  host::CpuStats stats;
  const host::RenderResult r = host::render_cpu(st.scene, st.all()[0], cam, o, &stats);
  CHECK(r.iterations == 2);
  // Spawned by iteration 0 (the camera rays' hits), a part of the reflected rays.
  CHECK(stats.total_internal == std::vector<uint64_t>{6, 0});
  CHECK(stats.reflected == std::vector<uint64_t>{6, 0});
  CHECK(stats.refracted == std::vector<uint64_t>{0, 0});
}

TEST_CASE(
    "A shadow ray's light is multiplied by t for each glass surface it crosses and blocked by an "
    "opaque one or by the eighth glass one") {
  // A floor at z = -5 seen straight down the camera's centre ray, lit from (3, 0, -2); panes
  // between them in the planes x = 0.3 ... , out of the camera ray's way.
  auto floor_colour = [](const std::vector<float>& panes, const host::AccelKind kind) {
    Scene s;
    Material floor;
    floor.reflect = 0.0f;
    floor.color = glm::vec3(0.5f);
    s.materials = {floor};
    quad_z(s, -1, 1, -1, 1, -5.0f, true, 0);
    for (size_t i = 0; i < panes.size(); ++i) {
      Material pane;
      pane.transmission = panes[i];
      pane.reflect = 0.0f;
      s.materials.push_back(pane);
      quad_x(s, 0.3f + 0.25f * float(i), -1, 1, -4.99f, -2.5f, true, uint32_t(i + 1));
    }
    s.lights = {{glm::vec3(3, 0, -2), glm::vec3(1)}};
    s.input_triangles = uint32_t(s.id.size());
    const Structures st(std::move(s));
    host::Camera cam;
    cam.position = glm::vec3(0.0f);
    cam.forward = glm::vec3(0, 0, -1);
    cam.up = glm::vec3(0, 1, 0);
    cam.yfov = 0.01f;
    const host::Accel& accel = st.of(kind);
    host::CpuStats stats;
    const host::RenderResult r = host::render_cpu(st.scene, accel, cam, options(0), &stats);
    REQUIRE(r.hit_id[0] >= 0.0f);
    REQUIRE(r.hit_id[0] <= 1.0f);  // the floor
    return double(r.rgb[0]);
  };
  for (const host::AccelKind kind : host::kAccelKinds) {
    CAPTURE(host::accel_name(kind));
    const double clear = floor_colour({}, kind);
    const double blocked = floor_colour({0.0f}, kind);
    const double lit = clear - blocked;  // the light's own term (the rest is ambient)
    REQUIRE(lit > 0.05);
    auto through = [&](const std::vector<float>& panes) {
      return (floor_colour(panes, kind) - blocked) / lit;
    };
    // Float output: the shares hold to its rounding.
    CHECK(through({0.6f}) == doctest::Approx(0.6).epsilon(1e-6));
    CHECK(through({0.6f, 0.5f}) == doctest::Approx(0.3).epsilon(1e-6));
    CHECK(through({0.6f, 0.0f, 0.5f}) == 0.0);
    CHECK(through(std::vector<float>(7, 0.9f)) == doctest::Approx(std::pow(0.9, 7)).epsilon(1e-6));
    CHECK(through(std::vector<float>(8, 0.9f)) == 0.0);  // the eighth glass surface blocks
  }
}
