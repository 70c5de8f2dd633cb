// Beams over tiles in the CPU tracer (--engine cpu --beams on; docs/studies/groups.md): the same
// beams as the stream tracer's passes march (kernels/beams.h), marched here one tile at a time by
// the kernel's own code run on the host at a lane width of one, and a 3D-DDA that starts where its
// tile's beam stopped. The CPU tracer walks in double precision, so the start is found its own
// way (cpu_dda_skip): the state its walk would reach, bit for bit, or no skip at all.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "host/accel/bvh.h"
#include "host/accel/grid.h"
#include "host/scene/camera.h"
#include "host/trace/render_options.h"
#include "kernels/beams.h"
#include "kernels/bvh_beams.h"

namespace host {

// Where a primary ray may start: the ray parameter t before which all of its tile's rays cross
// empty space (0: from the grid's face), or `missed`: the whole tile misses the grid. Through the
// BVH: the node its walk starts at and the index its walk ends at (its escape), or missed.
struct CpuBeamStart {
  float t = 0.0f;
  bool missed = false;
  int32_t node = 0, end = -1;
};

// What the beams cost, summed over every beam map a frame marched (one per sample position).
struct CpuBeamCounts {
  uint64_t tiles = 0, tiles_missed = 0;
  uint64_t passes = 0;  // per map, the most steps one tile ran: the passes a GPU would run
  uint64_t steps = 0;   // march steps over every tile (kernel runs)
  // Through a tree (CpuBvhBeams): the depth of each tile's node (its beam texel's w), summed
  // over the tiles, and the largest; `depths` says they were counted.
  uint64_t depth_sum = 0, depth_max = 0;
  bool depths = false;
};

class CpuBeams {
 public:
  CpuBeams(const Grid& grid, const Camera& camera, const RenderOptions& options);
  // The start of pixel (x, y)'s primary ray through the point j of the pixel (in [0, 1)^2 from
  // its top-left corner). Marches the beams of j's sample position the first time it is asked
  // (under a lock: the tracer's rows run in parallel), then only looks them up.
  CpuBeamStart start(int x, int y, glm::vec2 j) const;
  CpuBeamCounts counts() const;

 private:
  struct Map {
    std::vector<float> beams;  // per tile, the beam texel (kernels::BeamMarch's four channels)
  };
  const Map& map(glm::vec2 j) const;

  kernels::BeamMarch march_;
  std::vector<float> distances_;  // beam_distance_texels
  int tiles_x_ = 0, tiles_y_ = 0, tile_ = 8, dist_w_ = 0, dist_h_ = 0;
  mutable std::mutex mutex_;
  mutable std::map<std::pair<float, float>, std::unique_ptr<Map>> maps_;
  mutable CpuBeamCounts counts_;
};

// Beams through the BVH in the CPU tracer (--engine cpu --accel bvh --beams on): each tile's
// descent (kernels::BvhBeamDescend, its own code on the host at one lane, as CpuBeams marches),
// so that its rays walk only the subtree of its node, [node, escape), in depth-first order as the
// full walk would: every node outside it is missed by every ray of the tile.
class CpuBvhBeams {
 public:
  CpuBvhBeams(const Bvh& bvh, const Camera& camera, const RenderOptions& options);
  CpuBeamStart start(int x, int y, glm::vec2 j) const;
  CpuBeamCounts counts() const;

 private:
  struct Map {
    std::vector<float> beams;  // per tile, the beam texel (node, end, missed, depth)
  };
  const Map& map(glm::vec2 j) const;

  kernels::BvhBeamDescend descend_;
  std::vector<float> lo_, hi_;  // the node texels, as the stream tracer's BVH walk writes them
  int depth_ = 1, tiles_x_ = 0, tiles_y_ = 0, tile_ = 8;
  mutable std::mutex mutex_;
  mutable std::map<std::pair<float, float>, std::unique_ptr<Map>> maps_;
  mutable CpuBeamCounts counts_;
};

// Moves a 3D-DDA (Amanatides & Woo, as the CPU tracer runs it) on from its entry state to the
// voxel holding the point o + d ts: `vox` the voxel, `t_next` the next boundary per axis (grown by
// `t_delta` per step, as the walk grows it), `t_enter` where the ray entered the voxel. The new
// state is the one the walk reaches after the same additions in the same order, so it is the
// walk's own, bit for bit. Returns false (the state untouched) where the walk would not be in that
// voxel in that state (a point near a face or an edge, a voxel behind the entry, ties between
// axes) or where nothing would be skipped; the walk then starts at its entry. Every voxel it
// skips must be empty: the beam's job.
bool cpu_dda_skip(const Grid& grid, const glm::dvec3& o, const glm::dvec3& d, double ts,
                  glm::ivec3& vox, const glm::ivec3& step, glm::dvec3& t_next,
                  const glm::dvec3& t_delta, double& t_enter);

}  // namespace host
