// The compiled programs of the BVH walk's kernels (kernels/bvh.h; an extension): inicioBVH,
// recorridoBVH, cargarHoja, interseccionesBVH, their fused --mrt on forms and the looping walk.
// kernels/kernel_list.h assigns them to this file; every lane family of each is compiled here,
// once.
#define VGPU_PROGRAMS_bvh(K) template class vgpu::KernelProgram<kernels::K>;
#include "kernels/compile_programs.h"
