// The compiled programs of the triangle tests: intersecciones, proximoTriangulo,
// rayosIntersectando. kernels/kernel_list.h assigns them to this file; every lane family of each is
// compiled here, once.
#define VGPU_PROGRAMS_hits(K) template class vgpu::KernelProgram<kernels::K>;
#include "kernels/compile_programs.h"
