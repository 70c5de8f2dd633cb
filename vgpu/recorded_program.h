// A fragment program given as a recording (vgpu/record.h) instead of a C++ functor: the form a
// kernel written outside the project's build takes (issue 48: kernels from Python, from another
// C++ project). Its run() for every lane family executes the recording's nodes through the same
// Fragments<L> operations a functor calls (fetch, fetch_own, out, discard, loop), so the counting
// run, the profile's checks, the statistics, the cost model and the GLSL printer see it as they
// see a KernelProgram, and each lane family rounds it as it rounds a functor.
//
//   vgpu::RecordedProgram p(program.record(), "mine", "mio", 1, {"values"});
//   gpu.use_program(p);  // as any Program
//
// The recording is compiled once, when the program is made, into a list of instructions over
// registers (one per value the program computes; a fetch's channels are its four registers), and
// each run walks that list once over the family's lane values, kept in a per-thread register
// file: no allocation per batch, no virtual call per node.
//
// What a recording does not hold (today's vgpu/record.h keeps what the GLSL printer needs):
// f.branch() blocks leave no node, so a recorded program has no branches (its branch, idle-lane
// and batch-coherence counters are those of straight-line code; the blocks always run, as on
// fp30); mask operations with a constant operand were folded when recorded, so the counting run
// of a recording does not count them; the host shortcut's passthrough and idle-discard flags are
// not in it (of(p) takes p's). Named uniforms (Recording::uniforms, a kernel written in Python)
// are set between passes with set_uniform. Its outputs and discards are the functor's, bit
// for bit, at every width and precision (tests/kernels/test_recorded_program.cpp).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "vgpu/program.h"
#include "vgpu/record.h"

namespace vgpu {

class RecordedProgram final : public Program {
 public:
  // rec as Program::record() makes it (at most one loop, operands before their users). units[i]
  // names texture unit i (listings, generated shaders). Throws std::invalid_argument, naming the
  // program, where the recording cannot be run: a malformed node, a loop the executor cannot
  // follow (the same cases the GLSL printer refuses), outputs that differ from `outputs`.
  RecordedProgram(Recording rec, std::string name, std::string paper_name, int outputs,
                  std::vector<std::string> units = {});
  // p recorded with its current uniforms, under p's names, unit names and precision.
  static std::unique_ptr<RecordedProgram> of(const Program& p);

  const Recording& recording() const { return rec_; }

  const char* name() const override { return name_.c_str(); }
  const char* paper_name() const override { return paper_name_.c_str(); }
  int outputs() const override { return outputs_; }
  // The host shortcut's flags (vgpu/program.h): none for a recording made outside the build,
  // p's own for of(p) (a recording of p keeps what p says its outputs and discards are).
  bool has_passthrough() const override { return has_passthrough_; }
  int passthrough(int output) const override {
    return output >= 0 && output < kMaxOutputs ? passthrough_[size_t(output)] : -1;
  }
  bool idle_discards() const override { return idle_discards_; }

  void run(Fragments<SimdLanes<1>>& f) const override;
  void run(Fragments<SimdLanes<4>>& f) const override;
  void run(Fragments<SimdLanes<8>>& f) const override;
  void run(Fragments<SimdLanes<16>>& f) const override;
  void run(Fragments<CountingLanes>& f) const override;
  void run(Fragments<RoundedLanes<1, Format::fp24>>& f) const override;
  void run(Fragments<RoundedLanes<8, Format::fp24>>& f) const override;
  void run(Fragments<RoundedLanes<1, Format::fp16>>& f) const override;
  void run(Fragments<RoundedLanes<8, Format::fp16>>& f) const override;
  void run(Fragments<RecordingLanes>& f) const override;
  std::string unit_name(int unit) const override;
  // The recording's named uniforms (Recording::uniforms), in its order, and their values now.
  // A recording from a functor has none: its uniforms are constants fixed when it was recorded.
  std::vector<std::string> uniform_names() const;
  bool has_uniform(std::string_view name) const;
  float uniform(std::string_view name) const;
  // Sets a named uniform for the passes that follow (as the host sets a functor's members
  // between passes). Throws std::invalid_argument, naming the program, for a name it does not
  // have or a NaN value. Not while a pass of this program runs.
  void set_uniform(std::string_view name, float value);
  // The named uniforms' values: equal bytes, equal recording (the GL device keeps a compiled
  // shader per bytes, the loop analysis per program and bytes).
  std::span<const std::byte> uniform_bytes() const override {
    return std::as_bytes(std::span<const float>(values_));
  }

 private:
  // One instruction of the compiled recording. dst, a, b, c are register indices: float
  // registers for float values, mask registers for masks (which file each operand names follows
  // from op, as in RecNode). A fetch writes four float registers from dst on.
  struct Instr {
    Op op;
    int8_t unit = -1;  // fetch: texture unit
    int32_t dst = -1, a = -1, b = -1, c = -1;
    float value = 0;    // constant, mask_const
    int32_t node = -1;  // the recording's node (the recording run keeps its constants' ids)
  };
  // A value the loop carries from one iteration to the next: its register `var`, set from `from`
  // (before the loop: the starting value; after each iteration: the iteration's result).
  struct Copy {
    int32_t var, from;
    bool mask;
  };

  void compile();
  template <class L>
  void execute(Fragments<L>& f) const;
  template <class L>
  void step(Fragments<L>& f, typename L::F* fr, typename L::M* mr, const Instr* code, int from,
            int to, int prefix) const;

  Recording rec_;
  std::string name_, paper_name_;
  int outputs_;
  std::vector<std::string> units_;

  std::vector<Instr> code_;
  int float_regs_ = 0, mask_regs_ = 0;
  // The same without its constants, for the computing families: a constant's register keeps its
  // value from one batch to the next while the thread runs this program (a kernel's literals and
  // uniforms are a large part of its nodes), so they are set once, not per batch.
  std::vector<Instr> computed_;
  std::vector<Instr> constants_;
  int computed_body_begin_ = 0, computed_body_end_ = 0;
  // The loop, if any: code_[body_begin_, body_end_) is one iteration; starts_ set the carried
  // values before it, carries_ after each iteration. The lanes still looping live in mask
  // register active_ (the body's parameter, then f.loop's answer); more_ is the body's answer.
  bool has_loop_ = false;
  int body_begin_ = 0, body_end_ = 0, max_iterations_ = 0;
  int32_t entry_ = -1, active_ = -1, more_ = -1;
  std::vector<Copy> starts_, carries_;
  std::vector<std::array<int32_t, 4>> out_regs_;
  int32_t kill_ = -1;  // mask register of the discard, -1: none
  // The named uniforms' values, Recording::uniforms' order, and a stamp that no other program or
  // set of values has had: a thread's registers hold the constants of the stamp they were set for.
  std::vector<float> values_;
  uint64_t stamp_ = 0;
  bool has_passthrough_ = false, idle_discards_ = false;
  std::array<int, kMaxOutputs> passthrough_ = filled(-1);
  static constexpr std::array<int, kMaxOutputs> filled(int v) {
    std::array<int, kMaxOutputs> a{};
    a.fill(v);
    return a;
  }
};

}  // namespace vgpu
