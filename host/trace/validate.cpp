// The one validation of a render's options (host/trace/validate.h): the command line's checks,
// then those of RenderOptions alone (which every library caller meets too), then the scene's.
#include "host/trace/validate.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "host/accel/accel.h"
#include "host/model/formats.h"
#include "host/trace/mrt.h"
#include "host/trace/sampling.h"
#include "host/trace/stream/devices.h"
#include "host/trace/stream/ray_streams.h"
#include "vgpu/device.h"

namespace host {

namespace {

// The refusals so far, one per option (the first reason for each).
class Refusals {
 public:
  void add(std::string option, std::string value, std::string why) {
    for (const Refusal& r : list_)
      if (r.option == option) return;
    list_.push_back({std::move(option), std::move(value), std::move(why)});
  }
  std::vector<Refusal> take() { return std::move(list_); }

 private:
  std::vector<Refusal> list_;
};

// A share as the command line writes it: a percentage, "%g".
std::string percent(float share) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", double(share) * 100.0);
  return text;
}

bool reduced_precision(const Request& q) {
  return q.precision != "fp32" || !q.formats.empty();
}

// The command line's options that only it has (the engine, the files, the animation), and their
// combinations with RenderOptions.
void check_command_line(const RenderOptions& opt, const Request& q, Refusals& out) {
  // --aa-criterion: budget unless given; only adaptive sampling reads it.
  if (q.aa_criterion && *q.aa_criterion != "image" && !opt.adaptive)
    out.add("--aa-criterion", *q.aa_criterion,
            "--aa-criterion " + *q.aa_criterion +
                " decides where adaptive sampling refines: add --aa adaptive");
  try {
    parse_format_request(q.precision, q.formats);
  } catch (const std::invalid_argument& e) {
    if (q.formats.empty())
      out.add("--precision", q.precision, e.what());
    else
      out.add("--formats", q.formats, e.what());
  }
  if (opt.trace_pixel && (opt.trace_pixel->x >= opt.width || opt.trace_pixel->y >= opt.height))
    out.add("--trace-pixel", q.trace_pixel,
            "--trace-pixel: " + q.trace_pixel + " is outside the " + q.size + " image");
  if (q.engine != "stream" && q.engine != "cpu" && q.engine != "gl")
    out.add("--engine", q.engine, "--engine: expected stream, cpu or gl, got '" + q.engine + "'");
  // Settings the CPU reference does not use are refused rather than recorded as if they ran.
  if (q.engine == "cpu") {
    const char* unused = q.predict                ? "--predict"
                         : !q.trace_pixel.empty() ? "--trace-pixel"
                         : q.lanes_given          ? "--lanes"
                         : opt.masks              ? "--masks on"
                         : opt.mrt                ? "--mrt on"
                         : q.precision != "fp32"  ? "--precision"
                         : !q.formats.empty()     ? "--formats"
                         : opt.looping            ? "--kernels looping"
                         : opt.ray_streams        ? "--ray-streams on"
                                                  : nullptr;
    if (unused) {
      const std::string text = unused, option = text.substr(0, text.find(' '));
      out.add(option, text.size() > option.size() ? text.substr(option.size() + 1) : "",
              text +
                  " needs --engine stream (the cpu engine is a double-precision reference "
                  "without passes, lanes or masks)");
    }
  }
  if (opt.beams && q.accel == "auto")
    out.add("--beams", "on",
            "--beams on: beams go through the structure the frame walks, and --accel auto has "
            "not chosen it yet: name one (--accel " +
                accel_names(" or ") + "), or with --accel auto, --beams auto");
  if (opt.beams && reduced_precision(q))
    out.add("--beams", "on",
            "--beams on needs fp32 ray state (no --precision or --formats): the beam "
            "entry reaches the voxel the walk would only where both round as fp32");
  if (opt.beam_tile != 8 && q.beams == "off")
    out.add("--beam-tile", std::to_string(opt.beam_tile), "--beam-tile needs --beams on or auto");
  if (q.steps_given && !opt.looping)
    out.add("--steps-per-pass", std::to_string(opt.steps_per_pass),
            "--steps-per-pass needs --kernels looping");
}

// The command line's animation and output options.
void check_frames(const RenderOptions& opt, const Request& q, Refusals& out) {
  const bool animating = !q.time.empty() || !q.frames.empty();
  // Both given: the frame count is in question, so the checks that count frames wait for one.
  const bool both = !q.time.empty() && !q.frames.empty();
  if (both) out.add("--time", q.time, "--time and --frames: give one (--frames A:A:1 is --time A)");
  if (!animating && (!q.animation.empty() || q.update_given)) {
    const bool animation = !q.animation.empty();
    out.add(animation ? "--animation" : "--update", animation ? q.animation : q.update,
            std::string(animation ? "--animation" : "--update") + " needs --time or --frames");
  }
  if (q.update != "rebuild" && q.accel != "bvh")
    out.add("--update", q.update,
            "--update " + q.update +
                ": only a BVH's boxes can be refitted (--accel bvh); the grid and the "
                "kd-tree are rebuilt (--update rebuild)");
  if (q.frame_count > 1 && !both) {
    for (const Request::File& f : q.files)
      if (!f.numbered)
        out.add(f.option, f.path,
                f.option + " " + f.path + ": " + std::to_string(q.frame_count) +
                    " frames need '#' in the file name for the frame number (e.g. "
                    "frame_####.png)");
    const char* one_frame = opt.trace_pixel  ? "--trace-pixel"
                            : q.report_frame ? nullptr
                            : q.report       ? "--report"
                            : q.stats_csv    ? "--stats-csv"
                                             : nullptr;
    if (one_frame)
      out.add(one_frame, "",
              std::string(one_frame) + " follows one frame: render it with --time T" +
                  (opt.trace_pixel ? "" : ", or name one of the frames with --report-frame K"));
  }
  if (q.report_frame) {
    const std::string k = std::to_string(q.report_frame);
    if (q.frames.empty())
      out.add("--report-frame", k,
              "--report-frame needs --frames (with --time the report is that frame's)");
    if (!q.report && !q.stats_csv)
      out.add("--report-frame", k, "--report-frame needs --report or --stats-csv");
    if (size_t(q.report_frame) > q.frame_count && !both)
      out.add("--report-frame", k,
              "--report-frame " + k + ": --frames " + q.frames + " gives " +
                  std::to_string(q.frame_count) + " frame" + (q.frame_count > 1 ? "s" : "") +
                  ", numbered from 1");
  }
  if (q.walk_given && q.engine != "stream")
    out.add("--walk", opt.batch_walk ? "batches" : "passes",
            "--walk needs --engine stream (it says how the emulator runs the walk)");
  // Reduced precision runs at 1 or 8 lanes (vgpu/gpu.cpp): refuse another width.
  if (reduced_precision(q) && opt.lanes != 1 && opt.lanes != 8)
    out.add("--lanes", std::to_string(opt.lanes),
            "--lanes " + std::to_string(opt.lanes) + ": --precision " + q.precision +
                " runs at 1 or 8 lanes");
}

// The command line's engines and files, checked after RenderOptions' own.
void check_engines(const RenderOptions& opt, const Request& q, Refusals& out) {
  if (q.engine != "stream" && (q.report || q.stats_csv))
    out.add(q.report ? "--report" : "--stats-csv", "",
            "--report and --stats-csv need --engine stream (the report reads the "
            "emulator's per-fragment state)");
  if (q.engine == "gl") {
    if (!have_gl_device())
      out.add("--engine", "gl",
              "--engine gl: this build has no GL device (EGL and OpenGL were not found when it "
              "was built; scripts/setup.sh installs them)");
    // The GL device runs every fragment in fp32 GLSL; the emulator-only features are refused.
    if (q.predict || !q.trace_pixel.empty() || opt.masks || q.precision != "fp32")
      out.add("--engine", "gl",
              "--engine gl runs the multipass pipeline as a driver does: --predict, "
              "--trace-pixel, --masks on and --precision fp24/fp16 need --engine stream");
  } else if (q.gl_device != "auto" || q.gl_readback != "auto") {
    const bool device = q.gl_device != "auto";
    out.add(device ? "--gl-device" : "--gl-readback", device ? q.gl_device : q.gl_readback,
            std::string(device ? "--gl-device" : "--gl-readback") + " needs --engine gl");
  }
  if (q.report && q.report_max_pixels > 0 && int64_t(opt.width) * opt.height > q.report_max_pixels)
    out.add("--report", "",
            "--report: at most " + std::to_string(q.report_max_pixels) + " pixels (512x512); got " +
                q.size);
  // A caller's observer (Python's pass by pass) follows one frame of the stream engine, as the
  // report does.
  if (q.observer) {
    if (q.report || q.stats_csv)
      out.add("observer", "", "a pass observer and --report or --stats-csv: give one");
    else if (q.engine != "stream")
      out.add("observer", "",
              "following the passes needs --engine stream (the cpu engine has none)");
    else if (q.frame_count > 1)
      out.add("observer", "", "following the passes follows one frame: render it with --time T");
  }
}

// --aa's text for the messages: as the command line wrote it, else the mode's own name.
std::string aa_text(const RenderOptions& opt, const Request* q) {
  if (q && !q->aa.empty() && q->aa != "none" && q->aa != "adaptive") return q->aa;
  return "undersample:" + std::to_string(opt.undersample);
}

// The combinations RenderOptions alone cannot run, whoever asks (the command line's words).
void check_options(const RenderOptions& opt, const vgpu::Profile& profile, const Request* q,
                   Refusals& out) {
  // The devices without stencil masks (the GL device); the command line refuses these options
  // on --engine gl in its own words.
  if (!opt.recorded_programs.empty() && opt.device != "vgpu")
    out.add("recorded_programs", "",
            "recorded programs run on the emulator's executor; the " + opt.device +
                " device runs every program from its recording already");
  if (!q && opt.device != "vgpu") {
    if (opt.masks)
      out.add("--masks", "on",
              "--masks on needs stencil masks, which the " + opt.device + " device does not have");
    if (opt.trace_pixel)
      out.add("--trace-pixel", "",
              "--trace-pixel follows the emulator's finished-ray masks, which the " + opt.device +
                  " device does not have");
  }
  // Undersampling traces one ray through each traced pixel; supersampling traces several.
  if (opt.undersample > 0 && opt.spp > 1)
    out.add("--spp", std::to_string(opt.spp),
            "--aa " + aa_text(opt, q) + " traces one ray per traced pixel; drop --spp " +
                std::to_string(opt.spp));
  // The command line cannot ask for these two (--aa is one mode); a program can.
  if (opt.undersample < 0 || (opt.undersample > 0 && opt.adaptive))
    out.add("--aa", aa_text(opt, q),
            "undersample: K must be 1 or more, with one ray per traced pixel (spp 1, not "
            "adaptive)");
  // The budget's shares of the pixels that hit (kernels/cone_budget.h).
  if (opt.adaptive && opt.aa_criterion == RenderOptions::AaCriterion::budget) {
    if (opt.aa_budget.empty()) out.add("--aa-budget", "", "--aa-budget: give one share or more");
    for (const float b : opt.aa_budget)
      if (!(b > 0.0f && b <= 1.0f))
        out.add("--aa-budget", percent(b),
                "--aa-budget: each share is a percentage of the pixels that hit, above 0 and at "
                "most 100");
  }
  if (opt.mrt && opt.looping)
    out.add("--mrt", "on",
            "--mrt on with --kernels looping: the looping program already writes the traversal, "
            "voxel and hit targets in one pass; there are no separate passes left to fuse");
  if (opt.beams && opt.beam_tile < 1)
    out.add("--beam-tile", std::to_string(opt.beam_tile),
            "--beam-tile: a tile is 1 pixel wide or more");
  // A tile's beam bounds its pixels' rays; a dense stream packs the marked pixels' rays into
  // rows where neighbours are no longer neighbours.
  if (opt.beams && opt.compact && (opt.adaptive || opt.undersample > 0))
    out.add("--beams", "on",
            "--beams on: a dense stream's rays are packed, not laid out by tile: add --compact "
            "off");
  // Beams start a ray in the voxel the walk would reach, found with fp32 arithmetic: exact only
  // where the ray state and the traversal are fp32 too.
  const Formats& fm = opt.formats;
  if (opt.beams &&
      (fm[Group::rays] != vgpu::Format::fp32 || fm[Group::traversal] != vgpu::Format::fp32 ||
       fm.arithmetic(Group::traversal) != vgpu::Format::fp32))
    out.add("--beams", "on",
            "--beams on: needs fp32 rays and traversal (texels and arithmetic): the beam entry "
            "reaches the voxel the walk would only where both round as fp32");
  // The fused programs' outputs against the profile's limit, and their groups' formats.
  if (opt.mrt)
    if (const std::string why = mrt_refusal(profile, fm); !why.empty()) out.add("--mrt", "on", why);
  // The sample count (the command line's --spp checks it as it is parsed, in the same words).
  if (const std::string why = spp_refusal(opt.spp); !why.empty())
    out.add("--spp", std::to_string(opt.spp), "--spp: " + why);
}

// The kernels of one's own (host/trace/user_stage.h): what the stage they replace binds and
// writes, and the modes built on the project's own kernel for it.
template <class U>
void check_user_stage(const char* option, const UserStage<U>* k, const char* stage_words,
                      const Scene* scene, Refusals& out) {
  if (!k) return;
  const vgpu::Program& p = k->program();
  const std::string who = std::string(option) + " '" + p.name() + "'";
  if (p.outputs() != 1)
    out.add(option, p.name(),
            who + " writes " + std::to_string(p.outputs()) + " outputs; the " + stage_words +
                " writes 1");
  const std::vector<std::string> units = k->units();
  std::string known;
  for (const char* u : U::units) known += std::string(known.empty() ? "" : ", ") + u;
  for (size_t i = 0; i < units.size(); ++i) {
    auto at = std::find(U::units.begin(), U::units.end(), units[i]);
    if (at == U::units.end()) {
      out.add(option, p.name(),
              who + ": unit " + std::to_string(i) + " '" + units[i] + "' is not a texture of the " +
                  stage_words + (known.empty() ? " (it binds none)" : " (it binds " + known + ")"));
      return;
    }
    // kernels::Shader's units from kOrigins on exist on a scene with base-colour textures.
    if constexpr (std::is_same_v<U, kernels::ShaderStage>)
      if (scene && scene->textures.empty() && at - U::units.begin() >= kernels::Shader::kOrigins &&
          units[i] != "origins") {
        out.add(option, p.name(),
                who + ": unit " + std::to_string(i) + " '" + units[i] +
                    "' holds base-colour textures, and this scene has none");
        return;
      }
  }
}

void check_user_kernels(const RenderOptions& opt, const Request* q, const Scene* scene,
                        Refusals& out) {
  const UserKernels& u = opt.user;
  if (!u.any()) return;
  check_user_stage("shader", u.shader.get(), "shading stage (one pass per light)", scene, out);
  check_user_stage("camera", u.camera.get(), "camera stage (the primary rays)", scene, out);
  const char* option = u.shader ? "shader" : "camera";
  const std::string name = (u.shader ? u.shader->program() : u.camera->program()).name();
  if (q && q->engine == "cpu")
    out.add(option, name,
            std::string(option) + " '" + name +
                "': the cpu engine runs no kernels (a double-precision reference); a kernel of "
                "your own needs --engine stream or gl");
  if (!u.camera) return;
  const std::string cam = "camera '" + std::string(u.camera->program().name()) + "'";
  if (opt.beams || (q && q->beams != "off"))
    out.add("camera", u.camera->program().name(),
            cam +
                ": --beams march the project's camera (generadorRayos) over tiles; a camera "
                "of your own needs --beams off");
  if (opt.adaptive || opt.undersample > 0)
    out.add("camera", u.camera->program().name(),
            cam + ": --aa " + (opt.adaptive ? std::string("adaptive") : aa_text(opt, q)) +
                " builds on the project's camera (gated sample rays, dense streams); a camera "
                "of your own takes --spp N (its jitter as uniforms) or no --aa");
}

}  // namespace

std::vector<Refusal> validate(const RenderOptions& opt, const vgpu::Profile& profile,
                              const Request* request, const Scene* scene) {
  Refusals out;
  if (request) {
    check_command_line(opt, *request, out);
    check_frames(opt, *request, out);
  }
  check_options(opt, profile, request, out);
  if (request) check_engines(opt, *request, out);
  check_user_kernels(opt, request, scene, out);
  // Ray streams (a scene with glass, or --ray-streams on) move a pixel's rays to other texels.
  if (opt.trace_pixel && (opt.ray_streams || (scene && scene_has_glass(*scene))))
    out.add("--trace-pixel", request ? request->trace_pixel : "",
            "--trace-pixel follows one pixel's ray, and ray streams (a glass scene or "
            "--ray-streams on) move a pixel's rays to other texels");
  return out.take();
}

std::string refusal_lines(const std::vector<Refusal>& refusals) {
  std::string lines;
  for (const Refusal& r : refusals) lines += (lines.empty() ? "" : "\n") + r.why;
  return lines;
}

void throw_refusals(const std::vector<Refusal>& refusals) {
  if (refusals.empty()) return;
  if (refusals.front().why.rfind("--spp: ", 0) == 0)  // as the tracer always threw it
    throw std::invalid_argument(refusal_lines(refusals));
  throw vgpu::Error(refusal_lines(refusals));
}

}  // namespace host
