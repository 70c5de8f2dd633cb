// The walks of each acceleration structure: host/trace's half of the table of structures. A row
// per structure, keyed by host/accel/accel.h's kAccelRows (which holds each one's name, --accel's
// one-line description and its build) and in the same order, which a static_assert in
// structures.cpp checks. Each row gives
//   stream_walk  the stream tracer's walk (host/trace/walks/): its textures, programs and passes;
//   cpu          the CPU tracer's walk in double (host/trace/cpu/cpu_core.h's Tracer);
//   kernels      the kernels its walk loads that --accel auto's work counts read (walk_work).
// To add a structure: add a row here and in kAccelRows, write its Accel subclass
// (host/accel/accel.h, with its statistics: an alternative of host/accel/accel_stats.h's
// AccelStats), its walk and its CPU walk; nothing else lists structures.
#pragma once

#include <array>
#include <glm/glm.hpp>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>

#include "host/accel/accel.h"
#include "host/trace/render_options.h"

namespace vgpu {
class Device;
}

namespace host {

class AccelWalk;
struct CpuBeamStart;
namespace cpu_core {
class Tracer;
struct Hit;
struct Counters;
}  // namespace cpu_core

// The kernels of a walk that count its work (walk_work): the step pass and the intersection
// pass, each alone and fused (--mrt on), and the looping kernel (--kernels looping).
struct WalkKernels {
  bool tree;  // its steps visit nodes (WalkWork::nodes_visited), not cells (voxel_steps)
  std::array<const char*, 2> steps;  // the step, and the step fused with the load
  std::array<const char*, 2> tests;  // the intersection, and it fused with the next triangle
  const char* looping;
};

// The CPU tracer's walk: `start` takes the structure from the Accel (walked()) and makes its
// beams where --beams on; `trace` is the walk (Tracer::trace's contract, after its count).
struct CpuWalk {
  void (cpu_core::Tracer::*start)(const Accel& accel, const Camera& camera,
                                  const RenderOptions& opt);
  cpu_core::Hit (cpu_core::Tracer::*trace)(const glm::dvec3& o, const glm::dvec3& d, double tmax,
                                           bool any_hit, cpu_core::Counters& c,
                                           const CpuBeamStart* beam) const;
};

struct WalkRow {
  AccelKind kind;
  // The walk over `accel` (of this row's kind), its programs in `opt`'s formats; scene_width is
  // the scene textures' width, t_slack the hit slack (kSlackOfDiagonal of the box's diagonal).
  std::unique_ptr<AccelWalk> (*stream_walk)(vgpu::Device& gpu, const Accel& accel,
                                            const RenderOptions& opt, float scene_width,
                                            float t_slack);
  CpuWalk cpu;
  WalkKernels kernels;
};

// Every row, in kAccelRows' order.
std::span<const WalkRow> walk_rows();
// The row of `kind`.
const WalkRow& walk_row(AccelKind kind);

// The structure a row's walk needs from `accel` (e.g. accel.bvh()): throws std::logic_error
// where it is null, a row's walk given another kind's structure.
template <class T>
const T& walked(const T* structure, const Accel& accel) {
  if (!structure)
    throw std::logic_error("a walk was given a structure of another kind (" +
                           std::string(accel.name()) + ")");
  return *structure;
}

}  // namespace host
