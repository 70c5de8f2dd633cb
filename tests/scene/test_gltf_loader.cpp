// Tests for host/gltf_loader and host/camera: known answers on the small files written by
// tests/data/gltf/make_cases.py, and one rejection test per kind of broken input.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/epsilon.hpp>
#include <sstream>
#include <string>

#include "host/common/install_paths.h"
#include "host/scene/camera.h"
#include "host/scene/gltf_loader.h"

namespace {

std::string data_path(const std::string& name) {
  return std::string(VGPU_TEST_DATA) + "/gltf/" + name;
}

host::Scene load(const std::string& name, const host::LoadOptions& options = {}) {
  return host::load_scene(data_path(name), options);
}

// The InputError message for loading `path`, or "" when it loads.
std::string error_of(const std::string& path, const host::LoadOptions& options = {}) {
  try {
    host::load_scene(path, options);
  } catch (const host::InputError& e) {
    return e.what();
  }
  return "";
}

// Loading data/gltf/NAME fails with one line "PATH: ..." that contains `reason`.
void check_rejected(const std::string& name, const std::string& reason,
                    const host::LoadOptions& options = {}) {
  const std::string path = data_path(name);
  const std::string message = error_of(path, options);
  INFO("message: " << message);
  CHECK(message.starts_with(path + ": "));
  CHECK(message.find(reason) != std::string::npos);
  CHECK(message.find('\n') == std::string::npos);
}

std::string str(glm::vec3 v) {
  std::ostringstream s;
  s << "(" << v.x << ", " << v.y << ", " << v.z << ")";
  return s.str();
}

#define CHECK_VEC(a, b) CHECK_MESSAGE((a) == (b), str(a) << " != " << str(b))
#define CHECK_VEC_NEAR(a, b) \
  CHECK_MESSAGE(glm::all(glm::epsilonEqual((a), (b), 1e-6f)), str(a) << " !~ " << str(b))

bool has_warning(const host::Scene& s, const std::string& text) {
  return std::any_of(s.warnings.begin(), s.warnings.end(),
                     [&](const std::string& w) { return w.find(text) != std::string::npos; });
}

}  // namespace

// ---- valid files
// ---------------------------------------------------------------------------------

TEST_CASE(
    "A minimal triangle loads with its positions, normals, default material and default light") {
  const host::Scene s = load("triangle.gltf");
  REQUIRE(s.triangle_count() == 1);
  CHECK(s.name == "triangle");
  CHECK(s.source == data_path("triangle.gltf"));
  CHECK_VEC(s.p0[0], glm::vec3(0, 0, 0));
  CHECK_VEC(s.p1[0], glm::vec3(1, 0, 0));
  CHECK_VEC(s.p2[0], glm::vec3(0, 1, 0));
  CHECK_VEC(s.n0[0], glm::vec3(0, 0, 1));
  CHECK_VEC(s.n2[0], glm::vec3(0, 0, 1));
  CHECK(s.id[0] == 0);
  CHECK(s.input_triangles == 1);
  CHECK(s.dropped_degenerate == 0);
  REQUIRE(s.materials.size() == 1);
  CHECK(s.material[0] == 0);
  CHECK_VEC(s.materials[0].color, glm::vec3(0.8f));
  CHECK(s.materials[0].reflect == 0.0f);
  CHECK_FALSE(s.camera.has_value());
  CHECK(s.warnings.empty());
  // Default light: bounds centre + (0.3, 1.0, 0.6) * diagonal length, white.
  REQUIRE(s.lights.size() == 1);
  CHECK(s.default_light);
  const float diagonal = glm::length(glm::vec3(1, 1, 0));
  CHECK_VEC(s.lights[0].position,
            glm::vec3(0.5f, 0.5f, 0.0f) + glm::vec3(0.3f, 1.0f, 0.6f) * diagonal);
  CHECK_VEC(s.lights[0].color, glm::vec3(1.0f));
}

TEST_CASE(
    "The glb and external-buffer versions of the triangle load the same scene as the embedded "
    "gltf") {
  const host::Scene a = load("triangle.gltf");
  for (const char* name : {"triangle.glb", "triangle_external.gltf"}) {
    INFO(name);
    const host::Scene b = load(name);
    REQUIRE(b.triangle_count() == 1);
    CHECK_VEC(b.p0[0], a.p0[0]);
    CHECK_VEC(b.p1[0], a.p1[0]);
    CHECK_VEC(b.p2[0], a.p2[0]);
    CHECK_VEC(b.n1[0], a.n1[0]);
    CHECK(b.warnings.empty());
  }
}

TEST_CASE("Node transforms compose parent to child: TRS and matrix give exact world positions") {
  const host::Scene s = load("hierarchy.gltf");
  REQUIRE(s.triangle_count() == 4);
  CHECK(s.id == std::vector<uint32_t>{0, 1, 2, 3});
  // Node 0: translate (1,2,3) * rotate 180 degrees about Z * scale 2.
  CHECK_VEC(s.p0[0], glm::vec3(1, 2, 3));
  CHECK_VEC(s.p1[0], glm::vec3(-1, 2, 3));
  CHECK_VEC(s.p2[0], glm::vec3(1, 0, 3));
  // Node 1, child of node 0: matrix translate (10, 0, 0).
  CHECK_VEC(s.p0[1], glm::vec3(-19, 2, 3));
  CHECK_VEC(s.p1[1], glm::vec3(-21, 2, 3));
  CHECK_VEC(s.p2[1], glm::vec3(-19, 0, 3));
  CHECK_VEC(s.n0[1], glm::vec3(0, 0, 1));
}

TEST_CASE("Normals are transformed by the inverse transpose of the world matrix") {
  // Triangle in the plane x + y = 1 (normal (1,1,0)/sqrt 2) under scale (1, 2, 1): the world
  // plane is x + y/2 = 1, normal (2, 1, 0)/sqrt 5.
  const host::Scene s = load("hierarchy.gltf");
  REQUIRE(s.triangle_count() == 4);
  CHECK_VEC(s.p1[3], glm::vec3(0, 2, 0));
  const glm::vec3 expected = glm::normalize(glm::vec3(2, 1, 0));
  CHECK_VEC_NEAR(s.n0[3], expected);
  CHECK_VEC_NEAR(s.n1[3], expected);
  CHECK_VEC_NEAR(s.n2[3], expected);
}

TEST_CASE(
    "A mirroring node transform keeps stored triangles counter-clockwise around their normals") {
  const host::Scene s = load("hierarchy.gltf");
  REQUIRE(s.triangle_count() == 4);
  // Node 2 scales x by -1: corners 1 and 2 are swapped, the normal still points to +Z.
  CHECK_VEC(s.p0[2], glm::vec3(0, 0, 0));
  CHECK_VEC(s.p1[2], glm::vec3(0, 1, 0));
  CHECK_VEC(s.p2[2], glm::vec3(-1, 0, 0));
  CHECK_VEC(s.n0[2], glm::vec3(0, 0, 1));
  CHECK(glm::dot(glm::cross(s.p1[2] - s.p0[2], s.p2[2] - s.p0[2]), s.n0[2]) > 0.0f);
}

TEST_CASE("Without scenes every root node is loaded, depth-first in index order") {
  const host::Scene s = load("no_scenes.gltf");
  REQUIRE(s.triangle_count() == 3);
  // Roots 0 and 1; node 2 (z = 2) is node 0's child, so it comes before node 1 (z = 1).
  CHECK(s.p0[0].z == 0.0f);
  CHECK(s.p0[1].z == 2.0f);
  CHECK(s.p0[2].z == 1.0f);
}

TEST_CASE("Triangle strips and fans expand in the glTF order and ids follow that order") {
  const host::Scene s = load("strip_fan.gltf");
  REQUIRE(s.triangle_count() == 7);
  CHECK(s.id == std::vector<uint32_t>{0, 1, 2, 3, 4, 5, 6});
  const glm::vec3 v[5] = {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}, {2, 0, 0}};
  // Strip: (0,1,2), (1,3,2), (2,3,4).
  CHECK_VEC(s.p0[0], v[0]);
  CHECK_VEC(s.p1[0], v[1]);
  CHECK_VEC(s.p2[0], v[2]);
  CHECK_VEC(s.p0[1], v[1]);
  CHECK_VEC(s.p1[1], v[3]);
  CHECK_VEC(s.p2[1], v[2]);
  CHECK_VEC(s.p0[2], v[2]);
  CHECK_VEC(s.p1[2], v[3]);
  CHECK_VEC(s.p2[2], v[4]);
  // Fan around f[0]: (1,2,0), (2,3,0).
  const glm::vec3 f[4] = {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  CHECK_VEC(s.p0[3], f[1]);
  CHECK_VEC(s.p1[3], f[2]);
  CHECK_VEC(s.p2[3], f[0]);
  CHECK_VEC(s.p0[4], f[2]);
  CHECK_VEC(s.p1[4], f[3]);
  CHECK_VEC(s.p2[4], f[0]);
  // Non-indexed strip.
  const glm::vec3 w[4] = {{0, 0, 2}, {0, 1, 2}, {1, 0, 2}, {1, 1, 2}};
  CHECK_VEC(s.p0[5], w[0]);
  CHECK_VEC(s.p1[5], w[1]);
  CHECK_VEC(s.p2[5], w[2]);
  CHECK_VEC(s.p0[6], w[1]);
  CHECK_VEC(s.p1[6], w[3]);
  CHECK_VEC(s.p2[6], w[2]);
}

TEST_CASE("Unsigned byte, short and int indices give the same triangles") {
  const host::Scene s = load("index_types.gltf");
  REQUIRE(s.triangle_count() == 6);
  for (size_t t = 0; t < 6; ++t) {
    INFO("triangle " << t);
    CHECK(s.id[t] == t);
    CHECK_VEC(s.p0[t], glm::vec3(0, 0, 0));
    CHECK_VEC(s.p1[t], t % 2 == 0 ? glm::vec3(1, 0, 0) : glm::vec3(1, 1, 0));
    CHECK_VEC(s.p2[t], t % 2 == 0 ? glm::vec3(1, 1, 0) : glm::vec3(0, 1, 0));
  }
}

TEST_CASE("Non-indexed triangles use consecutive vertices") {
  const host::Scene s = load("non_indexed.gltf");
  REQUIRE(s.triangle_count() == 2);
  CHECK_VEC(s.p0[1], glm::vec3(0, 0, 1));
  CHECK_VEC(s.p1[1], glm::vec3(1, 0, 1));
  CHECK_VEC(s.p2[1], glm::vec3(0, 1, 1));
}

TEST_CASE("Quantized positions are dequantized as KHR_mesh_quantization says") {
  const host::Scene s = load("quantized.gltf");
  REQUIRE(s.triangle_count() == 3);
  // Normalized unsigned short: c / 65535 (strided, 8 bytes per vertex).
  CHECK_VEC(s.p1[0], glm::vec3(1, 0, 0));
  CHECK_VEC(s.p2[0], glm::vec3(0, 32768.0f / 65535.0f, 0));
  CHECK_VEC(s.n0[0], glm::vec3(0, 0, 1));  // normalized byte normal 127 -> 1
  // Normalized byte: max(c / 127, -1).
  CHECK_VEC(s.p0[1], glm::vec3(-1, 0, 0));
  CHECK_VEC(s.p1[1], glm::vec3(1, 0, 0));
  CHECK_VEC(s.p2[1], glm::vec3(0, 64.0f / 127.0f, 0));
  // Plain short: the integer value.
  CHECK_VEC(s.p1[2], glm::vec3(300, 0, 0));
  CHECK_VEC(s.p2[2], glm::vec3(0, -200, 0));
}

TEST_CASE("Missing normals are area-weighted averages over vertices sharing an index") {
  // Triangle A = (v0, v1, v2) in z = 0, cross (0,0,1); triangle B = (v1, v3, v2), cross
  // (-1,-1,1). v1 and v2 are shared: (-1,-1,2)/sqrt 6.
  const host::Scene s = load("no_normals.gltf");
  REQUIRE(s.triangle_count() == 3);
  const glm::vec3 shared = glm::normalize(glm::vec3(-1, -1, 2));
  CHECK_VEC_NEAR(s.n0[0], glm::vec3(0, 0, 1));
  CHECK_VEC_NEAR(s.n1[0], shared);
  CHECK_VEC_NEAR(s.n2[0], shared);
  CHECK_VEC_NEAR(s.n0[1], shared);
  CHECK_VEC_NEAR(s.n1[1], glm::normalize(glm::vec3(-1, -1, 1)));
  CHECK_VEC_NEAR(s.n2[1], shared);
  // A non-indexed triangle shares no index: flat normals.
  CHECK_VEC_NEAR(s.n0[2], glm::vec3(-1, 0, 0));
  CHECK_VEC_NEAR(s.n1[2], glm::vec3(-1, 0, 0));
  CHECK_VEC_NEAR(s.n2[2], glm::vec3(-1, 0, 0));
}

TEST_CASE("A degenerate triangle is dropped without changing the ids of the others") {
  const host::Scene s = load("degenerate.gltf");
  CHECK(s.input_triangles == 4);
  CHECK(s.dropped_degenerate == 2);
  REQUIRE(s.triangle_count() == 2);
  CHECK(s.id == std::vector<uint32_t>{0, 3});
  CHECK_VEC(s.p0[1], glm::vec3(0, 0, 1));
}

TEST_CASE("The camera is the first camera node met depth-first in the default scene") {
  // Default scene 1: root -> [group -> deep camera, shallow camera]. Depth-first reaches the
  // deep camera (node 2) before the shallow one (node 1); scene 0's camera is not loaded.
  const host::Scene s = load("cameras.gltf");
  REQUIRE(s.camera.has_value());
  CHECK(s.camera->yfov == 0.7f);
  CHECK_VEC_NEAR(s.camera->position, glm::vec3(1, 2, 13));
  CHECK_VEC_NEAR(s.camera->forward, glm::vec3(-1, 0, 0));  // -Z turned 90 degrees about +Y
  CHECK_VEC_NEAR(s.camera->up, glm::vec3(0, 1, 0));
  CHECK(s.triangle_count() == 1);
}

TEST_CASE("An orthographic camera is rejected") {
  check_rejected("orthographic_camera.gltf", "orthographic");
}

TEST_CASE(
    "Point lights are scaled by the brightest light; spot lights count as point lights; "
    "directional lights are skipped") {
  // color = rgb * intensity / max(1, I_max); here I_max = 4.
  const host::Scene s = load("lights.gltf");
  CHECK_FALSE(s.default_light);
  REQUIRE(s.lights.size() == 3);
  CHECK_VEC(s.lights[0].position, glm::vec3(1, 2, 3));
  CHECK_VEC(s.lights[0].color, glm::vec3(0.5f, 0.25f, 0.125f));
  CHECK_VEC(s.lights[1].position, glm::vec3(0, 5, 0));
  CHECK_VEC(s.lights[1].color, glm::vec3(1, 1, 1));
  CHECK_VEC(s.lights[2].position, glm::vec3(0, 0, 5));
  CHECK_VEC(s.lights[2].color, glm::vec3(0, 0.25f, 0));
  CHECK(has_warning(s, "spot light treated as a point light"));
  CHECK(has_warning(s, "directional lights are not supported"));
}

TEST_CASE(
    "Materials take color and reflection from the file, extras.reflect overrides, and a missing "
    "material is grey") {
  const host::Scene s = load("materials.gltf");
  REQUIRE(s.triangle_count() == 5);
  REQUIRE(s.materials.size() == 5);
  CHECK(s.material == std::vector<uint32_t>{0, 1, 2, 3, 4});
  CHECK_VEC(s.materials[0].color, glm::vec3(0.2f, 0.4f, 0.6f));
  CHECK(s.materials[0].reflect == 0.25f);
  CHECK(s.materials[1].reflect == 0.75f);  // extras.reflect beats metallicFactor 0.1
  // glTF defaults: baseColorFactor white, metallicFactor 1.
  CHECK_VEC(s.materials[2].color, glm::vec3(1.0f));
  CHECK(s.materials[2].reflect == 1.0f);
  CHECK(s.materials[3].reflect == 1.0f);  // extras.reflect 1.5 clamped
  CHECK(has_warning(s, "material 3: extras.reflect"));
  CHECK_VEC(s.materials[4].color, glm::vec3(0.8f));  // the default, for the primitive without one
  CHECK(s.materials[4].reflect == 0.0f);
}

TEST_CASE(
    "Glass materials take transmissionFactor and ior from their extensions, with the defaults 0 "
    "and 1.5") {
  const host::Scene s = load("glass.gltf");
  REQUIRE(s.materials.size() == 6);
  CHECK(s.materials[0].transmission == 0.75f);
  CHECK(s.materials[0].ior == 1.33f);
  CHECK(s.materials[1].transmission == 1.0f);
  CHECK(s.materials[1].ior == 1.5f);  // KHR_materials_ior absent: its default
  CHECK(s.materials[2].transmission == 0.0f);
  CHECK(s.materials[2].ior == 2.42f);
  CHECK(s.materials[5].ior == 1.0f);  // 1 is valid: an interface that does not bend light
  // The materials of the other tests' files stay opaque.
  for (const host::Material& m : load("materials.gltf").materials) CHECK(m.transmission == 0.0f);
}

TEST_CASE("An ior of 0 (a Fresnel term of 1) loads as the opaque mirror it is") {
  const host::Scene s = load("glass.gltf");
  // metallicFactor 0.5, transmissionFactor 0.5: reflect = a + t (1 - a) = 0.75, nothing passes.
  CHECK(s.materials[3].transmission == 0.0f);
  CHECK(s.materials[3].reflect == 0.75f);
}

TEST_CASE(
    "A transmissionTexture is ignored with a warning and KHR_materials_volume is ignored "
    "silently") {
  const host::Scene s = load("glass.gltf");
  CHECK(s.materials[4].transmission == 0.5f);
  CHECK(has_warning(s,
                    "material 4: KHR_materials_transmission.transmissionTexture is not "
                    "supported"));
  CHECK(s.materials[4].attenuation_distance == 0.0f);  // no absorption: volume is not modeled
  CHECK(s.warnings.size() == 1);
}

TEST_CASE("Points and lines primitives are skipped with a warning") {
  const host::Scene s = load("modes.gltf");
  CHECK(s.triangle_count() == 1);
  CHECK(has_warning(s, "skipped 1 LINES primitive"));
  CHECK(has_warning(s, "skipped 1 POINTS primitive"));
  CHECK(has_warning(s, "skipped 1 LINE_STRIP primitive"));
}

// ---- broken files
// --------------------------------------------------------------------------------

TEST_CASE("A missing file is rejected with the file name") {
  check_rejected("does_not_exist.gltf", "no such file");
}

TEST_CASE("A text file is rejected as not glTF") {
  check_rejected("not_gltf.txt", "not a glTF file");
}

TEST_CASE("A truncated glb is rejected with the file name and the reason") {
  check_rejected("truncated.glb", "truncated .glb");
}

TEST_CASE("A glb whose chunk length runs past the file is rejected as corrupt") {
  check_rejected("bad_chunk_length.glb", "corrupt .glb: chunk 0 announces 10000 bytes");
}

TEST_CASE("A glb with an unsupported header version is rejected") {
  check_rejected("bad_version.glb", "unsupported .glb version 1");
}

TEST_CASE("A JSON syntax error is reported with its line") {
  check_rejected("json_syntax.gltf", "invalid JSON: parse error at line 3");
}

TEST_CASE("An accessor reading past its buffer view is rejected") {
  check_rejected("accessor_past_view.gltf", "accessor 0 reads past the end of buffer view 0");
}

TEST_CASE("A buffer view outside its buffer is rejected") {
  check_rejected("view_past_buffer.gltf", "buffer view 1 (bytes 36 + 100) lies outside buffer 0");
}

TEST_CASE("A buffer shorter than its byteLength is rejected, external, embedded or in a glb") {
  check_rejected("short_buffer.gltf",
                 "buffer 0: file 'short_buffer.bin' holds 42 bytes but its byteLength is 50");
  check_rejected("short_buffer_embedded.gltf",
                 "buffer 0: its data URI holds 42 bytes but its byteLength is 50");
  check_rejected("short_buffer.glb", "byteLength 86 is larger than the .glb BIN chunk (80 bytes)");
}

TEST_CASE("An index past the vertex count is rejected") {
  check_rejected("index_past_vertices.gltf",
                 "index 5 (element 2 of accessor 1) is past the vertex count 3");
}

TEST_CASE("A NaN position is rejected") {
  check_rejected("nan_position.gltf", "element 1 has a NaN coordinate");
}

TEST_CASE("An infinite position is rejected") {
  check_rejected("inf_position.gltf", "element 2 has an infinite coordinate");
}

TEST_CASE("A scene with only lines has no triangles and is rejected") {
  check_rejected("only_lines.gltf", "the scene has no triangles (skipped 1 LINES primitive)");
}

TEST_CASE("More triangles than max_triangles are rejected naming the limit") {
  check_rejected("strip_fan.gltf", "more triangles than the limit of 6", host::LoadOptions{6});
  CHECK(load("strip_fan.gltf", host::LoadOptions{7}).triangle_count() == 7);
}

TEST_CASE("A node hierarchy with a cycle is rejected") {
  check_rejected("node_cycle.gltf", "node 0 is reached twice");
}

TEST_CASE("An accessor index out of range is rejected") {
  check_rejected("accessor_index_out_of_range.gltf",
                 "refers to accessor 7, but the file has 2 accessors");
}

TEST_CASE("A required extension the loader cannot read is rejected") {
  check_rejected("draco_required.gltf", "unsupported extension KHR_draco_mesh_compression");
}

TEST_CASE("JSON nested too deeply is rejected before tinygltf recurses into it") {
  check_rejected("deep_json.gltf", "nested deeper than 64 levels");
}

// ---- scene lookup
// --------------------------------------------------------------------------------

TEST_CASE(
    "resolve_scene returns an existing path unchanged and names unknown scenes in its error") {
  CHECK(host::resolve_scene(data_path("triangle.gltf")) == data_path("triangle.gltf"));
  try {
    host::resolve_scene("no-such-scene-anywhere");
    FAIL("expected InputError");
  } catch (const host::InputError& e) {
    CHECK(std::string(e.what()) == "no-such-scene-anywhere: no such file or scene in " +
                                       host::scenes_dir().string() + " (try `vgpu-rt scenes`)");
  }
}

TEST_CASE("list_scenes returns gltf and glb files sorted by name") {
  const auto scenes = host::list_scenes();
  CHECK(std::is_sorted(scenes.begin(), scenes.end()));
  for (const auto& [name, path] : scenes) {
    CHECK((path.ends_with(".gltf") || path.ends_with(".glb")));
    CHECK(host::resolve_scene(name) == path);
  }
}

// ---- camera contract
// -----------------------------------------------------------------------------

TEST_CASE("primary_dir follows the documented pixel-to-ray contract") {
  host::Camera cam;                    // at the origin, looking down -Z, +Y up
  cam.yfov = std::acos(-1.0f) / 2.0f;  // tan(yfov/2) = 1
  // Top-left pixel of a 4x2 image: x' = (2*0.5/4 - 1) * 1 * 2 = -1.5, y' = 1 - 2*0.5/2 = 0.5.
  CHECK_VEC_NEAR(host::primary_dir(cam, 4, 2, 0, 0), glm::normalize(glm::vec3(-1.5f, 0.5f, -1.0f)));
  // Bottom-right pixel mirrors it.
  CHECK_VEC_NEAR(host::primary_dir(cam, 4, 2, 3, 1), glm::normalize(glm::vec3(1.5f, -0.5f, -1.0f)));
  // The centre of the image looks straight ahead.
  CHECK_VEC_NEAR(host::primary_dir(cam, 2, 2, 0.5f, 0.5f), glm::vec3(0, 0, -1));
}

TEST_CASE("frame_bounds sees the whole bounding box with a margin, at any aspect") {
  host::Bounds b;
  b.extend({-1, 0, 2});
  b.extend({3, 1, 4});
  const glm::vec3 centre(1, 0.5f, 3);
  for (float aspect : {0.5f, 1.0f, 2.0f}) {
    INFO("aspect " << aspect);
    const host::Camera cam = host::frame_bounds(b, aspect);
    CHECK(cam.yfov == doctest::Approx(45.0 * std::acos(-1.0) / 180.0));
    CHECK_VEC_NEAR(cam.forward, -glm::normalize(glm::vec3(0, 0.35f, 1)));
    CHECK(glm::dot(cam.up, cam.forward) == doctest::Approx(0.0).epsilon(1e-6));
    CHECK(cam.up.y > 0.0f);
    CHECK_VEC_NEAR(glm::normalize(centre - cam.position), cam.forward);
    // The sphere (radius 1.05 * half diagonal) touches the frustum along its tighter axis.
    const float r = 1.05f * glm::length(b.hi - b.lo) / 2.0f;
    const float t = std::tan(cam.yfov / 2.0f);
    const float half = aspect < 1.0f ? std::atan(t * aspect) : cam.yfov / 2.0f;
    CHECK(glm::length(centre - cam.position) == doctest::Approx(r / std::sin(half)).epsilon(1e-5));
    // Every box corner projects inside the image.
    const glm::vec3 right = glm::normalize(glm::cross(cam.forward, cam.up));
    for (int i = 0; i < 8; ++i) {
      const glm::vec3 corner(i & 1 ? b.hi.x : b.lo.x, i & 2 ? b.hi.y : b.lo.y,
                             i & 4 ? b.hi.z : b.lo.z);
      const glm::vec3 v = corner - cam.position;
      const float depth = glm::dot(v, cam.forward);
      CHECK(std::abs(glm::dot(v, right) / depth) < t * aspect);
      CHECK(std::abs(glm::dot(v, cam.up) / depth) < t);
    }
  }
}

TEST_CASE("An ior below 1, negative, not a number or overflowing is refused, naming the material") {
  check_rejected("glass_ior_below_one.gltf", "material 1: KHR_materials_ior.ior 0.5");
  check_rejected("glass_ior_below_one.gltf", "is below 1");
  check_rejected("glass_ior_negative.gltf", "material 1: KHR_materials_ior.ior -1.5");
  check_rejected("glass_ior_string.gltf", "material 1: KHR_materials_ior.ior is not a number");
  check_rejected("glass_ior_overflow.gltf", "number overflow parsing '1e999'");
}

TEST_CASE("A transmissionFactor outside [0, 1] or not a number is refused, naming the material") {
  check_rejected("glass_transmission_above_one.gltf",
                 "material 1: KHR_materials_transmission.transmissionFactor 1.5");
  check_rejected("glass_transmission_above_one.gltf", "is outside [0, 1]");
  check_rejected("glass_transmission_negative.gltf",
                 "material 1: KHR_materials_transmission.transmissionFactor -0.25");
  check_rejected("glass_transmission_bool.gltf",
                 "material 1: KHR_materials_transmission.transmissionFactor is not a number");
}
