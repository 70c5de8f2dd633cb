// Beams over tiles in the CPU tracer (host/trace/cpu/cpu_beams.h).
#include "host/trace/cpu/cpu_beams.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "host/trace/walks/grid_beams.h"
#include "vgpu/fragment.h"

namespace host {

CpuBeams::CpuBeams(const Grid& grid, const Camera& camera, const RenderOptions& options)
    : distances_(beam_distance_texels(grid)),
      tiles_x_((options.width + options.beam_tile - 1) / options.beam_tile),
      tiles_y_((options.height + options.beam_tile - 1) / options.beam_tile),
      tile_(options.beam_tile),
      dist_w_(grid.res.x * grid.res.y),
      dist_h_(grid.res.z) {
  // The grid's uniforms as the stream tracer's grid walk sets them (only the box, the cells and
  // the resolution matter to the beams).
  kernels::GridUniforms g;
  g.lo = grid.lo;
  g.cell = grid.cell;
  g.res = glm::vec3(grid.res);
  kernels::BeamUniforms& u = march_.beams;
  set_beam_grid(u, g, options.beam_tile);
  // The primary rays' generator, as the stream tracer fills it (its generadorRayos uniforms).
  const int W = options.width, H = options.height;
  kernels::GenerateRays& c = u.camera;
  c.forward = camera.forward;
  c.right = glm::normalize(glm::cross(camera.forward, camera.up));
  c.up = glm::cross(c.right, camera.forward);
  c.tan_half_fov = std::tan(0.5f * camera.yfov);
  c.aspect = float(W) / float(H);
  c.width = float(W);
  c.height = float(H);
  u.eye = camera.position;
  u.far = beam_far(u, u.eye);
}

const CpuBeams::Map& CpuBeams::map(glm::vec2 j) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::unique_ptr<Map>& slot = maps_[{j.x, j.y}];
  if (slot) return *slot;
  slot = std::make_unique<Map>();
  Map& m = *slot;
  // The sample's offset from the pixel centre, as the stream tracer hands it to its beams.
  kernels::BeamMarch march = march_;
  march.beams.offset_x = j.x - 0.5f;
  march.beams.offset_y = j.y - 0.5f;
  const size_t tiles = size_t(tiles_x_) * size_t(tiles_y_);
  m.beams.assign(tiles * 4, 0.0f);  // every beam at the eye, marching
  // The kernel's code itself, one fragment (lane) at a time: each tile's fragment reads only its
  // own beam texel, so marching one tile to its end is what the passes do to it.
  using L = vgpu::SimdLanes<1>;
  using F = L::F;
  vgpu::BoundTexture units[2];
  units[kernels::BeamMarch::kBeams] = {m.beams.data(), tiles_x_, tiles_y_, 4};
  units[kernels::BeamMarch::kDistances] = {distances_.data(), dist_w_, dist_h_, 1};
  uint64_t idle = 0;
  vgpu::FetchTally tally;
  vgpu::Fragments<L> f(units, false, &idle, &tally);
  uint64_t most = 0;
  for (int ty = 0; ty < tiles_y_; ++ty)
    for (int tx = 0; tx < tiles_x_; ++tx) {
      float* b = &m.beams[(size_t(ty) * size_t(tiles_x_) + size_t(tx)) * 4];
      uint64_t runs = 0;
      while (b[0] >= 0.0f && runs < uint64_t(GridBeams::kMaxPasses)) {
        f.reset(F(float(tx) + 0.5f), F(float(ty) + 0.5f), L::M(true), 1);
        march(f);
        const kernels::Vec4<F>& out = f.output(0);
        b[0] = out.x[0];
        b[1] = out.y[0];
        b[2] = out.z[0];
        b[3] = out.w[0];
        ++runs;
      }
      most = std::max(most, runs);
      counts_.steps += runs;
      counts_.tiles_missed += b[2] > 0.0f;
    }
  counts_.tiles += tiles;
  counts_.passes += most;
  return m;
}

CpuBeamStart CpuBeams::start(int x, int y, glm::vec2 j) const {
  const Map& m = map(j);
  const size_t t = size_t(y / tile_) * size_t(tiles_x_) + size_t(x / tile_);
  return {m.beams[t * 4 + 1], m.beams[t * 4 + 2] > 0.0f};
}

CpuBeamCounts CpuBeams::counts() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return counts_;
}

bool cpu_dda_skip(const Grid& grid, const glm::dvec3& o, const glm::dvec3& d, double ts,
                  glm::ivec3& vox, const glm::ivec3& step, glm::dvec3& t_next,
                  const glm::dvec3& t_delta, double& t_enter) {
  if (!(ts > t_enter)) return false;
  const glm::dvec3 p = o + d * ts;
  glm::ivec3 to(0), n(0);
  for (int a = 0; a < 3; ++a) {
    const double v = std::floor((p[a] - double(grid.lo[a])) / double(grid.cell[a]));
    if (!(v >= 0.0 && v < double(grid.res[a]))) return false;
    to[a] = int(v);
    n[a] = (to[a] - vox[a]) * step[a];
    if (n[a] < 0 || (step[a] == 0 && to[a] != vox[a])) return false;
  }
  if (n == glm::ivec3(0)) return false;
  // Each axis's boundaries in the walk's own arithmetic: t_next grows by t_delta per step of that
  // axis. The walk takes the crossings in increasing order, so it stands in the new voxel with
  // exactly these values if its last crossing (the largest one taken) comes before every next one.
  glm::dvec3 next = t_next;
  double last = -std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a)
    for (int k = 0; k < n[a]; ++k) {
      last = std::max(last, next[a]);
      next[a] += t_delta[a];
    }
  const double first_next = std::min({next.x, next.y, next.z});
  if (!(last < first_next) || !(last <= ts) || !(last > t_enter)) return false;
  vox = to;
  t_next = next;
  t_enter = last;
  return true;
}

}  // namespace host
