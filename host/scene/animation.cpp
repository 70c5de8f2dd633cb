// glTF 2.0 animations (see animation.h): the samplers' interpolation, the file's animations read
// and checked, and the scene posed at a time through the loader kept open (gltf_internal.h).
#include "host/scene/animation.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

#include "host/scene/gltf_internal.h"

// tinygltf's declarations only: its implementation is compiled once, in gltf_file.cpp.
#include <tiny_gltf.h>

namespace host {
namespace {

using gltf_detail::fail;

// Where t falls among the keys: key k and the fraction u in [0, 1) towards key k + 1; or, before
// the first or after the last key, that key with u = 0 and `clamped`.
struct KeySpan {
  size_t k = 0;
  double u = 0, duration = 0;
  bool clamped = false;
};

KeySpan find_span(const std::vector<double>& times, double t) {
  const size_t n = times.size();
  if (n == 0) throw std::invalid_argument("a sampler without keys");
  if (!(t > times.front())) return {0, 0, 0, true};  // also NaN: the first key
  if (t >= times.back()) return {n - 1, 0, 0, true};
  const size_t k = size_t(std::upper_bound(times.begin(), times.end(), t) - times.begin()) - 1;
  const double d = times[k + 1] - times[k];
  return {k, (t - times[k]) / d, d, false};
}

// The value element of key k (CUBICSPLINE stores in-tangent, value, out-tangent per key).
const glm::dvec4& key_value(const Sampler& s, size_t k) {
  return s.interpolation == Interpolation::cubic_spline ? s.values[3 * k + 1] : s.values[k];
}

// glTF 2.0 Appendix C: the cubic Hermite spline between keys k and k + 1.
glm::dvec4 hermite(const Sampler& s, const KeySpan& w) {
  const double u = w.u, u2 = u * u, u3 = u2 * u, d = w.duration;
  const glm::dvec4& v0 = s.values[3 * w.k + 1];
  const glm::dvec4& b0 = s.values[3 * w.k + 2];    // out-tangent of key k
  const glm::dvec4& a1 = s.values[3 * (w.k + 1)];  // in-tangent of key k + 1
  const glm::dvec4& v1 = s.values[3 * (w.k + 1) + 1];
  return (2 * u3 - 3 * u2 + 1) * v0 + d * (u3 - 2 * u2 + u) * b0 + (-2 * u3 + 3 * u2) * v1 +
         d * (u3 - u2) * a1;
}

glm::dquat unit(const glm::dquat& q) {
  const double len = glm::length(q);
  return len > 0 && std::isfinite(len) ? q / len : glm::dquat(1, 0, 0, 0);
}

}  // namespace

glm::dquat slerp_short(const glm::dquat& a, const glm::dquat& b_in, double u) {
  glm::dquat b = b_in;
  double d = glm::dot(a, b);
  if (d < 0) b = -b, d = -d;
  if (d > 1.0 - 1e-12) return unit(a * (1.0 - u) + b * u);  // sin(theta) ~ 0: the chord will do
  const double theta = std::acos(std::min(d, 1.0)), s = std::sin(theta);
  return unit(a * (std::sin((1.0 - u) * theta) / s) + b * (std::sin(u * theta) / s));
}

glm::dvec3 sample_vec3(const Sampler& s, double t) {
  const KeySpan w = find_span(s.times, t);
  if (w.clamped || s.interpolation == Interpolation::step) return glm::dvec3(key_value(s, w.k));
  if (s.interpolation == Interpolation::linear)
    return glm::dvec3(glm::mix(key_value(s, w.k), key_value(s, w.k + 1), w.u));
  return glm::dvec3(hermite(s, w));
}

glm::dquat sample_rotation(const Sampler& s, double t) {
  const KeySpan w = find_span(s.times, t);
  if (w.clamped || s.interpolation == Interpolation::step) return unit(to_quat(key_value(s, w.k)));
  if (s.interpolation == Interpolation::linear)
    return slerp_short(unit(to_quat(key_value(s, w.k))), unit(to_quat(key_value(s, w.k + 1))), w.u);
  return unit(to_quat(hermite(s, w)));
}

// ---------------------------------------------------------------------------------------------
// The file's animations

namespace {

const char* path_name(AnimatedPath p) {
  return p == AnimatedPath::translation ? "translation"
         : p == AnimatedPath::rotation  ? "rotation"
                                        : "scale";
}

// Reads and checks every animation of the file (glTF 2.0 section 3.11).
std::vector<Animation> read_animations(const gltf_detail::OpenScene& file) {
  const tinygltf::Model& model = file.model();
  const std::string& path = file.path();
  std::vector<Animation> out;
  for (size_t a = 0; a < model.animations.size(); ++a) {
    const tinygltf::Animation& src = model.animations[a];
    const std::string where = "animation " + std::to_string(a);
    Animation anim;
    anim.name = src.name.empty() ? where : src.name;
    // Samplers: their times now, their values once a channel says how wide they are.
    std::vector<int> width(src.samplers.size(), 0);
    for (size_t i = 0; i < src.samplers.size(); ++i) {
      const tinygltf::AnimationSampler& ss = src.samplers[i];
      const std::string use = where + " sampler " + std::to_string(i);
      Sampler s;
      if (ss.interpolation == "LINEAR" || ss.interpolation.empty())
        s.interpolation = Interpolation::linear;
      else if (ss.interpolation == "STEP")
        s.interpolation = Interpolation::step;
      else if (ss.interpolation == "CUBICSPLINE")
        s.interpolation = Interpolation::cubic_spline;
      else
        fail(path, use + " has unknown interpolation '" + ss.interpolation + "'");
      s.times = file.read_doubles(ss.input, use + " input", 1, false);
      if (s.times.empty()) fail(path, use + " has no keys");
      for (size_t k = 1; k < s.times.size(); ++k)
        if (!(s.times[k] > s.times[k - 1]))
          fail(path, use + ": key times must increase strictly (key " + std::to_string(k) + " at " +
                         std::to_string(s.times[k]) + " s follows " +
                         std::to_string(s.times[k - 1]) + " s)");
      anim.samplers.push_back(std::move(s));
    }
    std::map<std::pair<int, AnimatedPath>, size_t> targeted;
    for (size_t c = 0; c < src.channels.size(); ++c) {
      const tinygltf::AnimationChannel& ch = src.channels[c];
      const std::string use = where + " channel " + std::to_string(c);
      if (ch.sampler < 0 || size_t(ch.sampler) >= anim.samplers.size())
        fail(path, use + " refers to sampler " + std::to_string(ch.sampler) +
                       ", but the animation has " + std::to_string(anim.samplers.size()) +
                       " samplers");
      AnimatedPath p;
      if (ch.target_path == "translation") {
        p = AnimatedPath::translation;
      } else if (ch.target_path == "rotation") {
        p = AnimatedPath::rotation;
      } else if (ch.target_path == "scale") {
        p = AnimatedPath::scale;
      } else {
        // Morph-target weights, or a path of an extension (KHR_animation_pointer's "pointer",
        // which has no node): refused when this animation is played, never ignored.
        if (anim.unsupported.empty())
          anim.unsupported =
              ch.target_path == "weights"
                  ? use + " animates morph-target weights (node " + std::to_string(ch.target_node) +
                        "); morph targets are not supported"
                  : use + " animates '" + ch.target_path + "', which is not supported";
        continue;
      }
      if (ch.target_node < 0) continue;  // glTF: a node's channel without a node is ignored
      if (size_t(ch.target_node) >= model.nodes.size())
        fail(path, use + " targets node " + std::to_string(ch.target_node) + ", but the file has " +
                       std::to_string(model.nodes.size()) + " nodes");
      const std::string target = "node " + std::to_string(ch.target_node) + " " + path_name(p);
      if (!model.nodes[size_t(ch.target_node)].matrix.empty())
        fail(path, use + " animates node " + std::to_string(ch.target_node) +
                       ", which has a matrix (glTF: an animated node has translation, rotation "
                       "and scale)");
      if (auto [it, fresh] = targeted.emplace(std::make_pair(ch.target_node, p), c); !fresh)
        fail(path, use + " animates " + target + " again (channel " + std::to_string(it->second) +
                       " does)");
      Sampler& s = anim.samplers[size_t(ch.sampler)];
      const int w = p == AnimatedPath::rotation ? 4 : 3;
      int& known = width[size_t(ch.sampler)];
      const std::string sampler_use = where + " sampler " + std::to_string(ch.sampler) + " output";
      if (known == 0) {
        const std::vector<double> v = file.read_doubles(
            src.samplers[size_t(ch.sampler)].output, sampler_use, w, p == AnimatedPath::rotation);
        const size_t per_key = s.interpolation == Interpolation::cubic_spline ? 3 : 1;
        if (v.size() / size_t(w) != per_key * s.times.size())
          fail(path, sampler_use + " has " + std::to_string(v.size() / size_t(w)) + " elements; " +
                         std::to_string(s.times.size()) + " keys" +
                         (per_key == 3 ? " of CUBICSPLINE need " : " need ") +
                         std::to_string(per_key * s.times.size()));
        for (size_t e = 0; e < v.size(); e += size_t(w))
          s.values.emplace_back(v[e], v[e + 1], v[e + 2], w == 4 ? v[e + 3] : 0.0);
        if (p == AnimatedPath::rotation)
          for (size_t k = 0; k < s.times.size(); ++k)
            if (!(glm::length(to_quat(key_value(s, k))) > 0))
              fail(path, sampler_use + ": key " + std::to_string(k) + " is not a quaternion");
        known = w;
      } else if (known != w) {
        fail(path, use + ": sampler " + std::to_string(ch.sampler) +
                       " is used for values of another width by an earlier channel");
      }
      anim.channels.push_back({ch.target_node, p, size_t(ch.sampler)});
    }
    // The time range of the samplers the channels use.
    bool first = true;
    for (const Channel& ch : anim.channels) {
      const Sampler& s = anim.samplers[ch.sampler];
      anim.start = first ? s.times.front() : std::min(anim.start, s.times.front());
      anim.end = first ? s.times.back() : std::max(anim.end, s.times.back());
      first = false;
    }
    out.push_back(std::move(anim));
  }
  return out;
}

}  // namespace

AnimatedScene::AnimatedScene(const std::string& path, const LoadOptions& options)
    : file_(std::make_unique<gltf_detail::OpenScene>(path, [&] {
        LoadOptions o = options;
        o.animations = true;
        return o;
      }())) {
  rest_ = file_->flatten();
  animations_ = read_animations(*file_);
}

AnimatedScene::~AnimatedScene() = default;
AnimatedScene::AnimatedScene(AnimatedScene&&) noexcept = default;

std::optional<size_t> AnimatedScene::find(const std::string& name_or_index) const {
  for (size_t a = 0; a < animations_.size(); ++a)
    if (animations_[a].name == name_or_index) return a;
  if (name_or_index.empty() || name_or_index.size() > 9 ||
      !std::all_of(name_or_index.begin(), name_or_index.end(),
                   [](char c) { return c >= '0' && c <= '9'; }))
    return std::nullopt;
  const size_t index = std::stoul(name_or_index);
  if (index < animations_.size()) return index;
  return std::nullopt;
}

std::vector<size_t> AnimatedScene::all() const {
  std::vector<size_t> every(animations_.size());
  for (size_t a = 0; a < every.size(); ++a) every[a] = a;
  return every;
}

std::string AnimatedScene::clash(const std::vector<size_t>& played) const {
  // Which animation drives each (node, path) so far; one animation never drives a pair twice
  // (read_animations refuses that).
  std::map<std::pair<int, AnimatedPath>, size_t> driver;
  for (const size_t a : played)
    for (const Channel& ch : animations_.at(a).channels) {
      const auto [it, fresh] = driver.emplace(std::make_pair(ch.node, ch.path), a);
      if (fresh || it->second == a) continue;
      const std::string& node_name = file_->model().nodes[size_t(ch.node)].name;
      const size_t first = it->second;
      return "animations " + std::to_string(first) + " '" + animations_[first].name + "' and " +
             std::to_string(a) + " '" + animations_[a].name + "' both drive node " +
             std::to_string(ch.node) + (node_name.empty() ? "" : " ('" + node_name + "')") + " " +
             path_name(ch.path);
    }
  return {};
}

std::pair<double, double> AnimatedScene::span(const std::vector<size_t>& played) const {
  std::pair<double, double> s{0.0, 0.0};
  bool first = true;
  for (const size_t a : played) {
    const Animation& anim = animations_.at(a);
    s.first = first ? anim.start : std::min(s.first, anim.start);
    s.second = first ? anim.end : std::max(s.second, anim.end);
    first = false;
  }
  return s;
}

void AnimatedScene::check(const std::vector<size_t>& played) const {
  const tinygltf::Model& model = file_->model();
  for (const int n : file_->walked()) {
    const tinygltf::Node& node = model.nodes[size_t(n)];
    if (node.skin >= 0)
      throw UnsupportedFeature(file_->path() + ": node " + std::to_string(n) + " uses skin " +
                               std::to_string(node.skin) + "; skinned meshes are not supported");
  }
  for (const size_t a : played)
    if (!animations_.at(a).unsupported.empty())
      throw UnsupportedFeature(file_->path() + ": " + animations_[a].unsupported);
  if (const std::string why = clash(played); !why.empty())
    throw InputError(file_->path() + ": " + why);
}

Scene AnimatedScene::at(const std::vector<size_t>& played, double time) const {
  if (!std::isfinite(time)) throw std::invalid_argument("the time is not a finite number");
  check(played);
  if (played.empty()) return rest_;
  const tinygltf::Model& model = file_->model();
  // Each animated node's T, R, S: the file's, with the animated ones replaced. No two channels
  // of `played` drive the same node and path (check), so the order does not matter.
  struct Trs {
    glm::dvec3 t{0.0}, s{1.0};
    glm::dquat r{1, 0, 0, 0};
  };
  std::map<int, Trs> posed;
  for (const size_t a : played) {
    const Animation& anim = animations_[a];
    for (const Channel& ch : anim.channels) {
      auto [it, fresh] = posed.try_emplace(ch.node);
      Trs& trs = it->second;
      if (fresh) {
        const tinygltf::Node& node = model.nodes[size_t(ch.node)];
        if (node.translation.size() == 3)
          trs.t = {node.translation[0], node.translation[1], node.translation[2]};
        if (node.rotation.size() == 4)
          trs.r = unit(
              glm::dquat(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]));
        if (node.scale.size() == 3) trs.s = {node.scale[0], node.scale[1], node.scale[2]};
      }
      const Sampler& s = anim.samplers[ch.sampler];
      if (ch.path == AnimatedPath::translation) trs.t = sample_vec3(s, time);
      if (ch.path == AnimatedPath::rotation) trs.r = sample_rotation(s, time);
      if (ch.path == AnimatedPath::scale) trs.s = sample_vec3(s, time);
    }
  }
  std::vector<std::optional<glm::dmat4>> local(model.nodes.size());
  for (const auto& [n, trs] : posed) {
    glm::dmat4 t(1.0), s(1.0);
    t[3] = glm::dvec4(trs.t, 1.0);
    s[0][0] = trs.s.x, s[1][1] = trs.s.y, s[2][2] = trs.s.z;
    local[size_t(n)] = t * glm::mat4_cast(trs.r) * s;
  }
  Scene scene = file_->flatten(local);
  if (scene.default_light) scene.lights = rest_.lights;
  return scene;
}

}  // namespace host
