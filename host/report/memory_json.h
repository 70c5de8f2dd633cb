#pragma once
// The memory model (docs/studies/scale.md, "Memory"): the bytes a frame holds, term by term,
// and their sum against the process's measured peak. The terms of what the program allocated
// are exact counts (texels, array sizes, the tallies' capacities); those of the code and the
// image library are the system's pages, read when the frame's statistics are written:
//   process         the code and libraries' pages resident now (file pages, shared), and the
//                   anonymous pages resident when the program started
//   image_library   the anonymous pages the image module's first use added (OpenImageIO and its
//                   libraries: relocated data, tables)
//   scene           the host's triangles, materials and texture images (Scene::host_bytes)
//   structure       the host's copy of the structure (Accel::host_bytes)
//   texture_storage the emulator's texels at their peak, 4 bytes a channel (Texture::
//                   peak_storage_bytes); the card's own bytes, by format, are `textures`
//   frame           the frame read back: colour, depth, hit ids and rays per pixel
//                   (RenderResult)
//   walk_tallies    a batch walk's per-pass tallies, every thread's (RenderResult::
//                   batch_walk_bytes): the emulator's bookkeeping, not the card's
// predicted = the sum; measured = getrusage's peak.

#include <cstdint>
#include <nlohmann/json.hpp>

#include "host/accel/accel.h"
#include "host/scene/scene.h"
#include "host/trace/render_options.h"
#include "host/trace/stream/stream_tracer.h"

namespace host {

struct MemoryTerms {
  uint64_t process = 0, image_library = 0, scene = 0, structure = 0, texture_storage = 0, frame = 0,
           walk_tallies = 0;
  uint64_t textures = 0;  // the modeled card's texture bytes (StreamTracer::texture_bytes)
  uint64_t predicted() const {
    return process + image_library + scene + structure + texture_storage + frame + walk_tallies;
  }
};

// The terms of a frame just rendered; tracer nullptr for the CPU reference (no textures).
MemoryTerms memory_terms(const Scene& scene, const Accel& accel, const StreamTracer* tracer,
                         const RenderResult& result);
// As the statistics' "memory" object: the terms, their sum, the measured peak and the ratio.
nlohmann::ordered_json memory_json(const MemoryTerms& m, uint64_t peak_resident);

}  // namespace host
