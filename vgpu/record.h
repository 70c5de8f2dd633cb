// The recording lane family: a kernel run once in it does not compute, each operation appends a
// node to an expression list (as SwiftShader's Reactor types build IR). vgpu/glsl.h prints that
// list as a GLSL fragment shader, so the GL device runs programs generated from the very functors
// the emulator runs: one kernel source, two devices.
//
// Like the counting run, every f.branch() block is taken (the fp30 model: both sides execute and
// results go through select), so the recorded program is straight-line code but for one
// data-dependent loop (RecLoop).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "vgpu/lanes.h"

namespace vgpu {

enum class Op : uint8_t {
  constant,  // value (a literal or a uniform of the functor; both become shader uniforms)
  frag_x,    // window position of the fragment: pixel centre, as Fragments::x
  frag_y,
  add,  // a + b
  sub,  // a - b
  mul,  // a * b
  div,  // a / b
  neg,  // -a
  min,  // a < b ? a : b (ARB_fragment_program MIN)
  max,  // a > b ? a : b
  abs,
  floor,
  sqrt,
  rsqrt,   // 1 / sqrt(a), two correctly rounded steps as the emulator computes it
  select,  // c ? a : b (c a mask)
  lt,
  le,
  gt,
  ge,
  eq,
  ne,          // masks from floats
  mask_const,  // value != 0
  mask_and,
  mask_or,
  mask_not,
  fetch,      // texel of unit `unit` at texRECT coordinates (a, b): a vec4
  fetch_own,  // texel of unit `unit` at this fragment's own pixel: a vec4
  channel,    // component `unit` (0..3) of the vec4 node a
};

// What a node computes: a float, a mask, or (a fetch) a texel of four floats; and what each of its
// operands a, b, c is (none where it has fewer). The one classification the executor
// (vgpu/recorded_program.cpp) and the GLSL printer (vgpu/glsl.cpp) read.
enum class Value : uint8_t { none, number, mask, texel };

constexpr Value value_of(Op op) {
  switch (op) {
    case Op::lt:
    case Op::le:
    case Op::gt:
    case Op::ge:
    case Op::eq:
    case Op::ne:
    case Op::mask_const:
    case Op::mask_and:
    case Op::mask_or:
    case Op::mask_not:
      return Value::mask;
    case Op::fetch:
    case Op::fetch_own:
      return Value::texel;
    default:
      return Value::number;
  }
}

// The values of a node's operands a, b, c (none where it has fewer).
constexpr std::array<Value, 3> operands_of(Op op) {
  using K = Value;
  switch (op) {
    case Op::add:
    case Op::sub:
    case Op::mul:
    case Op::div:
    case Op::min:
    case Op::max:
    case Op::lt:
    case Op::le:
    case Op::gt:
    case Op::ge:
    case Op::eq:
    case Op::ne:
    case Op::fetch:
      return {K::number, K::number, K::none};
    case Op::neg:
    case Op::abs:
    case Op::floor:
    case Op::sqrt:
    case Op::rsqrt:
      return {K::number, K::none, K::none};
    case Op::select:
      return {K::mask, K::number, K::number};
    case Op::mask_and:
    case Op::mask_or:
      return {K::mask, K::mask, K::none};
    case Op::mask_not:
      return {K::mask, K::none, K::none};
    case Op::channel:
      return {K::texel, K::none, K::none};
    default:  // constant, frag_x, frag_y, mask_const, fetch_own
      return {K::none, K::none, K::none};
  }
}

struct RecNode {
  Op op;
  int a = -1, b = -1, c = -1;
  int unit = -1;  // fetch: texture unit; channel: component
  float value = 0;
};

// A data-dependent loop (Fragments::loop) as recorded: its body twice, nodes [begin, mid) and
// [mid, end), each ending with the mask of lanes still looping (active && the body's answer).
// Where the second copy reads a node of the first instead of the value the first read, that
// value is carried from one iteration to the next (vgpu/glsl.cpp prints one loop from this).
struct RecLoop {
  int begin = 0, mid = 0, end = 0;
  int max_iterations = 0;
  int entry = -1;  // mask node: the lanes entering the loop
};

// A named uniform of a recording: the constant nodes that read it. A functor's uniforms are its
// data members, anonymous in its recording; a kernel written outside the project's build (from
// Python, python/vgpu_rt) names each, so that a frame can set them between passes
// (vgpu::RecordedProgram::set_uniform, host/trace/user_stage.h).
struct RecUniform {
  std::string name;
  std::vector<int> nodes;  // Op::constant nodes holding its value
};

// One program's operations in the order the functor performed them.
struct Recording {
  std::vector<RecNode> nodes;
  std::vector<std::array<int, 4>> outputs;  // node of each channel of each output register
  int kill = -1;                            // mask node: the fragment is discarded (-1: never)
  int mask_false = -1, mask_true = -1;
  std::vector<RecLoop> loops;        // at most one (the vgpu refuses more)
  std::vector<RecUniform> uniforms;  // named uniforms (none in a functor's recording)

  int push(const RecNode& n) {
    nodes.push_back(n);
    return int(nodes.size()) - 1;
  }
  // Every constant the functor makes is its own node, even where two values happen to be equal:
  // the program's text then depends on its code alone, never on its uniforms' values.
  int constant(float v) { return push({Op::constant, -1, -1, -1, -1, v}); }
  int mask_constant(bool v) {
    int& id = v ? mask_true : mask_false;
    if (id < 0) id = push({Op::mask_const, -1, -1, -1, -1, v ? 1.0f : 0.0f});
    return id;
  }
};

// The recording being written by this thread (set by Program::record()).
struct Recorder {
  static inline thread_local Recording* current = nullptr;
  static int emit(Op o, int a, int b = -1, int c = -1) { return current->push({o, a, b, c}); }
};

struct RMask;
// A float register: the node that computes it.
struct RFloat32 {
  int id = -1;
  RFloat32() = default;
  RFloat32(float f) : id(Recorder::current->constant(f)) {}
  static RFloat32 node(int id) {
    RFloat32 r;
    r.id = id;
    return r;
  }
#define VGPU_RECORDED_BINOP(op, code)                   \
  friend RFloat32 operator op(RFloat32 a, RFloat32 b) { \
    return node(Recorder::emit(Op::code, a.id, b.id));  \
  }                                                     \
  RFloat32& operator op##=(RFloat32 b) {                \
    return *this = *this op b;                          \
  }
  VGPU_RECORDED_BINOP(+, add)
  VGPU_RECORDED_BINOP(-, sub)
  VGPU_RECORDED_BINOP(*, mul)
  VGPU_RECORDED_BINOP(/, div)
#undef VGPU_RECORDED_BINOP
  friend RFloat32 operator-(RFloat32 a) {
    return node(Recorder::emit(Op::neg, a.id));
  }
  friend RMask operator<(RFloat32 a, RFloat32 b);
  friend RMask operator<=(RFloat32 a, RFloat32 b);
  friend RMask operator>(RFloat32 a, RFloat32 b);
  friend RMask operator>=(RFloat32 a, RFloat32 b);
  friend RMask operator==(RFloat32 a, RFloat32 b);
  friend RMask operator!=(RFloat32 a, RFloat32 b);
};

struct RMask {
  int id = -1;
  RMask() = default;
  explicit RMask(bool v) : id(Recorder::current->mask_constant(v)) {}
  static RMask node(int id) {
    RMask m;
    m.id = id;
    return m;
  }
  // Constant masks fold away, so `kill = kill || m` records just m.
  friend RMask operator&&(RMask a, RMask b) {
    const Recording& r = *Recorder::current;
    if (a.id == r.mask_true) return b;
    if (b.id == r.mask_true) return a;
    return node(Recorder::emit(Op::mask_and, a.id, b.id));
  }
  friend RMask operator||(RMask a, RMask b) {
    const Recording& r = *Recorder::current;
    if (a.id == r.mask_false) return b;
    if (b.id == r.mask_false) return a;
    return node(Recorder::emit(Op::mask_or, a.id, b.id));
  }
  friend RMask operator!(RMask a) { return node(Recorder::emit(Op::mask_not, a.id)); }
};

#define VGPU_RECORDED_CMP(op, code)                           \
  inline RMask operator op(RFloat32 a, RFloat32 b) {          \
    return RMask::node(Recorder::emit(Op::code, a.id, b.id)); \
  }
VGPU_RECORDED_CMP(<, lt)
VGPU_RECORDED_CMP(<=, le)
VGPU_RECORDED_CMP(>, gt)
VGPU_RECORDED_CMP(>=, ge)
VGPU_RECORDED_CMP(==, eq)
VGPU_RECORDED_CMP(!=, ne)
#undef VGPU_RECORDED_CMP

inline RFloat32 select(RMask m, RFloat32 a, RFloat32 b) {
  return RFloat32::node(Recorder::emit(Op::select, m.id, a.id, b.id));
}
inline RFloat32 min(RFloat32 a, RFloat32 b) {
  return RFloat32::node(Recorder::emit(Op::min, a.id, b.id));
}
inline RFloat32 max(RFloat32 a, RFloat32 b) {
  return RFloat32::node(Recorder::emit(Op::max, a.id, b.id));
}
inline RFloat32 abs(RFloat32 a) {
  return RFloat32::node(Recorder::emit(Op::abs, a.id));
}
inline RFloat32 floor(RFloat32 a) {
  return RFloat32::node(Recorder::emit(Op::floor, a.id));
}
inline RFloat32 sqrt(RFloat32 a) {
  return RFloat32::node(Recorder::emit(Op::sqrt, a.id));
}
inline RFloat32 rsqrt(RFloat32 a) {
  return RFloat32::node(Recorder::emit(Op::rsqrt, a.id));
}

struct RecordingLanes {
  static constexpr int width = 1;
  static constexpr bool counting = false;
  static constexpr bool recording = true;
  using F = RFloat32;
  using M = RMask;
};

}  // namespace vgpu
