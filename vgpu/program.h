// Fragment programs: a kernel functor with a name, its paper name, its outputs, and code written
// once over lanes. Wrapping it in KernelProgram<K> compiles it for every lane width and for the
// counting run that derives its instruction count and fetches from the code itself.
//
// A kernel K provides:
//   static constexpr const char* name;        // English name, used in statistics and logs
//   static constexpr const char* paper_name;  // the paper's name (e.g. "generadorRayos")
//   static constexpr int outputs;             // render targets written (1 on fp30)
//   template <class L> void operator()(Fragments<L>& f) const;
// and may provide, for the emulator's host shortcut (see Gpu::set_work_mask):
//   static constexpr std::array<int, outputs> passthrough;  // unit holding output i's old value
//   static constexpr bool idle_discards;                     // an idle fragment is discarded
// and, to name its texture units in listings and generated shaders:
//   static constexpr std::array<const char*, N> units;       // what unit i holds
// Uniforms are the functor's data members, set by the host between passes.
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <string>

#include "vgpu/abi.h"
#include "vgpu/fragment.h"
#include "vgpu/precision.h"

namespace vgpu {

class Program {
 public:
  virtual ~Program() = default;
  virtual const char* name() const = 0;
  virtual const char* paper_name() const = 0;
  virtual int outputs() const = 0;
  virtual bool has_passthrough() const = 0;
  virtual int passthrough(int output) const = 0;
  virtual bool idle_discards() const = 0;
  uint32_t id() const { return id_; }
  // Arithmetic precision the program asks for (Cg's float / half per program): fp32 by default.
  // A pass computes in the coarser of this and Gpu::precision(), as the profile allows
  // (Profile::computes).
  void set_precision(Format f) { precision_ = f; }
  Format precision() const { return precision_; }

  virtual void run(Fragments<SimdLanes<1>>& f) const = 0;
  virtual void run(Fragments<SimdLanes<4>>& f) const = 0;
  virtual void run(Fragments<SimdLanes<8>>& f) const = 0;
  virtual void run(Fragments<SimdLanes<16>>& f) const = 0;
  virtual void run(Fragments<CountingLanes>& f) const = 0;
  virtual void run(Fragments<RoundedLanes<1, Format::fp24>>& f) const = 0;
  virtual void run(Fragments<RoundedLanes<8, Format::fp24>>& f) const = 0;
  virtual void run(Fragments<RoundedLanes<1, Format::fp16>>& f) const = 0;
  virtual void run(Fragments<RoundedLanes<8, Format::fp16>>& f) const = 0;
  virtual void run(Fragments<RecordingLanes>& f) const = 0;
  // What texture unit u holds ("unit u" where the kernel names none).
  virtual std::string unit_name(int unit) const = 0;
  // The functor's uniforms as raw bytes: equal bytes give an equal recording (padding may
  // differ between equal values; that only costs a re-recording).
  virtual std::span<const std::byte> uniform_bytes() const = 0;

  // The counting run: static instructions per fragment and fetches per unit, with the current
  // uniforms (a uniform loop bound, e.g. the number of lights, changes the count).
  struct Analysis {
    int instructions = 0;
    int branches = 0;  // f.branch() calls, every branch taken (what a work-masked fragment skips)
    FetchTally fetches;
    LoopTally loop;  // data-dependent loops (f.loop): their bodies are inside the counts above
  };
  Analysis analyze() const;
  // The recording run: every operation of the program, with the current uniforms.
  Recording record() const;

 protected:
  // `abi`: the tag of the translation unit that constructs the program (vgpu/abi.h); a kernel
  // compiled with other target flags than the library is refused here, with std::logic_error.
  explicit Program(const AbiTag& abi = VGPU_ABI_HERE);

 private:
  uint32_t id_;
  Format precision_ = Format::fp32;
};

// Whether KernelProgram<K> runs at widths 4 and 16. The sanitizer build compiles the project's
// kernels (kernels/kernels.h turns this off for each) at widths 1 and 8 only, where it defines
// VGPU_KERNEL_WIDTHS_1_8 (CMakeLists.txt: their programs are a fifth of that build's compile
// time, widths 4 and 16 about a third of that; the Release build tests every width against
// width 1, tests/kernels/test_kernel_lane_widths.cpp). A pass at a width not compiled throws.
template <class K>
inline constexpr bool kEveryLaneWidth = true;
[[noreturn]] void refuse_lane_width(const char* program, int lanes);

template <class K>
class KernelProgram final : public Program {
 public:
  K kernel;  // uniforms live here: the host sets them between passes

  explicit KernelProgram(K k = K{}) : kernel(std::move(k)) {}
  const char* name() const override { return K::name; }
  const char* paper_name() const override { return K::paper_name; }
  int outputs() const override { return K::outputs; }
  bool has_passthrough() const override {
    return requires {
      K::passthrough;
    };
  }
  int passthrough(int output) const override {
    if constexpr (requires { K::passthrough; })
      return K::passthrough[output];
    else
      return -1;
  }
  bool idle_discards() const override {
    if constexpr (requires { K::idle_discards; })
      return K::idle_discards;
    else
      return false;
  }
  void run(Fragments<SimdLanes<1>>& f) const override { kernel(f); }
  void run(Fragments<SimdLanes<4>>& f) const override {
    if constexpr (kEveryLaneWidth<K>)
      kernel(f);
    else
      refuse_lane_width(K::name, 4);
  }
  void run(Fragments<SimdLanes<8>>& f) const override { kernel(f); }
  void run(Fragments<SimdLanes<16>>& f) const override {
    if constexpr (kEveryLaneWidth<K>)
      kernel(f);
    else
      refuse_lane_width(K::name, 16);
  }
  void run(Fragments<CountingLanes>& f) const override { kernel(f); }
  void run(Fragments<RoundedLanes<1, Format::fp24>>& f) const override { kernel(f); }
  void run(Fragments<RoundedLanes<8, Format::fp24>>& f) const override { kernel(f); }
  void run(Fragments<RoundedLanes<1, Format::fp16>>& f) const override { kernel(f); }
  void run(Fragments<RoundedLanes<8, Format::fp16>>& f) const override { kernel(f); }
  void run(Fragments<RecordingLanes>& f) const override { kernel(f); }
  std::string unit_name(int unit) const override {
    if constexpr (requires { K::units; })
      if (unit >= 0 && unit < int(K::units.size())) return K::units[size_t(unit)];
    return "unit" + std::to_string(unit);
  }
  std::span<const std::byte> uniform_bytes() const override {
    return std::as_bytes(std::span<const K, 1>(&kernel, 1));
  }
};

}  // namespace vgpu
