// The target flags a program must share with the library (CMakeLists.txt, vgpu_abi, says why):
// the lane types of SimdLanes<8> depend on -march, so a kernel compiled without the library's
// flags overrides Program::run for other types than the library calls, and reads its fragments
// with another layout. Program's constructor takes the tag of the code that constructs it (the
// default argument is evaluated there, in the kernel's own translation unit) and refuses one
// that differs from the library's, naming both.
#pragma once

#include <string>
#include <typeinfo>

#include "vgpu/lanes.h"

#if defined(__AVX2__) && defined(__FMA__)
#define VGPU_ISA_HERE "avx2+fma"
#elif defined(__AVX__)
#define VGPU_ISA_HERE "avx"
#else
#define VGPU_ISA_HERE "sse"
#endif
// The tag of the translation unit that expands it.
#define VGPU_ABI_HERE                                     \
  ::vgpu::AbiTag {                                        \
    typeid(::vgpu::SimdLanes<8>::F).name(), VGPU_ISA_HERE \
  }

namespace vgpu {

struct AbiTag {
  const char* lanes8 = "";  // the mangled name of SimdLanes<8>::F
  const char* isa = "";     // the vector instructions the compiler was allowed
};

// The library's own tag (compiled with its flags).
AbiTag library_abi();
// "avx2+fma, SimdLanes<8>::F = <mangled name>".
std::string describe(const AbiTag& tag);
// Throws std::logic_error when `here` differs from library_abi(): one line naming both and the
// fix (link the vgpu_rt::vgpu target, which carries the flags).
void check_abi(const AbiTag& here);

}  // namespace vgpu
