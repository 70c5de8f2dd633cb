// The two-level grid walk (an extension; kernels/grid2.h, host/accel/grid2.h): the structure's
// textures, and which pass runs next, steered by which query, in the grid walk's manner
// (grid_walk.h): one sub-cell per pass for every walking ray, then the triangles of the sub-cells
// reached, one per pass. The pass sequence is the kd-tree walk's (kd_walk.h) with these kernels,
// the entry sub-cell loaded once before the loop. With beams over tiles, the primary rays enter
// where their tile's beam stopped on the coarse grid (kernels/grid2_beams.h).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "host/accel/grid2.h"
#include "host/trace/passes.h"
#include "host/trace/render_options.h"
#include "host/trace/walks/accel_walk.h"
#include "host/trace/walks/grid_beams.h"
#include "kernels/kernels.h"
#include "vgpu/vgpu.h"

namespace host {

class Grid2Walk : public ListWalk {
 public:
  // Passes of the walk by where it issues them (walk::PassKey).
  enum Site : int {
    kEnter,          // rayosEnGrilla after inicioGrilla2
    kLoadFirst,      // cargarCelda of the entry sub-cell
    kStep,           // recorridoGrilla2
    kLoad,           // cargarCelda
    kStepLoad,       // recorridoGrilla2 + cargarCelda (--mrt on)
    kTesting,        // rayosIntersectando after the sub-cells are loaded
    kIntersect,      // interseccionesGrilla2
    kNext,           // proximoTriangulo
    kIntersectNext,  // interseccionesGrilla2 + proximoTriangulo (--mrt on)
    kTestingOn,      // rayosIntersectando in the triangle loop
    kWalking,        // rayosEnGrilla after the step
    kSites
  };

  // The structure's static textures, checked against the profile's limits (throws vgpu::Error
  // naming the limit); the walk's programs in their groups' formats.
  Grid2Walk(vgpu::Device& gpu, const Grid2& g2, const RenderOptions& options, float scene_width,
            float t_slack);
  void make_state(vgpu::Device& gpu, const WalkShared& shared) override;
  bool addresses_by_xy() const override { return xy_; }
  // The textures and the uniforms that depend on them; with `uploaded` (between frames,
  // AccelWalk::rebuild), the textures are kept where the new structure fits them and each one
  // whose texels changed is uploaded again and named there. Returns those bytes.
  uint64_t set_grid(vgpu::Device& gpu, const Grid2& g2, float scene_width, float t_slack,
                    std::vector<std::string>* uploaded);
  uint64_t rebuild(vgpu::Device& gpu, const Accel& accel, float scene_width,
                   std::vector<std::string>& uploaded) override;
  void trace(PassRunner& r, vgpu::Texture& origins, vgpu::Texture& rays, bool primary,
             glm::vec3 eye) override;
  void set_camera(const kernels::GenerateRays& camera, float offset_x, float offset_y) override {
    if (beams_) beams_->set_camera(camera, offset_x, offset_y);
  }

  // The multipass walk (host/trace/walks/walk.h); Cursor and write_back are ListWalk's.
  template <class X>
  void walk(X& x, Cursor& c);

 protected:
  // The beam texture pair and the beam passes' counting target (the beam distances are a static).
  uint64_t extra_bytes() const override { return beams_ ? beams_->state_bytes() : 0; }

 private:
  int max_list_ = 0;
  bool xy_ = false;        // addressed by (x, y) (RenderOptions::addressing)
  int64_t max_steps_ = 0;  // sub-cells a ray can visit at most
  vgpu::Texture cells_, subs_, lists_;
  vgpu::KernelProgram<kernels::Grid2Enter> enter_;
  vgpu::KernelProgram<kernels::Grid2Step> step_;
  vgpu::KernelProgram<kernels::Grid2LoadCell> load_;
  vgpu::KernelProgram<kernels::Grid2Intersections> intersect_;
  vgpu::KernelProgram<kernels::Grid2StepLoad> step_load_;
  vgpu::KernelProgram<kernels::Grid2IntersectNext> intersect_next_;
  vgpu::KernelProgram<kernels::Grid2Looping> looping_;
  // Beams over tiles (RenderOptions::beams; null: off): marched over the coarse grid, then each
  // primary ray entered at the sub-cell its walk reaches there (kernels/grid2_beams.h).
  std::unique_ptr<GridBeams> beams_;
  vgpu::KernelProgram<kernels::Grid2BeamEntry> beam_enter_;
};

}  // namespace host
