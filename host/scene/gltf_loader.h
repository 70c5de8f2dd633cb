// The glTF 2.0 loader: reads a .gltf (external or embedded buffers) or .glb file with tinygltf,
// validates every index, offset and length itself, and flattens the default scene into
// host::Scene (world-space triangles, materials, camera, point lights).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "host/common/install_paths.h"  // the scenes' folder; registers an installed prefix
#include "host/scene/scene.h"

namespace host {

// An image's texels as decoded (host/image's decode_image): the stored values scaled to [0, 1],
// no colour conversion, row 0 = top, `channels` floats per texel.
struct ImagePixels {
  int width = 0, height = 0, channels = 0;
  std::vector<float> pixels;
};

struct LoadOptions {
  // Input triangles (degenerate ones included) above this throw InputError. Values above
  // 2^32 - 1 act as 2^32 - 1, since triangle ids are 32-bit.
  uint64_t max_triangles = 50'000'000;
  // Decodes a PNG or JPEG image (host::decode_image); throws std::exception with the reason.
  // Unset: a file whose materials use a texture is refused (the scene room cannot decode images;
  // host/image, above it, can).
  std::function<ImagePixels(const std::vector<unsigned char>&)> read_image{};
  // Fit the base-colour textures to an atlas at most this many texels a side (a profile's
  // max_texture_size), by host/scene/texture_fit.h's rule, naming `fit_for` (the profile) in
  // Scene::textures_fitted; 0: keep every image as decoded. Either way an image whose header
  // passes kMaxDecodedImageBytes is refused before it is decoded.
  int fit_textures = 0;
  std::string fit_for{};
  // Parse the file's animations too (host/scene/animation.h); load_scene never uses them.
  bool animations = false;
};

// Loads the default scene (or scene 0, or every root node when the file has no scenes).
// Any problem with the file throws InputError with a one-line "PATH: problem" message.
//
// Geometry
// - Nodes are walked depth-first, pre-order, children in listed order; the hierarchy must be a
//   tree (a node reached twice is an error). A node's local transform is its matrix, or T*R*S.
// - Primitives of mode TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN are expanded as the glTF spec
//   says (strip triangle i = v[i], v[i+1+i%2], v[i+2-i%2]; fan triangle i = v[i+1], v[i+2], v[0]);
//   POINTS and LINE* primitives are skipped with a warning.
// - Positions may be float or (KHR_mesh_quantization) byte/short, normalized or not.
// - Triangle ids count every input triangle in that order. Triangles whose world-space cross
//   product is zero in float or shorter than 1e-30 are dropped (Scene::dropped_degenerate) and
//   keep their ids out of Scene::id.
// - Under a mirroring world matrix (negative determinant) corners 1 and 2 are swapped, so every
//   stored triangle is counter-clockwise seen from the side its normals point to.
// Normals
// - From the file: transformed by the inverse transpose of the world matrix, then normalised.
// - Absent: smooth normals computed in the mesh's local space, per primitive: a vertex's normal
//   is the sum of the (unnormalised) cross products of every triangle of the primitive that uses
//   that vertex index, i.e. the area-weighted average of the face normals; then transformed like
//   file normals. Vertices only shared by different indices (non-indexed primitives) get flat
//   normals. A normal that comes out zero or not finite is replaced by the face normal.
// Materials
// - color = pbrMetallicRoughness.baseColorFactor.rgb, reflect = metallicFactor, both clamped to
//   [0, 1], with the glTF defaults (white, metallicFactor 1) when absent; a number
//   `extras.reflect` in [0, 1] on the material overrides reflect. A primitive without a material
//   gets Material{} (0.8 grey, reflect 0), appended after the file's materials.
// - Glass: KHR_materials_transmission.transmissionFactor (default 0) into transmission, and
//   KHR_materials_ior.ior (default 1.5) into ior. A transmissionFactor outside [0, 1], an ior below
//   1, or either not a number: InputError naming the material. ior 0, which the extension
//   allows (a Fresnel term of 1 everywhere: nothing is transmitted), becomes the opaque mirror it
//   is: transmission 0, reflect = a + t (1 - a). A transmissionTexture is not supported: a
//   warning, and the factor alone is used. KHR_materials_volume is ignored (clear glass).
// Textures
// - pbrMetallicRoughness.baseColorTexture: its texture's image (a data: URI, a buffer view, or a
//   file beside the .gltf; PNG or JPEG, decoded by LoadOptions::read_image) and its sampler's
//   wrapS / wrapT (REPEAT, CLAMP_TO_EDGE, MIRRORED_REPEAT; filters are the renderer's option).
//   Texels are decoded from sRGB to linear (glTF's rule for base colour); the material's colour
//   multiplies them, alpha is ignored. The texture's texCoord set (TEXCOORD_n: VEC2 of float,
//   or normalized unsigned byte or short) gives each corner's coordinates, with
//   KHR_texture_transform (offset, rotation, scale; its texCoord override) applied per corner.
//   A textured primitive without that set, a texture, image or sampler out of range, an image
//   that cannot be read or decoded: InputError naming the image or accessor.
// Camera
// - The first camera node met in the walk; perspective only (orthographic is an error):
//   position = world translation, forward = world -Z, up = world +Y made orthogonal, yfov as is.
//   The file's aspectRatio is ignored (the image size decides).
// Lights (KHR_lights_punctual)
// - Point lights, at the node's world position. Spot lights are treated as point lights and
//   directional lights skipped, each with a warning.
// - Intensity rule: color = rgb * intensity / max(1, I_max), I_max the largest intensity among the
//   point and spot lights of the walk. Files whose lights are at most 1 keep their values; files
//   in physical units (Blender writes candela, often hundreds) are scaled so the brightest light is
//   exactly its rgb, which suits a Lambert shader without falloff; ratios between lights are kept.
// - No point light: one default white light at bounds centre + (0.3, 1.0, 0.6) * diagonal length,
//   with Scene::default_light = true.
Scene load_scene(const std::string& path, const LoadOptions& options = {});

// A path to an existing file is returned as is; otherwise NAME is looked up as DIR/NAME.gltf,
// then DIR/NAME.glb, DIR the bundled scenes' folder (host/common/install_paths.h finds it).
// Throws InputError when none exists.
std::string resolve_scene(const std::string& name_or_path);

// (name, path) of every *.gltf and *.glb in the bundled scenes' folder, sorted by name then
// path. Throws InputError when that folder is not found.
std::vector<std::pair<std::string, std::string>> list_scenes();

}  // namespace host
