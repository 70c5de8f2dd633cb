// The compiled programs of the kd-tree walk's kernels (kernels/kdtree.h; an extension): inicioKd,
// recorridoKd, cargarHojaKd, interseccionesKd, their fused --mrt on forms and the looping walk.
#include "kernels/kernels.h"

template class vgpu::KernelProgram<kernels::KdEnter>;
template class vgpu::KernelProgram<kernels::KdStep>;
template class vgpu::KernelProgram<kernels::KdLoadLeaf>;
template class vgpu::KernelProgram<kernels::KdIntersections>;
template class vgpu::KernelProgram<kernels::KdStepLoad>;
template class vgpu::KernelProgram<kernels::KdIntersectNext>;
template class vgpu::KernelProgram<kernels::KdLooping>;
