// glTF 2.0 animations: keyframe samplers (LINEAR, STEP, CUBICSPLINE), channels on node
// translation, rotation and scale, and a scene posed at a time T (node world transforms, then
// world-space triangles exactly as the loader flattens the static scene, gltf_loader.h).
#pragma once

#include <cstddef>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "host/scene/gltf_loader.h"
#include "host/scene/scene.h"

namespace host {

// A file asks for what the renderer does not do (a skinned mesh or morph-target weights when a
// time is asked for): what() is one line naming the file and the feature. Never a silently wrong
// frame; the CLI exits with status 2.
struct UnsupportedFeature : InputError {
  using InputError::InputError;
};

enum class Interpolation { linear, step, cubic_spline };
enum class AnimatedPath { translation, rotation, scale };

// One sampler: key times and values as the glTF spec lays them out.
struct Sampler {
  Interpolation interpolation = Interpolation::linear;
  std::vector<double> times;  // seconds, strictly increasing, at least one
  // Per key: its value (LINEAR, STEP), or its in-tangent, value and out-tangent (CUBICSPLINE,
  // 3 elements per key). Translation and scale use x, y, z; rotations are (x, y, z, w) as glTF
  // stores them.
  std::vector<glm::dvec4> values;
};

// The sampler at time t (seconds). Before the first key: the first key's value; after the last:
// the last's. Between keys k and k+1, with u = (t - t_k) / (t_k+1 - t_k) and d = t_k+1 - t_k:
//   STEP         v_k (a key's value holds until the next key's time);
//   LINEAR       (1 - u) v_k + u v_k+1;
//   CUBICSPLINE  (2u^3 - 3u^2 + 1) v_k + d (u^3 - 2u^2 + u) b_k + (-2u^3 + 3u^2) v_k+1
//                + d (u^3 - u^2) a_k+1, b the out-tangents and a the in-tangents (glTF 2.0,
//                Appendix C).
glm::dvec3 sample_vec3(const Sampler& s, double t);
// The same for a rotation: LINEAR is slerp_short; the result is normalised (CUBICSPLINE too,
// as the spec asks).
glm::dquat sample_rotation(const Sampler& s, double t);

// Spherical linear interpolation from unit a (u = 0) to unit b (u = 1) the short way round: b is
// negated when dot(a, b) < 0 (q and -q are the same rotation). Nearly equal quaternions are
// interpolated linearly and normalised.
glm::dquat slerp_short(const glm::dquat& a, const glm::dquat& b, double u);

// glTF quaternion order (x, y, z, w) to glm's.
inline glm::dquat to_quat(const glm::dvec4& xyzw) {
  return glm::dquat(xyzw.w, xyzw.x, xyzw.y, xyzw.z);
}

struct Channel {
  int node = 0;
  AnimatedPath path = AnimatedPath::translation;
  size_t sampler = 0;
};

struct Animation {
  std::string name;  // the file's, or "animation N" when it has none
  std::vector<Sampler> samplers;
  std::vector<Channel> channels;  // only translation, rotation and scale
  // Why this animation cannot be played (a channel on morph-target weights, or another path),
  // naming the channel; empty when it can.
  std::string unsupported;
  double start = 0, end = 0;  // seconds: the first and the last key time of any sampler
};

namespace gltf_detail {
class OpenScene;
}

// A glTF file whose scene can be posed at any time of one of its animations. The file is
// parsed once; each pose flattens the scene again.
class AnimatedScene {
 public:
  // Loads the file and its animations (throws InputError as load_scene does; an animation
  // that breaks the glTF rules, e.g. times not increasing, throws too).
  explicit AnimatedScene(const std::string& path, const LoadOptions& options = {});
  ~AnimatedScene();
  AnimatedScene(AnimatedScene&&) noexcept;

  // The scene with the file's own node transforms, as load_scene returns it.
  const Scene& rest() const { return rest_; }
  const std::vector<Animation>& animations() const { return animations_; }
  // The animation with this name, else the one with this index (decimal digits); nullopt when
  // neither exists.
  std::optional<size_t> find(const std::string& name_or_index) const;
  // Every animation of the file, 0 to N - 1: what a glTF viewer plays, and the CLI's default.
  // Exporters often write one animation per animated node (a parent's translation and its
  // child's rotation as two animations), meant to play together.
  std::vector<size_t> all() const;
  // Two animations of `played` that drive the same path of the same node cannot play together
  // (which value would win?). Empty when no two do; else the first such pair, e.g.
  // "animations 0 'rise' and 2 'sway' both drive node 1 ('outer') translation".
  std::string clash(const std::vector<size_t>& played) const;
  // The first and last key time of any animation of `played` (0, 0 when none): the span
  // --frames N covers.
  std::pair<double, double> span(const std::vector<size_t>& played) const;
  // Throws UnsupportedFeature, one line naming the feature, when the scene cannot be posed with
  // the animations `played` (none: the file's transforms): a node of the scene uses a skin, or
  // an animation has a channel on morph-target weights (or another unsupported path). Throws
  // InputError, "PATH: " and clash(), when two of them drive the same path of a node.
  void check(const std::vector<size_t>& played) const;
  void check(std::optional<size_t> animation) const { check(one(animation)); }
  // The scene at `time` seconds of the animations `played`, all sampled at the same time (none,
  // or a file without animations: the rest scene): each animated node's translation, rotation
  // and scale replaced by its channels' samples (the others kept), then flattened with the
  // loader's rules. Cameras and lights of the file move with their nodes; the default light (a
  // file without lights) stays the rest scene's, so that it does not follow the moving bounds.
  // Calls check(). Not thread-safe (the open file is reused).
  Scene at(const std::vector<size_t>& played, double time) const;
  Scene at(std::optional<size_t> animation, double time) const { return at(one(animation), time); }

 private:
  static std::vector<size_t> one(std::optional<size_t> a) {
    return a ? std::vector<size_t>{*a} : std::vector<size_t>{};
  }
  std::unique_ptr<gltf_detail::OpenScene> file_;
  Scene rest_;
  std::vector<Animation> animations_;
};

}  // namespace host
