// The lane widths the project's kernels run at in this build: 1, 4, 8 and 16, but 1 and 8 only
// in the sanitizer build, which compiles no others (VGPU_KERNEL_WIDTHS_1_8, vgpu/program.h).
// Tests that run the project's kernels at 4 or 16 lanes skip those widths there; the Release
// build runs them all. (Kernels a test defines itself run at every width in both.)
#pragma once

namespace test_support {

constexpr bool kernel_width_built(int lanes) {
#ifdef VGPU_KERNEL_WIDTHS_1_8
  return lanes == 1 || lanes == 8;
#else
  return lanes == 1 || lanes == 4 || lanes == 8 || lanes == 16;
#endif
}

}  // namespace test_support
