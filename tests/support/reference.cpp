// Test references (see reference.h): voxel walks from sorted plane crossings and brute-force
// ray/triangle intersection in double precision.
#include "tests/support/reference.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>

#include "host/common/parallel.h"

namespace host {

std::vector<glm::ivec3> voxel_walk_reference(const Grid& grid, glm::dvec3 origin, glm::dvec3 dir) {
  std::vector<glm::ivec3> walk;
  if (dir == glm::dvec3(0.0)) return walk;

  // Slab test against the grid box.
  double t_enter = 0.0, t_exit = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    const double lo = grid.boundary(a, 0), hi = grid.boundary(a, grid.res[a]);
    if (dir[a] == 0.0) {
      if (origin[a] < lo || origin[a] > hi) return walk;
      continue;
    }
    double t0 = (lo - origin[a]) / dir[a], t1 = (hi - origin[a]) / dir[a];
    if (t0 > t1) std::swap(t0, t1);
    t_enter = std::max(t_enter, t0);
    t_exit = std::min(t_exit, t1);
  }
  if (!(t_enter < t_exit)) return walk;

  // Every interior plane crossing strictly inside (t_enter, t_exit).
  std::vector<double> ts{t_enter, t_exit};
  for (int a = 0; a < 3; ++a) {
    if (dir[a] == 0.0) continue;
    for (int i = 1; i < grid.res[a]; ++i) {
      const double t = (grid.boundary(a, i) - origin[a]) / dir[a];
      if (t > t_enter && t < t_exit) ts.push_back(t);
    }
  }
  std::sort(ts.begin(), ts.end());
  for (size_t k = 0; k + 1 < ts.size(); ++k) {
    if (!(ts[k + 1] > ts[k])) continue;  // edge or corner: zero-length interval
    const glm::ivec3 v = grid.voxel_of(origin + dir * (0.5 * (ts[k] + ts[k + 1])));
    if (walk.empty() || walk.back() != v) walk.push_back(v);
  }
  return walk;
}

RefHit brute_force_hit(const Scene& scene, glm::dvec3 origin, glm::dvec3 dir, double tmin) {
  RefHit best;
  best.t = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < scene.triangle_count(); ++i) {
    const glm::dvec3 p0(scene.p0[i]), p1(scene.p1[i]), p2(scene.p2[i]);
    const glm::dvec3 e1 = p1 - p0, e2 = p2 - p0;
    const glm::dvec3 pv = glm::cross(dir, e2);
    const double det = glm::dot(e1, pv);
    if (det == 0.0) continue;  // ray parallel to the triangle's plane
    const double inv = 1.0 / det;
    const glm::dvec3 s = origin - p0;
    const double u = glm::dot(s, pv) * inv;
    if (u < 0.0 || u > 1.0) continue;
    const glm::dvec3 q = glm::cross(s, e1);
    const double v = glm::dot(dir, q) * inv;
    if (v < 0.0 || u + v > 1.0) continue;
    const double t = glm::dot(e2, q) * inv;
    if (t > tmin && t < best.t) best = RefHit{int64_t(i), t, u, v};  // strict: lowest index wins
  }
  if (best.tri < 0) best = RefHit{};
  return best;
}

std::vector<RefHit> brute_force_image(const Scene& scene,
                                      const std::function<glm::dvec3(int x, int y)>& dir_of_pixel,
                                      glm::dvec3 origin, int W, int H) {
  std::vector<RefHit> image(size_t(std::max(W, 0)) * size_t(std::max(H, 0)));
  if (image.empty()) return image;
  // Every pixel is independent, so the order in which rows are handed out does not matter.
  for_each_row(H, std::max(1u, std::thread::hardware_concurrency()), [&](unsigned, int y) {
    for (int x = 0; x < W; ++x)
      image[size_t(y) * W + x] = brute_force_hit(scene, origin, dir_of_pixel(x, y));
  });
  return image;
}

std::pair<double, double> box_interval(glm::dvec3 e, glm::dvec3 d, glm::dvec3 lo, glm::dvec3 hi) {
  double tn = -1e300, tf = 1e300;
  for (int a = 0; a < 3; ++a) {
    const double t0 = (lo[a] - e[a]) / d[a], t1 = (hi[a] - e[a]) / d[a];
    tn = std::max(tn, std::min(t0, t1));
    tf = std::min(tf, std::max(t0, t1));
  }
  return {tn, tf};
}

}  // namespace host
