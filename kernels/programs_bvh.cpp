// The compiled programs of the BVH walk's kernels (kernels/bvh.h; an extension): inicioBVH,
// recorridoBVH, cargarHoja, interseccionesBVH, their fused --mrt on forms and the looping walk.
#include "kernels/kernels.h"

template class vgpu::KernelProgram<kernels::BvhEnter>;
template class vgpu::KernelProgram<kernels::BvhStep>;
template class vgpu::KernelProgram<kernels::BvhLoadLeaf>;
template class vgpu::KernelProgram<kernels::BvhIntersections>;
template class vgpu::KernelProgram<kernels::BvhStepLoad>;
template class vgpu::KernelProgram<kernels::BvhIntersectNext>;
template class vgpu::KernelProgram<kernels::BvhLooping>;
