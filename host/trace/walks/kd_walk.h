// The kd-restart walk (an extension; kernels/kdtree.h): the tree's textures, and which pass runs
// next, steered by which query, in the grid walk's manner (grid_walk.h): one node per pass for
// every walking ray, then the triangles of the leaves reached, one per pass. The pass sequence
// is the BVH walk's (bvh_walk.h) with the kd-tree's kernels.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "host/accel/kdtree.h"
#include "host/trace/passes.h"
#include "host/trace/render_options.h"
#include "host/trace/walks/accel_walk.h"
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

  // The multipass walk (host/trace/walks/walk.h); Cursor and write_back are ListWalk's.
  template <class X>
  void walk(X& x, Cursor& c);

 private:
  int nodes_ = 0, max_leaf_ = 0, depth_ = 0, leaves_ = 0;
  vgpu::Texture tree_, lists_;
  vgpu::KernelProgram<kernels::KdEnter> enter_;
  vgpu::KernelProgram<kernels::KdStep> step_;
  vgpu::KernelProgram<kernels::KdLoadLeaf> load_;
  vgpu::KernelProgram<kernels::KdIntersections> intersect_;
  vgpu::KernelProgram<kernels::KdStepLoad> step_load_;
  vgpu::KernelProgram<kernels::KdIntersectNext> intersect_next_;
  vgpu::KernelProgram<kernels::KdLooping> looping_;
};

}  // namespace host
