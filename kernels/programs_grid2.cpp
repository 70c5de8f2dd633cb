// The compiled programs of the two-level grid walk's kernels (kernels/grid2.h; an extension):
// inicioGrilla2, recorridoGrilla2, cargarCelda, interseccionesGrilla2, their fused --mrt on forms
// and the looping walk.
#include "kernels/kernels.h"

template class vgpu::KernelProgram<kernels::Grid2Enter>;
template class vgpu::KernelProgram<kernels::Grid2Step>;
template class vgpu::KernelProgram<kernels::Grid2LoadCell>;
template class vgpu::KernelProgram<kernels::Grid2Intersections>;
template class vgpu::KernelProgram<kernels::Grid2StepLoad>;
template class vgpu::KernelProgram<kernels::Grid2IntersectNext>;
template class vgpu::KernelProgram<kernels::Grid2Looping>;
