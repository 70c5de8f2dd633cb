// The uniform grid's resolution fitted to a profile: its voxel pointers are one texture of
// sizeX*sizeY by sizeZ texels, which must fit the profile's largest texture.
#pragma once

#include "host/accel/grid.h"
#include "host/scene/scene.h"
#include "vgpu/profile.h"

namespace host {

// The grid spec to build for a profile: an automatic resolution is shrunk in x and y until the
// voxel pointer texture fits the profile's largest texture; an explicit one is kept (and refused
// at initialization if it does not fit).
GridSpec grid_spec_for(const GridSpec& spec, const Scene& scene, const vgpu::Profile& profile);

}  // namespace host
