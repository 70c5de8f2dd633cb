// Tests for host/scene/animation: the samplers' known answers on hand-made keys (LINEAR, STEP,
// CUBICSPLINE, slerp the short way round, clamping outside the keys), the scene of
// tests/data/gltf/animated.gltf posed at a time against its transforms applied by hand, and a
// file's animations played together (two_animations.gltf against the same scene posed by hand)
// or refused when two drive one node's path (animations_clash.gltf).
#include <doctest/doctest.h>

#include <cmath>
#include <glm/gtc/epsilon.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "host/scene/animation.h"

namespace {

using host::Interpolation;
using host::Sampler;

std::string data_path(const std::string& name) {
  return std::string(VGPU_TEST_DATA) + "/gltf/" + name;
}

std::string str(glm::dvec3 v) {
  std::ostringstream s;
  s << "(" << v.x << ", " << v.y << ", " << v.z << ")";
  return s.str();
}

#define CHECK_NEAR3(a, b) \
  CHECK_MESSAGE(glm::all(glm::epsilonEqual((a), (b), 1e-12)), str(a) << " !~ " << str(b))

Sampler vec3_sampler(Interpolation interpolation, std::vector<double> times,
                     std::vector<glm::dvec3> values) {
  Sampler s;
  s.interpolation = interpolation;
  s.times = std::move(times);
  for (const glm::dvec3& v : values) s.values.emplace_back(v, 0.0);
  return s;
}

// A unit quaternion in glTF order (x, y, z, w) for `angle` radians about unit `axis`.
glm::dvec4 axis_angle(glm::dvec3 axis, double angle) {
  return {axis * std::sin(angle / 2), std::cos(angle / 2)};
}

// Where a rotation sends +X.
glm::dvec3 turn_x(const glm::dquat& q) {
  return q * glm::dvec3(1, 0, 0);
}

}  // namespace

TEST_CASE("linear keys interpolate between their neighbours and clamp outside them") {
  const Sampler s =
      vec3_sampler(Interpolation::linear, {1, 3, 4}, {{0, 0, 0}, {4, 2, -2}, {4, 3, 0}});
  CHECK_NEAR3(host::sample_vec3(s, 2.0), glm::dvec3(2, 1, -1));
  CHECK_NEAR3(host::sample_vec3(s, 1.5), glm::dvec3(1, 0.5, -0.5));
  CHECK_NEAR3(host::sample_vec3(s, 3.5), glm::dvec3(4, 2.5, -1));
  CHECK_NEAR3(host::sample_vec3(s, 3.0), glm::dvec3(4, 2, -2));  // on a key: its value
  // Before the first key and after the last: those keys' values.
  CHECK_NEAR3(host::sample_vec3(s, 0.0), glm::dvec3(0, 0, 0));
  CHECK_NEAR3(host::sample_vec3(s, -7.0), glm::dvec3(0, 0, 0));
  CHECK_NEAR3(host::sample_vec3(s, 4.0), glm::dvec3(4, 3, 0));
  CHECK_NEAR3(host::sample_vec3(s, 100.0), glm::dvec3(4, 3, 0));
}

TEST_CASE("a step key holds its value until the next key's time") {
  const Sampler s = vec3_sampler(Interpolation::step, {0, 1, 2}, {{1, 1, 1}, {2, 2, 2}, {3, 3, 3}});
  CHECK_NEAR3(host::sample_vec3(s, -1.0), glm::dvec3(1));
  CHECK_NEAR3(host::sample_vec3(s, 0.999), glm::dvec3(1));
  CHECK_NEAR3(host::sample_vec3(s, 1.0), glm::dvec3(2));
  CHECK_NEAR3(host::sample_vec3(s, 1.5), glm::dvec3(2));
  CHECK_NEAR3(host::sample_vec3(s, 2.0), glm::dvec3(3));
  CHECK_NEAR3(host::sample_vec3(s, 9.0), glm::dvec3(3));
}

TEST_CASE("a cubic spline follows the glTF Hermite form, its tangents scaled by the key interval") {
  // Per key: in-tangent, value, out-tangent. Value 1 at both keys, leaving with slope 2 and
  // arriving with slope -2: a bump.
  const std::vector<glm::dvec3> keys = {{0, 0, 0},  {0, 1, 0}, {0, 2, 0},
                                        {0, -2, 0}, {0, 1, 0}, {0, 0, 0}};
  const Sampler one = vec3_sampler(Interpolation::cubic_spline, {0, 1}, keys);
  // u = 1/2: h00 = 1/2, h10 = 1/8, h01 = 1/2, h11 = -1/8: 1/2 + 2/8 + 1/2 + 2/8 = 1.5.
  CHECK_NEAR3(host::sample_vec3(one, 0.5), glm::dvec3(0, 1.5, 0));
  // u = 1/4: h00 = 27/32, h10 = 9/64, h01 = 5/32, h11 = -3/64: 1.375.
  CHECK_NEAR3(host::sample_vec3(one, 0.25), glm::dvec3(0, 1.375, 0));
  // The same keys two seconds apart: the tangent terms double (27/32 + 2 (9/64) 2 + 5/32 +
  // 2 (3/64) 2 = 1.75 at u = 1/4).
  const Sampler two = vec3_sampler(Interpolation::cubic_spline, {0, 2}, keys);
  CHECK_NEAR3(host::sample_vec3(two, 0.5), glm::dvec3(0, 1.75, 0));
  // At and outside the keys: the values, never a tangent.
  CHECK_NEAR3(host::sample_vec3(two, 0.0), glm::dvec3(0, 1, 0));
  CHECK_NEAR3(host::sample_vec3(two, -1.0), glm::dvec3(0, 1, 0));
  CHECK_NEAR3(host::sample_vec3(two, 2.0), glm::dvec3(0, 1, 0));
  CHECK_NEAR3(host::sample_vec3(two, 5.0), glm::dvec3(0, 1, 0));
}

TEST_CASE(
    "a three-key cubic spline inside its second interval at u = 1/4 gives the Hermite sum worked "
    "by hand from unequal keys and tangents") {
  // glTF 2.0, Appendix C: between keys k and k+1, with d = t_k+1 - t_k,
  //   p(u) = (2u^3 - 3u^2 + 1) v_k + d (u^3 - 2u^2 + u) b_k + (-2u^3 + 3u^2) v_k+1
  //          + d (u^3 - u^2) a_k+1,
  // a the in-tangents and b the out-tangents. Keys at 0, 1 and 3 s; t = 1.5 s is u = 1/4 of the
  // second interval (d = 2): h00 = 27/32, h10 = 9/64, h01 = 5/32, h11 = -3/64, so
  //   p = (27 v_1 + 9 b_1 + 5 v_2 - 3 a_2) / 32      (the tangents' terms times d = 2).
  // v_1 = (2, -1, 4), b_1 = (1, 3, -2), a_2 = (-4, 2, 5), v_2 = (6, 3, -2):
  //   x: (54 + 9 + 30 + 12) / 32 = 105/32;  y: (-27 + 27 + 15 - 6) / 32 = 9/32;
  //   z: (108 - 18 - 10 - 15) / 32 = 65/32.
  // Key 0, key 1's in-tangent and key 2's out-tangent are decoys far from every answer: an
  // interval off by one or the wrong tangent of a key moves the result by tens.
  const std::vector<glm::dvec3> keys = {
      {50, 50, 50},  {-30, 20, 10}, {40, -60, 70},  // key 0: in, value, out
      {90, -80, 60}, {2, -1, 4},    {1, 3, -2},     // key 1
      {-4, 2, 5},    {6, 3, -2},    {-70, 80, 90},  // key 2
  };
  const Sampler s = vec3_sampler(Interpolation::cubic_spline, {0, 1, 3}, keys);
  CHECK_NEAR3(host::sample_vec3(s, 1.5), glm::dvec3(105.0 / 32, 9.0 / 32, 65.0 / 32));
  // u = 3/4 of the same interval (t = 2.5): h00 = 5/32, h10 = 3/64, h01 = 27/32, h11 = -9/64:
  //   p = (5 v_1 + 3 b_1 + 27 v_2 - 9 a_2) / 32 = ((10 + 3 + 162 + 36), (-5 + 9 + 81 - 18),
  //   (20 - 6 - 54 - 45)) / 32 = (211, 67, -85) / 32.
  CHECK_NEAR3(host::sample_vec3(s, 2.5), glm::dvec3(211.0 / 32, 67.0 / 32, -85.0 / 32));
  // On the middle key: its value, not a tangent.
  CHECK_NEAR3(host::sample_vec3(s, 1.0), glm::dvec3(2, -1, 4));
}

TEST_CASE("a rotation's cubic spline is the same Hermite sum of quaternions, normalised") {
  // Rotations about +Y only, (x, y, z, w) with x = z = 0. Keys at 0, 1 and 3 s; t = 1.5 s is
  // u = 1/4 of the second interval, p = (27 v_1 + 9 b_1 + 5 v_2 - 3 a_2) / 32 as above, with
  // v_1 = identity (0, 0, 0, 1), b_1 = (0, 2/3, 0, -1), a_2 = (0, 2/3, 0, -2/3) and
  // v_2 = (0, 0.6, 0, 0.8):
  //   y: (0 + 6 + 3 - 2) / 32 = 7/32;  w: (27 - 9 + 4 + 2) / 32 = 24/32;
  // length 25/32, so the unit result is (0, 0.28, 0, 0.96): cos(angle/2) = 0.96, a turn taking
  // +X to (1 - 2 (0.28)^2, 0, -2 (0.28) (0.96)) = (0.8432, 0, -0.5376).
  Sampler s;
  s.interpolation = Interpolation::cubic_spline;
  s.times = {0, 1, 3};
  s.values = {glm::dvec4(0.5, 0, 0, 0),
              glm::dvec4(0, 0, 0.6, 0.8),
              glm::dvec4(0, 0, 0, 3),
              glm::dvec4(0, 5, 0, 0),
              glm::dvec4(0, 0, 0, 1),
              glm::dvec4(0, 2.0 / 3, 0, -1),
              glm::dvec4(0, 2.0 / 3, 0, -2.0 / 3),
              glm::dvec4(0, 0.6, 0, 0.8),
              glm::dvec4(4, 0, 0, 0)};
  const glm::dquat q = host::sample_rotation(s, 1.5);
  CHECK(q.x == doctest::Approx(0.0).epsilon(1e-12));
  CHECK(q.y == doctest::Approx(0.28).epsilon(1e-12));
  CHECK(q.z == doctest::Approx(0.0).epsilon(1e-12));
  CHECK(q.w == doctest::Approx(0.96).epsilon(1e-12));
  CHECK_NEAR3(turn_x(q), glm::dvec3(0.8432, 0, -0.5376));
}

TEST_CASE("rotations are slerped the short way round and come out unit length") {
  const double pi = std::numbers::pi;
  const glm::dvec4 identity(0, 0, 0, 1);
  const glm::dvec4 quarter = axis_angle({0, 1, 0}, pi / 2);  // +X -> -Z
  Sampler s;
  s.interpolation = Interpolation::linear;
  s.times = {0, 1};
  s.values = {identity, quarter};
  // Halfway: an eighth of a turn about +Y, +X -> (cos 45, 0, -sin 45).
  const glm::dvec3 half(std::sqrt(0.5), 0, -std::sqrt(0.5));
  CHECK_NEAR3(turn_x(host::sample_rotation(s, 0.5)), half);
  // A third of the way: 30 degrees, not the chord's angle.
  CHECK_NEAR3(turn_x(host::sample_rotation(s, 1.0 / 3)),
              glm::dvec3(std::cos(pi / 6), 0, -std::sin(pi / 6)));
  // The same rotation stored as -q: the short way is still an eighth of a turn (the long way
  // would pass through 135 degrees the other way round).
  s.values = {identity, -quarter};
  CHECK_NEAR3(turn_x(host::sample_rotation(s, 0.5)), half);
  const glm::dquat q = host::slerp_short(host::to_quat(identity), host::to_quat(-quarter), 0.5);
  CHECK(std::abs(glm::length(q) - 1.0) < 1e-12);
  CHECK(std::abs(q.w) == doctest::Approx(std::cos(pi / 8)).epsilon(1e-12));
  // STEP and clamping hand back unit keys; a cubic spline's result is normalised.
  s.interpolation = Interpolation::step;
  s.values = {identity * 2.0, quarter * 3.0};
  CHECK(glm::length(host::sample_rotation(s, 0.5)) == doctest::Approx(1.0).epsilon(1e-12));
  CHECK_NEAR3(turn_x(host::sample_rotation(s, 7.0)), glm::dvec3(0, 0, -1));
  s.interpolation = Interpolation::cubic_spline;
  s.values = {glm::dvec4(0), identity, glm::dvec4(0), glm::dvec4(0), quarter, glm::dvec4(0)};
  const glm::dquat c = host::sample_rotation(s, 0.5);  // (identity + quarter) / 2, normalised
  CHECK(glm::length(c) == doctest::Approx(1.0).epsilon(1e-12));
  CHECK_NEAR3(turn_x(c), half);
}

TEST_CASE("a file's animations are listed by name and index with their time ranges") {
  const host::AnimatedScene a(data_path("animated.gltf"));
  REQUIRE(a.animations().size() == 2);
  CHECK(a.animations()[0].name == "move");
  CHECK(a.animations()[1].name == "bounce");
  CHECK(a.animations()[0].channels.size() == 3);
  CHECK(a.animations()[0].start == 0.0);
  CHECK(a.animations()[0].end == 3.0);
  CHECK(a.animations()[1].end == 1.0);
  CHECK(a.find("bounce") == size_t(1));
  CHECK(a.find("0") == size_t(0));
  CHECK(a.find("1") == size_t(1));
  CHECK_FALSE(a.find("2"));
  CHECK_FALSE(a.find("walk"));
  CHECK_FALSE(a.find(""));
  CHECK(a.rest().triangle_count() == 26);
}

TEST_CASE("a posed scene is the rest scene with each node's animated transform applied by hand") {
  const host::AnimatedScene a(data_path("animated.gltf"));
  const host::Scene& rest = a.rest();
  // The nodes' world matrices by hand: at rest the body sits at (0, 0.5, 0) and the head, its
  // child, 1 above it at half size.
  const glm::dmat4 I(1.0);
  const glm::dmat4 body_rest = glm::translate(I, {0, 0.5, 0});
  const glm::dmat4 head_local = glm::scale(glm::translate(I, {0, 1, 0}), glm::dvec3(0.5));
  // Triangles 0-1 are the floor, 2-13 the body, 14-25 the head.
  // Positions are stored in float: compare at float precision.
  auto near = [](const host::Scene& s, const host::Scene& t) {
    for (size_t i = 0; i < s.triangle_count(); ++i)
      if (glm::any(glm::epsilonNotEqual(s.p0[i], t.p0[i], 1e-5f))) return false;
    return true;
  };
  // t = 0: every channel before or on its first key, which the rest pose equals.
  const host::Scene zero = a.at(0, 0.0);
  CHECK(near(zero, rest));
  // t = 2 of "move": the body halfway from (0, 0.5, 0) to (2, 0.5, 0) and an eighth of a turn
  // about +Y; the head (STEP at 2 s) at a quarter size.
  const double pi = std::numbers::pi;
  const glm::dmat4 body2 = glm::rotate(glm::translate(I, {1, 0.5, 0}), pi / 4, {0, 1, 0});
  const glm::dmat4 head2 = body2 * glm::scale(glm::translate(I, {0, 1, 0}), glm::dvec3(0.25));
  const host::Scene two = a.at(0, 2.0);
  for (size_t i = 0; i < rest.triangle_count(); ++i) {
    CAPTURE(i);
    const glm::dmat4 m = i < 2    ? I
                         : i < 14 ? body2 * glm::inverse(body_rest)
                                  : head2 * glm::inverse(body_rest * head_local);
    CHECK(two.id[i] == rest.id[i]);
    const glm::vec3 want(m * glm::dvec4(glm::dvec3(rest.p0[i]), 1.0));
    CHECK_MESSAGE(glm::all(glm::epsilonEqual(two.p0[i], want, 1e-5f)),
                  str(glm::dvec3(two.p0[i])) << " != " << str(glm::dvec3(want)));
    const glm::vec3 want2(m * glm::dvec4(glm::dvec3(rest.p2[i]), 1.0));
    CHECK(glm::all(glm::epsilonEqual(two.p2[i], want2, 1e-5f)));
  }
  // Normals turn with the body: the floor's stay +Y, the body's +X face now faces (1, 0, -1),
  // every body and head normal the rest one turned an eighth about +Y (the scale is uniform).
  CHECK(glm::all(glm::epsilonEqual(two.n0[0], glm::vec3(0, 1, 0), 1e-6f)));
  const glm::dmat4 turn = glm::rotate(I, pi / 4, {0, 1, 0});
  int plus_x = 0;
  for (size_t i = 2; i < rest.triangle_count(); ++i) {
    CAPTURE(i);
    for (const auto& [posed, at_rest] :
         {std::pair{two.n0[i], rest.n0[i]}, std::pair{two.n1[i], rest.n1[i]},
          std::pair{two.n2[i], rest.n2[i]}}) {
      const glm::vec3 want(turn * glm::dvec4(glm::dvec3(at_rest), 0.0));
      CHECK(glm::all(glm::epsilonEqual(posed, want, 1e-6f)));
    }
    if (rest.n0[i] == glm::vec3(1, 0, 0)) {
      ++plus_x;
      CHECK(glm::all(
          glm::epsilonEqual(two.n0[i], glm::vec3(std::sqrt(0.5f), 0, -std::sqrt(0.5f)), 1e-6f)));
    }
  }
  CHECK(plus_x == 4);  // two triangles of the body's +X face and two of the head's
  // Past the last key: clamped, the same as at the last key.
  CHECK(near(a.at(0, 3.0), a.at(0, 50.0)));
  CHECK_FALSE(near(a.at(0, 3.0), two));
  // "bounce" moves the head only: up to 1.5 above the body at 0.5 s (the spline's bump).
  const host::Scene bump = a.at(1, 0.5);
  const glm::dmat4 head_bump =
      body_rest * glm::scale(glm::translate(I, {0, 1.5, 0}), glm::dvec3(0.5));
  for (size_t i = 14; i < 26; ++i) {
    const glm::vec3 want(head_bump * glm::inverse(body_rest * head_local) *
                         glm::dvec4(glm::dvec3(rest.p1[i]), 1.0));
    CHECK(glm::all(glm::epsilonEqual(bump.p1[i], want, 1e-5f)));
  }
  for (size_t i = 0; i < 14; ++i) CHECK(bump.p1[i] == rest.p1[i]);
  // The camera and the light are not animated; no animation at all is the rest scene.
  REQUIRE(two.camera);
  CHECK(two.camera->position == rest.camera->position);
  CHECK(two.lights.size() == 1);
  CHECK(two.lights[0].position == rest.lights[0].position);
  CHECK(near(a.at(std::nullopt, 2.0), rest));
}

TEST_CASE(
    "a file's normals are posed by the inverse transpose of the node's matrix: turned and "
    "stretched, they lean as by hand") {
  // tests/data/gltf/animated_normals.gltf: a quad in z = 0 with normals leaning away from +Z; at
  // 1 s its node is turned an eighth about +Z (halfway along a LINEAR quarter turn) and stretched
  // to scale (2, 1, 1). Points go by M = R S; normals by (M^-1)^T = R S^-1: a normal (a, b, c)
  // becomes R (a/2, b, c), normalised. Taking M itself would give R (2a, b, c).
  const host::AnimatedScene a(data_path("animated_normals.gltf"));
  const host::Scene& rest = a.rest();
  REQUIRE(rest.triangle_count() == 2);
  const host::Scene posed = a.at(0, 1.0);
  const double pi = std::numbers::pi;
  const glm::dmat3 r(glm::rotate(glm::dmat4(1.0), pi / 4, {0, 0, 1}));
  const glm::dmat3 s_inv(glm::scale(glm::dmat4(1.0), glm::dvec3(0.5, 1, 1)));
  for (size_t i = 0; i < 2; ++i) {
    CAPTURE(i);
    for (const auto& [bound_p, bound_n] :
         {std::pair{posed.n0[i], rest.n0[i]}, std::pair{posed.n1[i], rest.n1[i]},
          std::pair{posed.n2[i], rest.n2[i]}}) {
      // Named copies: clang 14 cannot capture a structured binding (CAPTURE, INFO).
      const auto& p = bound_p;
      const auto& n = bound_n;
      const glm::vec3 want(glm::normalize(r * (s_inv * glm::dvec3(n))));
      CHECK_MESSAGE(glm::all(glm::epsilonEqual(p, want, 1e-6f)),
                    str(glm::dvec3(p)) << " != " << str(glm::dvec3(want)));
    }
  }
  // One corner in numbers: (-0.6, 0, 0.8) -> (-0.3, 0, 0.8) / sqrt(0.73), turned 45 degrees:
  // (-0.3 / sqrt(2), -0.3 / sqrt(2), 0.8) / sqrt(0.73) = (-0.248282, -0.248282, 0.936329).
  REQUIRE(rest.n0[0] == glm::vec3(-0.6f, 0, 0.8f));
  CHECK(glm::all(
      glm::epsilonEqual(posed.n0[0], glm::vec3(-0.248282f, -0.248282f, 0.936329f), 2e-6f)));
}

TEST_CASE("skinned meshes and morph-target weights are refused with one line naming the feature") {
  const std::string skinned = data_path("skinned.gltf"), morph = data_path("morph_weights.gltf");
  const host::AnimatedScene s(skinned);
  auto message = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const host::UnsupportedFeature& e) {
      return e.what();
    }
    return "";
  };
  const std::string skin_line = message([&] { s.at(0, 0.5); });
  CHECK(skin_line == skinned + ": node 0 uses skin 0; skinned meshes are not supported");
  CHECK(message([&] { s.check(std::nullopt); }) == skin_line);
  const host::AnimatedScene m(morph);
  CHECK(message([&] { m.at(0, 0.5); }) ==
        morph +
            ": animation 0 channel 0 animates morph-target weights (node 0); morph targets are "
            "not supported");
  CHECK(message([&] { m.check(std::nullopt); }).empty());  // the rest pose is the file's
  // A channel of an extension's path, without a node, is refused too, not skipped.
  const std::string pointer = data_path("animation_pointer.gltf");
  const host::AnimatedScene ptr(pointer);
  CHECK(message([&] { ptr.at(0, 0.5); }) ==
        pointer + ": animation 0 channel 0 animates 'pointer', which is not supported");
  // The static loader still reads both as before.
  CHECK(host::load_scene(skinned).triangle_count() == 1);
  CHECK(host::load_scene(morph).triangle_count() == 1);
}

TEST_CASE("key times that do not increase are refused, naming the sampler and the key") {
  const std::string path = data_path("animation_times_back.gltf");
  std::string message;
  try {
    host::AnimatedScene a(path);
  } catch (const host::InputError& e) {
    message = e.what();
  }
  CHECK(message == path +
                       ": animation 0 sampler 0: key times must increase strictly (key 2 at "
                       "1.000000 s follows 2.000000 s)");
  CHECK(host::load_scene(path).triangle_count() == 1);  // a static load ignores animations
}

// ---- every animation of a file played together (issue 34)

namespace {

// Two scenes with the same triangles, corners and normals, bit for bit.
void check_same_triangles(const host::Scene& s, const host::Scene& t) {
  REQUIRE(s.triangle_count() == t.triangle_count());
  for (size_t i = 0; i < s.triangle_count(); ++i) {
    CAPTURE(i);
    CHECK(s.id[i] == t.id[i]);
    CHECK(s.p0[i] == t.p0[i]);
    CHECK(s.p1[i] == t.p1[i]);
    CHECK(s.p2[i] == t.p2[i]);
    CHECK(s.n0[i] == t.n0[i]);
    CHECK(s.n1[i] == t.n1[i]);
    CHECK(s.n2[i] == t.n2[i]);
  }
}

}  // namespace

TEST_CASE("a parent's and a child's animations play together as the scene posed by hand") {
  // two_animations.gltf (make_cases.py): "rise" moves the outer cube (node 1) up from 0.5 to 1.5
  // over 0-2 s; "spin" turns its child, the inner cube (node 2), about +X from an eighth of a
  // turn (45 degrees) at 1 s to a half turn (180) at 3 s. The _at_1s and _at_3s files are the same
  // scene without animations, its two nodes' transforms set by hand to the values worked out there.
  const host::AnimatedScene a(data_path("two_animations.gltf"));
  REQUIRE(a.animations().size() == 2);
  CHECK(a.all() == std::vector<size_t>{0, 1});
  CHECK(a.clash(a.all()).empty());
  CHECK(a.span(a.all()) == std::pair<double, double>{0.0, 3.0});
  CHECK(a.span({1}) == std::pair<double, double>{1.0, 3.0});
  const host::Scene at1 = host::load_scene(data_path("two_animations_at_1s.gltf"));
  const host::Scene at3 = host::load_scene(data_path("two_animations_at_3s.gltf"));
  check_same_triangles(a.at(a.all(), 1.0), at1);
  check_same_triangles(a.at(a.all(), 3.0), at3);
  check_same_triangles(a.at(a.all(), 7.0), at3);  // past every key: the last keys hold
  // Either animation alone moves one cube: the other stays as the file has it. The inner cube's
  // triangles (14-25) follow "rise" too (it is the outer's child), but do not turn: triangle 18,
  // on the inner cube's -Y face, keeps its normal (a turn about +X moves it).
  const host::Scene rise_only = a.at(size_t(0), 1.0), spin_only = a.at(size_t(1), 1.0);
  const host::Scene& rest = a.rest();
  CHECK(rise_only.p0[2] == at1.p0[2]);     // the outer cube where "rise" puts it
  CHECK(rise_only.n0[18] == rest.n0[18]);  // the inner cube not turned
  CHECK(rise_only.n0[18] != at1.n0[18]);
  CHECK(spin_only.p0[2] == rest.p0[2]);  // the outer cube at rest
  CHECK(spin_only.n0[18] != rest.n0[18]);
  // Halfway through "spin" (2 s, u = 1/2): halfway from 45 to 180 degrees, 112.5 degrees about
  // +X, with the outer cube at the top (1.5, "rise" ended at 2 s). Slerp is not exact in
  // floats: compare the corners and normals with the hand-made matrices at float precision.
  const double pi = std::numbers::pi;
  const glm::dmat4 I(1.0);
  const glm::dmat4 outer = glm::translate(I, {0, 1.5, 0});
  const glm::dmat4 inner_local = glm::scale(
      glm::rotate(glm::translate(I, {0, 1.25, 0}), 5 * pi / 8, {1, 0, 0}), glm::dvec3(0.5));
  const glm::dmat4 inner_rest_world =
      glm::translate(I, {0, 0.5, 0}) * glm::scale(glm::translate(I, {0, 1.25, 0}), glm::dvec3(0.5));
  const host::Scene two = a.at(a.all(), 2.0);
  for (size_t i = 2; i < 26; ++i) {
    CAPTURE(i);
    const glm::dmat4 m = i < 14 ? outer * glm::inverse(glm::translate(I, {0, 0.5, 0}))
                                : outer * inner_local * glm::inverse(inner_rest_world);
    const glm::vec3 want(m * glm::dvec4(glm::dvec3(rest.p0[i]), 1.0));
    CHECK_MESSAGE(glm::all(glm::epsilonEqual(two.p0[i], want, 1e-5f)),
                  str(glm::dvec3(two.p0[i])) << " != " << str(glm::dvec3(want)));
    // Normals by the rotation alone (the scales are uniform).
    const glm::dmat3 turn =
        i < 14 ? glm::dmat3(1.0) : glm::dmat3(glm::rotate(I, 5 * pi / 8, {1, 0, 0}));
    const glm::vec3 n(glm::normalize(turn * glm::dvec3(rest.n0[i])));
    CHECK(glm::all(glm::epsilonEqual(two.n0[i], n, 1e-6f)));
  }
}

TEST_CASE("two animations of one node's path cannot play together and are refused by name") {
  const std::string path = data_path("animations_clash.gltf");
  const host::AnimatedScene a(path);
  const std::string why = "animations 0 'left' and 1 'right' both drive node 0 translation";
  CHECK(a.clash(a.all()) == why);
  CHECK(a.clash({1}).empty());
  std::string message;
  try {
    a.at(a.all(), 0.5);
  } catch (const host::InputError& e) {
    message = e.what();
  }
  CHECK(message == path + ": " + why);
  CHECK(a.at(size_t(1), 1.0).p0[0].x == 1.0f);  // "right" alone plays
}
