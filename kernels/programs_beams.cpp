// The compiled programs of beams over tiles (kernels/beams.h, bvh_beams.h, grid2_beams.h):
// rayosHaz, the entries, the tree descents and the count of tiles that miss (every lane family
// of each is compiled here, once).
#include "kernels/kernels.h"

template class vgpu::KernelProgram<kernels::BeamMarch>;
template class vgpu::KernelProgram<kernels::BeamMarchLooping>;
template class vgpu::KernelProgram<kernels::BeamEntry>;
template class vgpu::KernelProgram<kernels::BeamsMissed>;
template class vgpu::KernelProgram<kernels::BvhBeamDescend>;
template class vgpu::KernelProgram<kernels::BvhBeamDescendLooping>;
template class vgpu::KernelProgram<kernels::BvhBeamEnter>;
template class vgpu::KernelProgram<kernels::BvhBeamsDescending>;
template class vgpu::KernelProgram<kernels::Grid2BeamEntry>;
