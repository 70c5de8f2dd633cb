// The GLSL printer: a recording, live nodes only, one statement per instruction.
#include "vgpu/glsl.h"

#include <cstdio>
#include <map>
#include <stdexcept>

namespace vgpu {

namespace {

const char* binary_symbol(Op op) {
  switch (op) {
    case Op::add:
      return "+";
    case Op::sub:
      return "-";
    case Op::mul:
      return "*";
    case Op::div:
      return "/";
    case Op::lt:
      return "<";
    case Op::le:
      return "<=";
    case Op::gt:
      return ">";
    case Op::ge:
      return ">=";
    case Op::eq:
      return "==";
    case Op::ne:
      return "!=";
    case Op::mask_and:
      return "&&";
    case Op::mask_or:
      return "||";
    default:
      return nullptr;
  }
}

std::string float_text(float v) {
  char b[48];
  std::snprintf(b, sizeof b, "%.9g", double(v));
  return b;
}

}  // namespace

const char* fullscreen_vertex_shader() {
  return "#version 330 core\n"
         "// One triangle over the whole viewport: vertices (-1,-1), (3,-1), (-1,3).\n"
         "void main() {\n"
         "  vec2 p = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - "
         "1.0);\n"
         "  gl_Position = vec4(p, 0.0, 1.0);\n"
         "}\n";
}

GlslProgram to_glsl(const Program& p, const Recording& rec, bool annotate) {
  const std::vector<RecNode>& nodes = rec.nodes;
  const int n = int(nodes.size());
  // Live nodes: reachable from the outputs and the kill mask (operands precede their users).
  std::vector<char> live(size_t(n), 0);
  auto mark = [&](int id) {
    if (id >= 0) live[size_t(id)] = 1;
  };
  for (const auto& o : rec.outputs)
    for (int id : o) mark(id);
  mark(rec.kill);
  for (int i = n - 1; i >= 0; --i)
    if (live[size_t(i)]) {
      mark(nodes[size_t(i)].a);
      mark(nodes[size_t(i)].b);
      mark(nodes[size_t(i)].c);
    }

  GlslProgram out;
  std::map<int, int> sampler_of_unit;  // unit -> index in out.units
  std::vector<std::string> expr(static_cast<size_t>(n));
  std::string body;
  for (int i = 0; i < n; ++i) {
    if (!live[size_t(i)]) continue;
    const RecNode& nd = nodes[size_t(i)];
    auto e = [&](int id) -> const std::string& { return expr[size_t(id)]; };
    auto sampler = [&](int unit) -> const std::string& {
      auto [it, fresh] = sampler_of_unit.try_emplace(unit, int(out.units.size()));
      if (fresh) {
        out.units.push_back(unit);
        out.samplers.push_back("tex_" + p.unit_name(unit));
      }
      return out.samplers[size_t(it->second)];
    };
    std::string t = std::to_string(i), m = t;
    t.insert(0, 1, 't');
    m.insert(0, 1, 'm');
    auto def_float = [&](const std::string& rhs) {
      body += "  EXACT float " + t + " = " + rhs + ";\n";
      expr[size_t(i)] = t;
      ++out.statements;
    };
    auto def_mask = [&](const std::string& rhs) {
      body += "  bool " + m + " = " + rhs + ";\n";
      expr[size_t(i)] = m;
      ++out.statements;
    };
    switch (nd.op) {
      case Op::constant:
        expr[size_t(i)] = "k[" + std::to_string(out.constants.size()) + "]";
        out.constants.push_back(nd.value);
        break;
      case Op::frag_x:
        expr[size_t(i)] = "gl_FragCoord.x";
        break;
      case Op::frag_y:
        expr[size_t(i)] = "gl_FragCoord.y";
        break;
      case Op::mask_const:
        expr[size_t(i)] = nd.value != 0 ? "true" : "false";
        break;
      case Op::add:
      case Op::sub:
      case Op::mul:
      case Op::div:
        def_float(e(nd.a) + " " + binary_symbol(nd.op) + " " + e(nd.b));
        break;
      case Op::neg:
        def_float("-" + e(nd.a));
        break;
      case Op::min:
        def_float(e(nd.a) + " < " + e(nd.b) + " ? " + e(nd.a) + " : " + e(nd.b));
        break;
      case Op::max:
        def_float(e(nd.a) + " > " + e(nd.b) + " ? " + e(nd.a) + " : " + e(nd.b));
        break;
      case Op::abs:
        def_float("abs(" + e(nd.a) + ")");
        break;
      case Op::floor:
        def_float("floor(" + e(nd.a) + ")");
        break;
      case Op::sqrt:
        def_float("sqrt(" + e(nd.a) + ")");
        break;
      case Op::rsqrt:
        def_float("1.0 / sqrt(" + e(nd.a) + ")");
        break;
      case Op::select:
        def_float(e(nd.a) + " ? " + e(nd.b) + " : " + e(nd.c));
        break;
      case Op::lt:
      case Op::le:
      case Op::gt:
      case Op::ge:
      case Op::eq:
      case Op::ne:
      case Op::mask_and:
      case Op::mask_or:
        def_mask(e(nd.a) + " " + binary_symbol(nd.op) + " " + e(nd.b));
        break;
      case Op::mask_not:
        def_mask("!" + e(nd.a));
        break;
      case Op::fetch_own:
      case Op::fetch: {
        const std::string& s = sampler(nd.unit);
        const std::string v = "f" + std::to_string(i);
        const std::string at = nd.op == Op::fetch_own
                                   ? "own_texel(" + s + ")"
                                   : "texel_at(" + s + ", " + e(nd.a) + ", " + e(nd.b) + ")";
        body += "  vec4 " + v + " = texelFetch(" + s + ", " + at + ", 0);\n";
        expr[size_t(i)] = v;
        ++out.statements;
        break;
      }
      case Op::channel:
        expr[size_t(i)] = e(nd.a) + "." + "xyzw"[nd.unit];
        break;
    }
  }
  if (rec.kill >= 0) {
    body += "  if (" + expr[size_t(rec.kill)] + ") discard;\n";
    ++out.statements;
  }
  for (size_t o = 0; o < rec.outputs.size(); ++o) {
    const auto& c = rec.outputs[o];
    body += "  out" + std::to_string(o) + " = vec4(" + expr[size_t(c[0])] + ", " +
            expr[size_t(c[1])] + ", " + expr[size_t(c[2])] + ", " + expr[size_t(c[3])] + ");\n";
  }

  std::string s;
  s += "#version 330 core\n";
  s += std::string("// ") + p.name() + " (paper: " + p.paper_name() +
       "), generated from its C++ functor by vgpu's recording lanes.\n";
  s += "// One statement per fragment-program instruction; k[] holds every constant and uniform.\n";
  // No a*b+c fusion: the emulator rounds every operation (-ffp-contract=off).
  s += "#extension GL_ARB_gpu_shader5 : enable\n";
  s += "#ifdef GL_ARB_gpu_shader5\n#define EXACT precise\n#else\n#define EXACT\n#endif\n";
  for (const std::string& name : out.samplers) s += "uniform sampler2D " + name + ";\n";
  if (!out.constants.empty())
    s += "uniform float k[" + std::to_string(out.constants.size()) + "];\n";
  for (size_t o = 0; o < rec.outputs.size(); ++o)
    s += "layout(location = " + std::to_string(o) + ") out vec4 out" + std::to_string(o) + ";\n";
  if (!out.samplers.empty()) {
    s += "// texRECT: nearest texel floor(u), floor(v); NaN and negatives to 0, clamped at the "
         "edges.\n";
    s += "ivec2 texel_at(sampler2D s, float u, float v) {\n"
         "  vec2 hi = vec2(textureSize(s, 0) - 1);\n"
         "  float x = floor(u), y = floor(v);\n"
         "  x = x >= 0.0 ? x : 0.0;\n"
         "  y = y >= 0.0 ? y : 0.0;\n"
         "  x = x <= hi.x ? x : hi.x;\n"
         "  y = y <= hi.y ? y : hi.y;\n"
         "  return ivec2(x, y);\n"
         "}\n";
    s += "ivec2 own_texel(sampler2D s) {\n"
         "  return min(ivec2(gl_FragCoord.xy), textureSize(s, 0) - 1);\n"
         "}\n";
  }
  s += "void main() {\n" + body + "}\n";
  if (annotate && !out.constants.empty()) {
    s += "// constants and uniforms, as this run set them:\n";
    for (size_t i = 0; i < out.constants.size(); ++i)
      s += "//   k[" + std::to_string(i) + "] = " + float_text(out.constants[i]) + "\n";
  }
  out.source = std::move(s);
  return out;
}

}  // namespace vgpu
