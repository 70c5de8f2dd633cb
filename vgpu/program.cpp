// Program identity and the counting run.
#include "vgpu/program.h"

#include <algorithm>
#include <atomic>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include "vgpu/span.h"

namespace vgpu {

void refuse_lane_width(const char* program, int lanes) {
  throw std::logic_error(std::string(program) + ": this build compiled the project's kernels at " +
                         "1 and 8 lanes only (VGPU_KERNEL_WIDTHS_1_8, the sanitizer build), not " +
                         std::to_string(lanes));
}

Program::Program(const AbiTag& abi) {
  check_abi(abi);
  static std::atomic<uint32_t> next{1};
  id_ = next++;
}

Program::Analysis Program::analyze() const {
  Analysis a;
  BoundTexture none[kMaxTextureUnits]{};
  uint64_t idle = 0;
  Fragments<CountingLanes> f(none, false, &idle, &a.fetches);
  f.reset(CFloat(0.5f), CFloat(0.5f), CMask{true});
  f.set_loop_tally(&a.loop);
  const uint64_t before = OpCounter::ops;
  run(f);
  a.instructions = int(OpCounter::ops - before);
  a.branches = int(idle);  // the counting run's branch() counts each call as one idle lane
  if (a.loop.loops > 0) {  // the body's longest wait, from the recorded program (vgpu/span.h)
    // analyze() runs at every draw and program load, and a traversal kernel's recording takes
    // several us: the chain is kept per program and uniform bytes (equal bytes, equal
    // recording), per thread, as the GL device keeps its compiled programs.
    struct Memo {
      std::vector<std::byte> uniforms;
      LoopChain chain;
      int dependent = 0;
    };
    static thread_local std::unordered_map<uint32_t, Memo> memo;
    const std::span<const std::byte> bytes = uniform_bytes();
    auto [it, fresh] = memo.try_emplace(id_);
    Memo& m = it->second;
    if (fresh || !std::equal(bytes.begin(), bytes.end(), m.uniforms.begin(), m.uniforms.end())) {
      m.uniforms.assign(bytes.begin(), bytes.end());
      const Recording rec = record();
      m.chain = loop_chain(rec);
      m.dependent = loop_dependent_operations(rec);
    }
    a.loop.chain_fetches = m.chain.fetches;
    a.loop.chain_operations = m.chain.operations;
    a.loop.dependent_operations = m.dependent;
  }
  return a;
}

Recording Program::record() const {
  Recording rec;
  Recording* const outer = Recorder::current;
  Recorder::current = &rec;
  {
    BoundTexture none[kMaxTextureUnits]{};
    Fragments<RecordingLanes> f(none, false, nullptr, nullptr);
    f.reset(RFloat32::node(rec.push({Op::frag_x})), RFloat32::node(rec.push({Op::frag_y})),
            RMask(true), outputs());
    run(f);
    for (int o = 0; o < outputs(); ++o) {
      const Vec4<RFloat32>& v = f.output(o);
      rec.outputs.push_back({v.x.id, v.y.id, v.z.id, v.w.id});
    }
    const int kill = f.killed().id;
    rec.kill = kill == rec.mask_false ? -1 : kill;
  }
  Recorder::current = outer;
  return rec;
}

}  // namespace vgpu
