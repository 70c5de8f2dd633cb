// The uniform grid's resolution fitted to a profile (host/trace/grid_spec.h).
#include "host/trace/grid_spec.h"

#include <algorithm>
#include <cmath>

namespace host {

GridSpec grid_spec_for(const GridSpec& spec, const Scene& scene, const vgpu::Profile& profile) {
  if (!spec.automatic()) return spec;
  glm::ivec3 r = auto_resolution(scene.bounds(), scene.triangle_count());
  const double maxs = profile.max_texture_size;
  while (double(r.x) * r.y > maxs) {
    const double f = std::sqrt(maxs / (double(r.x) * r.y));
    r.x = std::max(1, int(r.x * f));
    r.y = std::max(1, int(r.y * f));
  }
  r.z = std::min(r.z, profile.max_texture_size);
  return GridSpec{r};
}

}  // namespace host
