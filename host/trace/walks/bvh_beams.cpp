// Beams over tiles through the BVH (host/trace/walks/bvh_beams.h): the descent's passes and the
// beam entry.
#include "host/trace/walks/bvh_beams.h"

#include <algorithm>
#include <vector>

#include "host/trace/walks/grid_beams.h"

namespace host {

using vgpu::Texture;

int bvh_levels(const Bvh& bvh) {
  // A node's children lie one level below it (the right child is where the left child's
  // subtree ends). Parents come before their children in the layout.
  std::vector<int> level(bvh.nodes.size(), 1);
  int depth = 1;
  for (size_t i = 0; i < bvh.nodes.size(); ++i) {
    depth = std::max(depth, level[i]);
    const int32_t escape = bvh.nodes[i].escape;
    if (bvh.nodes[i].count > 0 || i + 1 >= bvh.nodes.size() || size_t(escape) == i + 1) continue;
    level[i + 1] = level[i] + 1;
    const int32_t right = bvh.nodes[i + 1].escape;
    if (right > 0 && size_t(right) < bvh.nodes.size()) level[size_t(right)] = level[i] + 1;
  }
  return depth;
}

float bvh_beam_margin(const Bvh& bvh) {
  // Far above the rounding of the pixels' rays and of the plane test over the scene's extent,
  // far below any gap worth skipping.
  const glm::vec3 extent = bvh.nodes.empty() ? glm::vec3(1.0f) : bvh.nodes[0].hi - bvh.nodes[0].lo;
  return 1e-4f * std::max(1.0f, glm::length(extent));
}

void BvhBeams::set_bvh(const Bvh& bvh, const kernels::BvhUniforms& u) {
  descend_.kernel.u.bvh = u;
  entry_.kernel.tile = float(opt_.beam_tile);
  descend_.kernel.u.beams.tile = float(opt_.beam_tile);
  depth_ = bvh_levels(bvh);
  descend_.kernel.u.beams.margin = bvh_beam_margin(bvh);
  descend_looping_.kernel.levels = depth_;
}

int BvhBeams::tiles_x() const {
  return (opt_.width + opt_.beam_tile - 1) / opt_.beam_tile;
}
int BvhBeams::tiles_y() const {
  return (opt_.height + opt_.beam_tile - 1) / opt_.beam_tile;
}

void BvhBeams::make_state(vgpu::Device& gpu) {
  beams_ = {gpu.make_texture("bvh beams A", tiles_x(), tiles_y(), 4),
            gpu.make_texture("bvh beams B", tiles_x(), tiles_y(), 4)};
  counter_ = gpu.make_texture("bvh beam counter", tiles_x(), tiles_y(), 1);
}

uint64_t BvhBeams::state_bytes() const {
  return beams_[0].bytes() + beams_[1].bytes() + counter_.bytes();
}

void BvhBeams::set_camera(const kernels::GenerateRays& camera, float offset_x, float offset_y) {
  kernels::BeamUniforms& u = descend_.kernel.u.beams;
  u.camera = camera;
  u.offset_x = offset_x;
  u.offset_y = offset_y;
}

Bvh kd_beam_nodes(const KdTree& kd) {
  Bvh b;
  b.nodes.resize(kd.nodes.size());
  if (kd.nodes.empty()) return b;
  b.nodes[0].lo = kd.lo;
  b.nodes[0].hi = kd.hi;
  b.nodes[0].escape = -1;
  // Depth first: a parent comes before its children, so its box and escape are known first.
  for (size_t i = 0; i < kd.nodes.size(); ++i) {
    const KdNode& n = kd.nodes[i];
    BvhNode& p = b.nodes[i];
    if (n.axis == 3) {
      p.leaf = n.leaf;
      p.count = n.count;
      continue;
    }
    BvhNode& left = b.nodes[i + 1];
    BvhNode& right = b.nodes[size_t(n.right)];
    left.lo = right.lo = p.lo;
    left.hi = right.hi = p.hi;
    left.hi[n.axis] = n.split;
    right.lo[n.axis] = n.split;
    left.escape = n.right;
    right.escape = p.escape;
  }
  b.depth = kd.depth;
  b.leaves = kd.leaves;
  b.max_leaf = kd.max_leaf;
  return b;
}

void bvh_node_texels(const Bvh& bvh, std::span<float> lo, std::span<float> hi) {
  for (size_t i = 0; i < bvh.nodes.size(); ++i) {
    const BvhNode& n = bvh.nodes[i];
    for (int a = 0; a < 3; ++a) lo[4 * i + size_t(a)] = n.lo[a], hi[4 * i + size_t(a)] = n.hi[a];
    lo[4 * i + 3] = float(n.escape);
    hi[4 * i + 3] = n.count > 0 ? float(n.leaf) : kernels::kNone;
  }
}

void BvhBeams::descend(PassRunner& r, glm::vec3 eye, Texture& nodes_lo, Texture& nodes_hi) {
  vgpu::Device& gpu = r.device();
  descend_.kernel.u.beams.eye = eye;
  // Every beam starts at the root, descending (y = 0).
  beams_.make_current(0);
  gpu.clear(beams_.current(), {0, 0, 0, 0});
  WalkCounts& n = r.counts;
  n.beam_tiles += uint64_t(tiles_x()) * uint64_t(tiles_y());
  if (opt_.looping) {
    // The whole descent in one pass: no query per level, so no depths counted.
    descend_looping_.kernel.u = descend_.kernel.u;
    r.pass(descend_looping_, {&beams_.current(), &nodes_lo, &nodes_hi}, beams_.next());
    beams_.swap();
    ++n.beam_passes;
  }
  uint64_t descending = opt_.looping ? 0 : 1;
  if (!opt_.looping) n.beam_depths = true;
  // A beam moves down one level per pass and stops at a leaf at the latest.
  for (int pass = 0; pass < depth_ && descending > 0; ++pass) {
    r.pass(descend_, {&beams_.current(), &nodes_lo, &nodes_hi}, beams_.next());
    beams_.swap();
    ++n.beam_passes;
    gpu.begin_query();
    r.pass(descending_, {&beams_.current()}, counter_);
    descending = gpu.end_query();
    // The tiles still descending after pass k are those k or more levels down.
    n.beam_depth_sum += descending;
    if (descending > 0) n.beam_depth_max = std::max(n.beam_depth_max, uint64_t(pass + 1));
  }
  gpu.begin_query();
  r.pass(missed_, {&beams_.current()}, counter_);
  n.beam_tiles_missed += gpu.end_query();
  // The report's tile map (the emulator's texels, no read-back to count).
  if (n.beam_map.start.empty() && opt_.observer && dynamic_cast<vgpu::Gpu*>(&gpu))
    n.beam_map = beam_map(beams_.current(), opt_.beam_tile, true);
}

void BvhBeams::enter(PassRunner& r, Texture& rays, glm::vec3 eye, Texture& nodes_lo,
                     Texture& nodes_hi, Texture& traversal) {
  descend(r, eye, nodes_lo, nodes_hi);
  r.pass(entry_, {&rays, &beams_.current()}, traversal);
}

}  // namespace host
