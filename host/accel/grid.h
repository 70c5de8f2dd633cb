// The paper's static uniform grid ("grilla uniforme"), built offline on the host: the world box
// cut into res.x × res.y × res.z voxels, each listing the triangles that overlap it. The texture
// uploader turns it into the voxel-pointer and voxel-triangle-list textures; the DDA walks it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <string>
#include <vector>

#include "host/scene/scene.h"

namespace host {

// Grid resolution as asked on the command line: "auto", "N" (N×N×N) or "AxBxC".
struct GridSpec {
  glm::ivec3 res{0};  // voxels per axis; all zero means automatic
  bool automatic() const { return res.x == 0; }
};

// Largest accepted voxel count per axis (512³ voxels = 512 MiB of CSR offsets).
inline constexpr int kMaxGridRes = 512;

// Parses "auto", "N" or "AxBxC" (also "AXBXC"): positive decimal integers, each ≤ kMaxGridRes, no
// signs or spaces. Throws std::invalid_argument naming the text and the problem.
GridSpec parse_grid_spec(const std::string& text);

// The automatic resolution aims at kGridDensity voxels per triangle. 4 is the paper's own Fig. 1
// (848 faces in a 15×15×15 grid = 3.98 voxels per face); provisional until tuned by render time.
inline constexpr double kGridDensity = 4.0;
inline constexpr int kMaxAutoGridRes = 128;

// cells ≈ density × triangles with cubic voxels following the bounds' aspect ratio:
// res_i = round(extent_i · cbrt(density·N / volume)), clamped to [1, kMaxAutoGridRes].
// An axis whose share would be under one voxel (a flat or thin scene) is given 1 voxel and the
// budget is spread over the other axes (square root for two axes, the whole budget for one), so a
// flat scene still gets ≈ density·N voxels. Empty bounds or no triangles give 1×1×1.
glm::ivec3 auto_resolution(const Bounds& bounds, size_t triangles, double density = kGridDensity);

struct Grid {
  glm::vec3 lo{0.0f}, hi{0.0f};  // world space, the padded scene box (Scene::box())
  glm::ivec3 res{1};             // voxels per axis
  glm::vec3 cell{0.0f};          // world size of one voxel: (hi - lo) / res, in float
  // CSR: voxel v lists tris[start[v] .. start[v+1]), internal triangle indices into the Scene
  // arrays, ascending. start.size() == voxels() + 1.
  std::vector<uint32_t> start;
  std::vector<uint32_t> tris;
  double build_ms = 0.0;  // wall time of build_grid

  size_t voxels() const { return size_t(res.x) * size_t(res.y) * size_t(res.z); }
  // Voxel layout: x fastest, then y, then z:  index = (z·res.y + y)·res.x + x.
  size_t index(int x, int y, int z) const {
    return (size_t(z) * size_t(res.y) + size_t(y)) * size_t(res.x) + size_t(x);
  }
  size_t index(glm::ivec3 v) const { return index(v.x, v.y, v.z); }
  uint64_t references() const { return tris.size(); }
  size_t memory_bytes() const { return (start.size() + tris.size()) * sizeof(uint32_t); }
  std::span<const uint32_t> triangles_in(size_t voxel) const {
    return {tris.data() + start[voxel], tris.data() + start[voxel + 1]};
  }

  // The i-th voxel boundary plane along `axis` (0 = x), world space: lo + i·cell evaluated in
  // double from the float fields (the product is exact). boundary(a, 0) == lo[a]; boundary(a,
  // res[a]) equals hi[a] up to float rounding of cell. Voxel i along an axis is the closed slab
  // [boundary(i), boundary(i+1)].
  double boundary(int axis, int i) const {
    return double(lo[axis]) + double(i) * double(cell[axis]);
  }
  // The voxel containing world point p, half-open [boundary(i), boundary(i+1)) per axis, clamped
  // to the grid (points outside go to the nearest voxel; the last voxel's upper face belongs to
  // it).
  glm::ivec3 voxel_of(glm::dvec3 p) const;
  // Closed world-space box of voxel v.
  void voxel_box(glm::ivec3 v, glm::dvec3& box_lo, glm::dvec3& box_hi) const;
};

// Builds the grid over the scene's padded box (Scene::box()): a triangle goes in every voxel it
// actually overlaps (closed boxes, so a triangle lying exactly in a voxel face is listed in both
// voxels sharing it). Candidates come from the triangle's bounding box narrowed column by column by
// its plane; each candidate is decided by triangle_box_overlap. Multi-threaded over contiguous
// triangle ranges merged in order, so the result is identical for any thread count. `threads` = 0
// means hardware concurrency. Throws std::invalid_argument for a resolution outside [1,
// kMaxGridRes], std::length_error if the references overflow 32 bits.
Grid build_grid(const Scene& scene, const GridSpec& spec, unsigned threads = 0);

// The same over a given world box [lo, hi] (hi > lo on every axis) and resolution, unpadded:
// build_grid calls this with the scene's box. Parts of triangles outside the box are
// ignored (a triangle is listed only in voxels it overlaps). Tests use it to put voxel planes at
// known coordinates.
Grid build_grid_in_box(const Scene& scene, glm::vec3 lo, glm::vec3 hi, glm::ivec3 res,
                       unsigned threads = 0);

// Akenine-Möller's separating-axis triangle/box test (13 axes: 3 box faces, the triangle normal,
// 9 edge × axis cross products) in double, with closed boxes: touching counts as overlap. The
// box-face axes compare coordinates exactly, and a triangle lying in a box face is kept.
bool triangle_box_overlap(const glm::dvec3 tri[3], glm::dvec3 box_lo, glm::dvec3 box_hi);

}  // namespace host
