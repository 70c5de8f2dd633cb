// The scene's padded box (scene.h), the one place the padding rule lives, and its host bytes.
#include "host/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "host/common/memory.h"

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
  uint64_t b = 0;
  for (const auto* v : {&p0, &p1, &p2, &n0, &n1, &n2}) b += vector_bytes(*v);
  for (const auto* v : {&uv0, &uv1, &uv2}) b += vector_bytes(*v);
  b += vector_bytes(material) + vector_bytes(id) + vector_bytes(materials) +
       vector_bytes(textures) + vector_bytes(lights);
  for (const SceneTexture& t : textures) b += vector_bytes(t.texels);
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
