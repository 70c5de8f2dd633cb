// Known answers for host/trace/cpu/optics.h, the glass optics of the CPU reference tracer: Fresnel
// at normal incidence, total internal reflection exactly at the critical angle, Snell's law, the
// reflectance seen from both sides, Brewster's angle and 45 degrees (the s and p terms each by
// hand), and a slab's parallel displacement.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>

#include "host/trace/cpu/optics.h"

namespace {

namespace optics = host::optics;

// The unit direction at angle theta (radians) from -n, in the plane of n = +z and +x: a ray
// coming down onto the surface z = 0, whose facing normal is +z.
glm::dvec3 incoming(double theta) {
  return {std::sin(theta), 0.0, -std::cos(theta)};
}

}  // namespace

TEST_CASE("At normal incidence the reflectance is ((n - 1) / (n + 1))^2, from either side") {
  for (const double eta : {1.0, 1.33, 1.5, 2.42}) {
    const double expected = ((eta - 1) / (eta + 1)) * ((eta - 1) / (eta + 1));
    CHECK(optics::meet(1.0, 1.0 / eta).reflectance == doctest::Approx(expected).epsilon(1e-14));
    CHECK(optics::meet(1.0, eta).reflectance == doctest::Approx(expected).epsilon(1e-14));
    CHECK(optics::normal_reflectance(eta) == doctest::Approx(expected).epsilon(1e-14));
    CHECK_FALSE(optics::meet(1.0, eta).total);
  }
  CHECK(optics::meet(1.0, 1.0 / 1.5).reflectance == doctest::Approx(0.04).epsilon(1e-14));
  CHECK(optics::meet(1.0, 1.0).reflectance == 0.0);  // no interface: nothing reflected
}

TEST_CASE("Total internal reflection starts exactly past the critical angle") {
  for (const double eta : {1.33, 1.5, 2.42}) {
    const double critical = optics::critical_angle(eta);
    CHECK(std::sin(critical) * eta == doctest::Approx(1.0).epsilon(1e-15));
    const optics::Interface below = optics::meet(std::cos(critical - 1e-7), eta);
    const optics::Interface above = optics::meet(std::cos(critical + 1e-7), eta);
    CHECK_FALSE(below.total);
    CHECK(below.reflectance < 1.0);
    CHECK(below.reflectance > 0.99);  // F climbs steeply to 1 just before the critical angle
    CHECK(above.total);
    CHECK(above.reflectance == 1.0);
    // Entering the denser medium there is no critical angle: never total, even at grazing.
    CHECK_FALSE(optics::meet(std::cos(critical + 1e-7), 1.0 / eta).total);
    CHECK_FALSE(optics::meet(0.0, 1.0 / eta).total);
  }
}

TEST_CASE("The refracted direction obeys Snell's law and stays in the plane of incidence") {
  const glm::dvec3 n(0, 0, 1);
  for (const double eta : {1.33, 1.5, 2.42})
    for (const double theta : {0.0, 0.1, 0.5, 1.0, 1.4, 1.5}) {
      for (const double e : {1.0 / eta, eta}) {
        const glm::dvec3 d = incoming(theta);
        const optics::Interface f = optics::meet(d, n, e);
        CHECK(f.cos_i == doctest::Approx(std::cos(theta)).epsilon(1e-14));
        if (f.total) {
          CHECK(e * std::sin(theta) >= 1.0);
          continue;
        }
        const glm::dvec3 t = optics::refract(d, n, e, f);
        CHECK(glm::length(t) == doctest::Approx(1.0).epsilon(1e-14));
        CHECK(t.y == 0.0);  // in the plane of d and n
        CHECK(t.z < 0.0);   // across the surface
        CHECK(-t.z == doctest::Approx(f.cos_t).epsilon(1e-13));
        // η₁ sin θᵢ = η₂ sin θₜ, i.e. sin θₜ = e sin θᵢ, on the same side of the normal.
        CHECK(t.x == doctest::Approx(e * std::sin(theta)).epsilon(1e-13));
      }
    }
}

TEST_CASE("The reflectance is the same from both sides of an interface along one light path") {
  // A ray refracted from air into glass at theta_i, reversed, meets the interface from inside at
  // theta_t: Fresnel's reflectances of the two are equal (Stokes' relations).
  for (const double eta : {1.33, 1.5, 2.42})
    for (const double theta : {0.05, 0.3, 0.7, 1.1, 1.5}) {
      const optics::Interface outside = optics::meet(std::cos(theta), 1.0 / eta);
      const optics::Interface inside = optics::meet(outside.cos_t, eta);
      CHECK_FALSE(inside.total);
      CHECK(inside.cos_t == doctest::Approx(std::cos(theta)).epsilon(1e-12));
      CHECK(inside.reflectance == doctest::Approx(outside.reflectance).epsilon(1e-12));
      CHECK(outside.reflectance > 0.0);
      CHECK(outside.reflectance < 1.0);
    }
  // Grazing incidence reflects everything.
  CHECK(optics::meet(0.0, 1.0 / 1.5).reflectance == 1.0);
}

TEST_CASE("A slab shifts a ray by d sin(theta - theta_t) / cos(theta_t) and keeps its direction") {
  // The faces z = 0 and z = -d; the ray enters at the origin, is refracted, crosses to the back
  // face, and leaves refracted again.
  const double d = 0.75, eta = 1.5;
  for (const double theta : {0.2, 0.6, 1.2}) {
    const glm::dvec3 in = incoming(theta);
    const glm::dvec3 n(0, 0, 1);  // facing the ray at both faces
    const optics::Interface front = optics::meet(in, n, 1.0 / eta);
    const glm::dvec3 inside = optics::refract(in, n, 1.0 / eta, front);
    const glm::dvec3 exit_point = inside * (d / -inside.z);
    const optics::Interface back = optics::meet(inside, n, eta);
    REQUIRE_FALSE(back.total);
    const glm::dvec3 out = optics::refract(inside, n, eta, back);
    CHECK(glm::length(out - in) < 1e-14);
    // The distance between the incoming line (through the origin) and the outgoing one.
    const glm::dvec3 offset = exit_point - in * glm::dot(exit_point, in);
    const double theta_t = std::asin(std::sin(theta) / eta);
    CHECK(glm::length(offset) ==
          doctest::Approx(d * std::sin(theta - theta_t) / std::cos(theta_t)).epsilon(1e-13));
  }
}

TEST_CASE("At Brewster's angle for n = 1.5 the p-polarised light is not reflected: R = 0.0740") {
  // tan θB = n. There cos θᵢ = 1/sqrt(1 + n²) and cos θₜ = n/sqrt(1 + n²), so the s amplitude is
  // (1 - n²)/(1 + n²) = -5/13 and the p amplitude is 0: R = (25/169)/2 = 0.073964..., half the s
  // term alone (which would give 0.1479). The same from inside, at θ = atan(1/n).
  const double n = 1.5;
  const double r_s = 25.0 / 169.0;
  CHECK(r_s == doctest::Approx(0.147929).epsilon(1e-5));
  const optics::Interface outside = optics::meet(std::cos(std::atan(n)), 1.0 / n);
  CHECK(outside.reflectance == doctest::Approx(r_s / 2).epsilon(1e-12));
  CHECK(outside.reflectance == doctest::Approx(0.0740).epsilon(1e-3));
  const optics::Interface inside = optics::meet(std::cos(std::atan(1.0 / n)), n);
  CHECK_FALSE(inside.total);
  CHECK(inside.reflectance == doctest::Approx(r_s / 2).epsilon(1e-12));
}

TEST_CASE(
    "At 45 degrees from air into n = 1.5 the reflectance is 0.0502, the s and p terms by hand") {
  // cos θᵢ = 1/sqrt(2), n cos θₜ = sqrt(n² - 1/2): the s amplitude is (1 - q)/(1 + q) with
  // q = sqrt(2n² - 1) = sqrt(3.5), and at 45 degrees the p amplitude is the s amplitude squared
  // (Abelès): R_s = 0.0920134, R_p = 0.0084665, R = (R_s + R_p)/2 = 0.0502399.
  const double q = std::sqrt(3.5);
  const double rs = (1.0 - q) / (1.0 + q);
  const double expected = 0.5 * (rs * rs + rs * rs * rs * rs);
  CHECK(expected == doctest::Approx(0.0502399).epsilon(1e-6));
  const optics::Interface f = optics::meet(std::cos(std::numbers::pi / 4), 1.0 / 1.5);
  CHECK(f.reflectance == doctest::Approx(expected).epsilon(1e-12));
  // The textbook angle form, Fresnel's sines and tangents, at a few more angles.
  for (const double theta : {0.2, 0.7, 1.2, 1.5}) {
    const double theta_t = std::asin(std::sin(theta) / 1.5);
    const double s = std::sin(theta - theta_t) / std::sin(theta + theta_t);
    const double p = std::tan(theta - theta_t) / std::tan(theta + theta_t);
    CHECK(optics::meet(std::cos(theta), 1.0 / 1.5).reflectance ==
          doctest::Approx(0.5 * (s * s + p * p)).epsilon(1e-12));
  }
}
