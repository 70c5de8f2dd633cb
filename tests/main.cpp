// The doctest runner shared by every test executable.
//
// Sweeps: a test that repeats one check over every bundled scene, structure or thread count is
// marked `* doctest::test_suite("sweep")`. The sanitizer build (VGPU_SANITIZE) leaves the sweeps
// out, both from the list CTest registers and from a run, because under the sanitizers they cost
// minutes and reach the code that a single instance (a test of its own) already reaches; the
// README's build runs every test. docs/studies/speed.md has the figures.
#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

int main(int argc, char** argv) {
  doctest::Context context;
#ifdef VGPU_TEST_SKIP_SWEEPS
  context.addFilter("test-suite-exclude", "sweep");
#endif
  context.applyCommandLine(argc, argv);
  return context.run();
}
