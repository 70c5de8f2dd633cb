// The compiled programs of glass's ray streams (issue 25): dividirRayos, sumaPrefijos,
// contarRayos, compactarRayos, copiarFilas, reunirHijos and sombraVidrio (kernels/kernels.h
// declares them; every lane family of each is compiled here, once).
#include "kernels/kernels.h"

template class vgpu::KernelProgram<kernels::SplitRays>;
template class vgpu::KernelProgram<kernels::ScanStream>;
template class vgpu::KernelProgram<kernels::CountStream>;
template class vgpu::KernelProgram<kernels::CompactStream>;
template class vgpu::KernelProgram<kernels::CopyRows>;
template class vgpu::KernelProgram<kernels::GatherChildren>;
template class vgpu::KernelProgram<kernels::ShadowGlass>;
// Sampling that saves time (issue 35): compactarMarcados, generadorRayosDensos, reunirMarcados.
template class vgpu::KernelProgram<kernels::CompactMarks>;
template class vgpu::KernelProgram<kernels::GenerateDenseRays>;
template class vgpu::KernelProgram<kernels::GatherMarked>;
template class vgpu::KernelProgram<kernels::AccumulateDense>;
