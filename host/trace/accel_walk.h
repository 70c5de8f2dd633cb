// What the host loop (host/trace/stream_tracer.cpp) needs of an acceleration structure's walk:
// its static textures, its per-pixel state, and one stream of rays traced through it. The
// paper's uniform grid (grid_walk.h) and the extensions (bvh_walk.h) implement it; how their
// pass sequences run is host/trace/walk.h's business.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "host/accel/accel.h"
#include "host/trace/passes.h"
#include "vgpu/vgpu.h"

namespace host {

// The tracer's textures and masks a walk reads and writes: the scene's vertices, the
// intersection state (nearest hit so far) and the two masks of walking and testing rays.
struct WalkShared {
  const vgpu::Texture* vertices[3];
  vgpu::Texture* isect[2];
  int* cur_isect;  // which of isect is current
  vgpu::Stencil* grid_mask;
  vgpu::Stencil* isect_mask;
};

class AccelWalk {
 public:
  virtual ~AccelWalk() = default;
  // The per-pixel state textures, made after the tracer's own.
  virtual void make_state(vgpu::Device& gpu, const WalkShared& shared) = 0;
  // Video memory gets the static textures at initialization.
  virtual void upload(vgpu::Device& gpu) const = 0;
  // Between frames of a moving scene (StreamTracer::update): the structure `accel` (of the
  // kind the walk was made for, rebuilt for the scene posed anew) replaces the old one. Its
  // static textures are rewritten in place where the new structure fits them (else made anew),
  // each one whose texels changed is uploaded again and named in `uploaded`, and the uniforms
  // are set. Returns the bytes uploaded. Throws vgpu::Error past the profile's limits.
  virtual uint64_t rebuild(vgpu::Device& gpu, const Accel& accel, float scene_width,
                           std::vector<std::string>& uploaded) = 0;
  virtual uint64_t static_bytes() const = 0;   // the structure's textures, as upload() sends
  virtual uint64_t texture_bytes() const = 0;  // those and the per-pixel state
  // One stream of rays: enter the structure, then walk it until no ray is walking. Leaves the
  // nearest hits in the current intersection texture.
  virtual void trace(PassRunner& r, vgpu::Texture& origins, vgpu::Texture& rays, bool primary,
                     glm::vec3 eye) = 0;
};

}  // namespace host
