// The compiled programs of the fused programs of --mrt on and the looping traversal.
// kernels/kernel_list.h assigns them to this file; every lane family of each is compiled here,
// once.
#define VGPU_PROGRAMS_fused(K) template class vgpu::KernelProgram<kernels::K>;
#include "kernels/compile_programs.h"
