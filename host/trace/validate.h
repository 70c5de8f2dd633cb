// The one validation of a render's options (issue 47): every check of an option's value or of a
// combination of options that can be decided before anything is built, in one function. The
// command line (host/cli/render.cpp) calls it once before it loads the scene and prints one line
// per refused option (exit 2); the Python module runs the same render and raises one ValueError
// with the same lines; bench_gl calls it for every frame it will run before it loads a scene; the
// stream tracer's constructor calls it again, so that a program that skips the command line is
// refused too (vgpu::Error). What stays elsewhere: a file's own errors where the file is read
// (an unreadable glTF, an animation the file does not have), an output path where it is checked,
// and the limits that only a built structure knows (the texture atlas against the profile's
// texture size, a format's reach over the built structure's indices) at the build.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "host/trace/render_options.h"
#include "vgpu/profile.h"

namespace host {

struct Scene;

// One refused option: the option as the command line names it ("--mrt"), its value as given
// ("on"; empty for a flag, or where there is none), and why: the whole line the command line
// prints after "vgpu-rt: " (it names the option itself, in the words users and tests know).
struct Refusal {
  std::string option, value, why;
  bool operator==(const Refusal&) const = default;
};

// What the command line (and the Python module, which runs it) was asked beyond RenderOptions,
// as written, for the checks that read it; a library caller passes none. Defaults: the command
// line's.
struct Request {
  std::string engine = "stream";            // --engine: stream, gl or cpu
  std::string accel = "grid";               // --accel
  std::string beams = "off";                // --beams: off, on or auto
  std::string precision = "fp32";           // --precision
  std::string formats;                      // --formats (empty: not given)
  std::string aa = "none";                  // --aa
  std::optional<std::string> aa_criterion;  // --aa-criterion, when given
  std::string size = "256x256";             // --size
  std::string trace_pixel;                  // --trace-pixel (empty: not given)
  bool predict = false, lanes_given = false, steps_given = false, walk_given = false;
  std::string time, frames, animation;  // --time, --frames, --animation (empty: not given)
  std::string update = "rebuild";       // --update
  bool update_given = false;
  size_t frame_count = 1;  // the frames --time or --frames render
  int report_frame = 0;    // --report-frame (0: not given)
  // The image files each frame writes (--out, --aov), and whether the file name holds the '#'
  // of a frame number (host/cli/frames.h: has_frame_number).
  struct File {
    std::string option, path;
    bool numbered = false;
  };
  std::vector<File> files;
  bool report = false, stats_csv = false;  // --report, --stats-csv given
  std::string gl_device = "auto", gl_readback = "auto";
  bool observer = false;          // a caller follows the passes (Python's passes())
  int64_t report_max_pixels = 0;  // --report's largest image (host/report; 0: no limit)
};

// Every refused option of `opt` on `profile`, in the order the command line always checked them,
// one per option (the first reason for it); empty: these options run. `request`: the command
// line's options, for its own checks (nullptr: a library call, RenderOptions alone); `scene`,
// once loaded, for the checks that need it (a glass scene's ray streams and --trace-pixel).
// The MRT formats check reads `opt.formats`: resolved, or fp32 everywhere before that.
std::vector<Refusal> validate(const RenderOptions& opt, const vgpu::Profile& profile,
                              const Request* request = nullptr, const Scene* scene = nullptr);

// The refusals' lines, "\n" between them.
std::string refusal_lines(const std::vector<Refusal>& refusals);

// For library callers (the stream tracer): nothing when `refusals` is empty, else throws
// std::invalid_argument for a sample count that is not a square from 1 to 256 (the first
// refusal), vgpu::Error with refusal_lines otherwise.
void throw_refusals(const std::vector<Refusal>& refusals);

}  // namespace host
