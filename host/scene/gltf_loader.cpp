// The glTF 2.0 loader (see gltf_loader.h for the rules): checks the model tinygltf parsed, then
// walks the default scene depth-first, emitting world-space triangles (parsing: gltf_file.cpp).
#include "host/scene/gltf_loader.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <set>

#include "host/scene/gltf_internal.h"

// tinygltf's declarations only: its implementation is compiled once, in gltf_file.cpp.
#include <tiny_gltf.h>

namespace host {
namespace {

using gltf_detail::fail;
using gltf_detail::le32;
using gltf_detail::mode_name;
using gltf_detail::parse_file;
using gltf_detail::read_component;
using gltf_detail::shortest;
namespace fs = std::filesystem;

// glTF binary data is little-endian; accessors are read with memcpy.
static_assert(std::endian::native == std::endian::little);

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
  // Per vertex: texture coordinates of the material's texture, transformed (null: untextured).
  std::shared_ptr<const std::vector<glm::vec2>> uvs;
};

struct PendingLight {
  glm::vec3 position;
  glm::vec3 rgb;
  double intensity;
};

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

}  // namespace

namespace gltf_detail {

class Loader {
 public:
  // Parses and checks the file; flatten() walks its default scene.
  Loader(std::string path, const LoadOptions& options)
      : path_(std::move(path)),
        max_triangles_(std::min<uint64_t>(options.max_triangles, 0xFFFFFFFFull)),
        options_(options) {
    std::string textures;
    declared_lengths_ =
        parse_file(path_, model_, warnings_, textures, options.animations);  // gltf_file.cpp
    check_buffers_and_views();
    check_accessors();
    // Decoded once; every flatten() hands the same textures to its scene.
    Scene decoded;
    base_color_ = gltf_detail::read_textures(path_, textures, model_, options_, decoded);
    textures_ = std::move(decoded.textures);
    textures_fitted_ = std::move(decoded.textures_fitted);
    convert_materials();
    roots_ = root_nodes();
  }

  Scene flatten_last() {
    last_ = true;
    return flatten({});
  }

  // One walk of the default scene into a new Scene; `local[n]`, where set, replaces node n's
  // own local transform. Primitives are decoded once, at their first walk.
  Scene flatten(const std::vector<std::optional<glm::dmat4>>& local) {
    scene_ = Scene{};
    // The last flatten (load_scene's only one) takes the texels rather than copying them.
    scene_.textures = last_ ? std::move(textures_) : textures_;
    scene_.textures_fitted = textures_fitted_;
    lights_.clear();
    walked_.clear();
    invalid_file_normals_ = 0;
    local_ = &local;
    walk(roots_);
    local_ = nullptr;
    finish();
    return std::move(scene_);
  }

  const tinygltf::Model& model() const { return model_; }
  const std::string& path() const { return path_; }
  const std::vector<int>& walked() const { return walked_; }

  // Accessor `index` for `use` as doubles, `components` per element (1: SCALAR, 3: VEC3,
  // 4: VEC4): float components, or with `integers` also (normalized) byte and short ones.
  std::vector<double> read_doubles(int index, const std::string& use, int components,
                                   bool integers) const {
    const tinygltf::Accessor& acc = accessor_for(index, use);
    const int ct = acc.componentType;
    const int type = components == 1   ? TINYGLTF_TYPE_SCALAR
                     : components == 3 ? TINYGLTF_TYPE_VEC3
                                       : TINYGLTF_TYPE_VEC4;
    const bool normalized_int =
        integers && acc.normalized &&
        (ct == TINYGLTF_COMPONENT_TYPE_BYTE || ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
         ct == TINYGLTF_COMPONENT_TYPE_SHORT || ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
    if (acc.type != type || (ct != TINYGLTF_COMPONENT_TYPE_FLOAT && !normalized_int))
      fail(path_, use + ": accessor " + std::to_string(index) + " must be " +
                      (components == 1   ? "SCALAR"
                       : components == 3 ? "VEC3"
                                         : "VEC4") +
                      " of float" + (integers ? " or normalized byte or short" : "") +
                      " components");
    const int comp = tinygltf::GetComponentSizeInBytes(uint32_t(ct));
    std::vector<double> out(size_t(acc.count) * size_t(components));
    const Elements element = elements(acc);
    for (size_t i = 0; i < acc.count; ++i)
      for (int c = 0; c < components; ++c) {
        const double v = read_component(element[i] + c * comp, ct, acc.normalized);
        if (!std::isfinite(v))
          fail(path_, use + ": accessor " + std::to_string(index) + " element " +
                          std::to_string(i) + " is not finite");
        out[i * size_t(components) + size_t(c)] = v;
      }
    return out;
  }

 private:
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

  // TEXCOORD_n: VEC2 of float, or normalized unsigned byte or short (the glTF spec's types).
  std::shared_ptr<const std::vector<glm::vec2>> read_uvs(int index, const std::string& use) {
    if (auto it = uv_cache_.find(index); it != uv_cache_.end()) return it->second;
    const tinygltf::Accessor& acc = accessor_for(index, use);
    const int ct = acc.componentType;
    const bool ok = acc.type == TINYGLTF_TYPE_VEC2 &&
                    (ct == TINYGLTF_COMPONENT_TYPE_FLOAT ||
                     (acc.normalized && (ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                                         ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT)));
    if (!ok)
      fail(path_, use + ": accessor " + std::to_string(index) +
                      " must be VEC2 of float, or of normalized unsigned byte or short components");
    const int comp = tinygltf::GetComponentSizeInBytes(uint32_t(ct));
    auto out = std::make_shared<std::vector<glm::vec2>>(acc.count);
    const Elements element = elements(acc);
    for (size_t i = 0; i < acc.count; ++i) {
      const unsigned char* p = element[i];
      glm::vec2& v = (*out)[i];
      for (int c = 0; c < 2; ++c) v[c] = read_component(p + c * comp, ct, acc.normalized);
      if (!std::isfinite(v.x) || !std::isfinite(v.y))
        fail(path_, use + ": accessor " + std::to_string(index) + " element " + std::to_string(i) +
                        " is not finite");
    }
    uv_cache_[index] = out;
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
          warnings_.push_back(name + ": extras.reflect is not a number; ignored");
        } else {
          const double value = r.GetNumberAsDouble();
          if (value < 0.0 || value > 1.0)
            warnings_.push_back(name + ": extras.reflect " + std::to_string(value) +
                                " is outside [0, 1]; clamped");
          out.reflect = float(std::clamp(value, 0.0, 1.0));
        }
      }
      if (m < base_color_.size()) out.texture = base_color_[m].texture;
      read_glass(src, name, out);
      materials_.push_back(out);
    }
  }

  // KHR_materials_transmission and KHR_materials_ior into out.transmission and out.ior (see
  // gltf_loader.h for the rules). A number out of its valid range is refused: a typo in a glass
  // would otherwise render as some other glass without a word.
  void read_glass(const tinygltf::Material& src, const std::string& name, Material& out) {
    // The number `key` of extension `ext` on this material, or nullopt when absent.
    auto number = [&](const char* ext, const char* key) -> std::optional<double> {
      const auto it = src.extensions.find(ext);
      if (it == src.extensions.end()) return std::nullopt;
      if (!it->second.IsObject()) fail(path_, name + ": " + ext + " is not an object");
      if (!it->second.Has(key)) return std::nullopt;
      const tinygltf::Value& v = it->second.Get(key);
      if (!v.IsNumber()) fail(path_, name + ": " + ext + "." + key + " is not a number");
      return v.GetNumberAsDouble();  // finite: the JSON check refuses overflowing numbers
    };
    if (const auto t = number("KHR_materials_transmission", "transmissionFactor")) {
      if (!(*t >= 0.0 && *t <= 1.0))
        fail(path_, name + ": KHR_materials_transmission.transmissionFactor " + shortest(*t) +
                        " is outside [0, 1]");
      out.transmission = float(*t);
    }
    if (src.extensions.count("KHR_materials_transmission")) {
      const tinygltf::Value& v = src.extensions.at("KHR_materials_transmission");
      if (v.Has("transmissionTexture"))
        warnings_.push_back(name +
                            ": KHR_materials_transmission.transmissionTexture is not supported; "
                            "transmissionFactor alone is used");
    }
    if (const auto ior = number("KHR_materials_ior", "ior")) {
      if (*ior == 0.0) {
        // The extension's special value: the Fresnel term is 1 at every angle, so the surface
        // transmits nothing. Under the glass model that is exactly the opaque mirror whose
        // reflected share (1 - t) a + t is its reflection coefficient (its local share
        // (1 - t)(1 - a) is then 1 - reflect), and shadow rays stop at it, as no light passes.
        out.reflect = out.reflect + out.transmission * (1.0f - out.reflect);
        out.transmission = 0.0f;
      } else if (*ior < 1.0) {
        fail(path_, name + ": KHR_materials_ior.ior " + shortest(*ior) +
                        " is below 1 (only 0, the extension's special value, is allowed below 1)");
      } else {
        out.ior = float(*ior);
      }
    }
  }

  uint32_t default_material() {
    if (!default_material_) {
      default_material_ = uint32_t(materials_.size());
      materials_.push_back(Material{});
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
    if (local_ && index < local_->size() && (*local_)[index]) return *(*local_)[index];
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
      walked_.push_back(item.node);
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
    if (warned_.insert(message).second) warnings_.push_back(message);
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

    if (g.material < base_color_.size() && base_color_[g.material].texture >= 0) {
      const gltf_detail::BaseColorTexture& tex = base_color_[g.material];
      const std::string set = "TEXCOORD_" + std::to_string(tex.tex_coord);
      const auto uv = prim.attributes.find(set);
      if (uv == prim.attributes.end())
        fail(path_, name + ": material " + std::to_string(g.material) +
                        " has a baseColorTexture but the primitive has no " + set);
      const auto raw = read_uvs(uv->second, name + " " + set);
      if (raw->size() != vertex_count)
        fail(path_, name + ": " + set + " has " + std::to_string(raw->size()) +
                        " elements but POSITION has " + std::to_string(vertex_count));
      auto uvs = std::make_shared<std::vector<glm::vec2>>(raw->size());
      for (size_t i = 0; i < raw->size(); ++i)
        (*uvs)[i] = glm::vec2(tex.transform * glm::dvec3(glm::dvec2((*raw)[i]), 1.0));
      g.uvs = uvs;
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
      if (!scene_.textures.empty()) {
        const std::vector<glm::vec2>* uv = g.uvs.get();
        scene_.uv0.push_back(uv ? (*uv)[v[0]] : glm::vec2(0.0f));
        scene_.uv1.push_back(uv ? (*uv)[v[1]] : glm::vec2(0.0f));
        scene_.uv2.push_back(uv ? (*uv)[v[2]] : glm::vec2(0.0f));
      }
    }
  }

  // -- after the walk --------------------------------------------------------------------------

  void finish() {
    scene_.materials = materials_;
    scene_.warnings = warnings_;
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
  std::vector<int> roots_;
  std::vector<Material> materials_;
  std::vector<std::string> warnings_;  // the file's and the walks' so far, each once
  const std::vector<std::optional<glm::dmat4>>* local_ = nullptr;  // during flatten()
  std::vector<int> walked_;
  Scene scene_;
  std::vector<uint64_t> declared_lengths_;
  std::map<int, std::shared_ptr<const std::vector<glm::vec3>>> position_cache_, normal_cache_;
  std::map<int, std::shared_ptr<const std::vector<uint32_t>>> index_cache_;
  std::map<int, std::shared_ptr<const std::vector<glm::vec2>>> uv_cache_;
  const LoadOptions options_;  // a copy: an AnimatedScene outlives the options it was given
  std::vector<SceneTexture> textures_;  // the file's base-colour textures, decoded once
  std::string textures_fitted_;         // Scene::textures_fitted
  bool last_ = false;                   // set by flatten_last: the flatten may take textures_
  std::vector<gltf_detail::BaseColorTexture> base_color_;  // per file material
  std::map<std::pair<size_t, size_t>, PrimitiveGeometry> primitives_;
  std::optional<uint32_t> default_material_;
  std::vector<PendingLight> lights_;
  std::map<std::string, uint64_t> skipped_modes_;
  std::set<std::string> warned_;
  uint64_t invalid_file_normals_ = 0;
};

OpenScene::OpenScene(const std::string& path, const LoadOptions& options)
    : loader_(std::make_unique<Loader>(path, options)) {}
OpenScene::~OpenScene() = default;
Scene OpenScene::flatten(const std::vector<std::optional<glm::dmat4>>& local) {
  return loader_->flatten(local);
}
const tinygltf::Model& OpenScene::model() const {
  return loader_->model();
}
const std::string& OpenScene::path() const {
  return loader_->path();
}
const std::vector<int>& OpenScene::walked() const {
  return loader_->walked();
}
std::vector<double> OpenScene::read_doubles(int accessor, const std::string& use, int components,
                                            bool integers) const {
  return loader_->read_doubles(accessor, use, components, integers);
}

Scene OpenScene::flatten_last() {
  return loader_->flatten_last();
}

}  // namespace gltf_detail

Scene load_scene(const std::string& path, const LoadOptions& options) {
  return gltf_detail::OpenScene(path, options).flatten_last();
}

}  // namespace host
