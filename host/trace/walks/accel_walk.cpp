// What the walks share (host/trace/walks/accel_walk.h): the formats' checks, the static textures'
// rewrite between frames, the per-pixel state, and the looping variant's host loop.
#include "host/trace/walks/accel_walk.h"

#include <algorithm>

namespace host {

using vgpu::Format;
using vgpu::Texture;

Format looping_arithmetic(const Formats& fm) {
  Format loop_arith = fm.arithmetic(Group::traversal);
  for (Group g : {Group::voxel, Group::hits})
    if (vgpu::significand_bits(fm.arithmetic(g)) > vgpu::significand_bits(loop_arith))
      loop_arith = fm.arithmetic(g);
  return loop_arith;
}

void check_addresses(const Formats& fm, const std::string& structure,
                     std::initializer_list<AddressUse> uses, std::string_view past_fp32) {
  // Checked at construction and for each frame's rebuilt structure.
  for (const AddressUse& u : uses)
    for (const Format f : {fm[u.group], fm.arithmetic(u.group)})
      if (u.count - 1 > exact_addresses(f)) {
        const bool fp32_only = u.count - 1 > exact_addresses(Format::fp24);
        // Past fp32's reach no format holds a linear index (entry k at k mod width, k div
        // width), whatever the card's texture size; a texel's column and row it does.
        const std::string advice =
            f == Format::fp32 ? std::string(past_fp32)
                              : std::string("give it ") + (fp32_only ? "fp32" : "fp24 or fp32") +
                                    ": --formats " + std::string(group_name(u.group)) + "=fp32";
        throw vgpu::LimitError(structure + ": " + u.kind + " reach " + std::to_string(u.count - 1) +
                               "; the " + std::string(group_name(u.group)) + " group's " +
                               std::string(vgpu::format_name(f)) +
                               " addresses texels exactly only to " +
                               std::to_string(exact_addresses(f)) + " (" + advice + ")");
      }
}

bool addresses_by_xy(const RenderOptions& opt, std::initializer_list<AddressUse> uses) {
  using A = RenderOptions::Addressing;
  if (opt.addressing != A::automatic) return opt.addressing == A::xy;
  // Past fp32's linear reach (a narrower format is a choice of format: check_addresses refuses
  // it, naming the one that holds the index).
  uint64_t limit = exact_addresses(Format::fp32);
  if (opt.linear_address_limit) limit = std::min(limit, opt.linear_address_limit);
  for (const AddressUse& u : uses)
    if (u.count - 1 > limit) return true;
  return false;
}

StaticTexels::StaticTexels(Texture& t, bool made)
    : t_(&t), n_(t.data().size()), in_place_(made && t.format() == Format::fp32) {
  if (in_place_) {
    p_ = n_ ? t.texel_mut(0, 0) : nullptr;
  } else {
    copy_.assign(t.data().begin(), t.data().end());
    p_ = copy_.data();
  }
}

bool StaticTexels::keep() {
  return in_place_ ? true : t_->replace(copy_);
}

uint64_t replace_texels(vgpu::Device& gpu, std::initializer_list<StaticTexels*> textures,
                        std::vector<std::string>* uploaded) {
  uint64_t bytes = 0;
  for (StaticTexels* s : textures)
    if (s->keep() && uploaded) {
      gpu.upload(s->texture());
      bytes += s->texture().bytes();
      uploaded->push_back(s->texture().name());
    }
  return bytes;
}

bool holds(const Texture& t, size_t count) {
  return uint64_t(t.width()) * uint64_t(t.height()) >= count;
}

uint64_t replace_texels(
    vgpu::Device& gpu,
    std::initializer_list<std::pair<Texture*, const std::vector<float>*>> textures,
    std::vector<std::string>* uploaded) {
  uint64_t bytes = 0;
  for (auto [t, texels] : textures)
    if (t->replace(*texels) && uploaded) {
      gpu.upload(*t);
      bytes += t->bytes();
      uploaded->push_back(t->name());
    }
  return bytes;
}

ListWalk::ListWalk(const RenderOptions& options,
                   std::initializer_list<const vgpu::Texture*> statics)
    : opt_(options), statics_(statics) {
  compute_in(
      {{&next_, Group::voxel}, {&intersecting_, Group::queries}, {&walking_, Group::queries}});
}

void ListWalk::compute_in(std::initializer_list<std::pair<vgpu::Program*, Group>> programs) const {
  for (auto [prog, g] : programs) prog->set_precision(opt_.formats.arithmetic(g));
}

void ListWalk::compute_in_groups(vgpu::Program& enter, vgpu::Program& step,
                                 vgpu::Program& step_load, vgpu::Program& load,
                                 vgpu::Program& intersect, vgpu::Program& intersect_next,
                                 vgpu::Program& looping) const {
  compute_in({{&enter, Group::traversal},
              {&step, Group::traversal},
              {&step_load, Group::traversal},
              {&load, Group::voxel},
              {&intersect, Group::hits},
              {&intersect_next, Group::hits}});
  looping.set_precision(looping_arithmetic(opt_.formats));
}

void ListWalk::make_pairs(vgpu::Device& gpu, const WalkShared& shared, const std::string& trav_name,
                          const std::string& state_name) {
  sh_ = shared;
  const Formats& fm = opt_.formats;
  for (int i = 0; i < 2; ++i) {
    const std::string sfx = i ? " B" : " A";
    trav_[i] = gpu.make_texture(trav_name + sfx, opt_.width, opt_.height, 4, fm[Group::traversal]);
    vs_[i] = gpu.make_texture(state_name + sfx, opt_.width, opt_.height, 4, fm[Group::voxel]);
  }
}

void ListWalk::upload(vgpu::Device& gpu) const {
  for (const Texture* t : statics_) gpu.upload(*t);
}

uint64_t ListWalk::static_bytes() const {
  uint64_t bytes = 0;
  for (const Texture* t : statics_) bytes += t->bytes();
  return bytes;
}

uint64_t ListWalk::texture_bytes() const {
  return static_bytes() + state_bytes() + extra_bytes();
}

uint64_t ListWalk::state_bytes() const {
  return trav_[0].bytes() + trav_[1].bytes() + vs_[0].bytes() + vs_[1].bytes();
}

void ListWalk::clear(vgpu::Device& gpu) {
  gpu.clear(sh_.isect->current(), {kernels::kFar, 0, 0, kernels::kNone});
  gpu.clear(vs_.current(), {0, 0, 0, kernels::kNone});
}

uint64_t ListWalk::count_entered(PassRunner& r) {
  sh_.grid_mask->fill(1);
  const uint64_t walking = r.count(walking_, trav_.current(), nullptr, sh_.grid_mask);
  r.counts.rays_traced += walking;
  return walking;
}

WriteBack ListWalk::write_back(const Cursor& c) const {
  WriteBack wb;
  wb.npairs = 3;
  wb.pairs[0] = {const_cast<Texture*>(&trav_[0]), const_cast<Texture*>(&trav_[1])};
  wb.pairs[1] = {const_cast<Texture*>(&vs_[0]), const_cast<Texture*>(&vs_[1])};
  wb.pairs[2] = {&(*sh_.isect)[0], &(*sh_.isect)[1]};
  wb.current = {c.trav.which(), c.vs.which(), c.isect.which(), 0};
  wb.nmasks = 2;
  wb.masks = {sh_.grid_mask, sh_.isect_mask, nullptr, nullptr};
  return wb;
}

void ListWalk::walk_looping(PassRunner& r, const vgpu::Program& p, Texture& origins, Texture& rays,
                            std::initializer_list<const Texture*> statics, int64_t max_iterations,
                            uint64_t walking) {
  vgpu::Device& gpu = r.device();
  // A batch runs a multipass walk's passes; this walk is one program that loops.
  if (r.counts.passes_reason.empty())
    r.counts.passes_reason = std::string(p.name()) + " loops (--kernels looping)";
  const int64_t max_passes = (max_iterations + opt_.steps_per_pass - 1) / opt_.steps_per_pass;
  for (int64_t k = 0; walking > 0; ++k) {
    if (k == max_passes) {
      r.counts.rays_unfinished += walking;
      break;
    }
    Texture& trav = trav_.next();
    gpu.use_program(p);
    gpu.unbind_textures();
    int unit = 0;
    for (const Texture* t : std::initializer_list<const Texture*>{
             &origins, &rays, &trav_.current(), &vs_.current(), &sh_.isect->current(),
             sh_.vertices[0], sh_.vertices[1], sh_.vertices[2]})
      gpu.bind_texture(unit++, *t);
    for (const Texture* t : statics) gpu.bind_texture(unit++, *t);
    gpu.set_targets({&trav, &vs_.next(), &sh_.isect->next()});
    // The walking rays' mask, as for the multipass kernels (finished rays keep their state).
    r.set_work(sh_.grid_mask);
    const bool traced = r.traces_pixel(sh_.grid_mask);
    if (opt_.observer) opt_.observer->pass_begin(sh_.grid_mask);
    const vgpu::PassRecord& rec = r.rect ? gpu.draw(*r.rect) : gpu.draw();
    if (opt_.observer)
      opt_.observer->pass({p, rec, trav, gpu.branch_flags(), gpu.stats(), gpu.loop_iterations()});
    trav_.swap();
    vs_.swap();
    sh_.isect->swap();
    if (traced) r.trace_targets(p, {&trav_.current(), &vs_.current(), &sh_.isect->current()});
    walking = r.count(walking_, trav_.current(), sh_.grid_mask, sh_.grid_mask);
  }
}

}  // namespace host
