// The compiled programs of the grid walk's kernels: initTraversal, reinicializarTraversal,
// traversal, rayosEnGrilla, actualizarVoxel. kernels/kernel_list.h assigns them to this file; every
// lane family of each is compiled here, once.
#define VGPU_PROGRAMS_walk(K) template class vgpu::KernelProgram<kernels::K>;
#include "kernels/compile_programs.h"
