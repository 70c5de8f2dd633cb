// Fused programs for multiple render targets (MRT; the paper's future work, Sec. 5): on a part
// that writes more than one output per pass (GeForce 6, R300, the modern profiles), two kernels
// that always run back to back become one program writing both kernels' targets, so the frame
// has fewer passes and fewer program loads. `--mrt on` runs them
// (host/trace/stream/stream_tracer.cpp).
//
// Each fused program computes exactly what its two kernels compute, from the textures the first
// of them reads: no output is read back in the same pass (a read/write hazard), so where the
// second kernel read the first's output, the fused program uses the register instead. The same
// helpers as the single kernels do the work (dda_step, first_in_voxel, nearest_hit,
// next_in_list), so results are bit-identical to the multipass pipeline's.
#pragma once

#include "kernels/intersections.h"
#include "kernels/next_triangle.h"
#include "kernels/traversal.h"
#include "kernels/update_voxel.h"

namespace kernels {

// intersecciones + proximoTriangulo: both read the voxel state and neither reads the other's
// output (proximoTriangulo reads the voxel state intersecciones read), so one pass tests the
// current triangle and moves to the next list entry. One branch: the same rays test and move.
struct IntersectNext {
  static constexpr const char* name = "intersections + next triangle";
  static constexpr const char* paper_name = "intersecciones+proximoTriangulo";
  static constexpr int outputs = 2;  // -> intersection, voxel state
  enum Unit { kOrigins, kRays, kTraversal, kVoxelState, kIntersection, kV0, kV1, kV2, kLists };
  static constexpr std::array<const char*, 9> units{
      "origins",   "rays",      "traversal", "voxel_state",   "intersection",
      "vertices0", "vertices1", "vertices2", "triangle_lists"};
  static constexpr std::array<int, 2> passthrough{kIntersection, kVoxelState};

  GridUniforms grid;
  SceneUniforms scene;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> vs = f.fetch_own(kVoxelState);
    const Vec4<F> best = f.fetch_own(kIntersection);
    const auto testing = vs.w >= F(0.0f);
    Vec4<F> hit = best, next = vs;
    if (f.branch(testing)) {
      hit = nearest_hit(f, {kOrigins, kRays, kTraversal, kV0}, vs, best, testing, grid, scene);
      next = next_in_list(f, kLists, vs, testing, grid);
    }
    f.out(0) = hit;
    f.out(1) = next;
  }
};

// traversal + actualizarVoxel: one DDA step, then the first triangle of the voxel the ray just
// entered, from the stepped state in registers (actualizarVoxel would read it from the
// traversal texture this pass writes). The multipass pipeline runs actualizarVoxel only for rays
// still in the grid after the step; here it runs in the same pass for every ray that stepped,
// and a ray that left the grid (x = -1) or found its hit keeps its voxel state, as
// actualizarVoxel's own test (x >= 0) gives. The voxel coordinates it reads are small integers,
// exact in every format, so the register equals what the texture would hold. One branch, the
// traversal's: only a ray that walks can enter a voxel.
struct TraverseUpdate {
  static constexpr const char* name = "traversal + update voxel";
  static constexpr const char* paper_name = "traversal+actualizarVoxel";
  static constexpr int outputs = 2;  // -> traversal, voxel state
  enum Unit { kOrigins, kRays, kTraversal, kIntersection, kVoxelState, kPointers, kLists };
  static constexpr std::array<const char*, 7> units{
      "origins",     "rays",           "traversal",     "intersection",
      "voxel_state", "voxel_pointers", "triangle_lists"};
  static constexpr std::array<int, 2> passthrough{kTraversal, kVoxelState};

  GridUniforms grid;

  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    const Vec4<F> trav = f.fetch_own(kTraversal);
    const Vec4<F> hit = f.fetch_own(kIntersection);
    const Vec3<F> o = f.fetch_own(kOrigins).xyz();
    const Vec4<F> ray = f.fetch_own(kRays);
    const Vec4<F> vs = f.fetch_own(kVoxelState);
    const auto walking = trav.x >= F(0.0f);
    Vec4<F> stepped = trav, next = vs;
    if (f.branch(walking)) {
      stepped = dda_step<L>(trav, hit, o, ray.xyz(), ray.w, walking, grid);
      const auto load = (stepped.x >= F(0.0f)) && (vs.w < F(0.0f));
      next = first_in_voxel(f, kPointers, kLists, stepped, vs, load, grid);
    }
    f.out(0) = stepped;
    f.out(1) = next;
  }
};

}  // namespace kernels
