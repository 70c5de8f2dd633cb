// The paper's walk through the uniform grid (Sec. 2.2-2.3): the grid's textures, and which pass
// runs next, steered by which query. How the passes run is host/trace/walks/walk.h's business.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "host/accel/grid.h"
#include "host/model/formats.h"
#include "host/scene/scene.h"
#include "host/trace/passes.h"
#include "host/trace/render_options.h"
#include "host/trace/walks/accel_walk.h"
#include "host/trace/walks/grid_beams.h"
#include "kernels/kernels.h"
#include "vgpu/vgpu.h"

namespace host {

class GridWalk : public ListWalk {
 public:
  // The passes of the walk, by where the walk issues them. With the step (-1 before the first)
  // and the triangle index k within a step (-1 outside the triangle loop), a site names one
  // pass of the sequence (walk::PassKey).
  enum Site : int {
    kEnter,           // rayosEnGrilla before the first step
    kUpdate,          // actualizarVoxel
    kTesting,         // rayosIntersectando after actualizarVoxel
    kIntersect,       // intersecciones
    kNext,            // proximoTriangulo
    kIntersectNext,   // intersecciones + proximoTriangulo (--mrt on)
    kTestingOn,       // rayosIntersectando in the triangle loop
    kTraversal,       // traversal
    kTraverseUpdate,  // traversal + actualizarVoxel (--mrt on)
    kInGrid,          // rayosEnGrilla after the step
    kSites
  };

  using Shared = WalkShared;

  // The grid's static textures, built and checked against the profile's limits (throws
  // vgpu::Error naming the limit); the walk's programs, each computing in its group's format.
  GridWalk(vgpu::Device& gpu, const Grid& grid, const RenderOptions& options, float scene_width);
  // The per-pixel state textures (traversal, voxel state), made after the tracer's own.
  void make_state(vgpu::Device& gpu, const Shared& shared) override;
  // A new grid for the same scene texture layout, between frames of a moving scene: the
  // static textures rewritten (kept where the new grid fits them) and uniforms set; with
  // `uploaded`, each texture whose texels changed is uploaded again and named there. Returns
  // the bytes uploaded. The constructor calls it without `uploaded` (upload() follows). Throws
  // vgpu::Error as the constructor does.
  uint64_t set_grid(vgpu::Device& gpu, const Grid& grid, float scene_width,
                    std::vector<std::string>* uploaded);
  uint64_t rebuild(vgpu::Device& gpu, const Accel& accel, float scene_width,
                   std::vector<std::string>& uploaded) override {
    return set_grid(gpu, *accel.grid(), scene_width, &uploaded);
  }

  // One stream of rays through the grid: enter it (initTraversal for primary rays, from the eye;
  // reinicializarTraversal otherwise), then walk it until no ray is walking. Leaves the nearest
  // hits in the current intersection texture.
  void trace(PassRunner& r, vgpu::Texture& origins, vgpu::Texture& rays, bool primary,
             glm::vec3 eye) override;
  void set_camera(const kernels::GenerateRays& camera, float offset_x, float offset_y) override {
    if (beams_) beams_->set_camera(camera, offset_x, offset_y);
  }

  // The multipass walk (one voxel step and one triangle per pass), written once for every way
  // it runs (host/trace/walks/walk.h). Cursor and write_back are ListWalk's; its per-pixel state is
  // the traversal (voxel, entry t) and the voxel state (list position).
  template <class X>
  void walk(X& x, Cursor& c);

 protected:
  // The beam texture pair and the beam passes' counting target (the beam distances are a static).
  uint64_t extra_bytes() const override { return beams_ ? beams_->state_bytes() : 0; }

 private:
  glm::ivec3 res_;
  int max_list_ = 0;  // longest voxel list: a ray tests at most this many triangles per voxel
  // Static textures: the triangle lists, each closed by -1, and the voxel pointers.
  vgpu::Texture lists_, pointers_;
  vgpu::KernelProgram<kernels::InitTraversal> init_;
  vgpu::KernelProgram<kernels::ResetTraversal> reset_;
  vgpu::KernelProgram<kernels::Traversal> traversal_;
  vgpu::KernelProgram<kernels::UpdateVoxel> update_;
  vgpu::KernelProgram<kernels::Intersections> intersect_;
  // Fused programs for --mrt on (kernels/fused.h).
  vgpu::KernelProgram<kernels::IntersectNext> intersect_next_;
  vgpu::KernelProgram<kernels::TraverseUpdate> traverse_update_;
  vgpu::KernelProgram<kernels::LoopingTraversal> looping_;
  // Beams over tiles (RenderOptions::beams; null: off).
  std::unique_ptr<GridBeams> beams_;
};

}  // namespace host
