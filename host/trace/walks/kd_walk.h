// The kd-restart walk (an extension; kernels/kdtree.h): the tree's textures, and which pass runs
// next, steered by which query, in the grid walk's manner (grid_walk.h): one node per pass for
// every walking ray, then the triangles of the leaves reached, one per pass. The pass sequence
// is the BVH walk's (bvh_walk.h) with the kd-tree's kernels. With beams over tiles
// (RenderOptions::beams), each tile's beam descends the tree first (BvhBeams, on the nodes' boxes:
// kd_beam_nodes), and its primary rays start, and restart, at the node it reached.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "host/accel/kdtree.h"
#include "host/trace/passes.h"
#include "host/trace/render_options.h"
#include "host/trace/walks/accel_walk.h"
#include "host/trace/walks/bvh_beams.h"
#include "kernels/kernels.h"
#include "vgpu/vgpu.h"

namespace host {

class KdWalk : public ListWalk {
 public:
  // Passes of the walk by where it issues them (walk::PassKey).
  enum Site : int {
    kEnter,          // rayosEnGrilla after inicioKd
    kStep,           // recorridoKd
    kLoad,           // cargarHojaKd
    kStepLoad,       // recorridoKd + cargarHojaKd (--mrt on)
    kTesting,        // rayosIntersectando after the leaves are loaded
    kIntersect,      // interseccionesKd
    kNext,           // proximoTriangulo
    kIntersectNext,  // interseccionesKd + proximoTriangulo (--mrt on)
    kTestingOn,      // rayosIntersectando in the triangle loop
    kWalking,        // rayosEnGrilla after the step
    kSites
  };

  // The tree's static textures, checked against the profile's limits (throws vgpu::Error
  // naming the limit); the walk's programs in their groups' formats.
  KdWalk(vgpu::Device& gpu, const KdTree& kd, const RenderOptions& options, float scene_width,
         float t_slack);
  void make_state(vgpu::Device& gpu, const WalkShared& shared) override;
  // The tree's textures and the uniforms that depend on them; with `uploaded` (between frames,
  // AccelWalk::rebuild), the textures are kept where the new tree fits them and each one whose
  // texels changed is uploaded again and named there. Returns those bytes.
  uint64_t set_tree(vgpu::Device& gpu, const KdTree& kd, float scene_width, float t_slack,
                    std::vector<std::string>* uploaded);
  uint64_t rebuild(vgpu::Device& gpu, const Accel& accel, float scene_width,
                   std::vector<std::string>& uploaded) override;
  void trace(PassRunner& r, vgpu::Texture& origins, vgpu::Texture& rays, bool primary,
             glm::vec3 eye) override;
  void set_camera(const kernels::GenerateRays& camera, float offset_x, float offset_y) override {
    if (beams_) beams_->set_camera(camera, offset_x, offset_y);
  }
  bool addresses_by_xy() const override { return xy_; }
  // Beams over tiles (RenderOptions::beams; null: off).
  const BvhBeams* beams() const { return beams_.get(); }
  uint64_t extra_bytes() const override { return beams_ ? beams_->state_bytes() : 0; }

  // The multipass walk (host/trace/walks/walk.h); Cursor and write_back are ListWalk's.
  template <class X>
  void walk(X& x, Cursor& c);

 private:
  int nodes_ = 0, max_leaf_ = 0, depth_ = 0, leaves_ = 0;
  bool xy_ = false;  // addressed by (x, y) (RenderOptions::addressing)
  vgpu::Texture tree_, lists_;
  vgpu::KernelProgram<kernels::KdEnter> enter_;
  vgpu::KernelProgram<kernels::KdStep> step_;
  vgpu::KernelProgram<kernels::KdLoadLeaf> load_;
  vgpu::KernelProgram<kernels::KdIntersections> intersect_;
  vgpu::KernelProgram<kernels::KdStepLoad> step_load_;
  vgpu::KernelProgram<kernels::KdIntersectNext> intersect_next_;
  vgpu::KernelProgram<kernels::KdLooping> looping_;
  // Beams over tiles: the nodes' boxes (kd_beam_nodes, in the BVH's node layout), the descent,
  // and the programs of the primary trace that read each tile's node (beam_tile > 0).
  std::unique_ptr<BvhBeams> beams_;
  vgpu::Texture boxes_lo_, boxes_hi_;
  vgpu::KernelProgram<kernels::KdEnter> beam_enter_;
  vgpu::KernelProgram<kernels::KdStep> beam_step_;
  vgpu::KernelProgram<kernels::KdStepLoad> beam_step_load_;
  vgpu::KernelProgram<kernels::KdLooping> beam_looping_;
  const vgpu::Texture* beam_nodes_ = nullptr;  // during a primary trace with beams: each tile's
};

}  // namespace host
