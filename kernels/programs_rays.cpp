// The compiled programs of the ray kernels: generadorRayos, rayosSombra, inicioReflejo,
// direccionReflejo, shader, rayosReflejados, and supersampling's generadorRayosMuestra,
// acumularMuestras, resolverMuestras, and adaptive sampling's guardarImpactos, marcarPixeles,
// pixelesMarcados, guardarConos, guardarReflejos, marcarConos, puntuarConos, pixelesPuntuados,
// cortarPuntajes, and undersampling's marcarReticula, marcarHuecos, rellenarHuecos.
// kernels/kernel_list.h assigns them to this file; every lane family of each is compiled here,
// once.
#define VGPU_PROGRAMS_rays(K) template class vgpu::KernelProgram<kernels::K>;
#include "kernels/compile_programs.h"
