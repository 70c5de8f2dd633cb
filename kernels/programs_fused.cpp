// The compiled programs of the fused programs of --mrt on and the looping traversal
// (kernels/kernels.h declares them; every lane family of each is compiled here, once).
#include "kernels/kernels.h"

template class vgpu::KernelProgram<kernels::IntersectNext>;
template class vgpu::KernelProgram<kernels::TraverseUpdate>;
template class vgpu::KernelProgram<kernels::LoopingTraversal>;
