// Beams over tiles in the CPU tracer (host/trace/cpu/cpu_beams.h).
#include "host/trace/cpu/cpu_beams.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "host/trace/walks/bvh_beams.h"
#include "host/trace/walks/grid_beams.h"
#include "vgpu/fragment.h"

namespace host {

namespace {

// The primary rays' generator, as the stream tracer fills it (its generadorRayos uniforms).
kernels::GenerateRays beam_camera(const Camera& camera, const RenderOptions& options) {
  kernels::GenerateRays c;
  c.forward = camera.forward;
  c.right = glm::normalize(glm::cross(camera.forward, camera.up));
  c.up = glm::cross(c.right, camera.forward);
  c.tan_half_fov = std::tan(0.5f * camera.yfov);
  c.aspect = float(options.width) / float(options.height);
  c.width = float(options.width);
  c.height = float(options.height);
  return c;
}

// Runs a beam kernel's own code one fragment (lane) at a time over every tile of `beams` (four
// floats a tile, the beam texture `units` binds): a tile's fragment reads only its own beam texel,
// so running one tile to its end is what the passes do to it. A tile runs while `going(texel)`,
// at most `limit` times; the steps, the passes a GPU would run (the most one tile ran) and the
// tiles missed (z > 0) go into `counts`.
template <class K, class Going>
void run_tiles(const K& kernel, const vgpu::BoundTexture* units, std::vector<float>& beams,
               int tiles_x, int tiles_y, uint64_t limit, Going going, CpuBeamCounts& counts) {
  using L = vgpu::SimdLanes<1>;
  using F = L::F;
  uint64_t idle = 0;
  vgpu::FetchTally tally;
  vgpu::Fragments<L> f(units, false, &idle, &tally);
  uint64_t most = 0;
  for (int ty = 0; ty < tiles_y; ++ty)
    for (int tx = 0; tx < tiles_x; ++tx) {
      float* b = &beams[(size_t(ty) * size_t(tiles_x) + size_t(tx)) * 4];
      uint64_t runs = 0;
      while (going(b) && runs < limit) {
        f.reset(F(float(tx) + 0.5f), F(float(ty) + 0.5f), L::M(true), 1);
        kernel(f);
        const kernels::Vec4<F>& out = f.output(0);
        b[0] = out.x[0];
        b[1] = out.y[0];
        b[2] = out.z[0];
        b[3] = out.w[0];
        ++runs;
      }
      most = std::max(most, runs);
      counts.steps += runs;
      if (counts.depths) {
        counts.depth_sum += uint64_t(b[3]);
        counts.depth_max = std::max(counts.depth_max, uint64_t(b[3]));
      }
      counts.tiles_missed += b[2] > 0.0f;
    }
  counts.tiles += uint64_t(tiles_x) * uint64_t(tiles_y);
  counts.passes += most;
}

}  // namespace

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
  u.camera = beam_camera(camera, options);
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
  m.beams.assign(size_t(tiles_x_) * size_t(tiles_y_) * 4, 0.0f);  // every beam at the eye
  vgpu::BoundTexture units[2];
  units[kernels::BeamMarch::kBeams] = {m.beams.data(), tiles_x_, tiles_y_, 4};
  units[kernels::BeamMarch::kDistances] = {distances_.data(), dist_w_, dist_h_, 1};
  // A beam marches while x >= 0.
  run_tiles(
      march, units, m.beams, tiles_x_, tiles_y_, uint64_t(GridBeams::kMaxPasses),
      [](const float* b) { return b[0] >= 0.0f; }, counts_);
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

CpuBvhBeams::CpuBvhBeams(const Bvh& bvh, const Camera& camera, const RenderOptions& options)
    : depth_(bvh_levels(bvh)),
      tiles_x_((options.width + options.beam_tile - 1) / options.beam_tile),
      tiles_y_((options.height + options.beam_tile - 1) / options.beam_tile),
      tile_(options.beam_tile) {
  // The node texels in one row, as the BVH walk lays them out (x, y, z the box, w the escape;
  // hi's w the leaf's list, -1 for an inner node).
  const size_t n = bvh.nodes.size();
  lo_.assign(4 * n, 0.0f);
  hi_.assign(4 * n, 0.0f);
  bvh_node_texels(bvh, lo_, hi_);
  kernels::BvhBeamUniforms& u = descend_.u;
  u.bvh.node_width = float(std::max<size_t>(n, 1));
  u.bvh.nodes = float(n);
  u.beams.tile = float(options.beam_tile);
  u.beams.camera = beam_camera(camera, options);
  u.beams.eye = camera.position;
  u.beams.margin = bvh_beam_margin(bvh);
  counts_.depths = true;  // a descent's texel w is its node's depth
}

const CpuBvhBeams::Map& CpuBvhBeams::map(glm::vec2 j) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::unique_ptr<Map>& slot = maps_[{j.x, j.y}];
  if (slot) return *slot;
  slot = std::make_unique<Map>();
  Map& m = *slot;
  kernels::BvhBeamDescend descend = descend_;
  descend.u.beams.offset_x = j.x - 0.5f;
  descend.u.beams.offset_y = j.y - 0.5f;
  m.beams.assign(size_t(tiles_x_) * size_t(tiles_y_) * 4, 0.0f);  // every beam at the root
  const int nw = int(descend.u.bvh.node_width);
  vgpu::BoundTexture units[3];
  units[kernels::BvhBeamDescend::kBeams] = {m.beams.data(), tiles_x_, tiles_y_, 4};
  units[kernels::BvhBeamDescend::kNodesLo] = {lo_.data(), nw, 1, 4};
  units[kernels::BvhBeamDescend::kNodesHi] = {hi_.data(), nw, 1, 4};
  // As the stream tracer's passes: one level a pass while the beam descends (y 0).
  run_tiles(
      descend, units, m.beams, tiles_x_, tiles_y_, uint64_t(depth_),
      [](const float* b) { return b[1] <= 0.0f; }, counts_);
  return m;
}

CpuBeamStart CpuBvhBeams::start(int x, int y, glm::vec2 j) const {
  const Map& m = map(j);
  const size_t t = size_t(y / tile_) * size_t(tiles_x_) + size_t(x / tile_);
  CpuBeamStart s;
  s.missed = m.beams[t * 4 + 2] > 0.0f;
  s.node = int32_t(m.beams[t * 4]);
  s.end = int32_t(m.beams[t * 4 + 1]);
  return s;
}

CpuBeamCounts CpuBvhBeams::counts() const {
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
