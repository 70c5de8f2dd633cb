// The memory model's terms (memory_json.h).
#include "host/report/memory_json.h"

#include "host/common/memory.h"
#include "host/image/image_io.h"
#include "vgpu/texture.h"

namespace host {

MemoryTerms memory_terms(const Scene& scene, const Accel& accel, const StreamTracer* tracer,
                         const RenderResult& r) {
  MemoryTerms m;
  m.process = file_resident_bytes() + startup_anon_bytes();
  m.image_library = image_library_bytes();
  m.scene = scene.host_bytes();
  m.structure = accel.host_bytes();
  m.texture_storage = vgpu::Texture::peak_storage_bytes();
  m.frame = vector_bytes(r.rgb) + vector_bytes(r.depth) + vector_bytes(r.hit_id) +
            vector_bytes(r.rays_per_pixel);
  m.walk_tallies = r.batch_walk_bytes;
  if (tracer) m.textures = tracer->texture_bytes();
  return m;
}

nlohmann::ordered_json memory_json(const MemoryTerms& m, uint64_t peak_resident) {
  nlohmann::ordered_json j;
  j["textures"] = m.textures;
  j["texture_storage"] = m.texture_storage;
  j["scene"] = m.scene;
  j["structure"] = m.structure;
  j["frame"] = m.frame;
  j["walk_tallies"] = m.walk_tallies;
  j["image_library"] = m.image_library;
  j["process"] = m.process;
  j["predicted_peak"] = m.predicted();
  j["peak_resident"] = peak_resident;
  j["predicted_over_peak"] = peak_resident ? double(m.predicted()) / double(peak_resident) : 0.0;
  return j;
}

}  // namespace host
