// The camera contract: how a pixel becomes a primary ray direction, and the automatic framing
// used when a file has no camera. The ray-generation kernel and the CPU reference follow
// primary_dir() exactly.
#pragma once

#include <glm/glm.hpp>

#include "host/scene/scene.h"

namespace host {

// Automatic framing, all in world space:
//   centre c = (lo + hi) / 2, radius r = 1.05 * |hi - lo| / 2 (the box's bounding sphere plus a
//   5% margin; r = 1 for empty or zero-size bounds, c = 0 for empty bounds);
//   view direction d = normalize(0, 0.35, 1): the camera sits at c + dist * d, forward = -d;
//   yfov = 45 degrees; dist = max(r / sin(yfov / 2), r / sin(hfov / 2)) with
//   tan(hfov / 2) = aspect * tan(yfov / 2), the distance where the sphere is tangent to the
//   view frustum both vertically and horizontally;
//   up = +Y made orthogonal to forward.
// A non-positive or non-finite aspect counts as 1.
Camera frame_bounds(const Bounds& b, float aspect);

// The camera a render of `scene` uses: the file's own, else frame_bounds() of its bounds.
Camera scene_camera(const Scene& scene, float aspect = 1.0f);

// The primary ray direction (world space, unit) through pixel (x, y) of a W x H image; the top
// row is y = 0 and the ray passes through the pixel centre (x + 0.5, y + 0.5):
//   right = normalize(cross(forward, up)); t = tan(yfov / 2); a = W / H;
//   dir = normalize(forward + ((2 (x + 0.5) / W - 1) t a) right + ((1 - 2 (y + 0.5) / H) t) up)
glm::vec3 primary_dir(const Camera& cam, int W, int H, float x, float y);

}  // namespace host
