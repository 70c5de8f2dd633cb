// The compiled programs of the triangle tests: intersecciones, proximoTriangulo, rayosIntersectando
// (kernels/kernels.h declares them; every lane family of each is compiled here, once).
#include "kernels/kernels.h"

template class vgpu::KernelProgram<kernels::Intersections>;
template class vgpu::KernelProgram<kernels::NextTriangle>;
template class vgpu::KernelProgram<kernels::RaysIntersecting>;
