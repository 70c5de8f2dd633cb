// Program identity and the counting run.
#include "vgpu/program.h"

#include <atomic>

namespace vgpu {

Program::Program() {
  static std::atomic<uint32_t> next{1};
  id_ = next++;
}

Program::Analysis Program::analyze() const {
  Analysis a;
  BoundTexture none[kMaxTextureUnits]{};
  uint64_t idle = 0;
  Fragments<CountingLanes> f(none, false, &idle, &a.fetches);
  f.reset(CFloat(0.5f), CFloat(0.5f), CMask{true});
  const uint64_t before = OpCounter::ops;
  run(f);
  a.instructions = int(OpCounter::ops - before);
  a.branches = int(idle);  // the counting run's branch() counts each call as one idle lane
  return a;
}

}  // namespace vgpu
