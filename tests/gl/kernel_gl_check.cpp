// Switches on, for test_gl only, the GL comparison of every kernel-test pass
// (tests/kernels/kernel_pass.h, gl_check): set during static initialisation, before doctest
// runs any test.
#include "tests/gl/gl_compare.h"
#include "tests/kernels/kernel_pass.h"

namespace {

[[maybe_unused]] const bool gl_check_on = (ktest::gl_check() = &gltest::check_same_targets, true);

}  // namespace
