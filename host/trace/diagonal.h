// Lengths both tracers derive from the scene's grid diagonal, as fractions of it: the stream
// tracer's uniforms take float(k) * diagonal in float, the CPU tracer k * diagonal in double, so
// the two agree on the in-voxel rule, where a reflected ray starts and how light falls off.
#pragma once

namespace host {

inline constexpr double kSlackOfDiagonal = 1e-5;   // GridUniforms::t_slack (in-voxel rule)
inline constexpr double kOffsetOfDiagonal = 1e-4;  // ReflectionOrigin::offset (origin lift)
inline constexpr double kAttenOfDiagonal = 0.5;    // Shader::atten_dist

}  // namespace host
