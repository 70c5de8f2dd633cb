// The fused programs of --mrt on and why they cannot run (host/trace/mrt.h).
#include "host/trace/mrt.h"

#include <array>

#include "kernels/fused.h"

namespace host {

using namespace kernels;

namespace {

// The fused programs, each with its two kernels' groups (their arithmetic must agree).
struct FusedInfo {
  const char* name;
  int outputs;
  Group first, second;
};
const std::array<FusedInfo, 2>& fused_programs() {
  static const std::array<FusedInfo, 2> f{
      FusedInfo{IntersectNext::name, IntersectNext::outputs, Group::hits, Group::voxel},
      FusedInfo{TraverseUpdate::name, TraverseUpdate::outputs, Group::traversal, Group::voxel}};
  return f;
}

}  // namespace

std::string mrt_refusal(const vgpu::Profile& profile, const Formats& formats) {
  for (const FusedInfo& f : fused_programs()) {
    if (f.outputs > profile.max_outputs)
      return "--mrt on: program '" + std::string(f.name) + "' writes " + std::to_string(f.outputs) +
             " outputs; profile " + profile.name + " allows " +
             std::to_string(profile.max_outputs) + " (no multiple render targets)";
    if (formats.arithmetic(f.first) != formats.arithmetic(f.second))
      return "--mrt on: program '" + std::string(f.name) + "' computes in one format, but groups " +
             std::string(group_name(f.first)) + " (" +
             std::string(vgpu::format_name(formats.arithmetic(f.first))) + ") and " +
             std::string(group_name(f.second)) + " (" +
             std::string(vgpu::format_name(formats.arithmetic(f.second))) +
             ") differ; give them one arithmetic format (--formats)";
  }
  return {};
}

std::vector<std::string> mrt_programs() {
  std::vector<std::string> v;
  for (const FusedInfo& f : fused_programs()) v.push_back(f.name);
  return v;
}

}  // namespace host
