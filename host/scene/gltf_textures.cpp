// The glTF loader's textures: each material's baseColorTexture, its image (a data: URI, a buffer
// view or a file beside the .gltf) decoded through LoadOptions::read_image, its sampler's wraps
// and KHR_texture_transform. gltf_loader.cpp reads the texture coordinates.
#include <tiny_gltf.h>

#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string_view>
#include <tuple>

#include "host/scene/gltf_internal.h"
#include "host/scene/gltf_loader.h"
#include "host/scene/texture_fit.h"

namespace host::gltf_detail {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

constexpr int kGlRepeat = 10497, kGlClampToEdge = 33071, kGlMirroredRepeat = 33648;

// glTF's sRGB transfer function, inverted (base colour textures are sRGB-encoded).
float srgb_to_linear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// RFC 4648 base64, padding optional; nullopt on a character outside the alphabet.
std::optional<std::vector<unsigned char>> base64(std::string_view text) {
  std::vector<unsigned char> out;
  out.reserve(text.size() / 4 * 3);
  uint32_t acc = 0;
  int bits = 0;
  for (char c : text) {
    int v;
    if (c >= 'A' && c <= 'Z')
      v = c - 'A';
    else if (c >= 'a' && c <= 'z')
      v = c - 'a' + 26;
    else if (c >= '0' && c <= '9')
      v = c - '0' + 52;
    else if (c == '+')
      v = 62;
    else if (c == '/')
      v = 63;
    else if (c == '=')
      break;
    else
      return std::nullopt;
    acc = acc << 6 | uint32_t(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<unsigned char>(acc >> bits));
    }
  }
  return out;
}

// %XX escapes of a relative URI decoded.
std::string percent_decoded(const std::string& uri) {
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(uint8_t(uri[i + 1])) &&
        std::isxdigit(uint8_t(uri[i + 2]))) {
      out += char(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

class TextureReader {
 public:
  TextureReader(const std::string& path, const json& doc, const tinygltf::Model& model,
                const LoadOptions& options, Scene& scene)
      : path_(path), doc_(doc), model_(model), options_(options), scene_(scene) {}

  std::vector<BaseColorTexture> read() {
    const json& base = doc_["base_color"];
    std::vector<BaseColorTexture> out(base.size());
    for (size_t m = 0; m < base.size(); ++m) {
      if (base[m].is_null()) continue;
      const std::string owner = "material " + std::to_string(m) + " baseColorTexture";
      const json& info = base[m];
      if (!info.is_object() || !info.contains("index") || !info["index"].is_number_integer())
        fail(path_, owner + ": index must be an integer");
      out[m].tex_coord = tex_coord(info, owner);
      out[m].texture = texture(info["index"].get<int64_t>(), owner);
      if (info.contains("extensions") && info["extensions"].is_object() &&
          info["extensions"].contains("KHR_texture_transform"))
        transform(info["extensions"]["KHR_texture_transform"], owner, out[m]);
    }
    decode_all();
    return out;
  }

 private:
  static int tex_coord(const json& info, const std::string& owner, int fallback = 0) {
    if (!info.contains("texCoord")) return fallback;
    const json& t = info["texCoord"];
    if (!t.is_number_integer() || t.get<int64_t>() < 0 || t.get<int64_t>() > 31)
      throw std::invalid_argument(owner + ": texCoord must be an integer from 0 to 31");
    return int(t.get<int64_t>());
  }

  // KHR_texture_transform: uv' = T * R * S * uv (the extension's matrix, rotation
  // counter-clockwise in uv space).
  void transform(const json& ext, const std::string& owner, BaseColorTexture& t) const {
    const std::string where = owner + " KHR_texture_transform";
    if (!ext.is_object()) fail(path_, where + " must be an object");
    auto pair = [&](const char* key, glm::dvec2 dflt) {
      if (!ext.contains(key)) return dflt;
      const json& v = ext[key];
      if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number())
        fail(path_, where + ": " + key + " must be two numbers");
      return glm::dvec2(v[0].get<double>(), v[1].get<double>());
    };
    const glm::dvec2 offset = pair("offset", {0, 0}), scale = pair("scale", {1, 1});
    double rotation = 0;
    if (ext.contains("rotation")) {
      if (!ext["rotation"].is_number()) fail(path_, where + ": rotation must be a number");
      rotation = ext["rotation"].get<double>();
    }
    try {
      t.tex_coord = tex_coord(ext, where, t.tex_coord);
    } catch (const std::invalid_argument& e) {
      fail(path_, e.what());
    }
    const double c = std::cos(rotation), s = std::sin(rotation);
    // Columns: the images of u, of v, and the translation.
    t.transform =
        glm::dmat3(glm::dvec3(c * scale.x, -s * scale.x, 0),
                   glm::dvec3(s * scale.y, c * scale.y, 0), glm::dvec3(offset.x, offset.y, 1));
  }

  const json& item(const char* list, int64_t index, const std::string& owner) const {
    const json& a = doc_[list];
    if (index < 0 || uint64_t(index) >= a.size())
      fail(path_, owner + " refers to " + std::string(list).substr(0, std::strlen(list) - 1) + " " +
                      std::to_string(index) + ", but the file has " + std::to_string(a.size()) +
                      " " + list);
    if (!a[size_t(index)].is_object())
      fail(path_, std::string(list).substr(0, std::strlen(list) - 1) + " " + std::to_string(index) +
                      " is not an object");
    return a[size_t(index)];
  }

  static WrapMode wrap(const json& sampler, const char* key, const std::string& owner,
                       const std::string& path) {
    if (!sampler.contains(key)) return WrapMode::repeat;
    const json& w = sampler[key];
    const int64_t v = w.is_number_integer() ? w.get<int64_t>() : -1;
    if (v == kGlRepeat) return WrapMode::repeat;
    if (v == kGlClampToEdge) return WrapMode::clamp_to_edge;
    if (v == kGlMirroredRepeat) return WrapMode::mirrored_repeat;
    fail(path, owner + ": " + key + " " + w.dump() +
                   " is not a wrap mode (10497 REPEAT, 33071 CLAMP_TO_EDGE, 33648 "
                   "MIRRORED_REPEAT)");
  }

  // Scene::textures index of texture `index` (one per image and wrap pair).
  int texture(int64_t index, const std::string& owner) {
    const json& tex = item("textures", index, owner);
    const std::string tname = "texture " + std::to_string(index);
    if (!tex.contains("source") || !tex["source"].is_number_integer())
      fail(path_, tname + " has no image source (extensions' sources are not supported)");
    const int64_t image = tex["source"].get<int64_t>();
    const json& img = item("images", image, tname);
    WrapMode ws = WrapMode::repeat, wt = WrapMode::repeat;
    if (tex.contains("sampler")) {
      if (!tex["sampler"].is_number_integer()) fail(path_, tname + ": sampler must be an integer");
      const int64_t si = tex["sampler"].get<int64_t>();
      const json& s = item("samplers", si, tname);
      const std::string sname = "sampler " + std::to_string(si);
      ws = wrap(s, "wrapS", sname, path_);
      wt = wrap(s, "wrapT", sname, path_);
    }
    const auto key = std::make_tuple(image, ws, wt);
    if (auto it = made_.find(key); it != made_.end()) return it->second;
    SceneTexture t;  // decoded by decode_all, once every texture's size is known
    t.wrap_s = ws;
    t.wrap_t = wt;
    scene_.textures.push_back(std::move(t));
    images_.push_back({image, &img});
    return made_[key] = int(scene_.textures.size() - 1);
  }

  // Every used image's bytes and header size first: an image past kMaxDecodedImageBytes is
  // refused before any is decoded, and the fitting rule (texture_fit.h) decides each
  // texture's halvings from the sizes alone. Then each image is decoded, halved, and its
  // bytes and full-size texels let go before the next.
  void decode_all() {
    std::vector<std::vector<unsigned char>> bytes(images_.size());
    std::vector<glm::ivec2> sizes(images_.size(), glm::ivec2(1));
    for (size_t i = 0; i < images_.size(); ++i) {
      SceneTexture& t = scene_.textures[i];
      bytes[i] = image_bytes(images_[i].first, *images_[i].second, t.name);
      if (const auto size = image_header_size(bytes[i])) {
        const uint64_t texels = uint64_t(size->x) * uint64_t(size->y);
        if (texels > kMaxDecodedImageBytes / kDecodedBytesPerTexel)
          fail(path_, t.name + ": its header says " + std::to_string(size->x) + "x" +
                          std::to_string(size->y) + " texels, " +
                          std::to_string(texels * kDecodedBytesPerTexel >> 20) +
                          " MiB decoded, past the loader's bound of " +
                          std::to_string(kMaxDecodedImageBytes >> 20) +
                          " MiB (8192x8192); scale the image down");
        sizes[i] = *size;
      }
    }
    const int fit = options_.fit_textures;
    const std::vector<int> halvings =
        fit > 0 ? fit_halvings(sizes, fit) : std::vector<int>(sizes.size(), 0);
    std::string fitted;
    for (size_t i = 0; i < images_.size(); ++i) {
      SceneTexture& t = scene_.textures[i];
      const glm::ivec2 from = decode(std::move(bytes[i]), t, halvings[i] > 0);
      for (int k = halvings[i] > 0 ? 1 : 0; k < halvings[i]; ++k) {
        t.texels = halve(t.texels, t.width, t.height);
        t.width = std::max(1, t.width / 2);
        t.height = std::max(1, t.height / 2);
      }
      if (halvings[i] > 0)
        fitted += std::string(fitted.empty() ? "" : "; ") + t.name + " " + size_text(from) +
                  " -> " + size_text({t.width, t.height}) + " (1/" +
                  std::to_string(1 << halvings[i]) + " a side, mip level " +
                  std::to_string(halvings[i]) + " as its base)";
    }
    if (!fitted.empty())
      scene_.textures_fitted = "textures scaled down so that their atlas fits " + options_.fit_for +
                               "'s " + std::to_string(fit) + "x" + std::to_string(fit) +
                               " texels: " + fitted + " (--textures refuse: refuse instead)";
  }

  static std::string size_text(glm::ivec2 s) {
    return std::to_string(s.x) + "x" + std::to_string(s.y);
  }

  // Image `index`'s encoded bytes (a data URI, a file beside the .gltf or a buffer view);
  // `name` gets its message name, e.g. "image 0 (duck.png)".
  std::vector<unsigned char> image_bytes(int64_t index, const json& img, std::string& name) const {
    name = "image " + std::to_string(index);
    std::vector<unsigned char> bytes;
    if (img.contains("uri") && img["uri"].is_string()) {
      const std::string uri = img["uri"].get<std::string>();
      if (uri.rfind("data:", 0) == 0) {
        const size_t comma = uri.find(',');
        if (comma == uri.npos || uri.substr(0, comma).find(";base64") == uri.npos)
          fail(path_, name + ": its data URI is not base64");
        auto b = base64(std::string_view(uri).substr(comma + 1));
        if (!b) fail(path_, name + ": its data URI is not valid base64");
        bytes = std::move(*b);
      } else {
        const std::string file = percent_decoded(uri);
        name += " (" + one_line(file, 200) + ")";
        const fs::path p = fs::path(path_).parent_path() / file;
        std::error_code ec;
        if (!fs::is_regular_file(p, ec)) fail(path_, name + ": cannot read " + p.string());
        std::ifstream in(p, std::ios::binary);
        bytes.assign(std::istreambuf_iterator<char>(in), {});
        if (!in.good() && !in.eof()) fail(path_, name + ": cannot read " + p.string());
      }
    } else if (img.contains("bufferView") && img["bufferView"].is_number_integer()) {
      const int64_t v = img["bufferView"].get<int64_t>();
      if (v < 0 || uint64_t(v) >= model_.bufferViews.size())
        fail(path_, name + " refers to buffer view " + std::to_string(v) + ", but the file has " +
                        std::to_string(model_.bufferViews.size()) + " buffer views");
      // The loader checked every view against its buffer.
      const tinygltf::BufferView& view = model_.bufferViews[size_t(v)];
      const auto& data = model_.buffers[size_t(view.buffer)].data;
      bytes.assign(data.begin() + std::ptrdiff_t(view.byteOffset),
                   data.begin() + std::ptrdiff_t(view.byteOffset + view.byteLength));
    } else {
      fail(path_, name + " has neither a uri nor a bufferView");
    }
    return bytes;
  }

  // Decodes `bytes` into t's texels, linear RGBA, halved once on the way where `halved` (level
  // 1 made from the decoder's texels: the full-size RGBA floats are never held). Returns the
  // image's own size.
  glm::ivec2 decode(std::vector<unsigned char> bytes, SceneTexture& t, bool halved) const {
    const std::string& name = t.name;
    if (!options_.read_image)
      fail(path_, name + ": no image decoder was given (LoadOptions::read_image)");
    ImagePixels px;
    try {
      px = options_.read_image(bytes);
      std::vector<unsigned char>().swap(bytes);
    } catch (const std::exception& e) {
      fail(path_, name + ": cannot read the image: " + e.what());
    }
    if (px.width <= 0 || px.height <= 0 || px.channels <= 0 ||
        px.pixels.size() != size_t(px.width) * size_t(px.height) * size_t(px.channels))
      fail(path_, name + ": the decoder returned no texels");
    const int ch = px.channels;
    auto linear = [&](size_t i) {
      const float* p = px.pixels.data() + i * size_t(ch);
      const glm::vec3 rgb = ch >= 3 ? glm::vec3(p[0], p[1], p[2]) : glm::vec3(p[0]);
      const float a = ch == 2 ? p[1] : ch >= 4 ? p[3] : 1.0f;
      return glm::vec4(srgb_to_linear(rgb.r), srgb_to_linear(rgb.g), srgb_to_linear(rgb.b), a);
    };
    if (halved) {
      t.texels =
          halve_from([&](int x, int y) { return linear(size_t(y) * size_t(px.width) + size_t(x)); },
                     px.width, px.height);
      t.width = std::max(1, px.width / 2);
      t.height = std::max(1, px.height / 2);
    } else {
      t.width = px.width;
      t.height = px.height;
      t.texels.resize(size_t(px.width) * size_t(px.height));
      for (size_t i = 0; i < t.texels.size(); ++i) t.texels[i] = linear(i);
    }
    return {px.width, px.height};
  }

  const std::string& path_;
  const json& doc_;
  const tinygltf::Model& model_;
  const LoadOptions& options_;
  Scene& scene_;
  std::map<std::tuple<int64_t, WrapMode, WrapMode>, int> made_;
  std::vector<std::pair<int64_t, const json*>> images_;  // per texture: its image, to decode
};

}  // namespace

std::vector<BaseColorTexture> read_textures(const std::string& path, const std::string& textures,
                                            const tinygltf::Model& model,
                                            const LoadOptions& options, Scene& scene) {
  const json doc = json::parse(textures);
  try {
    return TextureReader(path, doc, model, options, scene).read();
  } catch (const std::invalid_argument& e) {
    fail(path, e.what());
  }
}

}  // namespace host::gltf_detail
