// Dielectric optics in double precision, as docs/studies/materials.md ("Glass: the model") fixes
// them: the exact Fresnel reflectance of unpolarised light, total internal reflection past the
// critical angle, and the refracted direction. The CPU reference tracer's glass uses them; so do
// its tests.
#pragma once

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>

namespace host::optics {

// One ray meeting one interface. e = η₁/η₂, the index on the ray's side over the index beyond
// (entering glass of index η from air: 1/η; leaving it: η). Angles are against the normal.
struct Interface {
  double cos_i = 1.0;      // cos θᵢ, in [0, 1]
  double cos_t = 1.0;      // cos θₜ of the refracted ray; 0 under total internal reflection
  bool total = false;      // total internal reflection: sin²θₜ = e²(1 − cos²θᵢ) ≥ 1
  double reflectance = 0;  // F: the reflected share of unpolarised light, 1 when total
};

// The interface for incidence cosine cos_i (clamped to [0, 1]) and ratio e.
inline Interface meet(double cos_i, double e) {
  Interface f;
  f.cos_i = std::clamp(cos_i, 0.0, 1.0);
  const double sin2_t = e * e * (1.0 - f.cos_i * f.cos_i);
  if (sin2_t >= 1.0) {
    f.total = true;
    f.cos_t = 0.0;
    f.reflectance = 1.0;
    return f;
  }
  f.cos_t = std::sqrt(1.0 - sin2_t);
  const double ci = f.cos_i, ct = f.cos_t;
  const double rs = (e * ci - ct) / (e * ci + ct);  // s (perpendicular) amplitude ratio
  const double rp = (ci - e * ct) / (ci + e * ct);  // p (parallel) amplitude ratio
  f.reflectance = 0.5 * (rs * rs + rp * rp);
  return f;
}

// The same for the unit direction d and the unit normal n turned to face the ray (dot(n, d) ≤ 0).
inline Interface meet(const glm::dvec3& d, const glm::dvec3& n, double e) {
  return meet(-glm::dot(d, n), e);
}

// F = ((η − 1)/(η + 1))², the reflectance at normal incidence (from either side).
inline double normal_reflectance(double eta) {
  const double r = (eta - 1.0) / (eta + 1.0);
  return r * r;
}

// The critical angle (radians) leaving a medium with ratio e > 1: sin θc = 1/e. Past it, every
// ray is totally reflected.
inline double critical_angle(double e) {
  return std::asin(1.0 / e);
}

// The mirror direction of d about n: d − 2 (d·n) n.
inline glm::dvec3 reflect(const glm::dvec3& d, const glm::dvec3& n) {
  return d - 2.0 * glm::dot(d, n) * n;
}

// The refracted direction e d + (e cos θᵢ − cos θₜ) n, normalised (unit d and n give a unit
// vector up to rounding), for an interface that is not total.
inline glm::dvec3 refract(const glm::dvec3& d, const glm::dvec3& n, double e, const Interface& f) {
  return glm::normalize(e * d + (e * f.cos_i - f.cos_t) * n);
}

}  // namespace host::optics
