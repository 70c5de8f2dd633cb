// The compiled programs of beams over tiles (kernels/beams.h, bvh_beams.h, grid2_beams.h):
// rayosHaz, the entries, the tree descents and the count of tiles that miss. kernels/kernel_list.h
// assigns them to this file; every lane family of each is compiled here, once.
#define VGPU_PROGRAMS_beams(K) template class vgpu::KernelProgram<kernels::K>;
#include "kernels/compile_programs.h"
