// Beams over tiles for the uniform grid's primary rays (an extension, issue 35;
// docs/studies/groups.md; the two-level grid's march over its coarse grid, kernels/grid2_beams.h):
// the beam distances (per voxel, how far the nearest voxel holding a triangle is), the beam
// texture (one texel per tile), and the passes that march the beams (rayosHaz, with an occlusion
// query per pass) and start each pixel's ray where its tile's beam stopped (inicioHaz). The grid
// walk (grid_walk.cpp) runs them in place of initTraversal.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "host/accel/grid.h"
#include "host/trace/passes.h"
#include "host/trace/ping_pong.h"
#include "host/trace/render_options.h"
#include "kernels/kernels.h"
#include "vgpu/vgpu.h"

namespace host {

// Per voxel of `grid`, x fastest then y then z, the chessboard distance (in voxels, at most
// `cap`) to the nearest voxel that lists a triangle: 0 for such a voxel, k for one whose
// neighbours fewer than k steps away along every axis are all empty. Voxels outside the grid
// count as empty. Two raster scans (forward, backward) over the 26 neighbours: exact for this
// distance.
std::vector<float> beam_distances(const Grid& grid, float cap = 1024.0f);
// beam_distances laid out as the beam march fetches them: voxel (X, Y, Z) at texel
// (X * res.y + Y, Z) of a res.x * res.y by res.z texture of one channel (the voxel pointers'
// layout).
std::vector<float> beam_distance_texels(const Grid& grid);
// The march's and the entry's uniforms that come from the grid (its uniforms `g`, the margin and
// the shortest step) and the tile size; the camera, the offset, the eye and `far` are the
// frame's (beam_far).
void set_beam_grid(kernels::BeamUniforms& u, const kernels::GridUniforms& g, int tile);
// BeamUniforms::far for a beam from `eye`: just past the grid box's farthest corner.
float beam_far(const kernels::BeamUniforms& u, glm::vec3 eye);

// The tile map of a beam texture after the march (kernels/beams.h's layout: y = t, z = missed,
// w = steps), `tile` pixels per tile side.
BeamMap beam_map(const vgpu::Texture& beams, int tile, bool tree = false);

class GridBeams {
 public:
  // Most beam passes a frame runs (a beam still marching then starts where it got to), and the
  // looping march's most steps.
  static constexpr int kMaxPasses = 48;

  explicit GridBeams(const RenderOptions& options) : opt_(options) {}
  // The beam distances of `grid` (made anew at initialization, rewritten between frames of a
  // moving scene: then uploaded and named in `uploaded`) and the grid's uniforms. Returns the
  // bytes uploaded.
  uint64_t set_grid(vgpu::Device& gpu, const Grid& grid, const kernels::GridUniforms& g,
                    std::vector<std::string>* uploaded);
  // The beam texture pair and the beam passes' counting target, one texel per tile.
  void make_state(vgpu::Device& gpu);
  // The primary rays' camera: the generator's uniforms and the sample's offset from the pixel
  // centre (pixels), as the frame's ray generation set them.
  void set_camera(const kernels::GenerateRays& camera, float offset_x, float offset_y);
  // The beam passes, then inicioHaz: the primary rays' traversal state into `traversal`.
  void enter(PassRunner& r, vgpu::Texture& rays, glm::vec3 eye, vgpu::Texture& traversal);
  // The beam passes alone (the two-level grid's walk runs its own entry after them): every
  // tile's beam marched from `eye`. Returns the beam texture; uniforms() are the march's.
  vgpu::Texture& march(PassRunner& r, glm::vec3 eye);
  const kernels::BeamUniforms& uniforms() const { return march_.kernel.beams; }

  const vgpu::Texture& distances() const { return distances_; }
  uint64_t state_bytes() const;
  int tiles_x() const;
  int tiles_y() const;

 private:
  const RenderOptions& opt_;
  vgpu::Texture distances_;
  PingPong<vgpu::Texture> beams_;
  vgpu::Texture counter_;
  vgpu::KernelProgram<kernels::BeamMarch> march_;
  vgpu::KernelProgram<kernels::BeamMarchLooping> march_looping_;  // --kernels looping
  vgpu::KernelProgram<kernels::BeamEntry> entry_;
  vgpu::KernelProgram<kernels::RaysInGrid> marching_;
  vgpu::KernelProgram<kernels::BeamsMissed> missed_;
};

}  // namespace host
