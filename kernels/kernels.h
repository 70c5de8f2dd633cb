// The paper's fragment programs (and the shadow-ray extension), one functor per file, and the
// fused two-output programs --mrt on runs (kernels/fused.h), and the ray streams of glass
// (dividirRayos, sumaPrefijos, contarRayos, compactarRayos, copiarFilas, reunirHijos,
// sombraVidrio).
#pragma once

#include "kernels/accumulate_samples.h"
#include "kernels/beams.h"
#include "kernels/bvh.h"
#include "kernels/bvh_beams.h"
#include "kernels/compact_marks.h"
#include "kernels/compact_stream.h"
#include "kernels/cone_budget.h"
#include "kernels/cones.h"
#include "kernels/copy_rows.h"
#include "kernels/count_stream.h"
#include "kernels/fused.h"
#include "kernels/gather_children.h"
#include "kernels/generate_rays.h"
#include "kernels/grid2.h"
#include "kernels/grid2_beams.h"
#include "kernels/init_traversal.h"
#include "kernels/intersections.h"
#include "kernels/kdtree.h"
#include "kernels/keep_hits.h"
#include "kernels/kernel_list.h"
#include "kernels/looping_traversal.h"
#include "kernels/mark_pixels.h"
#include "kernels/next_triangle.h"
#include "kernels/rays_in_grid.h"
#include "kernels/rays_intersecting.h"
#include "kernels/reflected_rays.h"
#include "kernels/reflection_direction.h"
#include "kernels/reflection_origin.h"
#include "kernels/reset_traversal.h"
#include "kernels/resolve_samples.h"
#include "kernels/scan_stream.h"
#include "kernels/shader.h"
#include "kernels/shadow_glass.h"
#include "kernels/shadow_rays.h"
#include "kernels/split_rays.h"
#include "kernels/traversal.h"
#include "kernels/undersample.h"
#include "kernels/update_voxel.h"
#include "vgpu/program.h"

// Each kernel's program (its run at every lane family: widths 1, 4, 8, 16, fp24/fp16 rounding,
// counting, recording) is compiled once, in the kernels/programs_*.cpp that kernels/kernel_list.h
// names for it: a file that includes this header and makes a vgpu::KernelProgram<K> links to that
// copy instead of compiling its own.
#ifdef VGPU_KERNEL_WIDTHS_1_8  // the sanitizer build (vgpu/program.h, kEveryLaneWidth)
namespace vgpu {
#define VGPU_NARROW_PROGRAM(K, file) \
  template <>                        \
  inline constexpr bool kEveryLaneWidth<kernels::K> = false;
VGPU_ALL_KERNELS(VGPU_NARROW_PROGRAM)
#undef VGPU_NARROW_PROGRAM
}  // namespace vgpu
#endif
#define VGPU_EXTERN_PROGRAM(K, file) extern template class vgpu::KernelProgram<kernels::K>;
VGPU_ALL_KERNELS(VGPU_EXTERN_PROGRAM)
#undef VGPU_EXTERN_PROGRAM
