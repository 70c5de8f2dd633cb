// The compiled programs of the kd-tree walk's kernels (kernels/kdtree.h; an extension): inicioKd,
// recorridoKd, cargarHojaKd, interseccionesKd, their fused --mrt on forms and the looping walk.
// kernels/kernel_list.h assigns them to this file; every lane family of each is compiled here,
// once.
#define VGPU_PROGRAMS_kdtree(K) template class vgpu::KernelProgram<kernels::K>;
#include "kernels/compile_programs.h"
