// Kernels of one's own in the frame (issue 48): a program that replaces one stage of the stream
// tracer's pipeline (kernels/stages.h: the shading pass, the camera), given from C++ as a functor
// or from Python as a recording. The frame binds the stage's textures to the units the kernel
// names, sets the stage's uniforms before each of its passes, and runs, counts and prices it as
// the pass it replaces, under its own name.
//
//   struct Toon {                        // a functor, as kernels/ are written
//     static constexpr const char* name = "toon";
//     static constexpr const char* paper_name = "toon (shader)";
//     static constexpr int outputs = 1;
//     static constexpr std::array<const char*, 3> units{"surface", "result", "normals0"};
//     kernels::ShaderStage stage;        // the frame sets it before each pass
//     template <class L> void operator()(vgpu::Fragments<L>& f) const { ... }
//   };
//   options.user.shader = host::user_stage<Toon>();
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "kernels/stages.h"
#include "vgpu/program.h"
#include "vgpu/recorded_program.h"

namespace host {

// A kernel for the stage whose uniforms are U (kernels::ShaderStage or kernels::CameraStage).
// The frame calls bind() between passes, on the thread that issues them; one frame at a time.
template <class U>
class UserStage {
 public:
  using Uniforms = U;
  virtual ~UserStage() = default;
  // The program (the frame sets its precision to the stage's group's, as the project's own).
  virtual vgpu::Program& program() const = 0;
  // What texture unit i holds: one of U::units' names each.
  virtual std::vector<std::string> units() const = 0;
  virtual void bind(const U& uniforms) = 0;
};
using UserShader = UserStage<kernels::ShaderStage>;
using UserCamera = UserStage<kernels::CameraStage>;

// A functor K with a data member `stage` of one of the stages' uniform types, and `units` naming
// the stage's textures it reads (none: no member).
template <class K>
class FunctorStage final : public UserStage<std::remove_cvref_t<decltype(K::stage)>> {
 public:
  using U = std::remove_cvref_t<decltype(K::stage)>;
  // KernelProgram<K> is compiled where K is, so the program checks that code's target flags
  // against the library's (vgpu/abi.h).
  explicit FunctorStage(K k = K{}) : program_(std::move(k)) {}
  vgpu::Program& program() const override { return program_; }
  std::vector<std::string> units() const override {
    if constexpr (requires { K::units; })
      return {K::units.begin(), K::units.end()};
    else
      return {};
  }
  void bind(const U& uniforms) override { program_.kernel.stage = uniforms; }
  K& kernel() { return program_.kernel; }

 private:
  mutable vgpu::KernelProgram<K> program_;
};

template <class K>
std::shared_ptr<FunctorStage<K>> user_stage(K k = K{}) {
  return std::make_shared<FunctorStage<K>>(std::move(k));
}

// A recorded kernel (vgpu::RecordedProgram: from Python, or recorded from any Program): each of
// its named uniforms that U names is set before every pass; its other uniforms keep their values.
template <class U>
class RecordedStage final : public UserStage<U> {
 public:
  RecordedStage(std::shared_ptr<vgpu::RecordedProgram> program, std::vector<std::string> units)
      : program_(std::move(program)), units_(std::move(units)) {}
  vgpu::Program& program() const override { return *program_; }
  std::vector<std::string> units() const override { return units_; }
  void bind(const U& uniforms) override {
    kernels::each_uniform(uniforms, [&](const char* name, float value) {
      if (program_->has_uniform(name)) program_->set_uniform(name, value);
    });
  }

 private:
  std::shared_ptr<vgpu::RecordedProgram> program_;
  std::vector<std::string> units_;
};

// Functor K recorded as a kernel written outside the build is (from Python): a RecordedStage
// whose named uniforms are the stage uniforms K reads, set by the frame before each pass. Each
// stage uniform is recorded twice with values no kernel has, and the constants holding them
// become its nodes; a uniform K folds into another constant on the host (F(stage.x * 2)) or
// whose value changes the length of K's code is refused (std::invalid_argument, naming K). A
// uniform K tests on the host is recorded as the test of a value no kernel has (true for
// stage.shadows != 0): write such a choice with select on the uniform, as a Python kernel must.
// For measuring and checking the recorded-program executor in a frame.
template <class K>
auto recorded_stage(const K& k = K{}) {
  using U = std::remove_cvref_t<decltype(K::stage)>;
  auto record_with = [&](float base) {
    K c = k;
    kernels::each_uniform(c.stage, [&](const char*, float& v) { v = base, base += 1.0f; });
    return vgpu::KernelProgram<K>(c).record();
  };
  const float a0 = -1000.25f, b0 = -3000.75f;
  vgpu::Recording a = record_with(a0);
  const vgpu::Recording b = record_with(b0);
  const std::string who = std::string("recording '") + K::name + "': ";
  if (a.nodes.size() != b.nodes.size())
    throw std::invalid_argument(who + "its code depends on a stage uniform's value");
  std::vector<bool> named(a.nodes.size(), false);
  float i = 0;
  kernels::each_uniform(k.stage, [&](const char* name, float) {
    vgpu::RecUniform u{name, {}};
    for (size_t n = 0; n < a.nodes.size(); ++n)
      if (a.nodes[n].op == vgpu::Op::constant && a.nodes[n].value == a0 + i &&
          b.nodes[n].value == b0 + i)
        u.nodes.push_back(int(n)), named[n] = true;
    if (!u.nodes.empty()) a.uniforms.push_back(std::move(u));
    i += 1.0f;
  });
  for (size_t n = 0; n < a.nodes.size(); ++n)
    if (!named[n] && (a.nodes[n].op != b.nodes[n].op || a.nodes[n].value != b.nodes[n].value))
      throw std::invalid_argument(who + "node " + std::to_string(n) +
                                  " folds a stage uniform into another constant on the host");
  std::vector<std::string> units;
  if constexpr (requires { K::units; }) units.assign(K::units.begin(), K::units.end());
  auto p = std::make_shared<vgpu::RecordedProgram>(std::move(a), K::name, K::paper_name, K::outputs,
                                                   units);
  kernels::each_uniform(k.stage, [&](const char* name, float v) {
    if (p->has_uniform(name)) p->set_uniform(name, v);
  });
  return std::make_shared<RecordedStage<U>>(std::move(p), std::move(units));
}

// The stages of a frame replaced by kernels of one's own (none: the project's kernels).
struct UserKernels {
  std::shared_ptr<UserShader> shader;
  std::shared_ptr<UserCamera> camera;
  bool any() const { return shader || camera; }
};

}  // namespace host
