// The compiled programs of the grid walk's kernels: initTraversal, reinicializarTraversal,
// traversal, rayosEnGrilla, actualizarVoxel (kernels/kernels.h declares them; every lane family of
// each is compiled here, once).
#include "kernels/kernels.h"

template class vgpu::KernelProgram<kernels::InitTraversal>;
template class vgpu::KernelProgram<kernels::ResetTraversal>;
template class vgpu::KernelProgram<kernels::Traversal>;
template class vgpu::KernelProgram<kernels::RaysInGrid>;
template class vgpu::KernelProgram<kernels::UpdateVoxel>;
