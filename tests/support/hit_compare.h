// Two renders' primary hit ids compared pixel by pixel, for tests that hold one walk against
// another. Two walks may disagree on a pixel only at a tie: a ray through an edge two triangles
// share (or a vertex) meets both at the same t, and either answer is right.
#pragma once

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <string>

#include "host/scene/camera.h"
#include "host/scene/scene.h"
#include "host/trace/cpu/cpu_tracer.h"
#include "host/trace/render_options.h"

namespace test_support {

// Moller-Trumbore in double, no culling, edges widened by 1e-4 (the tie looked for is a shared
// edge): the parameter t of the ray's hit on internal triangle i, or infinity.
inline double hit_t(const host::Scene& s, size_t i, glm::dvec3 o, glm::dvec3 d) {
  const glm::dvec3 p0(s.p0[i]), e1 = glm::dvec3(s.p1[i]) - p0, e2 = glm::dvec3(s.p2[i]) - p0;
  const glm::dvec3 p = glm::cross(d, e2);
  const double det = glm::dot(e1, p);
  if (det == 0) return INFINITY;
  const glm::dvec3 q = glm::cross(o - p0, e1);
  const double u = glm::dot(o - p0, p) / det, v = glm::dot(d, q) / det;
  const double eps = 1e-4;
  if (u < -eps || v < -eps || u + v > 1 + eps) return INFINITY;
  return glm::dot(e2, q) / det;
}

// The internal index of the triangle whose input id a hit buffer holds.
inline size_t internal_of(const host::Scene& s, float input_id) {
  for (size_t i = 0; i < s.id.size(); ++i)
    if (float(s.id[i]) == input_id) return i;
  FAIL("no triangle with input id " << input_id);
  return 0;
}

// Pixels whose ids differ, and of those the ties (both hit, at depths within 1e-5 relative: the
// same point on two triangles); coverage (hit or miss) differences apart.
struct IdDiff {
  int differ = 0, ties = 0, coverage = 0;
  std::string first;  // the first difference that is no tie
};

inline IdDiff compare_ids(const host::RenderResult& a, const host::RenderResult& b) {
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
inline int check_ties(const IdDiff& d) {
  CHECK(d.coverage == 0);
  CHECK_MESSAGE(d.differ == d.ties, "a difference that is no tie: ", d.first);
  return d.ties;
}

// Each pixel whose primary ids differ checked in double: both triangles met at the same t
// (relative 1e-5) by the pixel's ray.
inline void check_ties_in_double(const host::Scene& s, const host::Camera& cam, int w, int h,
                                 const host::RenderResult& a, const host::RenderResult& b) {
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * size_t(w) + size_t(x);
      if (a.hit_id[i] == b.hit_id[i] || a.hit_id[i] < 0 || b.hit_id[i] < 0) continue;
      INFO("pixel (" << x << ", " << y << "): " << a.hit_id[i] << " vs " << b.hit_id[i]);
      const glm::dvec3 o(cam.position), d = host::cpu_primary_dir(cam, w, h, x, y);
      const double ta = hit_t(s, internal_of(s, a.hit_id[i]), o, d);
      const double tb = hit_t(s, internal_of(s, b.hit_id[i]), o, d);
      CHECK(std::isfinite(ta));
      CHECK(std::isfinite(tb));
      CHECK(std::abs(ta - tb) <= 1e-5 * std::max(ta, tb));
    }
}

}  // namespace test_support
