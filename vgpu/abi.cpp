#include "vgpu/abi.h"

#include <cstring>
#include <stdexcept>

namespace vgpu {

AbiTag library_abi() {
  return VGPU_ABI_HERE;
}

std::string describe(const AbiTag& tag) {
  return std::string(tag.isa) + ", SimdLanes<8>::F = " + tag.lanes8;
}

void check_abi(const AbiTag& here) {
  const AbiTag lib = library_abi();
  if (std::strcmp(here.lanes8, lib.lanes8) == 0 && std::strcmp(here.isa, lib.isa) == 0) return;
  throw std::logic_error(
      "a fragment program was compiled with other target flags than the vgpu library (program: " +
      describe(here) + "; library: " + describe(lib) +
      "): compile it with the library's flags, which linking the CMake target vgpu_rt::vgpu "
      "adds (-march and -ffp-contract=off)");
}

}  // namespace vgpu
