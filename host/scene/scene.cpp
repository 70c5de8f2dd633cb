// The scene's padded box (scene.h), the one place the padding rule lives, and its host bytes.
#include "host/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

namespace host {

namespace {

// The float nearest to x, rounded toward -inf (down) or +inf (up): the box never shrinks when
// its double corners are stored as floats.
float round_float(double x, bool up) {
  float f = float(x);
  if (up && double(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  if (!up && double(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}

}  // namespace

uint64_t Scene::host_bytes() const {
  auto bytes = [](const auto& v) {
    return uint64_t(v.size()) * sizeof(typename std::decay_t<decltype(v)>::value_type);
  };
  uint64_t b = bytes(p0) + bytes(p1) + bytes(p2) + bytes(n0) + bytes(n1) + bytes(n2) +
               bytes(material) + bytes(id) + bytes(materials) + bytes(uv0) + bytes(uv1) +
               bytes(uv2) + bytes(textures) + bytes(lights);
  for (const SceneTexture& t : textures) b += bytes(t.texels);
  return b;
}

Bounds Scene::box() const {
  const Bounds b = bounds();
  Bounds box;
  box.lo = glm::vec3(-1.0f);  // no triangles: any box will do
  box.hi = glm::vec3(1.0f);
  if (b.empty()) return box;
  const glm::dvec3 blo(b.lo), bhi(b.hi);
  const glm::dvec3 mag = glm::max(glm::abs(blo), glm::abs(bhi));
  const double pad = std::max(kScenePadRelative * glm::length(bhi - blo),
                              kScenePadMagnitude * std::max({mag.x, mag.y, mag.z}));
  for (int a = 0; a < 3; ++a) {
    box.lo[a] = round_float(blo[a] - pad, false);
    box.hi[a] = round_float(bhi[a] + pad, true);
  }
  return box;
}

}  // namespace host
