// The glTF loader's file side: reading the file, splitting a .glb, pre-checking the JSON and
// buffer sizes (tinygltf accepts some broken files), then tinygltf's parse; and scenes by name.
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <span>
#include <string_view>

#include "host/common/install_paths.h"
#include "host/scene/gltf_internal.h"
#include "host/scene/gltf_loader.h"

// The one translation unit that holds tinygltf and stb. Images are never decoded: the image
// loader is a no-op, external images are not read and the JSON handed to tinygltf has no images.
#define TINYGLTF_IMPLEMENTATION
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

namespace host {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

constexpr uint64_t kMaxFileBytes = 0xFFFFFFFFull;  // tinygltf takes 32-bit sizes
constexpr size_t kMaxJsonDepth = 64;               // tinygltf converts extras recursively
constexpr size_t kMaxProblemChars = 300;
constexpr uint32_t kGlbMagic = 0x46546C67;      // "glTF"
constexpr uint32_t kGlbChunkJson = 0x4E4F534A;  // "JSON"
constexpr uint32_t kGlbChunkBin = 0x004E4942;   // "BIN\0"

}  // namespace

namespace gltf_detail {

std::string one_line(std::string_view text, size_t max_chars) {
  std::string out;
  bool pending_space = false;
  for (char c : text) {
    if (c == ' ' || c == '\n' || c == '\r' || c == '\t') {
      pending_space = !out.empty();
      continue;
    }
    if (out.size() >= max_chars) {
      out += "...";
      break;
    }
    if (pending_space) out += ' ';
    pending_space = false;
    const auto u = static_cast<unsigned char>(c);
    out += (u < 0x20 || u == 0x7F) ? '?' : c;
  }
  return out;
}

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw InputError(one_line(path, 1000) + ": " + one_line(problem, kMaxProblemChars));
}

}  // namespace gltf_detail

namespace {

using gltf_detail::fail;
using gltf_detail::le32;
using gltf_detail::one_line;

void put_le32(std::vector<unsigned char>& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<unsigned char>(v >> (8 * i)));
}

// ---------------------------------------------------------------------------------------------
// Reading the file and splitting a .glb

// Why read_file() failed: missing to too_large before opening the file, the others after.
enum class ReadError { none, missing, not_regular, no_size, too_large, no_open, short_read };

// Reads the whole regular file `path`, at most kMaxFileBytes, into `out`. `detail` gets the
// system's reason for no_size and no_open.
ReadError read_file(const std::string& path, std::vector<unsigned char>& out, std::string& detail) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (!fs::exists(st)) return ReadError::missing;
  if (!fs::is_regular_file(st)) return ReadError::not_regular;
  const uintmax_t size = fs::file_size(path, ec);
  if (ec) {
    detail = ec.message();
    return ReadError::no_size;
  }
  if (size > kMaxFileBytes) return ReadError::too_large;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    detail = std::strerror(errno);
    return ReadError::no_open;
  }
  out.resize(static_cast<size_t>(size));
  in.read(reinterpret_cast<char*>(out.data()), static_cast<std::streamsize>(size));
  return static_cast<uintmax_t>(in.gcount()) == size ? ReadError::none : ReadError::short_read;
}

std::vector<unsigned char> read_bytes(const std::string& path) {
  std::vector<unsigned char> bytes;
  std::string detail;
  switch (read_file(path, bytes, detail)) {
    case ReadError::none:
      break;
    case ReadError::missing:
      fail(path, "no such file");
    case ReadError::not_regular:
      fail(path, "not a regular file");
    case ReadError::no_size:
      fail(path, "cannot read the file: " + detail);
    case ReadError::too_large:
      fail(path, "the file is larger than 4 GiB");
    case ReadError::no_open:
      fail(path, "cannot open the file: " + detail);
    case ReadError::short_read:
      fail(path, "cannot read the whole file");
  }
  return bytes;
}

struct GlbParts {
  std::string json;
  std::span<const unsigned char> bin;  // inside the file's bytes
  bool has_bin = false;
};

// Checks the 12-byte header and every chunk header against the file size; the first chunk must
// be JSON, a BIN chunk may follow, later chunks are ignored (the spec allows extension chunks).
GlbParts split_glb(const std::string& path, const std::vector<unsigned char>& bytes) {
  const uint64_t size = bytes.size();
  if (size < 12)
    fail(path,
         "truncated .glb: " + std::to_string(size) + " bytes, shorter than the 12-byte header");
  const uint32_t version = le32(&bytes[4]);
  if (version != 2) fail(path, "unsupported .glb version " + std::to_string(version) + " (need 2)");
  const uint64_t length = le32(&bytes[8]);
  if (length > size)
    fail(path, "truncated .glb: the header announces " + std::to_string(length) +
                   " bytes but the file has " + std::to_string(size));
  if (length < size)
    fail(path, "corrupt .glb: the header announces " + std::to_string(length) +
                   " bytes but the file has " + std::to_string(size));
  GlbParts parts;
  uint64_t pos = 12;
  int chunk = 0;
  for (; pos < length; ++chunk) {
    if (length - pos < 8)
      fail(path, "corrupt .glb: the header of chunk " + std::to_string(chunk) + " at byte " +
                     std::to_string(pos) + " is cut off by the end of the file");
    const uint64_t chunk_length = le32(&bytes[pos]);
    const uint32_t chunk_type = le32(&bytes[pos + 4]);
    if (chunk_length > length - pos - 8)
      fail(path, "corrupt .glb: chunk " + std::to_string(chunk) + " announces " +
                     std::to_string(chunk_length) + " bytes but only " +
                     std::to_string(length - pos - 8) + " remain in the file");
    const unsigned char* data = &bytes[pos + 8];
    if (chunk == 0) {
      if (chunk_type != kGlbChunkJson) fail(path, "corrupt .glb: the first chunk is not JSON");
      parts.json.assign(reinterpret_cast<const char*>(data), chunk_length);
    } else if (chunk == 1 && chunk_type == kGlbChunkBin) {
      parts.bin = {data, size_t(chunk_length)};
      parts.has_bin = true;
    }
    pos += 8 + chunk_length;
  }
  if (chunk == 0) fail(path, "corrupt .glb: no JSON chunk");
  return parts;
}

// A well-formed .glb (4-byte aligned chunks) around `json_text` and the BIN chunk, for tinygltf:
// the JSON padded with spaces, the BIN chunk with zeros.
std::vector<unsigned char> make_glb(const std::string& json_text, const GlbParts& parts) {
  const auto padded = [](uint64_t n) { return (n + 3) / 4 * 4; };
  const uint64_t json_size = padded(json_text.size()), bin_size = padded(parts.bin.size());
  const bool with_bin = parts.has_bin && bin_size > 0;
  const uint64_t total = 12 + 8 + json_size + (with_bin ? 8 + bin_size : 0);
  std::vector<unsigned char> out;
  out.reserve(total);
  put_le32(out, kGlbMagic);
  put_le32(out, 2);
  put_le32(out, static_cast<uint32_t>(total));
  put_le32(out, static_cast<uint32_t>(json_size));
  put_le32(out, kGlbChunkJson);
  out.insert(out.end(), json_text.begin(), json_text.end());
  out.resize(out.size() + (json_size - json_text.size()), ' ');
  if (with_bin) {
    put_le32(out, static_cast<uint32_t>(bin_size));
    put_le32(out, kGlbChunkBin);
    out.insert(out.end(), parts.bin.begin(), parts.bin.end());
    out.resize(out.size() + (bin_size - parts.bin.size()), 0);
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Pre-checks on the JSON, before tinygltf sees it

// Deepest {}/[] nesting outside strings.
size_t json_depth(std::string_view text) {
  size_t depth = 0, deepest = 0;
  bool in_string = false, escaped = false;
  for (char c : text) {
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '{' || c == '[') {
      deepest = std::max(deepest, ++depth);
    } else if ((c == '}' || c == ']') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

// Bytes tinygltf's base64_decode (tiny_gltf.h) yields: it stops at the first '=' or non-base64
// character. Counted rather than decoded, since tinygltf decodes the URI itself afterwards.
uint64_t base64_decoded_size(std::string_view payload) {
  uint64_t n = 0;
  for (char c : payload) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '+' || c == '/')) break;
    ++n;
  }
  return n / 4 * 3 + (n % 4 > 1 ? n % 4 - 1 : 0);
}

bool required_extension_supported(const std::string& name) {
  return name == "KHR_mesh_quantization" || name == "KHR_lights_punctual" ||
         name.starts_with("KHR_materials_") || name.starts_with("KHR_texture_") ||
         name.starts_with("EXT_texture_");
}

// Parses and checks the JSON; returns each buffer's declared byteLength. Checks the size of
// every buffer's data (data URI, external file or .glb BIN chunk) against its byteLength.
std::vector<uint64_t> precheck_json(const std::string& path, const std::string& text,
                                    const GlbParts* glb, json& doc) {
  if (json_depth(text) > kMaxJsonDepth)
    fail(path, "the JSON is nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {
    std::string what = e.what();
    if (auto close = what.find("] "); what.starts_with("[json.exception.") && close != what.npos)
      what.erase(0, close + 2);
    fail(path, "invalid JSON: " + what);
  }
  if (!doc.is_object()) fail(path, "not a glTF file: the JSON root is not an object");
  const auto asset = doc.find("asset");
  if (asset == doc.end() || !asset->is_object())
    fail(path, "not a glTF file: there is no \"asset\" object");
  const auto version = asset->find("version");
  if (version == asset->end() || !version->is_string())
    fail(path, "not a glTF file: asset.version is missing");
  if (!version->get<std::string>().starts_with("2."))
    fail(path, "unsupported glTF version " + version->get<std::string>() + " (need 2.x)");
  if (auto req = doc.find("extensionsRequired"); req != doc.end() && req->is_array()) {
    for (const json& e : *req)
      if (e.is_string() && !required_extension_supported(e.get<std::string>()))
        fail(path, "the file requires the unsupported extension " + e.get<std::string>());
  }

  std::vector<uint64_t> lengths;
  const auto buffers = doc.find("buffers");
  if (buffers == doc.end()) return lengths;
  if (!buffers->is_array()) fail(path, "\"buffers\" is not an array");
  const fs::path dir = fs::path(path).parent_path();
  for (size_t i = 0; i < buffers->size(); ++i) {
    const json& b = (*buffers)[i];
    const std::string name = "buffer " + std::to_string(i);
    if (!b.is_object()) fail(path, name + " is not an object");
    const auto bl = b.find("byteLength");
    if (bl == b.end() || !bl->is_number_unsigned() || bl->get<uint64_t>() == 0)
      fail(path, name + ": byteLength is missing or not a positive integer");
    const uint64_t byte_length = bl->get<uint64_t>();
    lengths.push_back(byte_length);
    const auto uri_it = b.find("uri");
    if (uri_it != b.end() && !uri_it->is_string()) fail(path, name + ": uri is not a string");
    const std::string uri = uri_it == b.end() ? std::string() : uri_it->get<std::string>();
    if (uri.empty()) {
      if (!glb) fail(path, name + " has no uri (only a .glb may omit it)");
      if (!glb->has_bin) fail(path, name + " has no uri and the .glb has no BIN chunk");
      if (byte_length > glb->bin.size())
        fail(path, name + ": byteLength " + std::to_string(byte_length) +
                       " is larger than the .glb BIN chunk (" + std::to_string(glb->bin.size()) +
                       " bytes)");
    } else if (uri.starts_with("data:")) {
      const size_t comma = uri.find(',');
      if (comma == uri.npos || !std::string_view(uri).substr(0, comma).ends_with(";base64"))
        fail(path, name + ": only base64 data URIs are supported");
      const uint64_t held = base64_decoded_size(std::string_view(uri).substr(comma + 1));
      if (held != byte_length)
        fail(path, name + ": its data URI holds " + std::to_string(held) +
                       " bytes but its byteLength is " + std::to_string(byte_length));
    } else {
      if (uri.find("://") != uri.npos)
        fail(path, name + ": URI scheme not supported (only relative paths and data: URIs)");
      // The decoding tinygltf applies to buffer URIs (this file holds its implementation).
      const std::string decoded = tinygltf::dlib::urldecode(uri);
      if (decoded.find('\0') != decoded.npos) fail(path, name + ": the uri holds a NUL character");
      const fs::path file = dir / decoded;
      std::error_code ec;
      if (!fs::is_regular_file(file, ec)) fail(path, name + ": file '" + uri + "' not found");
      const uintmax_t held = fs::file_size(file, ec);
      if (ec) fail(path, name + ": cannot read '" + uri + "': " + ec.message());
      if (held != byte_length)
        fail(path, name + ": file '" + uri + "' holds " + std::to_string(held) +
                       " bytes but its byteLength is " + std::to_string(byte_length));
    }
  }
  return lengths;
}

// ---------------------------------------------------------------------------------------------
// tinygltf with a file system that only reads regular files, and no image decoding

bool fs_file_exists(const std::string& p, void*) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);
}
std::string fs_expand(const std::string& p, void*) {
  return p;
}
// Only failures before the file is opened add a reason; tinygltf reports the rest.
bool fs_read(std::vector<unsigned char>* out, std::string* err, const std::string& p, void*) {
  std::string detail;
  const ReadError e = read_file(p, *out, detail);
  if (e == ReadError::none) return true;
  if (err && e != ReadError::no_open && e != ReadError::short_read) *err += "cannot read " + p;
  return false;
}
bool fs_write(std::string*, const std::string&, const std::vector<unsigned char>&, void*) {
  return false;
}
bool no_image(tinygltf::Image*, const int, std::string*, std::string*, int, int,
              const unsigned char*, int, void*) {
  return true;
}

std::string first_line(const std::string& text) {
  size_t start = text.find_first_not_of(" \t\r\n");
  if (start == text.npos) return {};
  return text.substr(start, text.find_first_of("\r\n", start) - start);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// The parse: the file's bytes through the pre-checks to a tinygltf model

namespace gltf_detail {

std::vector<uint64_t> parse_file(const std::string& path, tinygltf::Model& model,
                                 std::vector<std::string>& warnings, std::string& textures,
                                 bool keep_animations) {
  const std::vector<unsigned char> bytes = read_bytes(path);  // freed once parsed
  if (bytes.empty()) fail(path, "the file is empty");
  GlbParts glb;
  const bool is_glb = bytes.size() >= 4 && le32(bytes.data()) == kGlbMagic;
  std::string text;
  if (is_glb) {
    glb = split_glb(path, bytes);
    text = std::move(glb.json);
  } else {
    size_t i = 0;
    if (bytes.size() >= 3 && bytes[0] == 0xEF && bytes[1] == 0xBB && bytes[2] == 0xBF) i = 3;
    while (i < bytes.size() && std::isspace(bytes[i])) ++i;
    if (i == bytes.size() || bytes[i] != '{')
      fail(path, "not a glTF file (neither a JSON object nor a binary .glb)");
    text.assign(reinterpret_cast<const char*>(bytes.data()) + i, bytes.size() - i);
  }

  json doc;
  std::vector<uint64_t> lengths = precheck_json(path, text, is_glb ? &glb : nullptr, doc);
  // Textures are read by the loader (gltf_loader.cpp), not by tinygltf, which reads image buffer
  // views without checking their range.
  json tex = json::object();
  for (const char* key : {"images", "textures", "samplers"})
    tex[key] = doc.contains(key) && doc[key].is_array() ? doc[key] : json::array();
  tex["base_color"] = json::array();
  if (doc.contains("materials") && doc["materials"].is_array())
    for (const json& m : doc["materials"]) {
      const json* info = nullptr;
      if (m.is_object() && m.contains("pbrMetallicRoughness")) {
        const json& pbr = m["pbrMetallicRoughness"];
        if (pbr.is_object() && pbr.contains("baseColorTexture")) info = &pbr["baseColorTexture"];
      }
      tex["base_color"].push_back(info ? *info : json());
    }
  textures = tex.dump();
  // Skins are never needed (images, textures and samplers were read above). Animations only
  // where asked for (host/scene/animation.cpp reads and checks them).
  for (const char* key : {"images", "textures", "samplers", "skins"}) doc.erase(key);
  if (!keep_animations) doc.erase("animations");
  // tinygltf drops a channel whose target has no node (KHR_animation_pointer's): give it node
  // -1, so that the channel is kept and animation.cpp refuses its path instead of a frame
  // silently missing it.
  if (auto anims = doc.find("animations"); anims != doc.end() && anims->is_array())
    for (json& anim : *anims) {
      if (!anim.is_object() || !anim.contains("channels") || !anim["channels"].is_array()) continue;
      for (json& channel : anim["channels"])
        if (channel.is_object() && channel.contains("target") && channel["target"].is_object() &&
            !channel["target"].contains("node"))
          channel["target"]["node"] = -1;
    }
  const std::string clean = doc.dump();
  if (clean.size() > kMaxFileBytes - 64) fail(path, "the JSON is larger than 4 GiB");

  tinygltf::TinyGLTF gltf;
  gltf.SetImageLoader(&no_image, nullptr);
  gltf.SetFsCallbacks({&fs_file_exists, &fs_expand, &fs_read, &fs_write, nullptr});
  std::string err, warn;
  const std::string base_dir = fs::path(path).parent_path().string();
  bool ok = false;
  try {
    if (is_glb) {
      const std::vector<unsigned char> rebuilt = make_glb(clean, glb);
      ok = gltf.LoadBinaryFromMemory(&model, &err, &warn, rebuilt.data(),
                                     static_cast<unsigned int>(rebuilt.size()), base_dir);
    } else {
      ok = gltf.LoadASCIIFromString(&model, &err, &warn, clean.data(),
                                    static_cast<unsigned int>(clean.size()), base_dir);
    }
  } catch (const std::exception& e) {
    fail(path, std::string("glTF error: ") + e.what());
  }
  if (!ok) {
    const std::string reason = first_line(err);
    fail(path,
         "glTF error: " + (reason.empty() ? std::string("tinygltf rejected the file") : reason));
  }
  for (const std::string& text_block : {err, warn}) {
    size_t start = 0;
    while (start < text_block.size()) {
      size_t end = text_block.find('\n', start);
      if (end == text_block.npos) end = text_block.size();
      const std::string line = one_line(text_block.substr(start, end - start), kMaxProblemChars);
      if (!line.empty()) warnings.push_back("tinygltf: " + line);
      start = end + 1;
    }
  }
  return lengths;
}

}  // namespace gltf_detail

// ---------------------------------------------------------------------------------------------
// Scenes by name

namespace {

// Where the bundled scenes were looked for, when none of the folders exists.
std::string no_scenes_dir() {
  std::string where;
  for (const fs::path& d : scenes_dir_candidates())
    where += (where.empty() ? "" : ", ") + d.string();
  return "the bundled scenes are not installed (looked in " + where +
         "; set VGPU_RT_SCENES to their folder)";
}

bool is_scene_file(const fs::path& p) {
  const std::string ext = p.extension().string();
  return ext == ".gltf" || ext == ".glb";
}

}  // namespace

std::string resolve_scene(const std::string& name_or_path) {
  std::error_code ec;
  if (fs::is_regular_file(name_or_path, ec)) return name_or_path;
  const fs::path dir = scenes_dir();
  for (const char* ext : {".gltf", ".glb"}) {
    if (dir.empty()) break;
    const fs::path candidate = dir / (name_or_path + ext);
    if (fs::is_regular_file(candidate, ec)) return candidate.string();
  }
  if (dir.empty()) throw InputError(one_line(name_or_path, 1000) + ": " + no_scenes_dir());
  throw InputError(one_line(name_or_path, 1000) + ": no such file or scene in " + dir.string() +
                   " (try `vgpu-rt scenes`)");
}

std::vector<std::pair<std::string, std::string>> list_scenes() {
  std::vector<std::pair<std::string, std::string>> out;
  const fs::path dir = scenes_dir();
  if (dir.empty()) throw InputError(no_scenes_dir());
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->is_regular_file(ec) && is_scene_file(it->path()))
      out.emplace_back(it->path().stem().string(), it->path().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

// ---------------------------------------------------------------------------------------------
// Small readers the loader (gltf_loader.cpp) uses

namespace gltf_detail {

const char* mode_name(int mode) {
  switch (mode) {
    case TINYGLTF_MODE_POINTS:
      return "POINTS";
    case TINYGLTF_MODE_LINE:
      return "LINES";
    case TINYGLTF_MODE_LINE_LOOP:
      return "LINE_LOOP";
    case TINYGLTF_MODE_LINE_STRIP:
      return "LINE_STRIP";
    case TINYGLTF_MODE_TRIANGLES:
      return "TRIANGLES";
    case TINYGLTF_MODE_TRIANGLE_STRIP:
      return "TRIANGLE_STRIP";
    case TINYGLTF_MODE_TRIANGLE_FAN:
      return "TRIANGLE_FAN";
    default:
      return "unknown";
  }
}

// One component as float; normalized integers follow the glTF spec (max(c / 127, -1), ...).
float read_component(const unsigned char* p, int component_type, bool normalized) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      int8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? std::max(float(v) / 127.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
      uint8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? float(v) / 255.0f : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(float(v) / 32767.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? float(v) / 65535.0f : float(v);
    }
    default: {  // FLOAT, checked by the caller
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
}

// A number as a message shows it: as the file most likely wrote it (0.5, not 0.500000).
std::string shortest(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", x);
  for (int digits = 1; digits < 17; ++digits) {  // the fewest digits that read back the same
    char shorter[32];
    std::snprintf(shorter, sizeof shorter, "%.*g", digits, x);
    if (std::strtod(shorter, nullptr) == x) return shorter;
  }
  return text;
}

}  // namespace gltf_detail

}  // namespace host
