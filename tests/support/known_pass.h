// A pass whose counts are known by hand (tests/vgpu/test_stats.cpp works them out): 64x64
// fragments of a five-instruction program that fetches three fp32x4 texels and writes one. The
// vgpu's statistics tests and the report room's JSON test of them share it.
#pragma once

#include "vgpu/vgpu.h"

namespace test_support {

using vgpu::Counters;
using vgpu::Format;
using vgpu::Fragments;
using vgpu::FrameStats;

// Three fetches, one multiply, one add: 5 instructions.
struct Add3 {
  static constexpr const char* name = "add3";
  static constexpr const char* paper_name = "intersecciones";
  static constexpr int outputs = 1;
  template <class L>
  void operator()(Fragments<L>& f) const {
    auto a = f.fetch_own(0), b = f.fetch_own(1), c = f.fetch_own(2);
    f.out(0) = {a.x + b.x * c.x, a.y, b.y, c.y};
  }
};

struct Known {
  Counters pass;
  FrameStats stats;
};

// The known pass: 64x64 fragments, three fp32x4 fetches each, one write into `target_format`.
inline Known known_pass(int threads, int lanes, Format target_format = Format::fp32,
                        Format source_format = Format::fp32) {
  vgpu::Gpu gpu(vgpu::profile("gf5700"), threads, lanes);
  vgpu::Texture a = gpu.make_texture("a", 64, 64, 4, source_format),
                b = gpu.make_texture("b", 64, 64, 4, source_format),
                c = gpu.make_texture("c", 64, 64, 4, source_format),
                o = gpu.make_texture("o", 64, 64, 4, target_format);
  vgpu::KernelProgram<Add3> p;
  gpu.use_program(p);
  gpu.bind_texture(0, a);
  gpu.bind_texture(1, b);
  gpu.bind_texture(2, c);
  gpu.set_targets({&o});
  const Counters pass = gpu.draw().counters;
  return {pass, gpu.stats()};
}

}  // namespace test_support
