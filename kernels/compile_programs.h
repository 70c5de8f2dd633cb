// Included by each kernels/programs_<file>.cpp after it defines VGPU_PROGRAMS_<file>(K): compiles
// the programs of the kernels that kernels/kernel_list.h assigns to that file, and of no other.
// (No include guard: one programs_*.cpp includes it once.)
#include "kernels/kernels.h"

#ifndef VGPU_PROGRAMS_beams
#define VGPU_PROGRAMS_beams(K)
#endif
#ifndef VGPU_PROGRAMS_bvh
#define VGPU_PROGRAMS_bvh(K)
#endif
#ifndef VGPU_PROGRAMS_fused
#define VGPU_PROGRAMS_fused(K)
#endif
#ifndef VGPU_PROGRAMS_grid2
#define VGPU_PROGRAMS_grid2(K)
#endif
#ifndef VGPU_PROGRAMS_hits
#define VGPU_PROGRAMS_hits(K)
#endif
#ifndef VGPU_PROGRAMS_kdtree
#define VGPU_PROGRAMS_kdtree(K)
#endif
#ifndef VGPU_PROGRAMS_rays
#define VGPU_PROGRAMS_rays(K)
#endif
#ifndef VGPU_PROGRAMS_streams
#define VGPU_PROGRAMS_streams(K)
#endif
#ifndef VGPU_PROGRAMS_walk
#define VGPU_PROGRAMS_walk(K)
#endif

// An explicit instantiation after kernels.h's extern declaration: this file's copy is the one.
#define VGPU_COMPILE_PROGRAM(K, file) VGPU_PROGRAMS_##file(K)
VGPU_ALL_KERNELS(VGPU_COMPILE_PROGRAM)
#undef VGPU_COMPILE_PROGRAM
