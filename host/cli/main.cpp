// vgpu-rt: the command line. `render` runs the stream ray tracer on the virtual GPU and prints
// the pass statistics (the render itself: render.h, a library call the Python module makes too;
// its options: options.h; a moving scene's frames: frames.h); `scenes` lists the bundled
// scenes; `compare` diffs two images.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "host/cli/commands.h"
#include "host/cli/options.h"
#include "host/cli/render.h"
#include "host/common/version.h"
#include "host/image/image_io.h"
#include "host/report/report.h"
#include "host/scene/animation.h"
#include "host/scene/gltf_loader.h"

namespace {

using cli::RenderArgs;
using cli::run_gl_devices;
using cli::run_kernels;
using cli::run_render;
using cli::UsageError;

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "vgpu-rt: a virtual 2004 GPU and the stream ray tracer of Fal, Vasconcelos & "
      "Delrieux (after Purcell et al. 2002)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("vgpu-rt ") + host::version(),
                       "Print the version and exit");
  RenderArgs a;
  auto* render = app.add_subcommand(
      "render", "Render a scene on the virtual GPU and print the pass statistics");
  cli::add_render_options(*render, a);
  auto* scenes = app.add_subcommand(
      "scenes",
      "List the scenes in scenes/, or the glTF files named: triangles and animations (index, "
      "name, key times, duration; render --time/--frames plays them all together by default)");
  std::vector<std::string> scene_files;
  scenes->add_option("files", scene_files, "glTF files to list instead of the bundled scenes");
  std::string kernel_name;
  bool kernel_glsl = false;
  auto* kernels_cmd = app.add_subcommand(
      "kernels", "List the fragment programs (kernels), or print one as its generated GLSL");
  kernels_cmd->add_option("name", kernel_name, "A kernel's name or paper name (e.g. traversal)");
  kernels_cmd->add_flag("--glsl", kernel_glsl,
                        "Print the GLSL fragment shader generated from the kernel's C++ functor");
  auto* gl_devices = app.add_subcommand("gl-devices", "List the EGL devices --gl-device can pick");
  std::string ca, cb;
  double threshold = 1.0 / 255.0;
  auto* compare = app.add_subcommand(
      "compare", "Compare two images (OpenImageIO): differing pixels, RMS, PSNR");
  compare->add_option("a", ca, "First image")->required()->check(CLI::ExistingFile);
  compare->add_option("b", cb, "Second image")->required()->check(CLI::ExistingFile);
  compare->add_option("--threshold", threshold, "Per-channel difference that makes a pixel differ")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();

  std::string da, db;
  auto* diff = app.add_subcommand(
      "diff", "Two runs' --stats-json side by side: per kernel and in total, B - A and B / A");
  diff->add_option("a", da, "First --stats-json file")->required();
  diff->add_option("b", db, "Second --stats-json file")->required();

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "vgpu-rt: %s (see vgpu-rt --help)\n", e.what());
    return 2;
  }
  try {
    if (*render) return run_render(a, render->count("--lanes") > 0);
    if (*scenes) return cli::run_scenes(scene_files);
    if (*diff) {
      std::cout << host::diff_stats(da, db);
      return 0;
    }
    if (*kernels_cmd) return run_kernels(kernel_name, kernel_glsl);
    if (*gl_devices) return run_gl_devices();
    if (*compare) {
      const host::ImageComparison c = host::compare_images(ca, cb, threshold);
      std::printf(
          "%dx%d, %d channels: %.4f%% of pixels differ by more than %g; RMS %.6g, PSNR %.2f dB, "
          "max %.6g\n",
          c.width, c.height, c.channels, 100.0 * c.differing_share, c.threshold, c.rms_error,
          c.psnr, c.max_error);
      return 0;
    }
  } catch (const UsageError& e) {  // one line per refused option (host::validate)
    const std::string lines = e.what();
    for (size_t start = 0; start <= lines.size();) {
      const size_t end = std::min(lines.find('\n', start), lines.size());
      std::fprintf(stderr, "vgpu-rt: %s\n", lines.substr(start, end - start).c_str());
      start = end + 1;
    }
    return 2;
  } catch (const host::UnsupportedFeature& e) {  // a feature a frame at a time cannot honour
    std::fprintf(stderr, "vgpu-rt: %s\n", e.what());
    return 2;
  } catch (const host::InputError& e) {  // a bad input file (or output path): the user's to fix
    std::fprintf(stderr, "vgpu-rt: %s\n", e.what());
    return 2;
  } catch (const vgpu::LimitError& e) {  // the scene outgrows the card or the structure
    std::fprintf(stderr, "vgpu-rt: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "vgpu-rt: %s\n", e.what());
    return 1;
  }
  return 0;
}
