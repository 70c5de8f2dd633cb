// Numerical-stability cases for the stream tracer: small hand-built scenes whose primary hit ids
// are known in advance. Shared by tests/trace/test_stability.cpp (asserts fp32) and
// bench/stability_report.cpp (fp32 / fp24 / fp16 table in docs/studies/stability.md).
//
// Expected answers are computed here in double, independently of the tracers: per triangle the
// ray/plane intersection and the three edge functions (signed areas) of the hit point, not
// Moller-Trumbore; closed meshes use their shape (L1 ball for the octahedron, polygon for the fan,
// "always" for a camera inside a closed cube). A pixel whose answer is too close to call is
// marked kDontCare instead of being guessed:
//   - a hit point within `margin` (barycentric units) of its triangle's edge, unless another
//     triangle is certainly hit nearer;
//   - two certain hits within 1e-6 relative in t;
//   - a mesh pixel within 1e-3 (relative to the mesh size) of the silhouette.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <string>
#include <vector>

#include "host/accel/grid.h"
#include "host/scene/camera.h"
#include "host/scene/scene.h"
#include "host/trace/cpu/cpu_tracer.h"
#include "host/trace/stream/stream_tracer.h"
#include "tests/support/reference.h"

namespace stability {

constexpr int kMiss = -1;      // the ray must miss everything
constexpr int kAnyMesh = -2;   // the ray must hit some triangle of Case::mesh_ids (no cracks)
constexpr int kDontCare = -3;  // too close to an edge or silhouette to demand one answer

struct Case {
  std::string name;   // doctest-style sentence
  std::string probe;  // what it probes, one line for docs/studies/stability.md
  host::Scene scene;
  host::Camera camera;
  int width = 9, height = 9;
  std::vector<int>
      expected;  // input id per pixel (row-major, y = 0 top), or kMiss/kAnyMesh/kDontCare
  glm::vec3 lo{0.0f}, hi{4.0f};  // grid box (build_grid_in_box): voxel planes at known places
  glm::ivec3 res{4};
  int bounces = 0;
  std::vector<int> mesh_ids;  // for kAnyMesh
  int dominant_channel = -1;  // >= 0: every pixel must have this colour channel dominant
                              // (the reflected wall's), never the mirror's own colour
};

// ---------------------------------------------------------------------------------------------
// Building blocks.

struct Builder {
  host::Scene s;
  uint32_t next_id = 100;
  Builder() { s.materials = {{{0.8f, 0.8f, 0.8f}, 0.0f}}; }
  int tri(glm::vec3 a, glm::vec3 b, glm::vec3 c, uint32_t material = 0) {
    s.add_flat_triangle(a, b, c, material, next_id);
    s.input_triangles = next_id + 1;
    return int(next_id++);
  }
  void quad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, uint32_t material = 0) {
    tri(a, b, c, material);
    tri(a, c, d, material);
  }
};

inline host::Camera look(glm::vec3 pos, glm::vec3 fwd, float yfov, glm::vec3 up = {0, 1, 0}) {
  host::Camera c;
  c.position = pos;
  c.forward = glm::normalize(fwd);
  c.up = glm::normalize(up - glm::dot(up, c.forward) * c.forward);
  c.yfov = yfov;
  return c;
}

// Nearest hit by plane intersection + edge functions, with the don't-care rule above.
// Hits outside the grid box [lo, hi] do not count (the grid lists only the parts of triangles
// inside it); a hit within 1e-6 of the box (relative to its size) is uncertain.
inline int analytic_hit(const host::Scene& s, glm::dvec3 o, glm::dvec3 d, double margin,
                        glm::dvec3 lo, glm::dvec3 hi) {
  struct Cand {
    double t;
    int id;
    bool sure;
  };
  std::vector<Cand> c;
  for (size_t i = 0; i < s.triangle_count(); ++i) {
    const glm::dvec3 a(s.p0[i]), b(s.p1[i]), e(s.p2[i]);
    const glm::dvec3 n = glm::cross(b - a, e - a);
    const double nn = glm::dot(n, n), dn = glm::dot(n, d);
    if (nn == 0 || std::abs(dn) < 1e-12 * std::sqrt(nn) * glm::length(d)) continue;
    const double t = glm::dot(n, a - o) / dn;
    if (t <= 0) continue;
    const glm::dvec3 p = o + t * d;
    const double w0 = glm::dot(n, glm::cross(e - b, p - b)) / nn;  // weight of a
    const double w1 = glm::dot(n, glm::cross(a - e, p - e)) / nn;  // weight of b
    const double w2 = glm::dot(n, glm::cross(b - a, p - a)) / nn;  // weight of e
    const double m = std::min({w0, w1, w2});
    if (m <= -margin) continue;
    double box = std::numeric_limits<double>::infinity();  // signed distance inside the box
    for (int a = 0; a < 3; ++a) box = std::min({box, p[a] - lo[a], hi[a] - p[a]});
    const double box_eps = 1e-6 * glm::length(hi - lo);
    if (box < -box_eps) continue;
    c.push_back({t, int(s.id[i]), m >= margin && box > box_eps});
  }
  std::sort(c.begin(), c.end(), [](const Cand& x, const Cand& y) { return x.t < y.t; });
  for (size_t k = 0; k < c.size(); ++k) {
    if (!c[k].sure) return kDontCare;  // an uncertain hit in front of everything else
    if (k + 1 < c.size() && c[k + 1].t - c[k].t <= 1e-6 * c[k].t) return kDontCare;
    return c[k].id;
  }
  return kMiss;
}

inline std::vector<int> expect_analytic(const Case& c, double margin = 1e-4) {
  std::vector<int> e(size_t(c.width) * c.height);
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x)
      e[size_t(y) * c.width + x] =
          analytic_hit(c.scene, glm::dvec3(c.camera.position),
                       host::cpu_primary_dir(c.camera, c.width, c.height, x, y), margin,
                       glm::dvec3(c.lo), glm::dvec3(c.hi));
  return e;
}

inline Case translated(Case c, float offset, const std::string& suffix) {
  const glm::vec3 t(offset);
  for (auto* v : {&c.scene.p0, &c.scene.p1, &c.scene.p2})
    for (auto& p : *v) p += t;
  for (auto& l : c.scene.lights) l.position += t;
  c.camera.position += t;
  c.lo += t;
  c.hi += t;
  c.name += suffix;
  c.probe += " (translated by " + suffix.substr(suffix.find_last_of(' ') + 1) + ")";
  return c;
}

// Octahedron |x-c|_1 <= r, 8 triangles; edges and vertices on the voxel planes x,y,z = 2.
inline Case octahedron_case() {
  Case c;
  c.name = "a closed octahedron has no cracks along its shared edges and vertices";
  c.probe =
      "closed mesh (octahedron, edges and apex on voxel planes; the centre ray hits the apex)";
  Builder b;
  const glm::vec3 ct(2, 2, 2);
  const float r = 1.5f;
  const glm::vec3 X(r, 0, 0), Y(0, r, 0), Z(0, 0, r);
  for (int sx : {-1, 1})
    for (int sy : {-1, 1})
      for (int sz : {-1, 1})
        c.mesh_ids.push_back(b.tri(ct + float(sx) * X, ct + float(sy) * Y, ct + float(sz) * Z));
  c.scene = b.s;
  c.camera = look({2, 2, 8}, {0, 0, -1}, 0.5f);
  c.width = c.height = 17;
  c.expected.resize(size_t(c.width) * c.height);
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) {
      const glm::dvec3 o = glm::dvec3(c.camera.position) - glm::dvec3(ct);
      const glm::dvec3 d = host::cpu_primary_dir(c.camera, c.width, c.height, x, y);
      double best = std::abs(o.x) + std::abs(o.y) + std::abs(o.z);
      for (int a = 0; a < 3; ++a)
        if (d[a] != 0) {
          const double t = -o[a] / d[a];
          if (t > 0) {
            const glm::dvec3 p = o + t * d;
            best = std::min(best, std::abs(p.x) + std::abs(p.y) + std::abs(p.z));
          }
        }
      c.expected[size_t(y) * c.width + x] = best < r * (1 - 1e-3)   ? kAnyMesh
                                            : best > r * (1 + 1e-3) ? kMiss
                                                                    : kDontCare;
    }
  return c;
}

// Planar quad in the voxel face z = 2, seen from above.
inline Case face_case() {
  Case c;
  c.name = "a quad lying exactly in a voxel face is hit";
  c.probe = "triangles lying in the voxel plane z = 2 (listed in the voxels on both sides)";
  Builder b;
  b.quad({0.5f, 0.5f, 2}, {3.5f, 0.5f, 2}, {3.5f, 3.5f, 2}, {0.5f, 3.5f, 2});
  c.scene = b.s;
  c.camera = look({2.1f, 1.9f, 10}, {0.05f, 0.03f, -1}, 0.6f);
  c.expected = expect_analytic(c);
  return c;
}

// ---------------------------------------------------------------------------------------------

inline std::vector<Case> cases() {
  std::vector<Case> out;

  {  // 1. rays parallel to one axis
    Case c;
    c.name = "rays parallel to one axis hit an axis-aligned quad";
    c.probe = "direction (0,0,-1) exactly for the centre pixel, near-parallel for the others";
    Builder b;
    b.quad({0.5f, 0.5f, 1.5f}, {3.5f, 0.5f, 1.5f}, {3.5f, 3.5f, 1.5f}, {0.5f, 3.5f, 1.5f});
    c.scene = b.s;
    c.camera = look({2.2f, 1.3f, 10}, {0, 0, -1}, 0.02f);
    c.width = c.height = 5;
    c.expected = expect_analytic(c);
    out.push_back(c);
  }
  {  // 2. rays parallel to two axes, lying in a voxel plane
    Case c;
    c.name = "rays parallel to a coordinate plane and lying in the voxel plane y = 2 hit a wall";
    c.probe = "direction with y = 0 exactly, ray inside the voxel plane y = 2";
    Builder b;
    b.tri({0.2f, 0.2f, 0.5f}, {3.8f, 0.2f, 0.5f}, {2, 3.8f, 0.5f});
    c.scene = b.s;
    c.camera = look({-3, 2, 6}, {1, 0, -1}, 0.1f);
    c.width = 9;
    c.height = 1;
    c.expected = expect_analytic(c);
    out.push_back(c);
  }
  {  // 3. along a voxel edge
    Case c;
    c.name = "a ray running along a voxel edge hits the triangle below it";
    c.probe = "centre ray on the line x = y = 2 (edge shared by four voxels)";
    Builder b;
    b.tri({1, 1, 0.5f}, {3.5f, 1, 0.5f}, {1, 3.5f, 0.5f});
    c.scene = b.s;
    c.camera = look({2, 2, 10}, {0, 0, -1}, 1e-3f);
    c.width = c.height = 3;
    c.expected = expect_analytic(c);
    out.push_back(c);
  }
  {  // 4. through voxel corners
    Case c;
    c.name = "a diagonal ray through voxel corners hits the triangle behind them";
    c.probe = "direction (1,1,1) from (-1,-1,-1): passes the corners (0,0,0), (1,1,1), (2,2,2)";
    Builder b;
    b.tri({3.5f, 3.5f, 0.5f}, {3.5f, 0.5f, 3.5f}, {0.5f, 3.5f, 3.5f});
    c.scene = b.s;
    c.camera = look({-1, -1, -1}, {1, 1, 1}, 1e-3f);
    c.width = c.height = 3;
    c.expected = expect_analytic(c);
    out.push_back(c);
  }
  out.push_back(face_case());
  {  // 6. whole-grid triangle
    Case c;
    c.name = "a triangle spanning the whole grid is hit everywhere it is seen";
    c.probe = "one slanted triangle crossing every voxel layer, clipped by the grid box";
    Builder b;
    b.tri({-2, -2, 6}, {8, -2, 1}, {-2, 8, 1});  // plane x + y + 2z = 8, through the grid centre
    c.scene = b.s;
    c.camera = look({2, 2, 12}, {0, 0, -1}, 0.2f);
    c.expected = expect_analytic(c);
    out.push_back(c);
  }
  {  // 7. hit just outside the current voxel
    Case c;
    c.name = "a hit just outside the current voxel is not taken before a nearer one";
    c.probe =
        "slanted triangle listed in the first voxels, hit at z = 1.9; a nearer one at z = 1.95";
    Builder b;
    // plane z = 1.9 + 2 (x - 2.3)
    auto z = [](float x) { return 1.9f + 2 * (x - 2.3f); };
    b.tri({1.5f, 1.0f, z(1.5f)}, {2.95f, 1.0f, z(2.95f)}, {2.2f, 3.9f, z(2.2f)});
    b.tri({1.8f, 2.1f, 1.95f}, {2.8f, 2.1f, 1.95f}, {2.3f, 3.1f, 1.95f});
    c.scene = b.s;
    c.camera = look({2.3f, 2.5f, 10}, {0, 0, -1}, 0.04f);
    c.width = c.height = 5;
    c.expected = expect_analytic(c);
    out.push_back(c);
  }
  out.push_back(octahedron_case());
  {  // 9. fan
    Case c;
    c.name = "a triangle fan has no cracks at its spokes and centre";
    c.probe = "12-triangle fan in z = 1.5, centre vertex on the voxel edge x = y = 2, seen head on";
    Builder b;
    const int n = 12;
    const double r = 1.7, pi = 3.14159265358979323846;
    const glm::vec3 ct(2, 2, 1.5f);
    for (int k = 0; k < n; ++k) {
      const double a0 = 2 * pi * k / n, a1 = 2 * pi * (k + 1) / n;
      c.mesh_ids.push_back(
          b.tri(ct, ct + glm::vec3(float(r * std::cos(a0)), float(r * std::sin(a0)), 0),
                ct + glm::vec3(float(r * std::cos(a1)), float(r * std::sin(a1)), 0)));
    }
    c.scene = b.s;
    c.camera = look({2, 2, 9}, {0, 0, -1}, 0.5f);
    c.width = c.height = 17;
    c.expected.resize(size_t(c.width) * c.height);
    for (int y = 0; y < c.height; ++y)
      for (int x = 0; x < c.width; ++x) {
        const glm::dvec3 o(c.camera.position);
        const glm::dvec3 d = host::cpu_primary_dir(c.camera, c.width, c.height, x, y);
        const glm::dvec3 p = o + (1.5 - o.z) / d.z * d - glm::dvec3(ct);
        double ang = std::atan2(p.y, p.x);
        if (ang < 0) ang += 2 * pi;
        const int k = std::min(n - 1, int(ang / (2 * pi / n)));
        const double mid = (k + 0.5) * 2 * pi / n;
        const double dist = p.x * std::cos(mid) + p.y * std::sin(mid);
        const double apothem = r * std::cos(pi / n);
        c.expected[size_t(y) * c.width + x] = dist < apothem * (1 - 1e-3)   ? kAnyMesh
                                              : dist > apothem * (1 + 1e-3) ? kMiss
                                                                            : kDontCare;
      }
    out.push_back(c);
  }
  {  // 10. grazing
    Case c;
    c.name = "grazing rays hit the floor they skim";
    c.probe = "rays 1 to 3 degrees above a floor quad (y = 1)";
    Builder b;
    b.quad({0.2f, 1, 0.2f}, {0.2f, 1, 3.8f}, {3.8f, 1, 3.8f}, {3.8f, 1, 0.2f});
    c.scene = b.s;
    c.camera = look({-3, 1.15f, 2.1f}, {1, -0.035f, 0}, 0.03f);
    c.expected = expect_analytic(c);
    out.push_back(c);
  }
  {  // 11. mirror / acne
    Case c;
    c.name = "a mirror facing a red wall shows the wall, never itself";
    c.probe = "reflection rays leaving a mirror in the voxel plane z = 1 (self-intersection acne)";
    Builder b;
    b.s.materials = {{{0, 1, 0}, 1.0f}, {{1, 0, 0}, 0.0f}};
    b.quad({0.2f, 0.2f, 1}, {3.8f, 0.2f, 1}, {3.8f, 3.8f, 1}, {0.2f, 3.8f, 1}, 0);  // mirror
    b.quad({0.1f, 0.1f, 3.8f}, {0.1f, 3.9f, 3.8f}, {3.9f, 3.9f, 3.8f}, {3.9f, 0.1f, 3.8f},
           1);  // wall
    b.s.lights = {{{2, 3.5f, 3.4f}, {1, 1, 1}}};
    c.scene = b.s;
    c.camera = look({2.3f, 2.2f, 3.0f}, {0.05f, -0.05f, -1}, 0.35f);
    c.bounces = 1;
    c.dominant_channel = 0;
    c.expected = expect_analytic(c);
    out.push_back(c);
  }
  {  // 12. camera inside a closed cube
    Case c;
    c.name = "a camera inside a closed cube sees a wall in every pixel";
    c.probe = "camera inside the grid, closed cube (12 triangles, shared edges and corners)";
    Builder b;
    const float l = 0.5f, h = 3.5f;
    const glm::vec3 v[8] = {{l, l, l}, {h, l, l}, {h, h, l}, {l, h, l},
                            {l, l, h}, {h, l, h}, {h, h, h}, {l, h, h}};
    const int f[6][4] = {{0, 1, 2, 3}, {4, 7, 6, 5}, {0, 4, 5, 1},
                         {3, 2, 6, 7}, {0, 3, 7, 4}, {1, 5, 6, 2}};
    for (auto& q : f) {
      c.mesh_ids.push_back(b.tri(v[q[0]], v[q[1]], v[q[2]]));
      c.mesh_ids.push_back(b.tri(v[q[0]], v[q[2]], v[q[3]]));
    }
    c.scene = b.s;
    c.camera = look({2, 2, 2}, {1, 1, -1}, 1.4f);
    c.width = c.height = 15;
    c.expected.assign(size_t(c.width) * c.height, kAnyMesh);
    out.push_back(c);
  }
  {  // 13. misses
    Case c;
    c.name = "rays that miss the grid miss";
    c.probe = "rays passing beside the grid box, parallel to its face x = 4";
    Builder b;
    b.quad({0.5f, 0.5f, 2}, {3.5f, 0.5f, 2}, {3.5f, 3.5f, 2}, {0.5f, 3.5f, 2});
    c.scene = b.s;
    c.camera = look({6, 2, 10}, {0, 0, -1}, 0.2f);
    c.expected = expect_analytic(c);
    out.push_back(c);
    c.name = "rays pointing away from the grid miss";
    c.probe = "rays starting outside the grid and pointing away from it";
    c.camera = look({2, 2, 10}, {0, 0.1f, 1}, 0.8f);
    c.expected = expect_analytic(c);
    out.push_back(c);
  }
  for (float off : {1e4f, 1e5f}) {  // 14. far from the origin
    const std::string s = off == 1e4f ? " at 1e4" : " at 1e5";
    Case f = translated(face_case(), off, s);
    f.expected = expect_analytic(f);
    out.push_back(f);
    Case o = translated(octahedron_case(), off, s);  // expected shape is translation invariant
    out.push_back(o);
  }
  {  // 15. thin triangle
    Case c;
    c.name = "a very thin triangle is hit across its width";
    c.probe = "sliver 3 units long, at most 1e-3 wide; rays 1e-4 apart across it";
    Builder b;
    b.tri({0.5f, 2.0f, 2.5f}, {3.5f, 2.0f, 2.5f}, {3.5f, 2.001f, 2.5f});
    c.scene = b.s;
    // at x = 2.75 the sliver spans y in [2, 2.00075]; 9 rows 1e-4 apart centred on 2.000375
    c.camera = look({2.75f, 2.000375f, 10}, {0, 0, -1}, 2 * std::atan(0.00045f / 7.5f));
    c.width = 1;
    c.height = 9;
    c.expected = expect_analytic(c, 2e-2);  // 2e-2 of the width = 1.5e-5 world units
    out.push_back(c);
  }
  {  // 16. huge triangle
    Case c;
    c.name = "a very large triangle behind a small one is hit around it";
    c.probe = "triangle with 4e4-unit edges (clipped to the grid) behind a small triangle";
    Builder b;
    b.tri({-1e4f, -1e4f, 1.2f}, {3e4f, -1e4f, 1.2f}, {-1e4f, 3e4f, 1.2f});
    b.tri({1.2f, 1.2f, 2.5f}, {2.8f, 1.2f, 2.5f}, {2, 2.8f, 2.5f});
    c.scene = b.s;
    c.camera = look({2, 2, 10}, {0, 0, -1}, 0.4f);
    c.expected = expect_analytic(c);
    out.push_back(c);
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Running a case.

struct Outcome {
  int checked = 0;       // pixels with a demanded answer (not kDontCare)
  int wrong = 0;         // of those, wrong hit id
  int colour_wrong = 0;  // dominant-channel failures
  uint64_t unfinished = 0;
  std::vector<int> got;  // input id per pixel
  std::string error;     // non-empty if the tracer threw (e.g. a profile limit)
};

inline host::Grid grid_of(const Case& c) {
  return host::build_grid_in_box(c.scene, c.lo, c.hi, c.res, 1);
}

inline host::RenderOptions options_of(const Case& c, vgpu::Format precision) {
  host::RenderOptions opt;
  opt.width = c.width;
  opt.height = c.height;
  opt.bounces = c.bounces;
  opt.shadows = false;
  opt.shading = kernels::ShadingModel::diffuse;
  opt.threads = 1;
  opt.formats = host::Formats::all(precision);
  return opt;
}

inline bool accepts(const Case& c, int expected, int got) {
  if (expected == kDontCare) return true;
  if (expected == kAnyMesh)
    return std::find(c.mesh_ids.begin(), c.mesh_ids.end(), got) != c.mesh_ids.end();
  return expected == got;
}

inline Outcome run(const Case& c, vgpu::Format precision) {
  Outcome o;
  try {
    const host::Grid grid = grid_of(c);
    host::StreamTracer tracer(c.scene, grid, options_of(c, precision));
    const host::RenderResult r = tracer.render(c.camera);
    o.unfinished = r.rays_unfinished;
    for (size_t i = 0; i < c.expected.size(); ++i) {
      const int got = int(std::lround(r.hit_id[i]));
      o.got.push_back(got);
      if (c.expected[i] == kDontCare) continue;
      ++o.checked;
      if (!accepts(c, c.expected[i], got)) ++o.wrong;
      if (c.dominant_channel >= 0 && got >= 0) {
        const float* p = &r.rgb[3 * i];
        for (int ch = 0; ch < 3; ++ch)
          if (ch != c.dominant_channel &&
              !(p[c.dominant_channel] > 4 * p[ch] && p[c.dominant_channel] > 0)) {
            ++o.colour_wrong;
            break;
          }
      }
    }
  } catch (const std::exception& e) {
    o.error = e.what();
  }
  return o;
}

}  // namespace stability
