// The stackless BVH walk (an extension; kernels/bvh.h): the hierarchy's textures, and which
// pass runs next, steered by which query, in the grid walk's manner (grid_walk.h): one node per
// pass for every walking ray, then the triangles of the leaves entered, one per pass.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "host/accel/bvh.h"
#include "host/trace/passes.h"
#include "host/trace/render_options.h"
#include "host/trace/walks/accel_walk.h"
#include "host/trace/walks/bvh_beams.h"
#include "kernels/kernels.h"
#include "vgpu/vgpu.h"

namespace host {

class BvhWalk : public ListWalk {
 public:
  // Passes of the walk by where it issues them (walk::PassKey).
  enum Site : int {
    kEnter,          // rayosEnGrilla after inicioBVH
    kStep,           // recorridoBVH
    kLoad,           // cargarHoja
    kStepLoad,       // recorridoBVH + cargarHoja (--mrt on)
    kTesting,        // rayosIntersectando after the leaves are loaded
    kIntersect,      // interseccionesBVH
    kNext,           // proximoTriangulo
    kIntersectNext,  // interseccionesBVH + proximoTriangulo (--mrt on)
    kTestingOn,      // rayosIntersectando in the triangle loop
    kWalking,        // rayosEnGrilla after the step
    kSites
  };

  // The hierarchy's static textures, checked against the profile's limits (throws vgpu::Error
  // naming the limit); the walk's programs in their groups' formats.
  BvhWalk(vgpu::Device& gpu, const Bvh& bvh, const RenderOptions& options, float scene_width);
  void make_state(vgpu::Device& gpu, const WalkShared& shared) override;
  // The hierarchy's textures and the uniforms that depend on them; with `uploaded` (between
  // frames, AccelWalk::rebuild), the textures are kept where the new hierarchy fits them and
  // each one whose texels changed is uploaded again and named there. Returns those bytes.
  uint64_t set_bvh(vgpu::Device& gpu, const Bvh& bvh, float scene_width,
                   std::vector<std::string>* uploaded);
  uint64_t rebuild(vgpu::Device& gpu, const Accel& accel, float scene_width,
                   std::vector<std::string>& uploaded) override;
  void trace(PassRunner& r, vgpu::Texture& origins, vgpu::Texture& rays, bool primary,
             glm::vec3 eye) override;
  void set_camera(const kernels::GenerateRays& camera, float offset_x, float offset_y) override {
    if (beams_) beams_->set_camera(camera, offset_x, offset_y);
  }
  // Beams over tiles (RenderOptions::beams; null: off).
  const BvhBeams* beams() const { return beams_.get(); }
  uint64_t extra_bytes() const override { return beams_ ? beams_->state_bytes() : 0; }

  // The multipass walk (host/trace/walks/walk.h); Cursor and write_back are ListWalk's.
  template <class X>
  void walk(X& x, Cursor& c);

 private:
  int nodes_ = 0, max_leaf_ = 0;
  vgpu::Texture nodes_lo_, nodes_hi_, lists_;
  vgpu::KernelProgram<kernels::BvhEnter> enter_;
  vgpu::KernelProgram<kernels::BvhStep> step_;
  vgpu::KernelProgram<kernels::BvhLoadLeaf> load_;
  vgpu::KernelProgram<kernels::BvhIntersections> intersect_;
  vgpu::KernelProgram<kernels::BvhStepLoad> step_load_;
  vgpu::KernelProgram<kernels::BvhIntersectNext> intersect_next_;
  vgpu::KernelProgram<kernels::BvhLooping> looping_;
  std::unique_ptr<BvhBeams> beams_;
};

}  // namespace host
