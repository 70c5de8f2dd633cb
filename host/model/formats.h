// Number formats per group of ray-state textures (--precision, --formats): each group's textures
// are stored in its format and the kernels that write them compute in it. `--precision auto`
// picks, per group, the fewest bits that keep this scene's integers exact and its other values
// within a stated error, and says why.
#pragma once

#include <array>
#include <string>
#include <string_view>

#include "host/accel/accel.h"
#include "host/accel/grid.h"
#include "host/scene/scene.h"
#include "vgpu/profile.h"

namespace host {

// A group: textures (kernels/layout.h) and the kernels writing them.
//   rays       rays, origins (and the hit points written there), shadow rays: generate rays,
//              reflection origin, reflection direction, shadow rays
//   traversal  traversal state: init traversal, reset traversal, traversal
//   voxel      voxel state (list positions, triangle ids): update voxel, next triangle
//   hits       intersection state (t, barycentrics, triangle id): intersections
//   colour     result (colour and ray weight): shader, reflected rays
//   queries    arithmetic only: the occlusion-query kernels rays in grid and rays intersecting
//              (their target, the counter, is fp16 whatever the group says: only the count
//              of surviving fragments matters)
enum class Group { rays, traversal, voxel, hits, colour, queries };
inline constexpr std::array<Group, 6> kGroups = {Group::rays, Group::traversal, Group::voxel,
                                                 Group::hits, Group::colour,    Group::queries};
std::string_view group_name(Group g);

// Per group: the texels' format and the writing kernels' arithmetic (NV3x code often stored half
// and computed float). fp32 everywhere by default. The statistics' "formats" object is written
// from it by the report room (host/report/stats_parts_json.h).
struct Formats {
  std::array<vgpu::Format, kGroups.size()> format{};  // texels
  std::array<vgpu::Format, kGroups.size()> arith{};   // arithmetic of the group's kernels
  std::array<std::string, kGroups.size()> why;        // per group, set by auto_formats
  vgpu::Format& operator[](Group g) { return format[size_t(g)]; }
  vgpu::Format operator[](Group g) const { return format[size_t(g)]; }
  vgpu::Format arithmetic(Group g) const { return arith[size_t(g)]; }
  void set(Group g, vgpu::Format texels, vgpu::Format arithmetic) {
    format[size_t(g)] = texels;
    arith[size_t(g)] = arithmetic;
  }
  static Formats all(vgpu::Format f);
  // The finest format of any group (what the render needs of the part at least somewhere).
  vgpu::Format finest() const;
};

// "fp32", "fp24" or "fp16"; throws std::invalid_argument naming `what` and the known names.
vgpu::Format parse_format(std::string_view text, const std::string& what);

// What the command line asked for: --precision (a format for every group, or auto) and
// --formats (GROUP=FORMAT for texels and arithmetic, or GROUP=TEXELS/ARITHMETIC, on top of it).
// Parsed before any work; resolved once the scene and grid are known.
struct FormatRequest {
  bool automatic = false;
  vgpu::Format all = vgpu::Format::fp32;
  std::array<bool, kGroups.size()> given{};  // groups named by --formats
  Formats overrides;
};
// Throws std::invalid_argument naming the option and the part it cannot parse.
FormatRequest parse_format_request(const std::string& precision, const std::string& formats);
// `list_entries`, when not 0, replaces the grid's list length (another structure's lists: the
// BVH's, host/accel/bvh.h).
Formats resolve(const FormatRequest& request, const Scene& scene, const Grid& grid,
                const vgpu::Profile& profile, uint64_t list_entries = 0);
// The same for the structure walked: the grid's own lists, or another structure's
// (Accel::list_entries) addressed beside the one voxel it reports as its grid.
Formats resolve(const FormatRequest& request, const Scene& scene, const Accel& accel,
                const vgpu::Profile& profile);

// The largest integers each group must hold exactly in this scene and grid.
struct IntegerRanges {
  uint64_t list_entries = 0;    // triangle-list texture entries (positions 0 .. entries - 1)
  uint64_t triangles = 0;       // triangle ids 0 .. triangles - 1
  uint64_t pointer_texels = 0;  // voxel pointer texture width: X * sizeY + Y < res.x * res.y
  uint64_t voxels_per_axis = 0;
};
IntegerRanges integer_ranges(const Scene& scene, const Grid& grid, uint64_t list_entries = 0);
// Integers n the kernels still add a texel centre (+ 1/2) to and address with exactly in format
// f: 0 .. 2^(bits - 1) - 1 (fp16 1023, fp24 65535). Stored alone an integer is exact up to
// 2^bits (fp16 2048, fp24 131072), but every id and position here is also an address.
uint64_t exact_addresses(vgpu::Format f);

// Per group, the fewest bits among the formats the part has (Profile::has_fp16, precision) that
// keep this scene's integers exact, with the reason in Formats::why. Values that decide which
// triangle is hit, or whether a light is shadowed, get no tolerance: auto keeps fp32's hit ids.
Formats auto_formats(const Scene& scene, const Grid& grid, const vgpu::Profile& profile,
                     uint64_t list_entries = 0);

// One line per group: "  voxel      fp32  list positions reach 14373 ...".
std::string describe(const Formats& f);

}  // namespace host
