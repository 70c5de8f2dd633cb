// The glTF 2.0 loader (see gltf_loader.h for the rules). tinygltf parses; this file checks every
// index, offset and length before reading, because tinygltf accepts some broken files. Order:
// read bytes -> split .glb -> pre-check the JSON and buffer sizes -> tinygltf -> validate the
// model -> walk the default scene depth-first, emitting world-space triangles.
#include "host/scene/gltf_loader.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <set>
#include <span>
#include <string_view>

// The one translation unit that holds tinygltf and stb. Images are never decoded: the image
// loader is a no-op, external images are not read and the JSON handed to tinygltf has no images.
#define TINYGLTF_IMPLEMENTATION
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#ifndef VGPU_SCENES_DIR
#define VGPU_SCENES_DIR "scenes"
#endif

namespace host {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

// glTF binary data is little-endian; accessors are read with memcpy.
static_assert(std::endian::native == std::endian::little);

constexpr uint64_t kMaxFileBytes = 0xFFFFFFFFull;  // tinygltf takes 32-bit sizes
constexpr size_t kMaxJsonDepth = 64;               // tinygltf converts extras recursively
constexpr size_t kMaxProblemChars = 300;
constexpr uint32_t kGlbMagic = 0x46546C67;      // "glTF"
constexpr uint32_t kGlbChunkJson = 0x4E4F534A;  // "JSON"
constexpr uint32_t kGlbChunkBin = 0x004E4942;   // "BIN\0"

// `text` as one printable line: whitespace runs become one space, control bytes '?'.
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

uint32_t le32(const unsigned char* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}
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

// ---------------------------------------------------------------------------------------------
// From the tinygltf model to the Scene

// A primitive in its mesh's local space, decoded once and instanced by every node that uses it.
struct PrimitiveGeometry {
  bool skipped = false;
  std::shared_ptr<const std::vector<glm::vec3>> positions;
  std::shared_ptr<const std::vector<glm::vec3>> normals;  // per vertex; zero = use face normal
  bool normals_from_file = false;
  std::vector<uint32_t> corners;  // 3 vertex indices per triangle, input order
  uint32_t material = 0;
};

struct PendingLight {
  glm::vec3 position;
  glm::vec3 rgb;
  double intensity;
};

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

glm::vec3 clamp01(const std::vector<double>& v) {
  return {float(std::clamp(v[0], 0.0, 1.0)), float(std::clamp(v[1], 0.0, 1.0)),
          float(std::clamp(v[2], 0.0, 1.0))};
}

// Whether the float sum of the coordinates is finite: false for a NaN or infinite coordinate, and
// also when finite coordinates overflow the sum (the loader's checks have always meant this).
bool all_finite(glm::vec3 v) {
  return std::isfinite(v.x + v.y + v.z);
}

// The distance between an accessor's elements: the view's byteStride, or `element` (the element
// size) when the view has none.
uint64_t element_stride(const tinygltf::BufferView& view, uint64_t element) {
  return view.byteStride ? view.byteStride : element;
}

class Loader {
 public:
  Loader(std::string path, const LoadOptions& options)
      : path_(std::move(path)),
        max_triangles_(std::min<uint64_t>(options.max_triangles, 0xFFFFFFFFull)) {}

  Scene load() {
    parse(read_bytes(path_));  // the file's bytes are freed once parsed
    check_buffers_and_views();
    check_accessors();
    convert_materials();
    walk(root_nodes());
    finish();
    return std::move(scene_);
  }

 private:
  // -- parsing ---------------------------------------------------------------------------------

  void parse(const std::vector<unsigned char>& bytes) {
    if (bytes.empty()) fail(path_, "the file is empty");
    GlbParts glb;
    const bool is_glb = bytes.size() >= 4 && le32(bytes.data()) == kGlbMagic;
    std::string text;
    if (is_glb) {
      glb = split_glb(path_, bytes);
      text = std::move(glb.json);
    } else {
      size_t i = 0;
      if (bytes.size() >= 3 && bytes[0] == 0xEF && bytes[1] == 0xBB && bytes[2] == 0xBF) i = 3;
      while (i < bytes.size() && std::isspace(bytes[i])) ++i;
      if (i == bytes.size() || bytes[i] != '{')
        fail(path_, "not a glTF file (neither a JSON object nor a binary .glb)");
      text.assign(reinterpret_cast<const char*>(bytes.data()) + i, bytes.size() - i);
    }

    json doc;
    declared_lengths_ = precheck_json(path_, text, is_glb ? &glb : nullptr, doc);
    // Never needed, and tinygltf reads image buffer views without checking their range.
    for (const char* key : {"images", "textures", "samplers", "animations", "skins"})
      doc.erase(key);
    const std::string clean = doc.dump();
    if (clean.size() > kMaxFileBytes - 64) fail(path_, "the JSON is larger than 4 GiB");

    tinygltf::TinyGLTF gltf;
    gltf.SetImageLoader(&no_image, nullptr);
    gltf.SetFsCallbacks({&fs_file_exists, &fs_expand, &fs_read, &fs_write, nullptr});
    std::string err, warn;
    const std::string base_dir = fs::path(path_).parent_path().string();
    bool ok = false;
    try {
      if (is_glb) {
        const std::vector<unsigned char> rebuilt = make_glb(clean, glb);
        ok = gltf.LoadBinaryFromMemory(&model_, &err, &warn, rebuilt.data(),
                                       static_cast<unsigned int>(rebuilt.size()), base_dir);
      } else {
        ok = gltf.LoadASCIIFromString(&model_, &err, &warn, clean.data(),
                                      static_cast<unsigned int>(clean.size()), base_dir);
      }
    } catch (const std::exception& e) {
      fail(path_, std::string("glTF error: ") + e.what());
    }
    if (!ok) {
      const std::string reason = first_line(err);
      fail(path_,
           "glTF error: " + (reason.empty() ? std::string("tinygltf rejected the file") : reason));
    }
    for (const std::string& text_block : {err, warn}) {
      size_t start = 0;
      while (start < text_block.size()) {
        size_t end = text_block.find('\n', start);
        if (end == text_block.npos) end = text_block.size();
        const std::string line = one_line(text_block.substr(start, end - start), kMaxProblemChars);
        if (!line.empty()) scene_.warnings.push_back("tinygltf: " + line);
        start = end + 1;
      }
    }
  }

  // -- validation of buffers, views and accessors, independent of tinygltf ---------------------

  // Fails unless 0 <= index < count: "OWNER refers to WHAT INDEX, but the file has COUNT PLURAL",
  // with `verb` in place of "refers to" where the owner holds a list.
  void check_index(const std::string& owner, const char* what, int index, size_t count,
                   const char* plural, const char* verb = "refers to") const {
    if (index < 0 || size_t(index) >= count)
      fail(path_, owner + " " + verb + " " + what + " " + std::to_string(index) +
                      ", but the file has " + std::to_string(count) + " " + plural);
  }

  void check_buffers_and_views() {
    if (model_.buffers.size() != declared_lengths_.size())
      fail(path_, "the file declares " + std::to_string(declared_lengths_.size()) +
                      " buffers but " + std::to_string(model_.buffers.size()) + " were loaded");
    for (size_t i = 0; i < model_.buffers.size(); ++i)
      if (model_.buffers[i].data.size() != declared_lengths_[i])
        fail(path_, "buffer " + std::to_string(i) + " holds " +
                        std::to_string(model_.buffers[i].data.size()) +
                        " bytes but its byteLength is " + std::to_string(declared_lengths_[i]));
    for (size_t v = 0; v < model_.bufferViews.size(); ++v) {
      const tinygltf::BufferView& view = model_.bufferViews[v];
      const std::string name = "buffer view " + std::to_string(v);
      check_index(name, "buffer", view.buffer, model_.buffers.size(), "buffers");
      const uint64_t size = model_.buffers[size_t(view.buffer)].data.size();
      if (view.byteOffset > size || view.byteLength > size - view.byteOffset)
        fail(path_, name + " (bytes " + std::to_string(view.byteOffset) + " + " +
                        std::to_string(view.byteLength) + ") lies outside buffer " +
                        std::to_string(view.buffer) + " (" + std::to_string(size) + " bytes)");
    }
  }

  // Every accessor with a buffer view must lie inside it: byteOffset + (count - 1) * stride +
  // element size <= byteLength of the view.
  void check_accessors() {
    for (size_t a = 0; a < model_.accessors.size(); ++a) {
      const tinygltf::Accessor& acc = model_.accessors[a];
      const std::string name = "accessor " + std::to_string(a);
      if (acc.bufferView < 0) continue;  // rejected when used
      check_index(name, "buffer view", acc.bufferView, model_.bufferViews.size(), "buffer views");
      const int comp = tinygltf::GetComponentSizeInBytes(uint32_t(acc.componentType));
      const int n = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
      if (comp <= 0)
        fail(path_, name + " has an invalid componentType " + std::to_string(acc.componentType));
      if (n <= 0) fail(path_, name + " has an invalid type");
      const tinygltf::BufferView& view = model_.bufferViews[size_t(acc.bufferView)];
      const uint64_t element = uint64_t(comp) * uint64_t(n);
      const uint64_t stride = element_stride(view, element);
      if (stride < element)
        fail(path_, name + ": buffer view " + std::to_string(acc.bufferView) + " has byteStride " +
                        std::to_string(stride) + ", smaller than the element size " +
                        std::to_string(element));
      if (acc.count == 0) continue;
      const uint64_t len = view.byteLength, off = acc.byteOffset, count = acc.count;
      if (off > len || element > len - off || count - 1 > (len - off - element) / stride)
        fail(path_, name + " reads past the end of buffer view " + std::to_string(acc.bufferView) +
                        " (byteOffset " + std::to_string(off) + ", count " + std::to_string(count) +
                        ", stride " + std::to_string(stride) + ", view byteLength " +
                        std::to_string(len) + ")");
    }
  }

  // Where an accessor's elements lie in its buffer: element i at byte start + i * stride.
  // check_accessors() proved the range of every element (with no element, start may lie past
  // the buffer, so it stays an offset).
  struct Elements {
    const unsigned char* buffer;
    size_t start, stride;
    const unsigned char* operator[](size_t i) const { return buffer + (start + i * stride); }
  };
  Elements elements(const tinygltf::Accessor& acc) const {
    const tinygltf::BufferView& view = model_.bufferViews[size_t(acc.bufferView)];
    const int comp = tinygltf::GetComponentSizeInBytes(uint32_t(acc.componentType));
    const int n = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
    return {model_.buffers[size_t(view.buffer)].data.data(), view.byteOffset + acc.byteOffset,
            size_t(element_stride(view, uint64_t(comp) * uint64_t(n)))};
  }

  // The accessor, checked for a use: in range, with data, not sparse.
  const tinygltf::Accessor& accessor_for(int index, const std::string& use) const {
    check_index(use, "accessor", index, model_.accessors.size(), "accessors");
    const tinygltf::Accessor& acc = model_.accessors[size_t(index)];
    if (acc.sparse.isSparse)
      fail(path_,
           use + ": accessor " + std::to_string(index) + " is sparse, which is not supported");
    if (acc.bufferView < 0)
      fail(path_, use + ": accessor " + std::to_string(index) +
                      " has no buffer view (zero-filled accessors are not supported)");
    if (acc.count > 0xFFFFFFFFull)
      fail(path_, use + ": accessor " + std::to_string(index) + " has more than 2^32 - 1 elements");
    return acc;
  }

  // VEC3 of float or (normalized) byte/short, as float vectors.
  std::shared_ptr<const std::vector<glm::vec3>> read_vec3(int index, const std::string& use,
                                                          bool positions) {
    auto& cache = positions ? position_cache_ : normal_cache_;
    if (auto it = cache.find(index); it != cache.end()) return it->second;
    const tinygltf::Accessor& acc = accessor_for(index, use);
    const int ct = acc.componentType;
    const bool ok_component =
        ct == TINYGLTF_COMPONENT_TYPE_FLOAT || ct == TINYGLTF_COMPONENT_TYPE_BYTE ||
        ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE || ct == TINYGLTF_COMPONENT_TYPE_SHORT ||
        ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    if (acc.type != TINYGLTF_TYPE_VEC3 || !ok_component)
      fail(path_, use + ": accessor " + std::to_string(index) +
                      " must be VEC3 of float, byte or short components");
    const int comp = tinygltf::GetComponentSizeInBytes(uint32_t(ct));
    auto out = std::make_shared<std::vector<glm::vec3>>(acc.count);
    const Elements element = elements(acc);
    for (size_t i = 0; i < acc.count; ++i) {
      const unsigned char* p = element[i];
      glm::vec3& v = (*out)[i];
      for (int c = 0; c < 3; ++c) v[c] = read_component(p + c * comp, ct, acc.normalized);
      if (positions && !all_finite(v)) {
        const bool nan = std::isnan(v.x) || std::isnan(v.y) || std::isnan(v.z);
        fail(path_, use + ": accessor " + std::to_string(index) + " element " + std::to_string(i) +
                        " has " + (nan ? "a NaN coordinate" : "an infinite coordinate"));
      }
    }
    cache[index] = out;
    return out;
  }

  std::shared_ptr<const std::vector<uint32_t>> read_indices(int index, const std::string& use) {
    if (auto it = index_cache_.find(index); it != index_cache_.end()) return it->second;
    const tinygltf::Accessor& acc = accessor_for(index, use);
    const int ct = acc.componentType;
    if (acc.type != TINYGLTF_TYPE_SCALAR || (ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                                             ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                                             ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
      fail(path_, use + ": accessor " + std::to_string(index) +
                      " must be SCALAR of unsigned byte, short or int components");
    auto out = std::make_shared<std::vector<uint32_t>>(acc.count);
    const Elements element = elements(acc);
    for (size_t i = 0; i < acc.count; ++i) {
      const unsigned char* p = element[i];
      uint32_t v = 0;
      if (ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE)
        v = p[0];
      else if (ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT)
        v = uint32_t(p[0]) | uint32_t(p[1]) << 8;
      else
        v = le32(p);
      (*out)[i] = v;
    }
    index_cache_[index] = out;
    return out;
  }

  // -- materials -------------------------------------------------------------------------------

  void convert_materials() {
    for (size_t m = 0; m < model_.materials.size(); ++m) {
      const tinygltf::Material& src = model_.materials[m];
      const std::string name = "material " + std::to_string(m);
      Material out;
      const auto& pbr = src.pbrMetallicRoughness;
      if (pbr.baseColorFactor.size() != 4)
        fail(path_, name + ": baseColorFactor must have 4 numbers");
      out.color = clamp01(pbr.baseColorFactor);
      out.reflect = float(std::clamp(pbr.metallicFactor, 0.0, 1.0));
      if (src.extras.IsObject() && src.extras.Has("reflect")) {
        const tinygltf::Value& r = src.extras.Get("reflect");
        if (!r.IsNumber()) {
          scene_.warnings.push_back(name + ": extras.reflect is not a number; ignored");
        } else {
          const double value = r.GetNumberAsDouble();
          if (value < 0.0 || value > 1.0)
            scene_.warnings.push_back(name + ": extras.reflect " + std::to_string(value) +
                                      " is outside [0, 1]; clamped");
          out.reflect = float(std::clamp(value, 0.0, 1.0));
        }
      }
      scene_.materials.push_back(out);
    }
  }

  uint32_t default_material() {
    if (!default_material_) {
      default_material_ = uint32_t(scene_.materials.size());
      scene_.materials.push_back(Material{});
    }
    return *default_material_;
  }

  // -- the node walk ---------------------------------------------------------------------------

  std::vector<int> root_nodes() const {
    const size_t node_count = model_.nodes.size();
    auto check = [&](const std::vector<int>& list, const std::string& owner) {
      for (int n : list) check_index(owner, "node", n, node_count, "nodes", "lists");
    };
    for (size_t n = 0; n < node_count; ++n)
      check(model_.nodes[n].children, "node " + std::to_string(n));
    if (model_.defaultScene >= 0 || !model_.scenes.empty()) {
      const int s = std::max(model_.defaultScene, 0);
      if (size_t(s) >= model_.scenes.size())
        fail(path_, "the default scene " + std::to_string(s) + " does not exist (the file has " +
                        std::to_string(model_.scenes.size()) + " scenes)");
      check(model_.scenes[size_t(s)].nodes, "scene " + std::to_string(s));
      return model_.scenes[size_t(s)].nodes;
    }
    std::vector<char> is_child(node_count, 0);
    for (const tinygltf::Node& node : model_.nodes)
      for (int c : node.children) is_child[size_t(c)] = 1;
    std::vector<int> roots;
    for (size_t n = 0; n < node_count; ++n)
      if (!is_child[n]) roots.push_back(int(n));
    return roots;
  }

  glm::dmat4 local_matrix(const tinygltf::Node& node, size_t index) const {
    const std::string name = "node " + std::to_string(index);
    auto check_size = [&](const std::vector<double>& v, size_t want, const char* what) {
      if (!v.empty() && v.size() != want)
        fail(path_, name + ": " + what + " must have " + std::to_string(want) + " numbers");
    };
    check_size(node.matrix, 16, "matrix");
    check_size(node.translation, 3, "translation");
    check_size(node.rotation, 4, "rotation");
    check_size(node.scale, 3, "scale");
    if (!node.matrix.empty()) return glm::make_mat4(node.matrix.data());  // column-major
    glm::dmat4 t(1.0), r(1.0), s(1.0);
    if (!node.translation.empty())
      t[3] = glm::dvec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
    if (!node.rotation.empty()) {
      // glTF stores (x, y, z, w); glm::dquat's constructor takes (w, x, y, z).
      glm::dquat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
      const double len = glm::length(q);
      if (!(len > 0.0) || !std::isfinite(len)) fail(path_, name + ": rotation is not a quaternion");
      r = glm::mat4_cast(q / len);
    }
    if (!node.scale.empty()) {
      s[0][0] = node.scale[0];
      s[1][1] = node.scale[1];
      s[2][2] = node.scale[2];
    }
    return t * r * s;
  }

  // Depth-first pre-order with an explicit stack (hierarchies can be deeper than the C++ stack).
  void walk(const std::vector<int>& roots) {
    struct Item {
      int node;
      glm::dmat4 parent;
    };
    std::vector<char> seen(model_.nodes.size(), 0);
    std::vector<Item> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it)
      stack.push_back({*it, glm::dmat4(1.0)});
    while (!stack.empty()) {
      const Item item = stack.back();
      stack.pop_back();
      const size_t n = size_t(item.node);
      if (seen[n])
        fail(path_, "node " + std::to_string(item.node) +
                        " is reached twice; the node hierarchy must be a tree");
      seen[n] = 1;
      const tinygltf::Node& node = model_.nodes[n];
      const glm::dmat4 world = item.parent * local_matrix(node, n);
      visit(node, n, world);
      for (auto it = node.children.rbegin(); it != node.children.rend(); ++it)
        stack.push_back({*it, world});
    }
  }

  void visit(const tinygltf::Node& node, size_t index, const glm::dmat4& world) {
    const std::string name = "node " + std::to_string(index);
    if (node.camera >= 0) {
      check_index(name, "camera", node.camera, model_.cameras.size(), "cameras");
      if (!scene_.camera) take_camera(size_t(node.camera), name, world);
    }
    if (auto ext = node.extensions.find("KHR_lights_punctual"); ext != node.extensions.end()) {
      const tinygltf::Value& v = ext->second;
      if (v.IsObject() && v.Has("light")) {
        const tinygltf::Value& l = v.Get("light");
        if (!l.IsInt()) fail(path_, name + ": KHR_lights_punctual.light is not an integer");
        const int li = l.GetNumberAsInt();
        check_index(name, "light", li, model_.lights.size(), "lights");
        take_light(size_t(li), world);
      }
    }
    if (node.mesh >= 0) {
      check_index(name, "mesh", node.mesh, model_.meshes.size(), "meshes");
      const tinygltf::Mesh& mesh = model_.meshes[size_t(node.mesh)];
      for (size_t p = 0; p < mesh.primitives.size(); ++p)
        emit(primitive(size_t(node.mesh), p), world, name);
    }
  }

  void take_camera(size_t index, const std::string& node_name, const glm::dmat4& world) {
    const tinygltf::Camera& cam = model_.cameras[index];
    const std::string name = "camera " + std::to_string(index) + " (" + node_name + ")";
    if (cam.type == "orthographic")
      fail(path_, name + " is orthographic; only perspective cameras are supported");
    if (cam.type != "perspective") fail(path_, name + " has unknown type '" + cam.type + "'");
    const double yfov = cam.perspective.yfov;
    if (!(yfov > 0.0 && yfov < std::numbers::pi)) fail(path_, name + ": yfov is outside (0, pi)");
    const glm::dvec3 position(world[3]);
    const glm::dvec3 forward(world * glm::dvec4(0, 0, -1, 0));
    const glm::dvec3 up(world * glm::dvec4(0, 1, 0, 0));
    const glm::dvec3 f = glm::normalize(forward);
    const glm::dvec3 u = glm::normalize(up - glm::dot(up, f) * f);
    Camera out;
    out.position = glm::vec3(position);
    out.forward = glm::vec3(f);
    out.up = glm::vec3(u);
    out.yfov = float(yfov);
    if (!all_finite(out.position) || !all_finite(out.forward) || !all_finite(out.up))
      fail(path_, name + ": the node transform is degenerate");
    scene_.camera = out;
  }

  void take_light(size_t index, const glm::dmat4& world) {
    const tinygltf::Light& light = model_.lights[index];
    const std::string name = "light " + std::to_string(index);
    if (light.type == "directional") {
      warn_once(name + ": directional lights are not supported; skipped");
      return;
    }
    if (light.type == "spot") {
      warn_once(name + ": spot light treated as a point light");
    } else if (light.type != "point") {
      warn_once(name + ": unknown light type '" + light.type + "'; skipped");
      return;
    }
    glm::vec3 rgb(1.0f);
    if (light.color.size() == 3) {
      rgb = clamp01(light.color);
    } else if (!light.color.empty()) {
      fail(path_, name + ": color must have 3 numbers");
    }
    const glm::vec3 position(world[3]);
    if (!all_finite(position)) fail(path_, name + ": the world position is not finite");
    lights_.push_back({position, rgb, std::clamp(light.intensity, 0.0, 1e30)});
  }

  void warn_once(const std::string& message) {
    if (warned_.insert(message).second) scene_.warnings.push_back(message);
  }

  // -- primitives ------------------------------------------------------------------------------

  const PrimitiveGeometry& primitive(size_t mesh_index, size_t prim_index) {
    const auto key = std::make_pair(mesh_index, prim_index);
    if (auto it = primitives_.find(key); it != primitives_.end()) return it->second;
    PrimitiveGeometry& g = primitives_[key];
    const tinygltf::Primitive& prim = model_.meshes[mesh_index].primitives[prim_index];
    const std::string name =
        "mesh " + std::to_string(mesh_index) + " primitive " + std::to_string(prim_index);

    const int mode = prim.mode;
    if (mode < TINYGLTF_MODE_POINTS || mode > TINYGLTF_MODE_TRIANGLE_FAN)
      fail(path_, name + " has an unknown mode " + std::to_string(mode));
    if (mode < TINYGLTF_MODE_TRIANGLES) {
      ++skipped_modes_[mode_name(mode)];
      g.skipped = true;
      return g;
    }
    const auto pos_it = prim.attributes.find("POSITION");
    if (pos_it == prim.attributes.end()) {
      ++skipped_modes_["position-less"];
      g.skipped = true;
      return g;
    }
    g.positions = read_vec3(pos_it->second, name + " POSITION", true);
    const size_t vertex_count = g.positions->size();

    if (prim.material >= 0) {
      check_index(name, "material", prim.material, model_.materials.size(), "materials");
      g.material = uint32_t(prim.material);
    } else {
      g.material = default_material();
    }

    std::shared_ptr<const std::vector<uint32_t>> indices;
    if (prim.indices >= 0) {
      indices = read_indices(prim.indices, name + " indices");
      for (size_t i = 0; i < indices->size(); ++i)
        if ((*indices)[i] >= vertex_count)
          fail(path_, name + ": index " + std::to_string((*indices)[i]) + " (element " +
                          std::to_string(i) + " of accessor " + std::to_string(prim.indices) +
                          ") is past the vertex count " + std::to_string(vertex_count));
    }
    const size_t n = indices ? indices->size() : vertex_count;
    const auto vertex = [&](size_t k) { return indices ? (*indices)[k] : uint32_t(k); };

    size_t triangles = 0;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      triangles = n / 3;
      if (n % 3 != 0) warn_once(name + ": vertex count is not a multiple of 3; extra ignored");
    } else {
      triangles = n >= 3 ? n - 2 : 0;
    }
    if (triangles > max_triangles_) too_many();
    g.corners.resize(triangles * 3);
    for (size_t t = 0; t < triangles; ++t) {
      uint32_t a, b, c;
      if (mode == TINYGLTF_MODE_TRIANGLES) {
        a = vertex(3 * t), b = vertex(3 * t + 1), c = vertex(3 * t + 2);
      } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        a = vertex(t), b = vertex(t + 1 + t % 2), c = vertex(t + 2 - t % 2);
      } else {  // fan
        a = vertex(t + 1), b = vertex(t + 2), c = vertex(0);
      }
      g.corners[3 * t] = a, g.corners[3 * t + 1] = b, g.corners[3 * t + 2] = c;
    }

    if (const auto nrm = prim.attributes.find("NORMAL"); nrm != prim.attributes.end()) {
      g.normals = read_vec3(nrm->second, name + " NORMAL", false);
      g.normals_from_file = true;
      if (g.normals->size() != vertex_count)
        fail(path_, name + ": NORMAL has " + std::to_string(g.normals->size()) +
                        " elements but POSITION has " + std::to_string(vertex_count));
    } else {
      g.normals = smooth_normals(*g.positions, g.corners);
    }
    return g;
  }

  // Area-weighted vertex normals in local space: |cross| is twice the triangle's area.
  static std::shared_ptr<const std::vector<glm::vec3>> smooth_normals(
      const std::vector<glm::vec3>& p, const std::vector<uint32_t>& corners) {
    std::vector<glm::dvec3> sum(p.size(), glm::dvec3(0.0));
    for (size_t k = 0; k < corners.size(); k += 3) {
      const glm::dvec3 a(p[corners[k]]), b(p[corners[k + 1]]), c(p[corners[k + 2]]);
      const glm::dvec3 cr = glm::cross(b - a, c - a);
      for (int j = 0; j < 3; ++j) sum[corners[k + size_t(j)]] += cr;
    }
    auto out = std::make_shared<std::vector<glm::vec3>>(p.size(), glm::vec3(0.0f));
    for (size_t v = 0; v < p.size(); ++v) {
      const double len = glm::length(sum[v]);
      if (len > 0.0 && std::isfinite(len)) (*out)[v] = glm::vec3(sum[v] / len);
    }
    return out;
  }

  [[noreturn]] void too_many() const {
    fail(path_, "the scene has more triangles than the limit of " + std::to_string(max_triangles_) +
                    " (LoadOptions::max_triangles)");
  }

  // Instances one primitive with the node's world matrix.
  void emit(const PrimitiveGeometry& g, const glm::dmat4& world, const std::string& node_name) {
    if (g.skipped) return;
    const size_t triangles = g.corners.size() / 3;
    if (triangles > max_triangles_ - scene_.input_triangles) too_many();

    const glm::dmat3 m(world);
    const double det = glm::determinant(m);
    // cofactor(M) = det(M) * inverse(M)^T, defined even when det = 0; the sign keeps it
    // pointing like inverse(M)^T.
    const glm::dmat3 cof(glm::cross(m[1], m[2]), glm::cross(m[2], m[0]), glm::cross(m[0], m[1]));
    const glm::dmat3 normal_matrix = det < 0.0 ? -cof : cof;
    const bool mirror = det < 0.0;
    const std::vector<glm::vec3>& pos = *g.positions;
    const std::vector<glm::vec3>& nrm = *g.normals;

    // Every vertex the triangles use, transformed once.
    struct WorldVertex {
      bool done = false;
      bool has_normal = false;  // false: the normal is zero or not finite, use the face normal
      glm::vec3 position, normal;
    };
    std::vector<WorldVertex> wv(pos.size());
    for (const uint32_t i : g.corners) {
      WorldVertex& out = wv[i];
      if (out.done) continue;
      out.done = true;
      out.position = glm::vec3(world * glm::dvec4(glm::dvec3(pos[i]), 1.0));
      if (!all_finite(out.position))
        fail(path_, node_name +
                        ": a world-space position is not finite (the node transforms "
                        "overflow float)");
      const glm::dvec3 w = normal_matrix * glm::dvec3(nrm[i]);
      const double len = glm::length(w);
      out.has_normal = len > 0.0 && std::isfinite(len);
      if (out.has_normal) out.normal = glm::vec3(w / len);
    }

    for (size_t t = 0; t < triangles; ++t) {
      const uint32_t id = scene_.input_triangles++;
      uint32_t v[3] = {g.corners[3 * t], g.corners[3 * t + 1], g.corners[3 * t + 2]};
      if (mirror) std::swap(v[1], v[2]);
      const glm::vec3 p[3] = {wv[v[0]].position, wv[v[1]].position, wv[v[2]].position};
      const glm::vec3 cross_f = glm::cross(p[1] - p[0], p[2] - p[0]);
      const glm::dvec3 cross_d =
          glm::cross(glm::dvec3(p[1]) - glm::dvec3(p[0]), glm::dvec3(p[2]) - glm::dvec3(p[0]));
      const double area2 = glm::length(cross_d);
      if (glm::length(cross_f) == 0.0f || area2 < 1e-30) {
        ++scene_.dropped_degenerate;
        continue;
      }
      const glm::vec3 face(cross_d / area2);
      glm::vec3 n[3];
      for (int c = 0; c < 3; ++c) {
        if (wv[v[c]].has_normal) {
          n[c] = wv[v[c]].normal;
        } else {
          n[c] = face;
          if (g.normals_from_file) ++invalid_file_normals_;  // per corner
        }
      }
      scene_.add_triangle(p[0], p[1], p[2], n[0], n[1], n[2], g.material, id);
    }
  }

  // -- after the walk --------------------------------------------------------------------------

  void finish() {
    std::string skipped;
    for (const auto& [what, count] : skipped_modes_) {
      const std::string item =
          std::to_string(count) + " " + what + " primitive" + (count == 1 ? "" : "s");
      scene_.warnings.push_back("skipped " + item + " (only triangles are rendered)");
      skipped += (skipped.empty() ? "" : ", ") + item;
    }
    if (invalid_file_normals_ > 0)
      scene_.warnings.push_back(std::to_string(invalid_file_normals_) +
                                " corner normals from the file were zero or not finite and were "
                                "replaced by face normals");
    if (scene_.input_triangles == 0)
      fail(path_,
           "the scene has no triangles" + (skipped.empty() ? "" : " (skipped " + skipped + ")"));
    if (scene_.triangle_count() == 0)
      fail(path_, "all " + std::to_string(scene_.input_triangles) +
                      " triangles of the scene are degenerate (zero area)");

    double brightest = 1.0;
    for (const PendingLight& l : lights_) brightest = std::max(brightest, l.intensity);
    for (const PendingLight& l : lights_)
      scene_.lights.push_back({l.position, l.rgb * float(l.intensity / brightest)});
    if (scene_.lights.empty()) {
      const Bounds b = scene_.bounds();
      const glm::vec3 centre = (b.lo + b.hi) * 0.5f;
      const float diagonal = glm::length(b.hi - b.lo);
      scene_.lights.push_back({centre + glm::vec3(0.3f, 1.0f, 0.6f) * diagonal, glm::vec3(1.0f)});
      scene_.default_light = true;
    }
    scene_.source = path_;
    scene_.name = fs::path(path_).stem().string();
  }

  std::string path_;
  uint64_t max_triangles_;
  tinygltf::Model model_;
  Scene scene_;
  std::vector<uint64_t> declared_lengths_;
  std::map<int, std::shared_ptr<const std::vector<glm::vec3>>> position_cache_, normal_cache_;
  std::map<int, std::shared_ptr<const std::vector<uint32_t>>> index_cache_;
  std::map<std::pair<size_t, size_t>, PrimitiveGeometry> primitives_;
  std::optional<uint32_t> default_material_;
  std::vector<PendingLight> lights_;
  std::map<std::string, uint64_t> skipped_modes_;
  std::set<std::string> warned_;
  uint64_t invalid_file_normals_ = 0;
};

bool is_scene_file(const fs::path& p) {
  const std::string ext = p.extension().string();
  return ext == ".gltf" || ext == ".glb";
}

}  // namespace

Scene load_scene(const std::string& path, const LoadOptions& options) {
  return Loader(path, options).load();
}

std::string resolve_scene(const std::string& name_or_path) {
  std::error_code ec;
  if (fs::is_regular_file(name_or_path, ec)) return name_or_path;
  for (const char* ext : {".gltf", ".glb"}) {
    const fs::path candidate = fs::path(VGPU_SCENES_DIR) / (name_or_path + ext);
    if (fs::is_regular_file(candidate, ec)) return candidate.string();
  }
  throw InputError(one_line(name_or_path, 1000) +
                   ": no such file or scene in scenes/ (try `vgpu-rt scenes`)");
}

std::vector<std::pair<std::string, std::string>> list_scenes() {
  std::vector<std::pair<std::string, std::string>> out;
  std::error_code ec;
  for (fs::directory_iterator it(VGPU_SCENES_DIR, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->is_regular_file(ec) && is_scene_file(it->path()))
      out.emplace_back(it->path().stem().string(), it->path().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace host
