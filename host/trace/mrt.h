// Multiple render targets (--mrt on, the paper's future work): the fused two-output programs
// (kernels/fused.h) every walk runs in place of two passes, and why a profile or a format choice
// cannot run them.
#pragma once

#include <string>
#include <vector>

#include "host/model/formats.h"
#include "vgpu/profile.h"

namespace host {

// Why RenderOptions::mrt cannot run with this profile and these formats (empty: it can): a
// fused program writes more outputs than the profile allows, or computes in one arithmetic
// format where its two kernels' groups differ (host/model/formats.h). Names the fused program.
std::string mrt_refusal(const vgpu::Profile& profile, const Formats& formats);

// The fused programs --mrt on runs (kernels/fused.h), by statistics name.
std::vector<std::string> mrt_programs();

}  // namespace host
