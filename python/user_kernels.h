// Kernels written in Python (issue 48), the C++ side: the package's recorder (python/vgpu_rt/
// __init__.py, vgpu_rt.kernel) runs the user's function once over lane values of its own, which
// append nodes to a list as vgpu/record.h's RecordingLanes do; one call here turns that list into
// a vgpu::Recording and a vgpu::RecordedProgram, which every device runs, counts and checks as it
// does the project's kernels. The card's rules are vgpu::check_program's (vgpu/device.cpp), the
// checks every pass makes: the line it throws, plus the built-in profiles the program fits.
//
// Included by python/vgpu_rt.cpp alone (the module is one translation unit on purpose).
#pragma once

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "host/trace/user_stage.h"
#include "kernels/stages.h"
#include "vgpu/glsl.h"
#include "vgpu/recorded_program.h"
#include "vgpu/vgpu.h"

namespace user_kernels {

namespace py = pybind11;

// vgpu::Op's names in the enum's order: the recorder's node codes are their indices.
inline std::vector<std::string> op_names() {
  return {"constant",   "frag_x",   "frag_y",  "add",      "sub",   "mul",       "div",
          "neg",        "min",      "max",     "abs",      "floor", "sqrt",      "rsqrt",
          "select",     "lt",       "le",      "gt",       "ge",    "eq",        "ne",
          "mask_const", "mask_and", "mask_or", "mask_not", "fetch", "fetch_own", "channel"};
}

// A recorded kernel as Python holds it (the Program a pass runs lives as long as this object).
struct UserProgram {
  std::shared_ptr<vgpu::RecordedProgram> program;
};

// One node as the recorder writes it: (op, a, b, c, unit, value).
using Node = std::tuple<int, int, int, int, int, float>;

inline UserProgram make_program(
    const std::string& name, int outputs, const std::vector<std::string>& units,
    const std::vector<Node>& nodes, const std::vector<std::array<int, 4>>& out_nodes, int kill,
    const std::optional<std::array<int, 5>>& loop,
    const std::vector<std::pair<std::string, std::vector<int>>>& uniforms) {
  vgpu::Recording rec;
  const int last = int(vgpu::Op::channel);
  for (const auto& [op, a, b, c, unit, value] : nodes) {
    if (op < 0 || op > last)
      throw std::invalid_argument("kernel '" + name + "': node " +
                                  std::to_string(rec.nodes.size()) + " has no operation " +
                                  std::to_string(op));
    rec.push({vgpu::Op(op), a, b, c, unit, value});
  }
  rec.outputs = out_nodes;
  rec.kill = kill;
  if (loop) {
    const auto& l = *loop;
    rec.loops.push_back({l[0], l[1], l[2], l[3], l[4]});
  }
  for (const auto& [uname, ids] : uniforms) rec.uniforms.push_back({uname, ids});
  return {std::make_shared<vgpu::RecordedProgram>(std::move(rec), name, name, outputs, units)};
}

// The rule check_program names on `profile`, and, where it refuses, the built-in profiles where
// the program passes every one of those rules ("; it fits gf6600").
inline void check(const UserProgram& k, const std::string& profile) {
  const vgpu::Program& p = *k.program;
  const vgpu::Program::Analysis a = p.analyze();
  try {
    vgpu::check_program(vgpu::profile(profile), p, a);
  } catch (const vgpu::Error& e) {
    std::vector<std::string> fits;
    for (const vgpu::Profile& other : vgpu::profiles()) {
      if (other.name == profile) continue;
      try {
        vgpu::check_program(other, p, a);
        fits.push_back(other.name);
      } catch (const vgpu::Error&) {
      }
    }
    std::string line = e.what();
    for (size_t i = 0; i < fits.size(); ++i)
      line += (i == 0 ? "; it fits " : i + 1 == fits.size() ? " and " : ", ") + fits[i];
    throw vgpu::Error(line);
  }
}

// Before a program of `units` texture units is made: the profile's rule, then the emulator's own
// limit (kMaxTextureUnits binding points, whatever a modern profile allows).
inline void check_units(const std::string& name, int units, const std::string& profile) {
  vgpu::check_texture_units(vgpu::profile(profile), name, units);
  if (units > vgpu::kMaxTextureUnits)
    throw vgpu::Error("program '" + name + "' reads texture unit " + std::to_string(units - 1) +
                      " (" + std::to_string(units) + " units); the vgpu binds " +
                      std::to_string(vgpu::kMaxTextureUnits) + " texture units");
}

inline py::dict analysis(const UserProgram& k) {
  const vgpu::Program::Analysis a = k.program->analyze();
  py::dict d;
  d["instructions"] = a.instructions;
  py::list per_unit;
  for (int u = 0; u < vgpu::kMaxTextureUnits; ++u)
    per_unit.append(int(a.fetches.per_unit[size_t(u)]));
  d["fetches"] = per_unit;
  d["loops"] = a.loop.loops;
  d["loop_iterations"] = a.loop.max_iterations;
  d["loop_body_instructions"] = a.loop.body_instructions;
  return d;
}

// The frame's stages a kernel of one's own can replace (kernels/stages.h): each one's texture
// units and uniforms with their defaults, {stage: (units, {name: default})}.
inline py::dict stages() {
  py::dict out;
  auto one = [&](const char* key, const auto& stage) {
    py::list units;
    for (const char* u : stage.units) units.append(u);
    py::dict uniforms;
    kernels::each_uniform(stage, [&](const char* name, float v) { uniforms[name] = v; });
    out[key] = py::make_tuple(units, uniforms);
  };
  one(kernels::ShaderStage::stage, kernels::ShaderStage{});
  one(kernels::CameraStage::stage, kernels::CameraStage{});
  return out;
}

// A recorded kernel as the stage it replaces in a frame (host/trace/user_stage.h).
template <class U>
std::shared_ptr<host::UserStage<U>> as_stage(const UserProgram& k,
                                             const std::vector<std::string>& units) {
  return std::make_shared<host::RecordedStage<U>>(k.program, units);
}

// The module's functions and the Device's _run_recorded (m.Device bound already).
template <class RunPass>
void bind(py::module_& m, RunPass run_pass) {
  auto device = py::reinterpret_borrow<py::class_<vgpu::Gpu>>(m.attr("Device"));
  m.def("record_ops", &op_names, "vgpu::Op's names in order (the recorder's node codes).");
  py::class_<UserProgram>(m, "RecordedKernel",
                          "A kernel written in Python, recorded into a vgpu::RecordedProgram.")
      .def_property_readonly("name", [](const UserProgram& k) { return k.program->name(); })
      .def_property_readonly("outputs", [](const UserProgram& k) { return k.program->outputs(); })
      .def("analyze", &analysis,
           "The counting run: instructions, fetches per unit, the loop's figures.")
      .def(
          "glsl", [](const UserProgram& k) { return vgpu::to_glsl(*k.program, true).source; },
          "The GLSL fragment shader the GL device would compile from this recording.")
      .def("__len__", [](const UserProgram& k) { return k.program->recording().nodes.size(); });
  m.def("record_kernel", &make_program, py::arg("name"), py::arg("outputs"), py::arg("units"),
        py::arg("nodes"), py::arg("out_nodes"), py::arg("kill"), py::arg("loop"),
        py::arg("uniforms") = std::vector<std::pair<std::string, std::vector<int>>>{},
        "A RecordedKernel from the recorder's node list (ValueError where it cannot be run).");
  m.def("stages", &stages,
        "The frame's stages a kernel can replace: {stage: (units, {uniform: default})}.");
  m.def("check_kernel", &check, py::arg("kernel"), py::arg("profile"),
        "Raises ValueError with the card's rule the kernel breaks on `profile`, if any.");
  m.def("check_units", &check_units, py::arg("name"), py::arg("units"), py::arg("profile"),
        "Raises ValueError where `units` texture units are more than the profile has.");
  device.def(
      "_run_recorded",
      [run_pass](vgpu::Gpu& gpu, const UserProgram& k,
                 const std::vector<std::shared_ptr<vgpu::Texture>>& units,
                 const std::vector<std::shared_ptr<vgpu::Texture>>& targets,
                 bool query) { return run_pass(gpu, *k.program, units, targets, query); },
      py::arg("kernel"), py::arg("units"), py::arg("targets"), py::arg("query") = false);
}

}  // namespace user_kernels
