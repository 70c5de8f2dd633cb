// The compiled programs of the ray kernels: generadorRayos, rayosSombra, inicioReflejo,
// direccionReflejo, shader, rayosReflejados, and supersampling's generadorRayosMuestra,
// acumularMuestras, resolverMuestras, and adaptive sampling's guardarImpactos,
// marcarPixeles, pixelesMarcados, guardarConos, guardarReflejos, marcarConos, puntuarConos,
// pixelesPuntuados, cortarPuntajes, and undersampling's marcarReticula, marcarHuecos,
// rellenarHuecos (kernels/kernels.h declares them; every lane family of each is compiled here,
// once).
#include "kernels/cone_budget.h"
#include "kernels/cones.h"
#include "kernels/kernels.h"

template class vgpu::KernelProgram<kernels::GenerateRays>;
template class vgpu::KernelProgram<kernels::ShadowRays>;
template class vgpu::KernelProgram<kernels::ReflectionOrigin>;
template class vgpu::KernelProgram<kernels::ReflectionDirection>;
template class vgpu::KernelProgram<kernels::Shader>;
template class vgpu::KernelProgram<kernels::ReflectedRays>;
template class vgpu::KernelProgram<kernels::GenerateSampleRays>;
template class vgpu::KernelProgram<kernels::AccumulateSamples>;
template class vgpu::KernelProgram<kernels::ResolveSamples>;
template class vgpu::KernelProgram<kernels::KeepHits>;
template class vgpu::KernelProgram<kernels::MarkPixels>;
template class vgpu::KernelProgram<kernels::MarkedPixels>;
template class vgpu::KernelProgram<kernels::KeepCones>;
template class vgpu::KernelProgram<kernels::KeepReflected>;
template class vgpu::KernelProgram<kernels::MarkCones>;
template class vgpu::KernelProgram<kernels::ScoreCones>;
template class vgpu::KernelProgram<kernels::ScoredHits>;
template class vgpu::KernelProgram<kernels::CutScores>;
template class vgpu::KernelProgram<kernels::MarkLattice>;
template class vgpu::KernelProgram<kernels::MarkGaps>;
template class vgpu::KernelProgram<kernels::FillGaps>;
