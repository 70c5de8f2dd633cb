// Beams over tiles for the BVH's primary rays (an extension, issue 35; docs/studies/groups.md): the
// beam texture (one texel per tile), the passes that descend each tile's beam from the root to the
// first node it cannot narrow down (rayosHazBVH, with an occlusion query per pass), and the pass
// that starts each pixel's ray at its tile's node, its walk ending at that node's escape
// (inicioHazBVH). The BVH walk (bvh_walk.cpp) runs them in place of inicioBVH.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "host/accel/bvh.h"
#include "host/accel/kdtree.h"
#include "host/trace/passes.h"
#include "host/trace/ping_pong.h"
#include "host/trace/render_options.h"
#include "kernels/kernels.h"
#include "vgpu/vgpu.h"

namespace host {

// The levels of the hierarchy (the most descent passes a beam needs: a node's children lie one
// level below it) and the frustum test's margin (from the size of the root's box): the stream
// tracer's descent and the CPU tracer's (host/trace/cpu/cpu_beams.h) take both from here.
int bvh_levels(const Bvh& bvh);
float bvh_beam_margin(const Bvh& bvh);

// The kd-tree's nodes as the descent reads them (beams through the kd-tree): node i of the
// result is the kd-tree's node i, with its box (the root's box cut by the planes above it), its
// escape (the index past its subtree; -1 where that is the end) and, for a leaf, its list. A
// kd-tree's children split their parent's box, so a beam that skips one child's box has all of
// its rays' segments inside the parent's box in the other child.
Bvh kd_beam_nodes(const KdTree& kd);

// The BVH walk's node texels (kernels/bvh.h): node i's lo texel holds its box's low corner and
// its escape, its hi texel the high corner and its leaf's list (-1 for an inner node or an empty
// leaf), written at 4 i onward of `lo` and `hi` (each at least 4 floats per node).
void bvh_node_texels(const Bvh& bvh, std::span<float> lo, std::span<float> hi);

class BvhBeams {
 public:
  explicit BvhBeams(const RenderOptions& options) : opt_(options) {}
  // The hierarchy's uniforms (its node texture's width, its node count) and the frustum test's
  // margin, from the size of the root's box.
  void set_bvh(const Bvh& bvh, const kernels::BvhUniforms& u);
  // The beam texture pair and the descent's counting target, one texel per tile.
  void make_state(vgpu::Device& gpu);
  // The primary rays' camera and the sample's offset from the pixel centre (pixels).
  void set_camera(const kernels::GenerateRays& camera, float offset_x, float offset_y);
  // The descent passes (at most one per level of the tree; with --kernels looping one pass of
  // rayosHazBVHIterativo) and the count of the tiles that missed: beams() then holds each
  // tile's node.
  void descend(PassRunner& r, glm::vec3 eye, vgpu::Texture& nodes_lo, vgpu::Texture& nodes_hi);
  // descend(), then inicioHazBVH: the primary rays' traversal state into `traversal`.
  void enter(PassRunner& r, vgpu::Texture& rays, glm::vec3 eye, vgpu::Texture& nodes_lo,
             vgpu::Texture& nodes_hi, vgpu::Texture& traversal);

  uint64_t state_bytes() const;
  int tiles_x() const;
  int tiles_y() const;
  // The beam texture after the last frame's descent (per tile: node, end, missed, depth).
  const vgpu::Texture& beams() const { return beams_.current(); }

 private:
  const RenderOptions& opt_;
  int depth_ = 1;  // levels of the tree: the most passes a descent needs
  PingPong<vgpu::Texture> beams_;
  vgpu::Texture counter_;
  vgpu::KernelProgram<kernels::BvhBeamDescend> descend_;
  vgpu::KernelProgram<kernels::BvhBeamDescendLooping> descend_looping_;  // --kernels looping
  vgpu::KernelProgram<kernels::BvhBeamEnter> entry_;
  vgpu::KernelProgram<kernels::BvhBeamsDescending> descending_;
  vgpu::KernelProgram<kernels::BeamsMissed> missed_;
};

}  // namespace host
