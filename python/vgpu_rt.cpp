// The Python module's C++ side, _vgpu_rt (pybind11): what python/vgpu_rt/__init__.py wraps into
// vgpu_rt. One translation unit on purpose: pybind11's templates are slow to compile, and each
// further file would pay for them again. What is here:
//  - render: `vgpu-rt render` as the command line runs it (host/cli/render.h), its image and
//    AOVs handed to NumPy without a copy, its statistics as --stats-json's text;
//  - the cost model (host/model/cost_model.h) over a frame's statistics, and the profiles;
//  - a Device: textures as NumPy arrays over their own storage, one kernel run over them;
//  - a frame pass by pass: a render on a worker thread that stops after each pass.
// C++ exceptions become Python ones (translate below); nothing here lets one escape otherwise.

// GCC 12 reports false positives inside nlohmann_json's templates.
#if defined(__GNUC__) && !defined(__clang__)  // GCC's warnings; clang has neither
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wrestrict"
#endif
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "host/cli/render.h"
#include "host/common/version.h"
#include "host/model/cost_model.h"
#include "host/report/counters_json.h"
#include "host/scene/animation.h"
#include "host/scene/gltf_loader.h"
#include "host/scene/scene.h"
#include "kernels/registry.h"
#include "user_kernels.h"
#include "vgpu/vgpu.h"

namespace py = pybind11;

namespace {

// A file that is not there: Python's FileNotFoundError, with the command line's message.
struct FileNotFound : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// C++ errors as the Python exceptions a caller expects: a bad value (the command line's usage
// errors, an unreadable scene, an unknown profile) is a ValueError, a missing file a
// FileNotFoundError; the message is the command line's line without its "vgpu-rt: " prefix. What
// the device refuses (vgpu::Error: a texture past the profile's size, a read/write hazard, a unit
// read with no texture bound) is a ValueError too.
void translate(std::exception_ptr p) {
  try {
    if (p) std::rethrow_exception(p);
  } catch (const FileNotFound& e) {
    PyErr_SetString(PyExc_FileNotFoundError, e.what());
  } catch (const cli::UsageError& e) {
    PyErr_SetString(PyExc_ValueError, e.what());
  } catch (const host::InputError& e) {
    PyErr_SetString(PyExc_ValueError, e.what());
  } catch (const vgpu::Error& e) {  // what the device refuses: a hazard, a missing texture, a size
    PyErr_SetString(PyExc_ValueError, e.what());
  } catch (const std::invalid_argument& e) {
    PyErr_SetString(PyExc_ValueError, e.what());
  } catch (const std::out_of_range& e) {
    PyErr_SetString(PyExc_ValueError, e.what());
  }
}

// A vector's floats as a NumPy array of `shape` that owns them (no copy: the vector moves into
// the array's base object).
py::array_t<float> to_array(std::vector<float>&& v, std::vector<py::ssize_t> shape) {
  auto* owned = new std::vector<float>(std::move(v));
  py::capsule base(owned, [](void* p) { delete static_cast<std::vector<float>*>(p); });
  return py::array_t<float>(shape, owned->data(), base);
}

// --------------------------------------------------------------------------------------------
// Frames

// The scene argument as the command line resolves it; a name or path that is neither a bundled
// scene nor a file is FileNotFoundError (every other problem with the file is a ValueError).
void check_scene(const std::string& scene) {
  try {
    host::resolve_scene(scene);
  } catch (const host::InputError& e) {
    throw FileNotFound(e.what());
  }
}

// What render() returns to the Python side: image, depth, hit ids, the statistics as JSON text
// (json.loads on the Python side) and the frame's statistics for predict().
// shader, camera: kernels written in Python for those stages, as (RecordedKernel, units), or None.
using StageArg = std::optional<std::pair<user_kernels::UserProgram, std::vector<std::string>>>;
void set_stages(cli::RenderArgs& a, const StageArg& shader, const StageArg& camera) {
  if (shader)
    a.user.shader = user_kernels::as_stage<kernels::ShaderStage>(shader->first, shader->second);
  if (camera)
    a.user.camera = user_kernels::as_stage<kernels::CameraStage>(camera->first, camera->second);
}

py::tuple render(const std::vector<std::string>& args, const StageArg& shader,
                 const StageArg& camera) {
  bool lanes_given = false;
  cli::RenderArgs a = cli::parse_render_args(args, lanes_given);
  set_stages(a, shader, camera);
  check_scene(a.scene);
  auto outcome = std::make_unique<cli::RenderOutcome>();
  {
    py::gil_scoped_release unlocked;  // the frame runs without holding Python up
    cli::run_render(a, lanes_given, outcome.get());
  }
  host::RenderResult& r = outcome->result;
  const py::ssize_t h = r.height, w = r.width;
  auto stats = std::make_shared<vgpu::FrameStats>(std::move(r.stats));
  return py::make_tuple(to_array(std::move(r.rgb), {h, w, 3}), to_array(std::move(r.depth), {h, w}),
                        to_array(std::move(r.hit_id), {h, w}), outcome->stats.dump(), stats);
}

// The bundled scenes: name -> path.
std::vector<std::pair<std::string, std::string>> scenes() {
  return host::list_scenes();
}

// --------------------------------------------------------------------------------------------
// The cost model

py::dict breakdown_dict(const host::CostBreakdown& c) {
  py::dict d;
  for (const auto& [key, v] : c.items()) d[py::str(key)] = v;
  d["total_ms"] = c.total_ms;
  return d;
}

// A frame's statistics from --stats-json's object (a file the command line wrote, or a render's
// dict): each kernel's counters and the frame's totals. The command line keeps no per-pass records
// (RenderOptions::keep_pass_records), so the cost model prices its frames from these same
// per-kernel totals, and the figure is the command line's.
vgpu::FrameStats stats_from_json(const std::string& text) {
  const nlohmann::json j = nlohmann::json::parse(text);
  if (!j.is_object() || !j.contains("totals") || !j.contains("kernels"))
    throw std::invalid_argument(
        "predict: the statistics have no 'totals' and 'kernels' (is this a --stats-json of one "
        "frame?)");
  auto counters = [](const nlohmann::json& o) {
    vgpu::Counters c;
    for (const auto& [name, field] : vgpu::kCounterFields)
      if (o.contains(name) && o[name].is_number()) c.*field = o[name].get<uint64_t>();
    return c;
  };
  vgpu::FrameStats s;
  s.totals = counters(j["totals"]);
  for (const nlohmann::json& k : j["kernels"]) {
    vgpu::FrameStats::ProgramTotals& p = s.program(k.value("name", ""), k.value("paper_name", ""),
                                                   k.value("static_instructions", 0));
    p.counters = counters(k);
  }
  s.downloads = j.value("downloads", uint64_t(0));
  s.download_bytes = j.value("download_bytes", uint64_t(0));
  return s;
}

py::dict predict(const vgpu::FrameStats& stats, const std::string& profile) {
  return breakdown_dict(host::predict(stats, vgpu::profile(profile)));
}

py::dict profile_dict(const vgpu::Profile& p) {
  py::dict d;
  d["name"] = p.name;
  d["core_mhz"] = p.core_mhz;
  d["mem_gbps"] = p.mem_gbps;
  d["bus_mbps"] = p.bus_mbps;
  d["max_outputs"] = p.max_outputs;
  d["max_texture_size"] = p.max_texture_size;
  d["memory_mib"] = p.memory_mib;
  d["max_loop_iterations"] = p.max_loop_iterations;
  // What the cost model prices with (host/model/cost_model.cpp): the arithmetic, texture and
  // fixed-cost figures, and whether batches of idle fragments can skip a branch's body.
  d["display"] = p.display;
  d["pipelines"] = p.pipelines;
  d["alu_lanes"] = p.alu_lanes;
  d["alu_per_clock"] = p.alu_per_clock;
  d["fp32_rate"] = p.fp32_rate;
  d["texels_per_clock"] = p.texels_per_clock;
  d["pass_us"] = p.pass_us;
  d["program_load_us"] = p.program_load_us;
  d["readback_us"] = p.readback_us;
  d["dynamic_branching"] = p.branching == vgpu::Branching::dynamic;
  d["branches_as_selects"] = p.branches_as_selects;
  d["branch_granularity"] = p.branch_granularity;
  // The card the GL device measured it on, as its GL_RENDERER names it ("" for modeled cards).
  d["gl_renderer"] = p.gl_renderer;
  return d;
}

// --------------------------------------------------------------------------------------------
// The device: textures as NumPy arrays, the kernels by name, one pass at a time

using TexturePtr = std::shared_ptr<vgpu::Texture>;

vgpu::Format parse_format(const std::string& name) {
  for (vgpu::Format f : {vgpu::Format::fp32, vgpu::Format::fp24, vgpu::Format::fp16})
    if (vgpu::format_name(f) == name) return f;
  throw std::invalid_argument("format: expected fp32, fp24 or fp16, got '" + name + "'");
}

// A texture's texels as an (height, width, channels) float32 array over its own storage: no
// copy, for every format (the store holds floats already rounded to the format). Read-only: a
// write must round to the format and count as a host write (Texture::write below).
py::array texture_array(py::object self) {
  const vgpu::Texture& t = self.cast<const vgpu::Texture&>();
  const py::ssize_t c = t.channels(), w = t.width(), f = sizeof(float);
  py::array a(py::dtype::of<float>(), {py::ssize_t(t.height()), w, c}, {w * c * f, c * f, f},
              t.data().data(), self);  // `self` is the base: the texture outlives the view
  a.attr("flags").attr("writeable") = false;
  return a;
}

// Host -> texture: `texels` (height, width, channels), rounded to the texture's format (a copy
// into the store, as an upload is).
void texture_write(vgpu::Texture& t,
                   const py::array_t<float, py::array::c_style | py::array::forcecast>& texels) {
  const std::vector<py::ssize_t> want{t.height(), t.width(), t.channels()};
  const bool flat_channel = t.channels() == 1 && texels.ndim() == 2;
  if (!flat_channel && (texels.ndim() != 3 || texels.shape(0) != want[0] ||
                        texels.shape(1) != want[1] || texels.shape(2) != want[2]))
    throw std::invalid_argument("texture '" + t.name() + "': expected texels of shape (" +
                                std::to_string(want[0]) + ", " + std::to_string(want[1]) + ", " +
                                std::to_string(want[2]) + ")");
  if (flat_channel && (texels.shape(0) != want[0] || texels.shape(1) != want[1]))
    throw std::invalid_argument("texture '" + t.name() + "': expected texels of shape (" +
                                std::to_string(want[0]) + ", " + std::to_string(want[1]) + ")");
  t.replace(std::span<const float>(texels.data(), size_t(texels.size())));
}

// Every kernel of kernels/registry.h, with its default uniforms, for the module's lifetime.
const std::vector<std::unique_ptr<vgpu::Program>>& kernel_programs() {
  static const auto programs = kernels::all_programs(kernels::Programs::with_looping);
  return programs;
}

// The texture units a kernel reads: those its functor names, and any it fetches from.
std::vector<std::string> kernel_units(const vgpu::Program& p) {
  int n = 0;
  const vgpu::Program::Analysis a = p.analyze();
  for (int u = 0; u < vgpu::kMaxTextureUnits; ++u)
    if (p.unit_name(u) != "unit" + std::to_string(u) || a.fetches.per_unit[size_t(u)] > 0)
      n = u + 1;
  std::vector<std::string> out;
  for (int u = 0; u < n; ++u) out.push_back(p.unit_name(u));
  return out;
}

py::dict counters_dict(const vgpu::Counters& c) {
  py::dict d;
  for (const auto& [name, field] : vgpu::kCounterFields) d[name] = c.*field;
  return d;
}

// One pass of `kernel` over all of targets[0], units[i] bound to texture unit i; returns the
// pass's counters, and with `query` the fragments an occlusion query counted.
py::dict run_pass(vgpu::Gpu& gpu, const vgpu::Program& kernel, const std::vector<TexturePtr>& units,
                  const std::vector<TexturePtr>& targets, bool query) {
  if (int(targets.size()) != kernel.outputs())
    throw std::invalid_argument(std::string("run: ") + kernel.name() + " writes " +
                                std::to_string(kernel.outputs()) + " target(s), got " +
                                std::to_string(targets.size()));
  for (const TexturePtr& t : units)
    if (!t) throw std::invalid_argument("run: a texture unit is None");
  for (const TexturePtr& t : targets)
    if (!t) throw std::invalid_argument("run: a target is None");
  for (size_t i = 1; i < targets.size(); ++i)
    if (targets[i]->width() != targets[0]->width() || targets[i]->height() != targets[0]->height())
      throw std::invalid_argument("run: the targets differ in size");
  gpu.use_program(kernel);
  gpu.unbind_textures();
  for (size_t i = 0; i < units.size(); ++i) gpu.bind_texture(int(i), *units[i]);
  switch (targets.size()) {
    case 1:
      gpu.set_targets({targets[0].get()});
      break;
    case 2:
      gpu.set_targets({targets[0].get(), targets[1].get()});
      break;
    default:
      throw std::invalid_argument("run: one or two targets");
  }
  std::optional<uint64_t> counted;
  vgpu::PassRecord record;
  {
    py::gil_scoped_release unlocked;
    if (query) gpu.begin_query();
    record = gpu.draw();
    if (query) counted = gpu.end_query();
  }
  gpu.unbind_textures();
  py::dict d;
  d["kernel"] = record.program;
  d["size"] = py::make_tuple(record.width, record.height);
  d["counters"] = counters_dict(record.counters);
  d["query"] = counted ? py::object(py::int_(*counted)) : py::object(py::none());
  return d;
}

// --------------------------------------------------------------------------------------------
// A frame, pass by pass: the render runs on a worker thread and, as the tracer's observer, stops
// after each pass until Python asks for the next one (stop: stop asking; resume: ask again).

const char* trace_name(host::PassObserver::TraceKind k) {
  using K = host::PassObserver::TraceKind;
  return k == K::primary ? "primary" : k == K::shadow ? "shadow" : "reflected";
}

// What Python is shown of one pass. The target's texels are a copy: the frame moves on once
// Python resumes it, and the pass's texture is rewritten by later passes.
struct PassEvent {
  uint64_t index = 0;  // 0-based, in the frame's order
  std::string kernel, paper_name, target;
  int iteration = 0;
  std::string trace;
  int width = 0, height = 0, channels = 0;
  vgpu::Counters counters, frame_totals;
  std::optional<uint64_t> query;
  std::vector<float> texels;
  // Per pixel of the target, row by row (empty: not known for this pass). work: the fragments
  // with work before the pass (the stencil it ran under; empty when every fragment ran); written:
  // the fragments a counting pass's query counted; iterations: a looping pass's loop count.
  int mask_width = 0, mask_height = 0;
  std::vector<uint8_t> work, written;
  std::vector<uint32_t> iterations;
};

class PassStepper final : public host::PassObserver {
 public:
  PassStepper(const std::vector<std::string>& args, const StageArg& shader,
              const StageArg& camera) {
    a_ = cli::parse_render_args(args, lanes_given_);
    set_stages(a_, shader, camera);
    check_scene(a_.scene);
    worker_ = std::thread([this] { work(); });
  }
  ~PassStepper() {
    {
      std::lock_guard<std::mutex> lock(m_);
      cancel_ = true;  // the worker stops waiting: the frame runs to its end unobserved
    }
    cv_.notify_all();
    worker_.join();
  }

  // The next pass, or nullopt at the frame's end; rethrows the render's error.
  std::optional<PassEvent> next() {
    std::unique_lock<std::mutex> lock(m_);
    wanted_ = true;
    cv_.notify_all();
    cv_.wait(lock, [this] { return ready_.has_value() || done_; });
    wanted_ = false;
    if (ready_) {
      std::optional<PassEvent> e = std::move(ready_);
      ready_.reset();
      cv_.notify_all();
      return e;
    }
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
    return std::nullopt;
  }
  bool done() {
    std::lock_guard<std::mutex> lock(m_);
    return done_ && !ready_;
  }
  cli::RenderOutcome* outcome() { return outcome_ ? &*outcome_ : nullptr; }

  // The observer, on the worker thread.
  void iteration(int i) override {
    flush();
    iteration_ = i;
  }
  void trace_begin(TraceKind k) override {
    flush();
    trace_ = trace_name(k);
  }
  void trace_end() override {
    flush();
    trace_.clear();
  }
  void pass_begin(const vgpu::Stencil* mask) override {
    flush();
    work_.clear();
    if (mask) {
      work_w_ = mask->width();
      work_h_ = mask->height();
      work_.assign(mask->row(0), mask->row(0) + size_t(work_w_) * size_t(work_h_));
    }
  }
  void pass(const Pass& p) override {
    flush();
    PassEvent e;
    e.index = count_++;
    e.kernel = p.program.name();
    e.paper_name = p.program.paper_name();
    e.target = p.target.name();
    e.iteration = std::max(iteration_, 1);
    e.trace = trace_;
    e.width = p.target.width();
    e.height = p.target.height();
    e.channels = p.target.channels();
    e.counters = p.record.counters;
    e.frame_totals = p.stats.totals;
    e.texels.assign(p.target.data().begin(), p.target.data().end());
    // The masks are kept only where they cover the target texel for texel (the looping kernels'
    // one-fragment passes and the sampling modes' smaller targets are left without).
    if (!work_.empty() && work_w_ == e.width && work_h_ == e.height) e.work = std::move(work_);
    work_.clear();
    if (p.loop_iterations.size() == size_t(e.width) * size_t(e.height))
      e.iterations.assign(p.loop_iterations.begin(), p.loop_iterations.end());
    pending_ = std::move(e);
  }
  void query(uint64_t result, const vgpu::Stencil* written, const vgpu::FrameStats& s) override {
    if (pending_) {
      pending_->query = result;
      pending_->frame_totals = s.totals;  // the read-back counted
      if (written && written->width() == pending_->width && written->height() == pending_->height)
        pending_->written.assign(
            written->row(0), written->row(0) + size_t(pending_->width) * size_t(pending_->height));
    }
    flush();
  }

 private:
  void work() {
    try {
      cli::RenderOutcome o;
      cli::run_render(a_, lanes_given_, &o, this);
      flush();
      std::lock_guard<std::mutex> lock(m_);
      outcome_.emplace(std::move(o));
    } catch (...) {
      std::lock_guard<std::mutex> lock(m_);
      error_ = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(m_);
    done_ = true;
    cv_.notify_all();
  }
  // Hands the pass seen last to Python and waits until Python asks for the one after it.
  void flush() {
    if (!pending_) return;
    std::unique_lock<std::mutex> lock(m_);
    if (cancel_) {
      pending_.reset();
      return;
    }
    ready_ = std::move(pending_);
    pending_.reset();
    cv_.notify_all();
    cv_.wait(lock, [this] { return cancel_ || (!ready_ && wanted_); });
  }

  cli::RenderArgs a_;
  bool lanes_given_ = false;
  std::thread worker_;
  std::mutex m_;
  std::condition_variable cv_;
  std::optional<PassEvent> pending_, ready_;  // pending_: the worker's own, until flushed
  bool wanted_ = false, done_ = false, cancel_ = false;
  std::exception_ptr error_;
  std::optional<cli::RenderOutcome> outcome_;
  int iteration_ = 0;
  std::string trace_;  // empty outside a trace (the ray generator's pass)
  uint64_t count_ = 0;
  std::vector<uint8_t> work_;  // the stencil the coming pass runs under (empty: none)
  int work_w_ = 0, work_h_ = 0;
};

py::dict pass_dict(PassEvent&& e) {
  py::dict d;
  d["index"] = e.index;
  d["kernel"] = e.kernel;
  d["paper_name"] = e.paper_name;
  d["iteration"] = e.iteration;
  d["trace"] = e.trace.empty() ? py::object(py::none()) : py::object(py::str(e.trace));
  d["target_name"] = e.target;
  d["counters"] = counters_dict(e.counters);
  d["frame_totals"] = counters_dict(e.frame_totals);
  d["query"] = e.query ? py::object(py::int_(*e.query)) : py::object(py::none());
  d["target"] = to_array(std::move(e.texels), {e.height, e.width, e.channels});
  const auto mask = [&](std::vector<uint8_t>& m) -> py::object {
    if (m.empty()) return py::none();
    py::array_t<bool> a({py::ssize_t(e.height), py::ssize_t(e.width)});
    bool* out = a.mutable_data();
    for (size_t i = 0; i < m.size(); ++i) out[i] = m[i] != 0;
    return py::object(std::move(a));
  };
  d["work"] = mask(e.work);
  d["written"] = mask(e.written);
  if (e.iterations.empty()) {
    d["iterations"] = py::none();
  } else {
    py::array_t<uint32_t> a({py::ssize_t(e.height), py::ssize_t(e.width)});
    std::copy(e.iterations.begin(), e.iterations.end(), a.mutable_data());
    d["iterations"] = std::move(a);
  }
  return d;
}

}  // namespace

PYBIND11_MODULE(_vgpu_rt, m) {
  m.doc() = "vgpu-rt's C++ side; use the package vgpu_rt, which wraps it.";
  py::register_exception_translator(translate);

  py::class_<vgpu::FrameStats, std::shared_ptr<vgpu::FrameStats>>(
      m, "FrameStats",
      "A frame's pass statistics as the C++ library keeps them (per kernel and in total).")
      .def_property_readonly(
          "passes", [](const vgpu::FrameStats& s) { return s.totals.passes; },
          "Render-to-texture passes in the frame.")
      .def(
          "json", [](const vgpu::FrameStats& s) { return host::frame_counters_json(s).dump(2); },
          "The per-kernel totals as JSON text.");

  m.def("render", &render, py::arg("args"), py::arg("shader") = py::none(),
        py::arg("camera") = py::none(),
        "Runs `vgpu-rt render` with command-line arguments (the scene first); returns (image, "
        "depth, hit, stats JSON text, FrameStats).");
  m.def(
      "render_options",
      [] {
        py::list out;
        for (const cli::RenderOptionInfo& o : cli::render_option_infos())
          out.append(py::make_tuple(o.name, o.default_value, o.description, o.flag));
        return out;
      },
      "The render options as (name, default, description, is_flag), as `vgpu-rt render --help` "
      "lists them.");
  m.def(
      "library_render_ms",
      [](const std::vector<std::string>& args) {
        bool lanes_given = false;
        const cli::RenderArgs a = cli::parse_render_args(args, lanes_given);
        cli::RenderOutcome outcome;
        py::gil_scoped_release unlocked;
        const auto t0 = std::chrono::steady_clock::now();
        cli::run_render(a, lanes_given, &outcome);
        return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
            .count();
      },
      py::arg("args"),
      "For the benchmark (python/bench_render.py): ms of the library call alone, cli::run_render "
      "with these arguments, timed in C++.");
  m.def("scenes", &scenes, "The bundled scenes as (name, path) pairs.");
  m.def(
      "version", [] { return std::string(host::version()); }, "vgpu-rt's version (VERSION).");
  m.def(
      "scenes_dir", [] { return host::scenes_dir().string(); },
      "The bundled scenes' folder, empty when none is found.");
  m.def("check_scene", &check_scene, py::arg("scene"),
        "Raises FileNotFoundError when the scene is neither a bundled name nor a file.");
  m.def("predict", &predict, py::arg("stats"), py::arg("profile"),
        "The cost model's breakdown (ms) of a frame's statistics on a profile.");
  m.def(
      "predict_json",
      [](const std::string& text, const std::string& profile) {
        return predict(stats_from_json(text), profile);
      },
      py::arg("stats_json"), py::arg("profile"),
      "The cost model over --stats-json's object (JSON text): each kernel's totals spread over "
      "its passes.");
  m.def(
      "profiles",
      [] {
        py::list out;
        for (const vgpu::Profile& p : vgpu::profiles()) out.append(profile_dict(p));
        return out;
      },
      "The built-in hardware profiles, each as a dict of its main figures.");

  py::class_<vgpu::Texture, TexturePtr>(
      m, "Texture", py::buffer_protocol(),
      "A texture of the virtual GPU: height x width texels of 1 to 4 float channels, stored "
      "rounded to its format (fp32, fp24 or fp16).")
      .def_buffer([](vgpu::Texture& t) {
        const py::ssize_t c = t.channels(), w = t.width(), f = sizeof(float);
        return py::buffer_info(const_cast<float*>(t.data().data()), f,
                               py::format_descriptor<float>::format(), 3,
                               {py::ssize_t(t.height()), w, c}, {w * c * f, c * f, f}, true);
      })
      .def_property_readonly("name", &vgpu::Texture::name)
      .def_property_readonly("width", &vgpu::Texture::width)
      .def_property_readonly("height", &vgpu::Texture::height)
      .def_property_readonly("channels", &vgpu::Texture::channels)
      .def_property_readonly(
          "format",
          [](const vgpu::Texture& t) { return std::string(vgpu::format_name(t.format())); })
      .def_property_readonly(
          "array", &texture_array,
          "The texels as a read-only (height, width, channels) float32 array "
          "over the texture's own storage (no copy; it keeps the texture alive).")
      .def("write", &texture_write, py::arg("texels"),
           "Writes every texel from an array of shape (height, width, channels) (or (height, "
           "width) for one channel), rounded to the format: a copy, as an upload is.")
      .def("__repr__", [](const vgpu::Texture& t) {
        return "<vgpu_rt.Texture '" + t.name() + "' " + std::to_string(t.width()) + "x" +
               std::to_string(t.height()) + "x" + std::to_string(t.channels()) + " " +
               std::string(vgpu::format_name(t.format())) + ">";
      });

  py::class_<vgpu::Program, std::unique_ptr<vgpu::Program, py::nodelete>>(
      m, "Kernel", "A fragment program of kernels/registry.h, with its default uniforms.")
      .def_property_readonly("name", &vgpu::Program::name)
      .def_property_readonly("paper_name", &vgpu::Program::paper_name)
      .def_property_readonly("outputs", &vgpu::Program::outputs, "Render targets one pass writes.")
      .def_property_readonly("units", &kernel_units,
                             "What each texture unit holds, by unit number.")
      .def_property_readonly(
          "instructions", [](const vgpu::Program& p) { return p.analyze().instructions; },
          "Static instructions per fragment (the counting run, default uniforms).")
      .def("__repr__", [](const vgpu::Program& p) {
        return std::string("<vgpu_rt.Kernel ") + p.name() + " (" + p.paper_name() + ")>";
      });
  m.def(
      "kernels",
      [] {
        py::dict d;
        for (const auto& p : kernel_programs()) d[p->name()] = py::cast(p.get());
        return d;
      },
      "Every kernel by name, in kernels/registry.h's order.");

  py::class_<vgpu::Gpu>(m, "Device",
                        "The virtual GPU with a hardware profile's limits and counters.")
      .def(py::init([](const std::string& profile, int threads) {
             return std::make_unique<vgpu::Gpu>(vgpu::profile(profile), threads);
           }),
           py::arg("profile") = "gf5700", py::arg("threads") = 1)
      .def_property_readonly("profile", [](const vgpu::Gpu& g) { return g.profile().name; })
      .def(
          "texture",
          [](const vgpu::Gpu& g, const std::string& name, int width, int height, int channels,
             const std::string& format) {
            if (channels < 1 || channels > 4)
              throw std::invalid_argument("texture '" + name + "': channels must be 1 to 4, got " +
                                          std::to_string(channels));
            return std::make_shared<vgpu::Texture>(
                g.make_texture(name, width, height, channels, parse_format(format)));
          },
          py::arg("name"), py::arg("width"), py::arg("height"), py::arg("channels") = 4,
          py::arg("format") = "fp32",
          "A new texture of zeros in the device's memory (the profile's size limit applies).")
      .def("run", &run_pass, py::arg("kernel"), py::arg("units"), py::arg("targets"),
           py::arg("query") = false,
           "One pass of `kernel` over the whole of targets[0] (its outputs' targets, one or two), "
           "units[i] bound to texture unit i. Returns the pass's counters and, with query=True, "
           "the fragments an occlusion query counted (else None).")
      .def_property_readonly(
          "totals", [](vgpu::Gpu& g) { return counters_dict(g.stats().totals); },
          "The counters of every pass this device ran.")
      .def(
          "_frame_stats",
          [](vgpu::Gpu& g) { return std::make_shared<vgpu::FrameStats>(g.stats()); },
          "A copy of every pass's statistics, per kernel, for predict().")
      .def(
          "_stats_json",
          [](vgpu::Gpu& g) {
            nlohmann::ordered_json j = host::frame_counters_json(g.stats());
            nlohmann::ordered_json out;
            out["totals"] = std::move(j["totals"]);
            out["downloads"] = j["downloads"];
            out["download_bytes"] = j["download_bytes"];
            out["kernels"] = std::move(j["programs"]);  // the key --stats-json uses
            return out.dump();
          },
          "The statistics as --stats-json writes them: totals, downloads, kernels.");
  py::class_<PassStepper>(m, "PassStepper",
                          "A render on a worker thread that stops after each pass.")
      .def(py::init<const std::vector<std::string>&, const StageArg&, const StageArg&>(),
           py::arg("args"), py::arg("shader") = py::none(), py::arg("camera") = py::none())
      .def(
          "next",
          [](PassStepper& s) -> py::object {
            std::optional<PassEvent> e;
            {
              py::gil_scoped_release unlocked;
              e = s.next();
            }
            if (!e) return py::none();
            return pass_dict(std::move(*e));
          },
          "The next pass as a dict, or None at the frame's end.")
      .def(
          "result",
          [](PassStepper& s) -> py::object {
            cli::RenderOutcome* o = s.done() ? s.outcome() : nullptr;
            if (!o) return py::none();
            host::RenderResult& r = o->result;
            const py::ssize_t h = r.height, w = r.width;
            return py::make_tuple(to_array(std::vector<float>(r.rgb), {h, w, 3}),
                                  to_array(std::vector<float>(r.depth), {h, w}),
                                  to_array(std::vector<float>(r.hit_id), {h, w}), o->stats.dump(),
                                  std::make_shared<vgpu::FrameStats>(r.stats));
          },
          "Once every pass was seen: the frame as render() returns it; else None.");
  user_kernels::bind(m, &run_pass);  // kernels written in Python (python/user_kernels.h)
}
