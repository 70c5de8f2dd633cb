// Independent references for tests: the voxels a ray crosses (plane crossings sorted, no DDA) and
// brute-force ray/triangle hits over every triangle (no grid), all in double precision.
#pragma once

#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <utility>
#include <vector>

#include "host/accel/grid.h"
#include "host/scene/scene.h"

namespace host {

// The voxels the ray origin + t·dir, t ≥ 0, passes through, in order, computed without a DDA:
// clip to the grid box [boundary(a, 0), boundary(a, res)] (slab test), collect every t where the
// ray crosses an interior voxel plane, sort, and take the voxel holding the midpoint of each
// interval of positive length (Grid::voxel_of). Consequences at the edges:
//  - a ray through a voxel edge or corner crosses two or three planes at the same t; the
//    zero-length intervals are skipped, so it goes diagonally (a DDA may add one neighbour);
//  - a ray lying in a voxel plane walks the voxels on its + side (voxel_of is half-open), or the
//    inner voxels when the plane is the grid's outer face;
//  - a ray starting inside the grid starts in the voxel holding its origin;
//  - a miss, a zero direction, or a ray that only grazes the box at one point gives an empty list.
std::vector<glm::ivec3> voxel_walk_reference(const Grid& grid, glm::dvec3 origin, glm::dvec3 dir);

// Where the line e + t d enters and leaves the box [lo, hi], by the slab test in double: {t_in,
// t_out} (t_in > t_out where the line misses it).
std::pair<double, double> box_interval(glm::dvec3 e, glm::dvec3 d, glm::dvec3 lo, glm::dvec3 hi);

struct RefHit {
  int64_t tri = -1;     // internal triangle index, -1 = miss
  double t = 0;         // ray parameter, in units of |dir|
  double u = 0, v = 0;  // barycentrics: hit = (1-u-v)·p0 + u·p1 + v·p2
};

// Nearest hit with t > tmin over every triangle: Möller–Trumbore in double, two-sided, closed
// triangles (edges included); ties in t go to the lowest internal index.
RefHit brute_force_hit(const Scene& scene, glm::dvec3 origin, glm::dvec3 dir, double tmin = 0);

// brute_force_hit (tmin = 0) for every pixel, row-major (index y·W + x), over std::threads.
// dir_of_pixel is called concurrently and must be thread-safe. Same result for any thread count.
std::vector<RefHit> brute_force_image(const Scene& scene,
                                      const std::function<glm::dvec3(int x, int y)>& dir_of_pixel,
                                      glm::dvec3 origin, int W, int H);

}  // namespace host
