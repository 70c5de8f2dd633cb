// Formats per texture group: parsing --precision / --formats, and --precision auto's choice
// from the scene's integer ranges (see formats.h).
#include "host/model/formats.h"

#include <algorithm>
#include <stdexcept>

namespace host {

using vgpu::Format;

std::string_view group_name(Group g) {
  static constexpr std::string_view names[] = {"rays", "traversal", "voxel",
                                               "hits", "colour",    "queries"};
  return names[size_t(g)];
}

Formats Formats::all(Format f) {
  Formats r;
  r.format.fill(f);
  r.arith.fill(f);
  return r;
}

Format Formats::finest() const {
  Format f = format[0];
  for (const auto& fs : {format, arith})
    for (Format g : fs)
      if (vgpu::significand_bits(g) > vgpu::significand_bits(f)) f = g;
  return f;
}

Format parse_format(std::string_view text, const std::string& what) {
  for (Format f : {Format::fp32, Format::fp24, Format::fp16})
    if (text == vgpu::format_name(f)) return f;
  throw std::invalid_argument(what + ": expected fp32, fp24 or fp16, got '" + std::string(text) +
                              "'");
}

FormatRequest parse_format_request(const std::string& precision, const std::string& formats) {
  FormatRequest r;
  if (precision == "auto")
    r.automatic = true;
  else
    r.all = parse_format(precision, "--precision (or auto)");
  size_t begin = 0;
  while (begin < formats.size()) {
    size_t end = formats.find(',', begin);
    if (end == std::string::npos) end = formats.size();
    const std::string item = formats.substr(begin, end - begin);
    begin = end + 1;
    const size_t eq = item.find('=');
    const std::string name = item.substr(0, eq);
    const auto g = std::find_if(kGroups.begin(), kGroups.end(),
                                [&](Group k) { return group_name(k) == name; });
    if (eq == std::string::npos || g == kGroups.end()) {
      std::string known;
      for (Group k : kGroups) known += (known.empty() ? "" : ", ") + std::string(group_name(k));
      throw std::invalid_argument("--formats: expected GROUP=FORMAT,... with GROUP one of " +
                                  known + ", got '" + item + "'");
    }
    const std::string value = item.substr(eq + 1);
    const size_t slash = value.find('/');
    const Format texels = parse_format(value.substr(0, slash), "--formats " + name);
    r.overrides.set(
        *g, texels,
        slash == std::string::npos
            ? texels
            : parse_format(value.substr(slash + 1), "--formats " + name + " (arithmetic)"));
    r.given[size_t(*g)] = true;
  }
  return r;
}

Formats resolve(const FormatRequest& request, const Scene& scene, const Grid& grid,
                const vgpu::Profile& profile, uint64_t list_entries) {
  Formats f = request.automatic ? auto_formats(scene, grid, profile, list_entries)
                                : Formats::all(request.all);
  for (Group g : kGroups)
    if (request.given[size_t(g)]) {
      f.set(g, request.overrides[g], request.overrides.arithmetic(g));
      f.why[size_t(g)] = "set by --formats";
    }
  return f;
}

Formats resolve(const FormatRequest& request, const Scene& scene, const Accel& accel,
                const vgpu::Profile& profile) {
  if (const Grid* grid = accel.grid()) return resolve(request, scene, *grid, profile);
  // Only the resolution of the grid is read where the list length is given: one voxel.
  const Grid one_voxel;
  return resolve(request, scene, one_voxel, profile, accel.list_entries());
}

IntegerRanges integer_ranges(const Scene& scene, const Grid& grid, uint64_t list_entries) {
  IntegerRanges r;
  r.list_entries = list_entries;
  if (!list_entries) {
    // As the stream tracer lays the lists out: a shared -1, then each non-empty list and its -1.
    uint64_t nonempty = 0;
    for (size_t v = 0; v < grid.voxels(); ++v) nonempty += grid.start[v + 1] > grid.start[v];
    r.list_entries = 1 + grid.tris.size() + nonempty;
  }
  r.triangles = scene.triangle_count();
  r.pointer_texels = uint64_t(grid.res.x) * uint64_t(grid.res.y);
  r.voxels_per_axis = uint64_t(std::max({grid.res.x, grid.res.y, grid.res.z}));
  return r;
}

uint64_t exact_addresses(Format f) {
  return (uint64_t(1) << (vgpu::significand_bits(f) - 1)) - 1;
}

namespace {

// The formats the part has, fewest bits first (NV3x: fp16, fp32; R300: fp24 only). The vgpu
// can emulate fp24 on any part, but auto models no more than the hardware offered.
std::vector<Format> formats_of(const vgpu::Profile& p) {
  std::vector<Format> out;
  if (p.has_fp16 && p.precision != Format::fp16) out.push_back(Format::fp16);
  out.push_back(p.precision);
  return out;
}

std::string name(Format f) {
  return std::string(vgpu::format_name(f));
}

}  // namespace

Formats auto_formats(const Scene& scene, const Grid& grid, const vgpu::Profile& profile,
                     uint64_t list_entries) {
  const IntegerRanges r = integer_ranges(scene, grid, list_entries);
  const std::vector<Format> can = formats_of(profile);
  const Format finest = can.back();
  Formats f = Formats::all(finest);
  const std::string only =
      can.size() == 1 ? "; " + profile.name + " computes only in " + name(finest) : "";
  // Values that decide which triangle is hit: no tolerance (auto keeps fp32's hit ids), so the
  // finest format the part has.
  f.why[size_t(Group::rays)] = "directions and origins decide the hit (no tolerance)" + only;
  f.why[size_t(Group::traversal)] =
      "t where a ray enters its voxel decides the voxel walk (no tolerance)" + only;
  f.why[size_t(Group::hits)] = "t and barycentrics pick the nearest hit (no tolerance)" + only;
  // Voxel state: integers only, each also a texel address (positions in the lists, triangle
  // ids, voxel pointer texels).
  {
    const uint64_t need = std::max(
        {r.list_entries - 1, r.triangles - 1, r.pointer_texels - 1, r.voxels_per_axis - 1});
    const char* what = need == r.list_entries - 1     ? "list positions"
                       : need == r.triangles - 1      ? "triangle ids"
                       : need == r.pointer_texels - 1 ? "voxel pointer texels"
                                                      : "voxel indices";
    Format pick = finest;
    for (Format c : can)
      if (need <= exact_addresses(c)) {
        pick = c;
        break;
      }
    f.set(Group::voxel, pick, pick);
    std::string why = std::string(what) + " reach " + std::to_string(need);
    if (pick != can.front())
      why += "; " + name(can.front()) + " addresses texels exactly only to " +
             std::to_string(exact_addresses(can.front()));
    else
      why += ", within " + name(pick) + "'s exact addresses (to " +
             std::to_string(exact_addresses(pick)) + ")";
    f.why[size_t(Group::voxel)] = why + only;
  }
  // Colour: the shader compares shadow-ray hits with the light's distance, and fp16 arithmetic
  // moves shadow edges (sphere: PSNR 16 dB against fp32), so it computes at full precision. Its
  // texels only hold colour and weights, which fp16 keeps within 1/255 (stated error: one 8-bit
  // step; 2^-11 relative per store, a few stores per bounce, channels below 2).
  f.set(Group::colour, can.front(), finest);
  f.why[size_t(Group::colour)] = can.size() == 1
                                     ? "colour and weights" + only
                                     : "texels hold colour and weights, within 1/255 of fp32 in " +
                                           name(can.front()) +
                                           "; the shader's arithmetic compares shadow hits "
                                           "with the light distance (no tolerance)";
  // The query kernels test only the sign of an integer marker (traversal x = -1 when done, voxel
  // state w = -1 when nothing is left): rounding keeps signs, so any format is exact.
  f.set(Group::queries, can.front(), can.front());
  f.why[size_t(Group::queries)] =
      "query kernels test only the sign of a -1 marker: exact in every format" + only;
  return f;
}

std::string describe(const Formats& f) {
  std::string out;
  for (Group g : kGroups) {
    std::string line = "  " + std::string(group_name(g));
    line.resize(13, ' ');
    line += name(f[g]) + " texels, " + name(f.arithmetic(g)) + " arithmetic";
    if (!f.why[size_t(g)].empty()) line += "  " + f.why[size_t(g)];
    out += line + "\n";
  }
  return out;
}

}  // namespace host
