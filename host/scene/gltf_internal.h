// What the glTF loader's files share (gltf_file.cpp reads and parses, gltf_loader.cpp builds
// the Scene, animation.cpp poses it): the one-line error messages, little-endian reads, the parse
// step itself and the loader kept open.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "host/scene/gltf_loader.h"

namespace tinygltf {
class Model;
}

namespace host {
struct LoadOptions;
struct Scene;
}  // namespace host

namespace host::gltf_detail {

// `text` as one printable line: whitespace runs become one space, control bytes '?'.
std::string one_line(std::string_view text, size_t max_chars);

// Throws InputError "PATH: problem", both made one line.
[[noreturn]] void fail(const std::string& path, const std::string& problem);

inline uint32_t le32(const unsigned char* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

// Reads `path` (a .gltf or .glb), pre-checks its JSON and buffer sizes and parses it with
// tinygltf into `model`; tinygltf's warnings go to `warnings`. Returns each buffer's declared
// byteLength. Any problem throws InputError. tinygltf never sees the images, textures and samplers
// (it reads image buffer views unchecked): `textures` gets them as JSON text, an object with
// "images", "textures", "samplers" and "base_color" (each material's baseColorTexture or null).
// The file's animations are parsed only with `keep_animations`.
std::vector<uint64_t> parse_file(const std::string& path, tinygltf::Model& model,
                                 std::vector<std::string>& warnings, std::string& textures,
                                 bool keep_animations);

// A material's baseColorTexture as the loader applies it: which Scene::textures entry, which
// TEXCOORD_n set, and KHR_texture_transform's matrix (identity without it).
struct BaseColorTexture {
  int texture = -1;
  int tex_coord = 0;
  glm::dmat3 transform{1.0};
};

// Every material's baseColorTexture (gltf_textures.cpp), from parse_file's `textures` JSON:
// appends each (image, wraps) pair's decoded texture to scene.textures and returns one entry per
// material (texture -1 where it has none). Any problem throws InputError.
std::vector<BaseColorTexture> read_textures(const std::string& path, const std::string& textures,
                                            const tinygltf::Model& model,
                                            const LoadOptions& options, Scene& scene);

class Loader;

// The loader kept open, so that one file's scene can be flattened again for other node
// transforms (host/scene/animation.cpp, once per frame): the file is parsed and checked once,
// each primitive decoded once.
class OpenScene {
 public:
  // Parses and checks the file (throws InputError as load_scene does).
  OpenScene(const std::string& path, const LoadOptions& options);
  ~OpenScene();
  // The default scene flattened as load_scene() does (gltf_loader.h's rules), with local[n],
  // where set, as node n's local transform instead of the file's.
  Scene flatten(const std::vector<std::optional<glm::dmat4>>& local = {});
  // The same, once and for the last time: the scene takes the decoded textures (no copy).
  Scene flatten_last();
  const tinygltf::Model& model() const;
  const std::string& path() const;
  // The nodes the last flatten() walked, in walk order.
  const std::vector<int>& walked() const;
  // Accessor `accessor` read for `use` as doubles, `components` per element (1: SCALAR, 3:
  // VEC3, 4: VEC4): float components, with `integers` also normalized byte and short ones.
  // Checked like every accessor (in range, not sparse); a non-finite value throws InputError.
  std::vector<double> read_doubles(int accessor, const std::string& use, int components,
                                   bool integers) const;

 private:
  std::unique_ptr<Loader> loader_;
};

// A primitive mode's name as the glTF spec spells it (TRIANGLES, ...), "unknown" past them.
const char* mode_name(int mode);
// One accessor component as float; normalized integers follow the glTF spec (max(c / 127, -1),
// ...); any other component type is read as FLOAT (checked by the caller).
float read_component(const unsigned char* p, int component_type, bool normalized);
// A number as a message shows it: as the file most likely wrote it (0.5, not 0.500000).
std::string shortest(double x);

}  // namespace host::gltf_detail
