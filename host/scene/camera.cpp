// The camera contract (see camera.h): automatic framing and primary ray directions.
#include "host/scene/camera.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace host {

Camera frame_bounds(const Bounds& b, float aspect) {
  if (!(aspect > 0.0f) || !std::isfinite(aspect)) aspect = 1.0f;
  glm::vec3 centre(0.0f);
  float radius = 1.0f;
  if (!b.empty()) {
    centre = (b.lo + b.hi) * 0.5f;
    const float half_diagonal = glm::length(b.hi - b.lo) * 0.5f;
    if (half_diagonal > 0.0f && std::isfinite(half_diagonal)) radius = half_diagonal;
  }
  radius *= 1.05f;

  Camera cam;
  cam.yfov = 45.0f * std::numbers::pi_v<float> / 180.0f;
  const float tan_half_y = std::tan(cam.yfov * 0.5f);
  const float half_x = std::atan(tan_half_y * aspect);
  const float distance = std::max(radius / std::sin(cam.yfov * 0.5f), radius / std::sin(half_x));
  const glm::vec3 d = glm::normalize(glm::vec3(0.0f, 0.35f, 1.0f));
  cam.position = centre + distance * d;
  cam.forward = -d;
  const glm::vec3 y(0.0f, 1.0f, 0.0f);
  cam.up = glm::normalize(y - glm::dot(y, cam.forward) * cam.forward);
  return cam;
}

Camera scene_camera(const Scene& scene, float aspect) {
  return scene.camera ? *scene.camera : frame_bounds(scene.bounds(), aspect);
}

glm::vec3 primary_dir(const Camera& cam, int W, int H, float x, float y) {
  const glm::vec3 right = glm::normalize(glm::cross(cam.forward, cam.up));
  const float t = std::tan(cam.yfov / 2.0f);
  const float a = float(W) / float(H);
  const float sx = (2.0f * (x + 0.5f) / float(W) - 1.0f) * t * a;
  const float sy = (1.0f - 2.0f * (y + 0.5f) / float(H)) * t;
  return glm::normalize(cam.forward + sx * right + sy * cam.up);
}

}  // namespace host
