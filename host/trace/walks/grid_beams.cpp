// Beams over tiles for the uniform grid (host/trace/walks/grid_beams.h): the beam distances
// built on the host with the grid, and the passes that march the tiles' beams before the walk.
#include "host/trace/walks/grid_beams.h"

#include <algorithm>
#include <cmath>

#include "host/trace/walks/accel_walk.h"

namespace host {

using vgpu::Texture;

std::vector<float> beam_distances(const Grid& grid, float cap) {
  const glm::ivec3 r = grid.res;
  std::vector<float> d(grid.voxels(), cap);
  for (size_t v = 0; v < grid.voxels(); ++v)
    if (grid.start[v + 1] > grid.start[v]) d[v] = 0.0f;
  // A voxel's distance is one more than its nearest neighbour's: the forward scan takes the 13
  // neighbours already visited (lower z, or the same z and lower y, or the same row to the left),
  // the backward scan the other 13.
  auto scan = [&](int sign) {
    const int n = int(grid.voxels());
    for (int i = 0; i < n; ++i) {
      const int v = sign > 0 ? i : n - 1 - i;
      const int x = v % r.x, y = (v / r.x) % r.y, z = v / (r.x * r.y);
      float best = d[size_t(v)];
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int order = dz != 0 ? dz : dy != 0 ? dy : dx;
            if (order * sign >= 0) continue;  // only neighbours this scan has visited
            const int nx = x + dx, ny = y + dy, nz = z + dz;
            if (nx < 0 || ny < 0 || nz < 0 || nx >= r.x || ny >= r.y || nz >= r.z) continue;
            best = std::min(best, d[grid.index(nx, ny, nz)] + 1.0f);
          }
      d[size_t(v)] = std::min(best, cap);
    }
  };
  scan(1);
  scan(-1);
  return d;
}

std::vector<float> beam_distance_texels(const Grid& grid) {
  const glm::ivec3 r = grid.res;
  const std::vector<float> d = beam_distances(grid);
  std::vector<float> texels(size_t(r.x) * size_t(r.y) * size_t(r.z));
  for (int z = 0; z < r.z; ++z)
    for (int y = 0; y < r.y; ++y)
      for (int x = 0; x < r.x; ++x)
        texels[size_t(z) * size_t(r.x * r.y) + size_t(x * r.y + y)] = d[grid.index(x, y, z)];
  return texels;
}

void set_beam_grid(kernels::BeamUniforms& u, const kernels::GridUniforms& g, int tile) {
  u.grid = g;
  u.min_cell = std::min({g.cell.x, g.cell.y, g.cell.z});
  // Rounding of points and faces is a few ulps of the grid's coordinates: keep a thousandth of a
  // cell, and step on only by half a cell or more.
  u.margin = 1e-3f * u.min_cell;
  u.min_step = 0.5f * u.min_cell;
  u.tile = float(tile);
}

float beam_far(const kernels::BeamUniforms& u, glm::vec3 eye) {
  const glm::vec3 lo = u.grid.lo, hi = u.grid.lo + u.grid.cell * u.grid.res;
  float far = 0.0f;
  for (int c = 0; c < 8; ++c) {
    const glm::vec3 corner{c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z};
    far = std::max(far, glm::length(corner - eye));
  }
  return far * 1.0001f + u.margin;
}

uint64_t GridBeams::set_grid(vgpu::Device& gpu, const Grid& grid, const kernels::GridUniforms& g,
                             std::vector<std::string>* uploaded) {
  const glm::ivec3 r = grid.res;
  // The same layout as the voxel pointers: voxel (X, Y, Z) at texel (X * sizeY + Y, Z).
  if (!uploaded || distances_.width() != r.x * r.y || distances_.height() != r.z)
    distances_ = gpu.make_texture("beam distances", r.x * r.y, r.z, 1);
  const std::vector<float> texels = beam_distance_texels(grid);
  const uint64_t bytes = replace_texels(gpu, {{&distances_, &texels}}, uploaded);
  set_beam_grid(march_.kernel.beams, g, opt_.beam_tile);
  entry_.kernel.beams = march_.kernel.beams;
  return bytes;
}

int GridBeams::tiles_x() const {
  return (opt_.width + opt_.beam_tile - 1) / opt_.beam_tile;
}
int GridBeams::tiles_y() const {
  return (opt_.height + opt_.beam_tile - 1) / opt_.beam_tile;
}

void GridBeams::make_state(vgpu::Device& gpu) {
  beams_ = {gpu.make_texture("beams A", tiles_x(), tiles_y(), 4),
            gpu.make_texture("beams B", tiles_x(), tiles_y(), 4)};
  counter_ = gpu.make_texture("beam counter", tiles_x(), tiles_y(), 1);
}

uint64_t GridBeams::state_bytes() const {
  return beams_[0].bytes() + beams_[1].bytes() + counter_.bytes();
}

void GridBeams::set_camera(const kernels::GenerateRays& camera, float offset_x, float offset_y) {
  for (kernels::BeamUniforms* u : {&march_.kernel.beams, &entry_.kernel.beams}) {
    u->camera = camera;
    u->offset_x = offset_x;
    u->offset_y = offset_y;
  }
}

BeamMap beam_map(const vgpu::Texture& beams, int tile, bool tree) {
  BeamMap m;
  m.tiles_x = beams.width();
  m.tiles_y = beams.height();
  m.tile = tile;
  m.tree = tree;
  for (int y = 0; y < m.tiles_y; ++y)
    for (int x = 0; x < m.tiles_x; ++x) {
      const float* b = beams.texel(x, y);
      m.start.push_back(tree ? b[0] : b[1]);
      m.steps.push_back(b[3]);
      m.missed.push_back(b[2] > 0.0f ? 1 : 0);
    }
  return m;
}

void GridBeams::enter(PassRunner& r, Texture& rays, glm::vec3 eye, Texture& traversal) {
  Texture& beams = march(r, eye);
  entry_.kernel.beams = march_.kernel.beams;
  r.pass(entry_, {&rays, &beams}, traversal);
}

Texture& GridBeams::march(PassRunner& r, glm::vec3 eye) {
  vgpu::Device& gpu = r.device();
  kernels::BeamUniforms& u = march_.kernel.beams;
  u.eye = eye;
  // Past the farthest corner of the grid box from the eye, a beam has left the box behind.
  u.far = beam_far(u, eye);
  // Every beam starts at the eye, marching.
  beams_.make_current(0);
  gpu.clear(beams_.current(), {0, 0, 0, 0});
  WalkCounts& n = r.counts;
  n.beam_tiles += uint64_t(tiles_x()) * uint64_t(tiles_y());
  // With the looping kernels, the whole march in one pass (the same texels, no query per step).
  if (opt_.looping) {
    march_looping_.kernel.beams = u;
    march_looping_.kernel.steps = kMaxPasses;
    r.pass(march_looping_, {&beams_.current(), &distances_}, beams_.next());
    beams_.swap();
    ++n.beam_passes;
  }
  uint64_t marching = opt_.looping ? 0 : 1;
  for (int pass = 0; pass < kMaxPasses && marching > 0; ++pass) {
    r.pass(march_, {&beams_.current(), &distances_}, beams_.next());
    beams_.swap();
    ++n.beam_passes;
    gpu.begin_query();
    r.pass(marching_, {&beams_.current()}, counter_);
    marching = gpu.end_query();
  }
  gpu.begin_query();
  r.pass(missed_, {&beams_.current()}, counter_);
  n.beam_tiles_missed += gpu.end_query();
  // The report's tile map: the first primary trace's beams, read from the emulator's host memory
  // (no download is issued, so the frame's statistics are those of a frame without a report).
  if (n.beam_map.start.empty() && opt_.observer && dynamic_cast<vgpu::Gpu*>(&gpu))
    n.beam_map = beam_map(beams_.current(), opt_.beam_tile);
  return beams_.current();
}

}  // namespace host
