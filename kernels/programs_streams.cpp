// The compiled programs of glass's ray streams (issue 25): dividirRayos, sumaPrefijos, contarRayos,
// compactarRayos, copiarFilas, reunirHijos and sombraVidrio; and of sampling that saves time (issue
// 35): compactarMarcados, generadorRayosDensos, reunirMarcados. kernels/kernel_list.h assigns them
// to this file; every lane family of each is compiled here, once.
#define VGPU_PROGRAMS_streams(K) template class vgpu::KernelProgram<kernels::K>;
#include "kernels/compile_programs.h"
