// The compiled programs of the two-level grid walk's kernels (kernels/grid2.h; an extension):
// inicioGrilla2, recorridoGrilla2, cargarCelda, interseccionesGrilla2, their fused --mrt on forms
// and the looping walk. kernels/kernel_list.h assigns them to this file; every lane family of each
// is compiled here, once.
#define VGPU_PROGRAMS_grid2(K) template class vgpu::KernelProgram<kernels::K>;
#include "kernels/compile_programs.h"
