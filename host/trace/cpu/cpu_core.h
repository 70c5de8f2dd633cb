// The CPU reference tracer's core (cpu_tracer.h says what it does): the Tracer class, which
// traces one pixel's rays by Whitted's recursion in double precision, and its counters. Private
// to host/trace/cpu: cpu_tracer.cpp renders frames and the sampling modes with it,
// cpu_levels.cpp the ray logs and per-level images that tests and benches read.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <vector>

#include "host/trace/cpu/cpu_beams.h"
#include "host/trace/cpu/cpu_tracer.h"
#include "host/trace/cpu/optics.h"
#include "host/trace/diagonal.h"
#include "host/trace/sampling.h"
#include "host/trace/structures.h"
#include "host/trace/textures.h"
#include "host/trace/walks/bvh_beams.h"
#include "kernels/kernels.h"

namespace host::cpu_core {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A triangle as the intersection test wants it, world space.
struct Tri {
  glm::dvec3 p0, e1, e2;  // corner 0 and the edges to corners 1 and 2
};

struct Hit {
  int64_t tri = -1;               // internal triangle index, -1 = none
  double t = kInf, u = 0, v = 0;  // ray parameter (unit direction: world distance), barycentrics
};

// Per-thread counters, summed at the end; each on its own cache line, so the workers do not
// share one.
struct alignas(64) Counters {
  uint64_t rays = 0, entered = 0, voxel_steps = 0, triangle_tests = 0, nodes_visited = 0,
           restarts = 0, glass_shadow_crossings = 0;
  int iterations = 0;
  // Rays spawned per iteration by kind (index i: spawned by iteration i, traced in i + 1).
  std::vector<uint64_t> reflected, refracted, total_internal;
  void count(std::vector<uint64_t>& kind, int iteration) {
    if (kind.size() <= size_t(iteration)) kind.resize(size_t(iteration) + 1, 0);
    ++kind[size_t(iteration)];
  }
};

// Adds b into a, entry by entry, a growing to b's length.
inline void add_into(std::vector<uint64_t>& a, const std::vector<uint64_t>& b) {
  if (a.size() < b.size()) a.resize(b.size(), 0);
  for (size_t i = 0; i < b.size(); ++i) a[i] += b[i];
}

// Moller-Trumbore, two-sided, closed triangle, t > 0: the kernels' intersect_triangle in double.
inline bool intersect(const glm::dvec3& o, const glm::dvec3& d, const Tri& tri, double& t,
                      double& u, double& v) {
  const glm::dvec3 p = glm::cross(d, tri.e2);
  const double det = glm::dot(tri.e1, p);
  if (det == 0.0) return false;
  const double inv = 1.0 / det;
  const glm::dvec3 s = o - tri.p0;
  u = glm::dot(s, p) * inv;
  if (u < 0.0 || u > 1.0) return false;
  const glm::dvec3 q = glm::cross(s, tri.e1);
  v = glm::dot(d, q) * inv;
  if (v < 0.0 || u + v > 1.0) return false;
  t = glm::dot(tri.e2, q) * inv;
  return t > 0.0;
}

// cpu_primary_dir, with the part that is the same for every pixel (camera basis, tan(yfov / 2),
// aspect) evaluated once per image.
struct PrimaryRays {
  PrimaryRays(const Camera& camera, int width, int height)
      : forward(camera.forward),
        up(camera.up),
        right(glm::normalize(glm::cross(forward, up))),
        t(std::tan(double(camera.yfov) / 2.0)),
        a(double(width) / double(height)),
        W(width),
        H(height) {}

  glm::dvec3 dir(int x, int y) const { return dir(x, y, 0.5, 0.5); }
  // Through the point (jx, jy) of the pixel, in [0, 1)^2 from its top-left corner.
  glm::dvec3 dir(int x, int y, double jx, double jy) const {
    const double sx = (2.0 * (x + jx) / double(W) - 1.0) * t * a;
    const double sy = (1.0 - 2.0 * (y + jy) / double(H)) * t;
    return glm::normalize(forward + sx * right + sy * up);
  }

  glm::dvec3 forward, up, right;
  double t, a;  // tan(yfov / 2), W / H
  int W, H;
};

class Tracer {
 public:
  Tracer(const Scene& scene, const Accel& accel, const Camera& camera, const RenderOptions& opt)
      : scene_(scene), cam_(camera), opt_(opt), primary_(camera, opt.width, opt.height) {
    tris_.reserve(scene.triangle_count());
    geo_normals_.reserve(scene.triangle_count());
    for (size_t i = 0; i < scene.triangle_count(); ++i) {
      const glm::dvec3 p0(scene.p0[i]);
      const Tri& tri =
          tris_.emplace_back(Tri{p0, glm::dvec3(scene.p1[i]) - p0, glm::dvec3(scene.p2[i]) - p0});
      geo_normals_.push_back(glm::normalize(glm::cross(tri.e1, tri.e2)));
    }
    const Bounds& box = accel.box();
    const double diag = glm::length(glm::dvec3(box.hi) - glm::dvec3(box.lo));
    slack_ = kSlackOfDiagonal * diag;
    offset_ = kOffsetOfDiagonal * diag;
    atten_dist_ = kAttenOfDiagonal * diag;
    iterations_ = 1 + std::max(0, opt.bounces);
    const kernels::Shader shader;
    ambient_ = glm::dvec3(shader.ambient);
    background_ = glm::dvec3(shader.background);
    specular_ = shader.specular;
    min_weight_ = kernels::ReflectedRays{}.min_weight;
    for (const SceneTexture& t : scene.textures) chains_.push_back(build_mip_chain(t));
    for (const Material& m : scene.materials) has_glass_ = has_glass_ || m.transmission > 0.0f;
    spread_ = 2.0 * primary_.t / double(opt.height);
    // The structure's CPU walk, its row's (host/trace/structures.h): its structure and beams.
    const CpuWalk& walk = walk_row(accel.kind()).cpu;
    (this->*walk.start)(accel, camera, opt);
    walk_ = walk.trace;
  }

  // The CPU walks' starts (their rows' CpuWalk::start): each takes its structure from `accel`
  // and makes its beams over tiles where --beams on: for the uniform grid's walk, the two-level
  // grid's (marched over its coarse grid), the BVH's and the kd-tree's (through its nodes' boxes).
  void start_grid(const Accel& accel, const Camera& camera, const RenderOptions& opt) {
    grid_ = &walked(accel.grid(), accel);
    for (int a = 0; a < 3; ++a) {  // the grid walk's box: its outer voxel planes
      box_lo_[a] = grid_->boundary(a, 0);
      box_hi_[a] = grid_->boundary(a, grid_->res[a]);
    }
    if (opt.beams) beams_ = std::make_unique<CpuBeams>(*grid_, camera, opt);
  }
  void start_grid2(const Accel& accel, const Camera& camera, const RenderOptions& opt) {
    grid2_ = &walked(accel.grid2(), accel);
    if (opt.beams) beams_ = std::make_unique<CpuBeams>(grid2_->coarse, camera, opt);
  }
  void start_bvh(const Accel& accel, const Camera& camera, const RenderOptions& opt) {
    bvh_ = &walked(accel.bvh(), accel);
    if (opt.beams) bvh_beams_ = std::make_unique<CpuBvhBeams>(*bvh_, camera, opt);
  }
  void start_kd(const Accel& accel, const Camera& camera, const RenderOptions& opt) {
    kd_ = &walked(accel.kd(), accel);
    if (opt.beams) bvh_beams_ = std::make_unique<CpuBvhBeams>(kd_beam_nodes(*kd_), camera, opt);
  }

  // What the frame's beams cost (nothing where beams are off).
  std::optional<CpuBeamCounts> beam_counts() const {
    if (beams_) return beams_->counts();
    if (bvh_beams_) return bvh_beams_->counts();
    return std::nullopt;
  }
  // Where the primary ray of pixel (x, y) through point j of it starts (null: beams are off).
  const CpuBeamStart* beam_start(int x, int y, glm::vec2 j, CpuBeamStart& s) const {
    if (beams_)
      s = beams_->start(x, y, j);
    else if (bvh_beams_)
      s = bvh_beams_->start(x, y, j);
    else
      return nullptr;
    return &s;
  }

  // The base-colour texel of hit h of the ray o + t d, as kernels/base_color.h filters it: the
  // corners' coordinates interpolated, the level of detail from the ray's differentials.
  glm::dvec4 base_texel(const Hit& h, const glm::dvec3& d, int texture) const {
    const size_t k = size_t(h.tri);
    const glm::dvec2 uv0(scene_.uv0[k]), uv1(scene_.uv1[k]), uv2(scene_.uv2[k]);
    const glm::dvec2 d1 = uv1 - uv0, d2 = uv2 - uv0;
    const glm::dvec2 uv = uv0 + d1 * h.u + d2 * h.v;
    const MipChain& chain = chains_[size_t(texture)];
    const SceneTexture& tex = scene_.textures[size_t(texture)];
    double rho = 0.0;
    if (opt_.texture_filter == vgpu::Filter::trilinear) {
      const Tri& tri = tris_[k];
      const glm::dvec3 ng = geo_normals_[k];
      const double d00 = glm::dot(tri.e1, tri.e1), d01 = glm::dot(tri.e1, tri.e2),
                   d11 = glm::dot(tri.e2, tri.e2);
      const double inv = 1.0 / (d00 * d11 - d01 * d01);
      const glm::dvec2 size(chain.levels[0].width, chain.levels[0].height);
      double rho2 = 0.0;
      for (const glm::dvec3& axis : {primary_.right, primary_.up}) {
        const glm::dvec3 w = (axis - d * glm::dot(axis, d)) * (h.t * spread_);
        const glm::dvec3 dp = w - d * (glm::dot(w, ng) / glm::dot(d, ng));
        const double q1 = glm::dot(dp, tri.e1), q2 = glm::dot(dp, tri.e2);
        const double db1 = (d11 * q1 - d01 * q2) * inv, db2 = (d00 * q2 - d01 * q1) * inv;
        const glm::dvec2 step = (d1 * db1 + d2 * db2) * size;
        rho2 = std::max(rho2, glm::dot(step, step));
      }
      rho = std::sqrt(rho2);
    }
    return sample_chain(chain, tex.wrap_s, tex.wrap_t, opt_.texture_filter, uv.x, uv.y, rho);
  }

  // The nearest valid hit along o + t d, 0 < t < tmax (d unit, world space). any_hit: stop at
  // the first valid hit (shadow rays only need to know whether one exists). `beam` (a primary
  // ray's, with beams over tiles): the whole tile misses, or the walk may start further on.
  Hit trace(const glm::dvec3& o, const glm::dvec3& d, double tmax, bool any_hit, Counters& c,
            const CpuBeamStart* beam = nullptr) const {
    ++c.rays;
    return (this->*walk_)(o, d, tmax, any_hit, c, beam);
  }

  // The uniform grid's walk (Amanatides & Woo, the paper's) in double: every triangle of each
  // voxel the ray crosses, a hit counting only inside its voxel (with the slack). `beam` (a
  // primary ray's, beams over tiles): the whole tile misses, or the walk may start further on.
  Hit trace_grid(const glm::dvec3& o, const glm::dvec3& d, double tmax, bool any_hit, Counters& c,
                 const CpuBeamStart* beam) const {
    Hit best;
    // Slab test against the grid box.
    double tnear = 0.0, tfar = tmax;
    for (int a = 0; a < 3; ++a) {
      if (d[a] == 0.0) {
        if (o[a] < box_lo_[a] || o[a] > box_hi_[a]) return best;
        continue;
      }
      double t0 = (box_lo_[a] - o[a]) / d[a], t1 = (box_hi_[a] - o[a]) / d[a];
      if (t0 > t1) std::swap(t0, t1);
      tnear = std::max(tnear, t0);
      tfar = std::min(tfar, t1);
    }
    if (!(tnear <= tfar)) return best;
    ++c.entered;
    if (beam && beam->missed) return best;  // its tile's beam left the grid box behind

    // Amanatides & Woo set-up: the entry voxel, the t of the next boundary per axis, and the t
    // between two boundaries per axis.
    glm::ivec3 vox = grid_->voxel_of(o + d * tnear);
    glm::ivec3 step(0);
    glm::dvec3 t_next(kInf), t_delta(kInf);
    for (int a = 0; a < 3; ++a) {
      if (d[a] > 0.0) {
        step[a] = 1;
        t_next[a] = (grid_->boundary(a, vox[a] + 1) - o[a]) / d[a];
        t_delta[a] = double(grid_->cell[a]) / d[a];
      } else if (d[a] < 0.0) {
        step[a] = -1;
        t_next[a] = (grid_->boundary(a, vox[a]) - o[a]) / d[a];
        t_delta[a] = -double(grid_->cell[a]) / d[a];
      }
    }

    double t_enter = tnear;
    // Start where the tile's beam stopped: the walk's own state there, or at the entry.
    if (beam) cpu_dda_skip(*grid_, o, d, double(beam->t), vox, step, t_next, t_delta, t_enter);
    for (;;) {
      ++c.voxel_steps;
      const double t_exit = std::min({t_next.x, t_next.y, t_next.z});
      // Every triangle of the voxel; a hit counts only inside the voxel (with the slack).
      for (const uint32_t k : grid_->triangles_in(grid_->index(vox))) {
        ++c.triangle_tests;
        double t, u, v;
        if (!intersect(o, d, tris_[k], t, u, v)) continue;
        if (t < t_enter - slack_ || t > t_exit + slack_ || !(t < tmax) || !(t < best.t)) continue;
        best = Hit{int64_t(k), t, u, v};
        if (any_hit) return best;
      }
      if (best.tri >= 0) return best;
      // Next voxel: every axis tied at the exit steps at once (an edge or corner crossing).
      bool outside = false;
      for (int a = 0; a < 3; ++a) {
        if (t_next[a] != t_exit) continue;
        vox[a] += step[a];
        t_next[a] += t_delta[a];
        outside = outside || vox[a] < 0 || vox[a] >= grid_->res[a];
      }
      if (outside) return best;
      t_enter = t_exit;
      if (t_enter - slack_ >= tmax) return best;  // nothing left can pass t < tmax
    }
  }

  // The colour through point (jx, jy) of pixel (x, y), in [0, 1)^2 from its top-left corner.
  glm::dvec3 sample(int x, int y, glm::vec2 j, Hit* primary, Counters& c,
                    Hit* reflected = nullptr) const {
    CpuBeamStart s;
    return radiance(glm::dvec3(cam_.position), primary_.dir(x, y, j.x, j.y), 0, 1.0, primary, c,
                    CpuRayKind::primary, reflected, beam_start(x, y, j, s));
  }
  // The centre ray of pixel (x, y) for adaptive sampling and undersampling: its colour; its
  // hit's depth and input id into the AOVs; in `key`, the material its triangle has, -1 for a
  // miss (guardarImpactos' surface key); in `reflected_key` (if given), its opaque surface's
  // reflected ray's (guardarReflejos: -1 for a miss or no reflected ray).
  glm::dvec3 centre(int x, int y, RenderResult& out, int& key, Counters& c,
                    int* reflected_key = nullptr) const {
    const size_t i = size_t(y) * size_t(opt_.width) + size_t(x);
    Hit h, r;
    const glm::dvec3 colour = sample(x, y, {0.5f, 0.5f}, &h, c, reflected_key ? &r : nullptr);
    key = h.tri < 0 ? -1 : int(scene_.material[size_t(h.tri)]);
    if (reflected_key) *reflected_key = r.tri < 0 ? -1 : int(scene_.material[size_t(r.tri)]);
    if (h.tri >= 0) {
      out.depth[i] = float(h.t);
      out.hit_id[i] = float(scene_.id[size_t(h.tri)]);
    }
    return colour;
  }

  // One pixel: the primary ray and, recursively, its reflections.
  void pixel(int x, int y, RenderResult& out, Counters& c) const {
    const size_t idx = size_t(y) * size_t(opt_.width) + size_t(x);
    Hit primary;
    glm::dvec3 colour(0.0);
    CpuBeamStart s;
    if (opt_.spp <= 1) {
      colour = radiance(glm::dvec3(cam_.position), primary_.dir(x, y), 0, 1.0, &primary, c,
                        CpuRayKind::primary, nullptr, beam_start(x, y, {0.5f, 0.5f}, s));
    } else {
      // The stream tracer's sample positions; the AOVs are the first sample's, as there.
      for (int k = 0; k < opt_.spp; ++k) {
        const glm::vec2 j = sample_offset(opt_.spp, k, opt_.sample_seed);
        colour += radiance(glm::dvec3(cam_.position), primary_.dir(x, y, j.x, j.y), 0, 1.0,
                           k == 0 ? &primary : nullptr, c, CpuRayKind::primary, nullptr,
                           beam_start(x, y, j, s));
      }
      colour /= double(opt_.spp);
    }
    if (primary.tri >= 0) {
      out.depth[idx] = float(primary.t);
      out.hit_id[idx] = float(scene_.id[size_t(primary.tri)]);
    }
    for (int ch = 0; ch < 3; ++ch) out.rgb[idx * 3 + size_t(ch)] = float(colour[ch]);
  }

  // Whitted's recursion: the colour seen along o + t d (d unit) by the surface `depth` (0-based)
  // of the tree, whose weight in the final colour is w. Opaque: returns (1 - a) C + a L_reflected,
  // so the primary call returns the paper's sum_i w_i (1 - a_i) C_i. Glass (t > 0, the model of
  // docs/studies/materials.md):
  //   (1 - t)(1 - a) C + ((1 - t) a + t F) L_reflected + t (1 - F) L_refracted.
  // A ray is spawned only if its weight is at least 1/512 and the path has fewer than 1 + bounces
  // surfaces, as rayosReflejados does; `kind` is what spawned this one (cpu_ray_tree's log).
  // `reflected_out` (if given) gets an opaque surface's reflected ray's hit (tri -1: none);
  // `beam` (a primary ray's): where its walk may start (trace).
  glm::dvec3 radiance(const glm::dvec3& o, const glm::dvec3& d, int depth, double w, Hit* hit_out,
                      Counters& c, CpuRayKind kind = CpuRayKind::primary,
                      Hit* reflected_out = nullptr, const CpuBeamStart* beam = nullptr) const {
    c.iterations = std::max(c.iterations, depth + 1);
    const Hit h = trace(o, d, kInf, false, c, beam);
    if (hit_out) *hit_out = h;
    const size_t logged = log_ ? log_->size() : 0;
    if (log_) log_->push_back(CpuRay{depth, kind, o, d, w, h.tri, h.t, 1.0});
    if (h.tri < 0) return background_;
    const size_t k = size_t(h.tri);
    const glm::dvec3 p = o + d * h.t;  // world space, on the surface
    glm::dvec3 ng = geo_normals_[k];
    if (glm::dot(ng, d) > 0.0) ng = -ng;
    const glm::dvec3 lifted = p + ng * offset_;  // origin of the shadow and reflected rays
    glm::dvec3 n = glm::dvec3(scene_.n0[k]) * (1.0 - h.u - h.v) + glm::dvec3(scene_.n1[k]) * h.u +
                   glm::dvec3(scene_.n2[k]) * h.v;
    const double len = glm::length(n);
    n = len > 0.0 ? n / len : ng;
    if (glm::dot(n, d) > 0.0) n = -n;

    const Material& mat = scene_.materials[scene_.material[k]];
    glm::dvec3 kd(mat.color);
    if (mat.texture >= 0) kd *= glm::dvec3(base_texel(h, d, mat.texture));
    glm::dvec3 local = kd * ambient_;
    // The share of w the surface's own shading gets, known before the lights so that a clear
    // glass (t = 1, share 0) casts no shadow rays.
    const double tr = mat.transmission;
    const double a = mat.reflect;
    const double local_share = tr > 0.0 ? (1.0 - tr) * (1.0 - a) : 1.0 - a;
    if (log_) (*log_)[logged].local_share = local_share;
    for (const PointLight& light : scene_.lights) {
      if (tr > 0.0 && local_share == 0.0) break;
      const glm::dvec3 lp(light.position);
      double through = 1.0;  // the share of the light that reaches p past glass
      if (opt_.shadows) {
        through = light_through(lifted, lp, c);
        if (through == 0.0) continue;
      }
      const glm::dvec3 to = lp - p;
      const double dist = glm::length(to);
      const glm::dvec3 l = to / dist;
      glm::dvec3 lit = kd * std::max(glm::dot(n, l), 0.0);
      if (opt_.shading != kernels::ShadingModel::diffuse) {
        const glm::dvec3 r = glm::reflect(l, n);          // mirror of l, pointing away
        const double rv = std::max(glm::dot(r, d), 0.0);  // = max(r'.v, 0), v = -d
        lit += glm::dvec3(specular_ * std::pow(rv, 32.0));
      }
      if (opt_.shading == kernels::ShadingModel::phong_atten) {
        const double q = dist / atten_dist_;
        lit /= 1.0 + q * q;
      }
      local += lit * glm::dvec3(light.color) * through;  // x 1 is exact: opaque scenes unchanged
    }

    if (tr <= 0.0) {  // opaque: the paper's model, in the paper's arithmetic
      glm::dvec3 colour = local * (1.0 - a);
      if (w * a >= min_weight_ && depth + 1 < iterations_) {
        const glm::dvec3 r = glm::normalize(glm::reflect(d, n));
        c.count(c.reflected, depth);
        colour +=
            a * radiance(lifted, r, depth + 1, w * a, reflected_out, c, CpuRayKind::reflected);
      }
      return colour;
    }

    // Glass (docs/studies/materials.md): entering when d meets the front of the triangle's winding.
    const bool entering = glm::dot(d, geo_normals_[k]) < 0.0;
    const double e = entering ? 1.0 / double(mat.ior) : double(mat.ior);
    const optics::Interface f = optics::meet(d, n, e);
    const double reflect_share = (1.0 - tr) * a + tr * f.reflectance;
    const double refract_share = tr * (1.0 - f.reflectance);
    glm::dvec3 colour = local * local_share;
    if (depth + 1 < iterations_) {
      if (reflect_share > 0.0 && w * reflect_share >= min_weight_) {
        const glm::dvec3 r = glm::normalize(glm::reflect(d, n));
        // Past the critical angle the reflected ray is a totally internally reflected one.
        const bool tir = f.total;
        c.count(c.reflected, depth);
        if (tir) c.count(c.total_internal, depth);
        colour +=
            reflect_share * radiance(lifted, r, depth + 1, w * reflect_share, nullptr, c,
                                     tir ? CpuRayKind::total_internal : CpuRayKind::reflected);
      }
      if (refract_share > 0.0 && w * refract_share >= min_weight_) {
        const glm::dvec3 r = optics::refract(d, n, e, f);
        c.count(c.refracted, depth);
        colour += refract_share * radiance(p - ng * offset_, r, depth + 1, w * refract_share,
                                           nullptr, c, CpuRayKind::refracted);
      }
    }
    return colour;
  }

  // The share of a light at lp that reaches `from` (the lifted hit point): 0 behind an opaque
  // surface, the product of the transmissions of the glass surfaces between (no caustics:
  // refraction does not bend the shadow ray), 0 past more than kMaxGlassCrossings of them.
  double light_through(const glm::dvec3& from, const glm::dvec3& lp, Counters& c) const {
    const glm::dvec3 to_light = lp - from;
    double dist = glm::length(to_light);
    const glm::dvec3 ds = to_light / dist;
    // Without glass any hit blocks, so the first one found will do.
    if (!has_glass_) return trace(from, ds, dist, true, c).tri >= 0 ? 0.0 : 1.0;
    double through = 1.0;
    glm::dvec3 o = from;
    for (int crossed = 0;; ++crossed) {
      const Hit h = trace(o, ds, dist, false, c);  // the nearest: the crossings go in order
      if (h.tri < 0) return through;
      const double t = scene_.materials[scene_.material[size_t(h.tri)]].transmission;
      if (t <= 0.0 || crossed == kMaxGlassCrossings) return 0.0;
      ++c.glass_shadow_crossings;
      through *= t;
      o += ds * (h.t + offset_);  // p + d_s ε, on along the same line
      dist -= h.t + offset_;
      if (!(dist > 0.0)) return through;
    }
  }

  // Where radiance() writes every ray it traces (cpu_ray_tree), or null.
  std::vector<CpuRay>* log_ = nullptr;

  // The stackless BVH walk (kernels/bvh.h) in double: every node in depth-first order whose
  // padded box the ray meets before the nearest hit so far, its escape otherwise. `beam` (a
  // primary ray's, beams through the BVH): only its tile's node's subtree, or nothing where the
  // whole tile misses.
  Hit trace_bvh(const glm::dvec3& o, const glm::dvec3& d, double tmax, bool any_hit, Counters& c,
                const CpuBeamStart* beam) const {
    Hit best;
    if (!(tmax >= 0.0)) return best;
    ++c.entered;
    if (beam && beam->missed) return best;  // its tile's beam missed the root's box
    const std::vector<BvhNode>& nodes = bvh_->nodes;
    const int32_t count = beam ? std::min(beam->end, int32_t(nodes.size())) : int32_t(nodes.size());
    for (int32_t i = beam ? beam->node : 0; i >= 0 && i < count;) {
      ++c.nodes_visited;
      const BvhNode& n = nodes[size_t(i)];
      double tn = 0.0, tf = std::min(best.t, tmax);
      for (int a = 0; a < 3 && tn <= tf; ++a) {
        if (d[a] == 0.0) {
          if (o[a] < n.lo[a] || o[a] > n.hi[a]) tf = -kInf;
          continue;
        }
        double t0 = (double(n.lo[a]) - o[a]) / d[a], t1 = (double(n.hi[a]) - o[a]) / d[a];
        if (t0 > t1) std::swap(t0, t1);
        tn = std::max(tn, t0);
        tf = std::min(tf, t1);
      }
      if (!(tn <= tf)) {
        i = n.escape;
        continue;
      }
      if (n.count == 0 && n.leaf < 0) {
        ++i;
        continue;
      }
      for (int32_t k = n.leaf; k >= 0 && bvh_->lists[size_t(k)] >= 0; ++k) {
        const auto tri = size_t(bvh_->lists[size_t(k)]);
        ++c.triangle_tests;
        double t, u, v;
        if (!intersect(o, d, tris_[tri], t, u, v)) continue;
        if (!(t < tmax) || !(t < best.t)) continue;
        best = Hit{int64_t(tri), t, u, v};
        if (any_hit) return best;
      }
      i = n.escape;
    }
    return best;
  }

  // kd-restart (kernels/kdtree.h) in double: descend to the first leaf the segment reaches, test
  // its triangles with the in-leaf rule (the segment widened by the slack), restart past it.
  // `beam` (a primary ray's, beams through the kd-tree): start and restart at its tile's node,
  // or nothing where the whole tile misses.
  Hit trace_kd(const glm::dvec3& o, const glm::dvec3& d, double tmax, bool any_hit, Counters& c,
               const CpuBeamStart* beam) const {
    Hit best;
    if (!(tmax >= 0.0)) return best;
    double tn = 0.0, tend = tmax;
    for (int a = 0; a < 3; ++a) {
      if (d[a] == 0.0) {
        if (o[a] < kd_->lo[a] || o[a] > kd_->hi[a]) return best;
        continue;
      }
      double t0 = (double(kd_->lo[a]) - o[a]) / d[a], t1 = (double(kd_->hi[a]) - o[a]) / d[a];
      if (t0 > t1) std::swap(t0, t1);
      tn = std::max(tn, t0);
      tend = std::min(tend, t1);
    }
    if (!(tn <= tend) || (beam && beam->missed)) return best;
    ++c.entered;
    double tmin = tn, tmx = tend;
    const int32_t root = beam ? beam->node : 0;
    int32_t i = root;
    for (;;) {
      ++c.nodes_visited;
      const KdNode& n = kd_->nodes[size_t(i)];
      if (n.axis == 3) {
        for (int32_t k = n.leaf; kd_->lists[size_t(k)] >= 0; ++k) {
          const auto tri = size_t(kd_->lists[size_t(k)]);
          ++c.triangle_tests;
          double t, u, v;
          if (!intersect(o, d, tris_[tri], t, u, v)) continue;
          if (t < tmin - slack_ || t > tmx + slack_ || !(t < tmax) || !(t < best.t)) continue;
          best = Hit{int64_t(tri), t, u, v};
          if (any_hit) return best;
        }
        if (best.tri >= 0 || tmx >= tend) return best;
        ++c.restarts;
        tmin = tmx;
        tmx = tend;
        i = root;
        continue;
      }
      const int a = n.axis;
      const double s = double(n.split);
      const double ts = (s - o[a]) / d[a];
      const bool below = o[a] < s || (o[a] == s && d[a] <= 0.0);
      const int32_t near = below ? i + 1 : n.right, far = below ? n.right : i + 1;
      const bool near_only = d[a] == 0.0 || ts >= tmx || ts <= 0.0;
      if (!near_only && ts <= tmin) {
        i = far;
      } else {
        i = near;
        if (!near_only) tmx = ts;
      }
    }
  }

  // The two-level grid (kernels/grid2.h) in double: the sub-cell of coarse cell c (Grid::index)
  // holding coordinate x along `axis`, half-open slabs, clamped to the sub-grid.
  int grid2_sub_of(size_t c, int axis, double x) const {
    const int last = grid2_->sub_res[c][axis] - 1;
    const double f =
        std::floor((x - double(grid2_->sub_lo[c][axis])) / double(grid2_->sub_cell[c][axis]));
    int i = std::isnan(f) ? 0 : int(std::clamp(f, 0.0, double(last)));
    while (i > 0 && x < grid2_->sub_boundary(c, axis, i)) --i;
    while (i < last && x >= grid2_->sub_boundary(c, axis, i + 1)) ++i;
    return i;
  }

  // Moves the two-level walk on from its entry (coarse cell cc, sub-cell s, entered at t_enter)
  // to the state it reaches in the coarse cell holding o + d ts, bit for bit, as the beam entry
  // does in float (kernels/grid2_beams.h says why it is the walk's own): every coarse cell before
  // it is empty, a one-cell sub-grid whose far face along an axis depends on its coordinate
  // there alone, so the walk crosses each axis's faces in order of t. Returns false (the state
  // untouched) where the checks fail or nothing would be skipped.
  bool grid2_skip(const glm::dvec3& o, const glm::dvec3& d, double ts, glm::ivec3& cc, size_t& ci,
                  glm::ivec3& s, double& t_enter) const {
    if (!(ts > t_enter)) return false;
    const Grid& g = grid2_->coarse;
    // The far face along `a` of an empty coarse cell at coordinate k there, as the walk computes
    // it (Grid2::sub_boundary of its one sub-cell: its box minimum, plus its size going up).
    auto face = [&](int a, int k) {
      const double lo = double(float(g.boundary(a, k)));
      return (lo + (d[a] > 0.0 ? double(g.cell[a]) : 0.0) - o[a]) / d[a];
    };
    glm::ivec3 v(0);
    glm::dvec3 into(-kInf);
    double te = -kInf, next = kInf;
    for (int a = 0; a < 3; ++a) {
      const double f = std::floor((o[a] + d[a] * ts - double(g.lo[a])) / double(g.cell[a]));
      if (!(f >= 0.0 && f < double(g.res[a]))) return false;
      v[a] = int(f);
      if (d[a] == 0.0) {
        if (v[a] != cc[a]) return false;
        continue;
      }
      const int dir = d[a] > 0.0 ? 1 : -1;
      if ((v[a] - cc[a]) * dir < 0) return false;
      if (v[a] != cc[a]) te = std::max(te, into[a] = face(a, v[a] - dir));
      next = std::min(next, face(a, v[a]));
    }
    if (!(te > t_enter) || !(te < next) || !(te <= ts)) return false;
    cc = v;
    ci = g.index(cc);
    for (int a = 0; a < 3; ++a)
      s[a] = into[a] == te ? (d[a] > 0.0 ? 0 : grid2_->sub_res[ci][a] - 1)
                           : grid2_sub_of(ci, a, o[a] + d[a] * te);
    t_enter = te;
    return true;
  }

  // The walk of kernels/grid2.h: each sub-cell's triangles with the in-cell rule (its segment
  // widened by the slack), then the next sub-cell; leaving the sub-grid steps the coarse grid
  // and enters the next cell's sub-grid on the face crossed. `beam` (a primary ray's, beams over
  // the coarse grid): the whole tile misses, or the walk may start further on.
  Hit trace_grid2(const glm::dvec3& o, const glm::dvec3& d, double tmax, bool any_hit, Counters& c,
                  const CpuBeamStart* beam) const {
    Hit best;
    const Grid& g = grid2_->coarse;
    double tnear = 0.0, tfar = tmax;
    for (int a = 0; a < 3; ++a) {
      const double lo = g.boundary(a, 0), hi = g.boundary(a, g.res[a]);
      if (d[a] == 0.0) {
        if (o[a] < lo || o[a] > hi) return best;
        continue;
      }
      double t0 = (lo - o[a]) / d[a], t1 = (hi - o[a]) / d[a];
      if (t0 > t1) std::swap(t0, t1);
      tnear = std::max(tnear, t0);
      tfar = std::min(tfar, t1);
    }
    if (!(tnear <= tfar) || !(tmax >= 0.0)) return best;
    ++c.entered;
    if (beam && beam->missed) return best;  // its tile's beam left the grid box behind
    glm::ivec3 cc = g.voxel_of(o + d * tnear);
    size_t ci = g.index(cc);
    glm::ivec3 s;
    for (int a = 0; a < 3; ++a) s[a] = grid2_sub_of(ci, a, o[a] + d[a] * tnear);
    double t_enter = tnear;
    if (beam) grid2_skip(o, d, double(beam->t), cc, ci, s, t_enter);
    for (;;) {
      ++c.voxel_steps;
      const glm::ivec3 r = grid2_->sub_res[ci];
      glm::dvec3 exits(kInf);
      for (int a = 0; a < 3; ++a)
        if (d[a] != 0.0)
          exits[a] = (grid2_->sub_boundary(ci, a, s[a] + (d[a] > 0.0 ? 1 : 0)) - o[a]) / d[a];
      const double t_exit = std::min({exits.x, exits.y, exits.z});
      const size_t k = grid2_->first[ci] + size_t((s.z * r.y + s.y) * r.x + s.x);
      for (int32_t e = grid2_->list_start[k]; grid2_->lists[size_t(e)] >= 0; ++e) {
        const auto tri = size_t(grid2_->lists[size_t(e)]);
        ++c.triangle_tests;
        double t, u, v;
        if (!intersect(o, d, tris_[tri], t, u, v)) continue;
        if (t < t_enter - slack_ || t > t_exit + slack_ || !(t < tmax) || !(t < best.t)) continue;
        best = Hit{int64_t(tri), t, u, v};
        if (any_hit) return best;
      }
      if (best.tri >= 0) return best;
      // Every axis tied at the exit steps; those leaving the sub-grid step the coarse grid.
      glm::ivec3 st(0);
      bool leaving[3] = {false, false, false}, any_leaving = false;
      for (int a = 0; a < 3; ++a) {
        if (exits[a] != t_exit) continue;
        st[a] = d[a] > 0.0 ? 1 : -1;
        s[a] += st[a];
        if (s[a] < 0 || s[a] >= r[a]) {
          leaving[a] = any_leaving = true;
          cc[a] += st[a];
          if (cc[a] < 0 || cc[a] >= g.res[a]) return best;
        }
      }
      if (any_leaving) {
        ci = g.index(cc);
        for (int a = 0; a < 3; ++a)
          s[a] = leaving[a] ? (st[a] > 0 ? 0 : grid2_->sub_res[ci][a] - 1)
                            : grid2_sub_of(ci, a, o[a] + d[a] * t_exit);
      }
      t_enter = t_exit;
      if (t_enter - slack_ >= tmax) return best;  // nothing left can pass t < tmax
    }
  }

 private:
  const Scene& scene_;
  const Grid* grid_ = nullptr;  // the uniform grid, when it is the structure walked
  const Bvh* bvh_ = nullptr;
  const KdTree* kd_ = nullptr;
  const Grid2* grid2_ = nullptr;
  // Its row's CpuWalk::trace: trace_grid, trace_grid2, trace_bvh or trace_kd.
  Hit (Tracer::*walk_)(const glm::dvec3&, const glm::dvec3&, double, bool, Counters&,
                       const CpuBeamStart*) const = nullptr;
  const Camera& cam_;
  const RenderOptions& opt_;
  const PrimaryRays primary_;
  std::vector<Tri> tris_;
  std::vector<glm::dvec3> geo_normals_;  // unit geometric normal per triangle: e1 x e2 normalized
  double slack_ = 0, offset_ = 0, atten_dist_ = 0;
  glm::dvec3 box_lo_{0.0}, box_hi_{0.0};
  int iterations_ = 1;  // surfaces per chain at most: 1 + bounces
  // kernels::Shader's and rayosReflejados' constants, so both tracers read them from one place.
  glm::dvec3 ambient_, background_;
  double specular_ = 0, min_weight_ = 0;
  std::vector<MipChain> chains_;            // per Scene::textures entry
  bool has_glass_ = false;                  // some material has transmission > 0
  double spread_ = 0;                       // angle between neighbouring pixels' rays (base_texel)
  std::unique_ptr<CpuBeams> beams_;         // beams over tiles (RenderOptions::beams), or null
  std::unique_ptr<CpuBvhBeams> bvh_beams_;  // ... through the BVH

 public:
  // The stream tracer's float of it (marcarConos' uniform: 2 tan(fov / 2) / height).
  float pixel_spread() const { return 2.0f * std::tan(0.5f * cam_.yfov) / float(opt_.height); }
  // Whether the stream tracer runs this scene's frames as ray streams (a glass scene, or
  // --ray-streams on), where no reflected surface keys are kept (kernels/cones.h).
  bool ray_streams() const { return has_glass_ || opt_.ray_streams; }
};

}  // namespace host::cpu_core
