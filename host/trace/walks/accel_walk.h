// What the host loop (host/trace/stream/stream_tracer.cpp) needs of an acceleration structure's
// walk (AccelWalk), and what the four walks share (ListWalk): the paper's uniform grid
// (grid_walk.h) and the extensions (bvh_walk.h, kd_walk.h, grid2_walk.h) each keep only their
// textures, programs, pass sites and sequence. How a pass sequence runs is
// host/trace/walks/walk.h's business.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "host/accel/accel.h"
#include "host/model/formats.h"
#include "host/trace/passes.h"
#include "host/trace/ping_pong.h"
#include "host/trace/render_options.h"
#include "kernels/kernels.h"
#include "vgpu/vgpu.h"

namespace host {

// The tracer's textures and masks a walk reads and writes: the scene's vertices, the
// intersection state (nearest hit so far) and the two masks of walking and testing rays.
struct WalkShared {
  const vgpu::Texture* vertices[3];
  PingPong<vgpu::Texture>* isect;  // the nearest hit so far (host/trace/ping_pong.h)
  vgpu::Stencil* grid_mask;
  vgpu::Stencil* isect_mask;
};

class AccelWalk {
 public:
  virtual ~AccelWalk() = default;
  // The per-pixel state textures, made after the tracer's own.
  virtual void make_state(vgpu::Device& gpu, const WalkShared& shared) = 0;
  // Video memory gets the static textures at initialization.
  virtual void upload(vgpu::Device& gpu) const = 0;
  // Between frames of a moving scene (StreamTracer::update): the structure `accel` (of the
  // kind the walk was made for, rebuilt for the scene posed anew) replaces the old one. Its
  // static textures are rewritten in place where the new structure fits them (else made anew),
  // each one whose texels changed is uploaded again and named in `uploaded`, and the uniforms
  // are set. Returns the bytes uploaded. Throws vgpu::Error past the profile's limits.
  virtual uint64_t rebuild(vgpu::Device& gpu, const Accel& accel, float scene_width,
                           std::vector<std::string>& uploaded) = 0;
  virtual uint64_t static_bytes() const = 0;  // the structure's textures, as upload() sends
  // Whether its pointers are (x, y) texel coordinates (RenderOptions::addressing).
  virtual bool addresses_by_xy() const { return false; }
  virtual uint64_t texture_bytes() const = 0;  // those and the per-pixel state
  // One stream of rays: enter the structure, then walk it until no ray is walking. Leaves the
  // nearest hits in the current intersection texture.
  virtual void trace(PassRunner& r, vgpu::Texture& origins, vgpu::Texture& rays, bool primary,
                     glm::vec3 eye) = 0;
  // The primary rays' camera (the generator's uniforms) and the sample's offset from the pixel
  // centre, in pixels, before each frame's primary trace: what beams over tiles march
  // (RenderOptions::beams). A walk without beams ignores it.
  virtual void set_camera(const kernels::GenerateRays& /*camera*/, float /*offset_x*/,
                          float /*offset_y*/) {}
};

// The arithmetic of a looping program, which does the traversal, voxel and hits groups' work:
// the finest of their arithmetic formats (their textures keep their own formats).
vgpu::Format looping_arithmetic(const Formats& formats);

// A structure's node indices or list positions (`count` of them, `kind`) held in `group`'s
// texels and arithmetic.
struct AddressUse {
  uint64_t count;
  Group group;
  const char* kind;
};
// Refuses a format that cannot hold the addresses (a walk would stall at an index that no
// longer counts up, as the grid's does past its cap): throws vgpu::Error "STRUCTURE: KIND
// reach N; ...". The advice names fp32 alone where fp24 cannot hold them either, and
// `past_fp32` where fp32 cannot (by default (x, y) addressing, for the kd-tree's and the
// two-level grid's linear indices).
inline constexpr std::string_view kAddressByXy =
    "address its textures by (x, y): --addressing auto or xy";
void check_addresses(const Formats& formats, const std::string& structure,
                     std::initializer_list<AddressUse> uses,
                     std::string_view past_fp32 = kAddressByXy);

// Whether a structure addresses its textures by (x, y) (RenderOptions::addressing): as forced,
// or, automatic, where one of its linear indices `uses` passes what fp32 addresses exactly
// (2^23 - 1) or RenderOptions::linear_address_limit, where lower.
bool addresses_by_xy(const RenderOptions& options, std::initializer_list<AddressUse> uses);

// Whether a static texture holds `count` entries (between frames it is kept where it does).
bool holds(const vgpu::Texture& t, size_t count);

// A static texture's texels as a walk writes them (a structure's nodes, cells, lists): into the
// texture itself where it was just `made` (its untouched zeros: nothing to compare, and no copy
// of the whole texture beside it, which held a large structure's textures twice while they
// were written), else into a copy that replace_texels compares with the texture (between
// frames, only a texture whose texels changed is uploaded again). Static textures are fp32:
// nothing to round in place.
class StaticTexels {
 public:
  StaticTexels(vgpu::Texture& t, bool made);
  std::span<float> span() { return {p_, n_}; }
  float& operator[](size_t i) { return p_[i]; }
  vgpu::Texture& texture() { return *t_; }
  // Whether the texture now holds other texels than before (one just made: yes).
  bool keep();

 private:
  vgpu::Texture* t_;
  std::vector<float> copy_;
  float* p_ = nullptr;
  size_t n_ = 0;
  bool in_place_ = false;
};

// Static textures get their new texels; with `uploaded` (between frames), each one whose texels
// changed is uploaded again and named there. Returns the bytes uploaded.
uint64_t replace_texels(vgpu::Device& gpu, std::initializer_list<StaticTexels*> textures,
                        std::vector<std::string>* uploaded);
uint64_t replace_texels(
    vgpu::Device& gpu,
    std::initializer_list<std::pair<vgpu::Texture*, const std::vector<float>*>> textures,
    std::vector<std::string>* uploaded);

// What the four walks share: per pixel a traversal pair (where the ray is in the structure)
// and a list-state pair (its position in the triangle list it tests), the queries that count
// walking and testing rays (rayosEnGrilla, rayosIntersectando), proximoTriangulo, the triangle
// loop of the multipass walk and the host loop of the looping variant.
class ListWalk : public AccelWalk {
 public:
  // Where the walk is: the rays it traces and the current texture of each ping-pong pair.
  struct Cursor {
    vgpu::Texture *origins, *rays;
    // Copies of the pairs' current/next (a batch walk runs a copy per batch of pixels), written
    // back by settle() when the walk ends.
    PingPongRef<vgpu::Texture> trav, vs, isect;
  };
  // Not copied: statics_ points at the walk's own members.
  ListWalk(const ListWalk&) = delete;
  ListWalk& operator=(const ListWalk&) = delete;

  // The state a batch walk hands back: the three ping-pong pairs and both masks.
  WriteBack write_back(const Cursor& c) const;

  void upload(vgpu::Device& gpu) const final;  // each static texture, in the walk's order
  uint64_t static_bytes() const final;
  uint64_t texture_bytes() const final;

 protected:
  // `statics`: the walk's static textures (members of the walk, made by it), in the order they
  // are uploaded. The shared programs compute in their groups' arithmetic formats.
  ListWalk(const RenderOptions& options, std::initializer_list<const vgpu::Texture*> statics);

  // Each program computes in its group's arithmetic format (host/model/formats.h: which kernel
  // is where).
  void compute_in(std::initializer_list<std::pair<vgpu::Program*, Group>> programs) const;
  // The programs of an extension's walk (BVH, kd-tree, two-level grid), each computing in its
  // group's arithmetic format: the entry and step in the traversal group's, the list load in
  // the voxel group's, the intersection in the hits group's, a fused program in its first
  // kernel's (mrt_refusal checked both agree), the looping one in looping_arithmetic.
  void compute_in_groups(vgpu::Program& enter, vgpu::Program& step, vgpu::Program& step_load,
                         vgpu::Program& load, vgpu::Program& intersect,
                         vgpu::Program& intersect_next, vgpu::Program& looping) const;

  // The per-pixel state textures: `trav_name` A and B in the traversal group's format,
  // `state_name` A and B in the voxel group's.
  void make_pairs(vgpu::Device& gpu, const WalkShared& shared, const std::string& trav_name,
                  const std::string& state_name);
  uint64_t state_bytes() const;  // both pairs
  // A walk's textures other than its statics and both pairs (the grid's beam textures), counted
  // by texture_bytes().
  virtual uint64_t extra_bytes() const { return 0; }
  // Before a trace's entry pass: no hit yet, no list position.
  void clear(vgpu::Device& gpu);
  // The looping variant, after the entry pass: every ray the entry left walking is marked in
  // the walking mask and counted as traced. Returns how many.
  uint64_t count_entered(PassRunner& r);
  // The multipass walk starts from the current textures and leaves them where it ends.
  Cursor cursor(vgpu::Texture& origins, vgpu::Texture& rays) {
    return {&origins, &rays, PingPongRef<vgpu::Texture>(trav_), PingPongRef<vgpu::Texture>(vs_),
            PingPongRef<vgpu::Texture>(*sh_.isect)};
  }
  void settle(const Cursor& c) {
    trav_.make_current(c.trav.which());
    vs_.make_current(c.vs.which());
    sh_.isect->make_current(c.isect.which());
  }

  // The passes of the triangle loop by where it issues them (the walk's own Site numbers).
  struct TriangleSites {
    int testing, intersect, next, intersect_next, testing_on;
  };
  // The triangles of the list each walking ray stands at, one per pass, until no ray has one
  // left (at most max_list + 1 passes: lists are not longer, a stuck position is fp16's).
  // `intersect` reads (origins, rays, [traversal,] list state, hits, vertices) as
  // `reads_traversal` says, `intersect_next` the same and `lists` (--mrt on). `key(step, k,
  // site)` names each pass (walk::PassKey). Written once for every X of host/trace/walks/walk.h.
  template <class X, class Key>
  void test_triangles(X& x, Cursor& c, const Key& key, int step, const TriangleSites& site,
                      int max_list, const vgpu::Program& intersect,
                      const vgpu::Program& intersect_next, const vgpu::Texture& lists,
                      bool reads_traversal);

  // The passes of a step by where it issues them (the walk's own Site numbers).
  struct StepSites {
    int step, load, step_load;
  };
  // One step of every walking ray to its next node or cell, then the load of the list it
  // reached: `step` (reading origins, rays, traversal, hits, `nodes`, `more_nodes`) and `load`
  // (traversal, list state, `lists`), or under --mrt on both in one pass, `step_load` (as
  // `step`, with the list state before the nodes and `lists` after). `more_nodes` may be
  // nullptr (a structure with one node texture). `tail` (the kd-tree's beams), where given, is
  // read last by both forms (after the nodes by `step`, after `lists` by `step_load`).
  template <class X, class Key>
  void step_and_load(X& x, Cursor& c, const Key& key, int step, const StepSites& site,
                     const vgpu::Program& step_p, const vgpu::Program& load,
                     const vgpu::Program& step_load, const vgpu::Texture& nodes,
                     const vgpu::Texture* more_nodes, const vgpu::Texture& lists,
                     const vgpu::Texture* tail = nullptr);

  // The looping variant (RenderOptions::looping): `looping`, reading (origins, rays,
  // traversal, list state, hits, vertices, then `statics`), drawn again while rays walk,
  // steps_per_pass iterations per pass. Past max_iterations (rounded up to whole passes) the
  // host stops, as the multipass loop does, and reports the rays left unfinished.
  void walk_looping(PassRunner& r, const vgpu::Program& looping, vgpu::Texture& origins,
                    vgpu::Texture& rays, std::initializer_list<const vgpu::Texture*> statics,
                    int64_t max_iterations, uint64_t walking);

  const RenderOptions& opt_;
  std::vector<const vgpu::Texture*> statics_;
  // Addressed by (x, y) (kernels/lists.h, Addr): the texture step_and_load's load pass reads
  // the list start from (the traversal state has no channel left for it); null: linear.
  const vgpu::Texture* load_reads_ = nullptr;
  WalkShared sh_{};
  // Per-pixel state (ping-pong pairs): traversal and list state.
  PingPong<vgpu::Texture> trav_, vs_;
  vgpu::KernelProgram<kernels::NextTriangle> next_;
  vgpu::KernelProgram<kernels::RaysIntersecting> intersecting_;
  vgpu::KernelProgram<kernels::RaysInGrid> walking_;
};

template <class X, class Key>
void ListWalk::test_triangles(X& x, Cursor& c, const Key& key, int step, const TriangleSites& site,
                              int max_list, const vgpu::Program& intersect,
                              const vgpu::Program& intersect_next, const vgpu::Texture& lists,
                              bool reads_traversal) {
  vgpu::Texture &origins = *c.origins, &rays = *c.rays;
  const vgpu::Texture* const* v = sh_.vertices;
  vgpu::Stencil &grid_mask = *sh_.grid_mask, &isect_mask = *sh_.isect_mask;
  x.copy(isect_mask, grid_mask);
  auto testing =
      x.count(key(step, -1, site.testing), intersecting_, c.vs.current(), &grid_mask, &isect_mask);
  for (int k = 0; X::any(testing); ++k) {
    if (k == max_list + 1) break;  // lists cannot be longer: stuck positions (fp16)
    const vgpu::Texture *trav = &c.trav.current(), *vs = &c.vs.current();
    if (opt_.mrt) {
      // The intersection and proximoTriangulo in one pass, two targets.
      const auto key_k = key(step, k, site.intersect_next);
      if (reads_traversal)
        x.pass(key_k, intersect_next,
               {&origins, &rays, trav, vs, &c.isect.current(), v[0], v[1], v[2], &lists},
               {&c.isect.next(), &c.vs.next()}, &isect_mask);
      else
        x.pass(key_k, intersect_next,
               {&origins, &rays, vs, &c.isect.current(), v[0], v[1], v[2], &lists},
               {&c.isect.next(), &c.vs.next()}, &isect_mask);
      c.isect.swap();
      c.vs.swap();
    } else {
      const auto key_k = key(step, k, site.intersect);
      if (reads_traversal)
        x.pass(key_k, intersect, {&origins, &rays, trav, vs, &c.isect.current(), v[0], v[1], v[2]},
               {&c.isect.next()}, &isect_mask);
      else
        x.pass(key_k, intersect, {&origins, &rays, vs, &c.isect.current(), v[0], v[1], v[2]},
               {&c.isect.next()}, &isect_mask);
      c.isect.swap();
      x.pass(key(step, k, site.next), next_, {&c.vs.current(), &lists}, {&c.vs.next()},
             &isect_mask);
      c.vs.swap();
    }
    testing = x.count(key(step, k, site.testing_on), intersecting_, c.vs.current(), &isect_mask,
                      &isect_mask);
  }
}

template <class X, class Key>
void ListWalk::step_and_load(X& x, Cursor& c, const Key& key, int step, const StepSites& site,
                             const vgpu::Program& step_p, const vgpu::Program& load,
                             const vgpu::Program& step_load, const vgpu::Texture& nodes,
                             const vgpu::Texture* more_nodes, const vgpu::Texture& lists,
                             const vgpu::Texture* tail) {
  vgpu::Texture &origins = *c.origins, &rays = *c.rays;
  const vgpu::Texture *trav = &c.trav.current(), *hits = &c.isect.current();
  vgpu::Stencil* grid_mask = sh_.grid_mask;
  if (opt_.mrt) {
    const auto key_s = key(step, -1, site.step_load);
    const vgpu::Texture* vs = &c.vs.current();
    if (more_nodes)
      x.pass(key_s, step_load, {&origins, &rays, trav, hits, vs, &nodes, more_nodes, &lists},
             {&c.trav.next(), &c.vs.next()}, grid_mask);
    else if (tail)
      x.pass(key_s, step_load, {&origins, &rays, trav, hits, vs, &nodes, &lists, tail},
             {&c.trav.next(), &c.vs.next()}, grid_mask);
    else
      x.pass(key_s, step_load, {&origins, &rays, trav, hits, vs, &nodes, &lists},
             {&c.trav.next(), &c.vs.next()}, grid_mask);
    c.trav.swap();
    c.vs.swap();
    return;
  }
  const auto key_s = key(step, -1, site.step);
  if (more_nodes || tail)
    x.pass(key_s, step_p, {&origins, &rays, trav, hits, &nodes, more_nodes ? more_nodes : tail},
           {&c.trav.next()}, grid_mask);
  else
    x.pass(key_s, step_p, {&origins, &rays, trav, hits, &nodes}, {&c.trav.next()}, grid_mask);
  c.trav.swap();
  if (load_reads_)  // addressed by (x, y): the load reads the list start from this texture
    x.pass(key(step, -1, site.load), load,
           {&c.trav.current(), &c.vs.current(), &lists, load_reads_}, {&c.vs.next()}, grid_mask);
  else
    x.pass(key(step, -1, site.load), load, {&c.trav.current(), &c.vs.current(), &lists},
           {&c.vs.next()}, grid_mask);
  c.vs.swap();
}

}  // namespace host
