// What the glTF loader's two files share (gltf_file.cpp reads and parses, gltf_loader.cpp builds
// the Scene): the one-line error messages, little-endian reads and the parse step itself.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace tinygltf {
class Model;
}

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
// byteLength. Any problem throws InputError.
std::vector<uint64_t> parse_file(const std::string& path, tinygltf::Model& model,
                                 std::vector<std::string>& warnings);

}  // namespace host::gltf_detail
