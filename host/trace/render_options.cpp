// The refusals of option combinations (RenderOptions::refusal): written once, read by the
// command line and by the stream tracer.
#include "host/trace/render_options.h"

#include "host/trace/mrt.h"

namespace host {

std::string RenderOptions::refusal(const vgpu::Profile& profile, std::string_view aa) const {
  // Undersampling traces one ray through each traced pixel; supersampling traces several.
  if (undersample > 0 && spp > 1) {
    std::string why = "--aa ";
    if (!aa.empty()) {
      why += aa;
    } else {
      why += "undersample:";
      why += std::to_string(undersample);
    }
    why += " traces one ray per traced pixel; drop --spp ";
    why += std::to_string(spp);
    return why;
  }
  // The command line cannot ask for these two (--aa is one mode); a program can.
  if (undersample < 0 || (undersample > 0 && adaptive))
    return "undersample: K must be 1 or more, with one ray per traced pixel (spp 1, not adaptive)";
  // The budget's shares of the pixels that hit (kernels/cone_budget.h).
  if (adaptive && aa_criterion == AaCriterion::budget) {
    if (aa_budget.empty()) return "--aa-budget: give one share or more";
    for (const float b : aa_budget)
      if (!(b > 0.0f && b <= 1.0f))
        return "--aa-budget: each share is a percentage of the pixels that hit, above 0 and at "
               "most 100";
  }
  if (mrt && looping)
    return "--mrt on with --kernels looping: the looping program already writes the traversal, "
           "voxel and hit targets in one pass; there are no separate passes left to fuse";
  if (beams && beam_tile < 1) return "--beam-tile: a tile is 1 pixel wide or more";
  // A tile's beam bounds its pixels' rays; a dense stream packs the marked pixels' rays into
  // rows where neighbours are no longer neighbours.
  if (beams && compact && (adaptive || undersample > 0))
    return "--beams on: a dense stream's rays are packed, not laid out by tile: add --compact off";
  // Beams start a ray in the voxel the walk would reach, found with fp32 arithmetic: exact only
  // where the ray state and the traversal are fp32 too.
  if (beams && (formats[Group::rays] != vgpu::Format::fp32 ||
                formats[Group::traversal] != vgpu::Format::fp32 ||
                formats.arithmetic(Group::traversal) != vgpu::Format::fp32))
    return "--beams on: needs fp32 rays and traversal (texels and arithmetic): the beam entry "
           "reaches the voxel the walk would only where both round as fp32";
  // The fused programs' outputs against the profile's limit, and their groups' formats.
  if (mrt) return mrt_refusal(profile, formats);
  return {};
}

}  // namespace host
