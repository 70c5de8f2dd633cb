// The GLSL printer: a recording, live nodes only, one statement per instruction.
#include "vgpu/glsl.h"

#include <cstdio>
#include <map>
#include <stdexcept>

#include "vgpu/recorded_program.h"

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

namespace {

// The loop of a recording (RecLoop), as the printer places it: the first copy of its body
// [b, m) is printed inside a GLSL loop, the second [m, e) only tells which values are carried. A
// value is carried where the second copy reads a node of the first (`next`) where the first read
// a node from before the loop (`init`); each becomes a variable lv<j>. After the loop, a read of
// the second copy's node is a read of the variable whose `next` is the corresponding node of the
// first.
struct LoopPlan {
  struct Carried {
    int init, next;
  };
  const Program* p = nullptr;
  const std::vector<RecNode>* nodes = nullptr;
  bool has_loop = false;
  RecLoop lp;
  int b = 0, m = 0, e = 0, d = 0;
  std::vector<Carried> vars;
  std::map<int, int> var_of_next;  // next node -> variable
  std::map<int, int> var_at;       // 4 * node + slot of the first copy -> variable read there

  [[noreturn]] void fail_loop(const std::string& why) const {
    throw std::runtime_error(std::string("program '") + p->name() +
                             "': its loop cannot be printed as GLSL (" + why + ")");
  }

  // A reference from node `user` (n: the outputs and kill) to node `id`, slot `slot`: the loop
  // variable it reads, or -1.
  int var_read(int user, int slot, int id) const {
    if (!has_loop || id < 0) return -1;
    if (user >= b && user < m) {
      auto it = var_at.find(4 * user + slot);
      return it == var_at.end() ? -1 : it->second;
    }
    if (user >= e && id >= m && id < e) {
      auto it = var_of_next.find(id - d);
      if (it == var_of_next.end()) fail_loop("a value of the body read after the loop");
      return it->second;
    }
    if (user >= e && id >= b && id < m && (*nodes)[size_t(id)].op != Op::constant &&
        (*nodes)[size_t(id)].op != Op::mask_const)
      fail_loop("a value of the body read after the loop");
    return -1;
  }
};

int operand(const RecNode& nd, int slot) {
  return slot == 0 ? nd.a : slot == 1 ? nd.b : nd.c;
}

// Step 1: finds the loop's carried values, checking that the two recorded iterations agree.
LoopPlan plan_loop(const Program& p, const Recording& rec) {
  const std::vector<RecNode>& nodes = rec.nodes;
  if (rec.loops.size() > 1)
    throw std::runtime_error(std::string("program '") + p.name() + "': more than one loop");
  LoopPlan L;
  L.p = &p;
  L.nodes = &nodes;
  L.has_loop = !rec.loops.empty();
  L.lp = L.has_loop ? rec.loops[0] : RecLoop{};
  L.b = L.lp.begin;
  L.m = L.lp.mid;
  L.e = L.has_loop ? L.lp.end : 0;
  L.d = L.m - L.b;
  if (!L.has_loop) return L;
  const int b = L.b, m = L.m, d = L.d;
  if (L.e - m != d) L.fail_loop("the two recorded iterations differ");
  for (int k = b; k < m; ++k) {
    const RecNode &na = nodes[size_t(k)], &nb = nodes[size_t(k + d)];
    if (na.op != nb.op || na.unit != nb.unit) L.fail_loop("the two recorded iterations differ");
    for (int slot = 0; slot < 3; ++slot) {
      const int oa = operand(na, slot), ob = operand(nb, slot);
      if (oa == ob) continue;                           // a value from before the loop, or none
      if (oa >= b && oa < m && ob == oa + d) continue;  // within the iteration
      if (oa >= 0 && oa < b && ob >= b && ob < m) {     // carried
        auto [it, fresh] = L.var_of_next.try_emplace(ob, int(L.vars.size()));
        if (fresh) L.vars.push_back({oa, ob});
        if (L.vars[size_t(it->second)].init != oa) L.fail_loop("one value, two starting values");
        L.var_at[4 * k + slot] = it->second;
        continue;
      }
      L.fail_loop("an operand the printer cannot place");
    }
  }
  if (!L.var_of_next.count(m - 1)) L.fail_loop("no loop mask");
  return L;
}

// Step 2: the live nodes, reachable from the outputs and the kill mask (operands precede their
// users). The whole first copy of a loop body is kept; the second never is.
std::vector<char> live_nodes(const Recording& rec, const LoopPlan& L) {
  const int n = int(rec.nodes.size());
  std::vector<char> live(size_t(n), 0);
  auto mark = [&](int id) {
    if (id >= 0) live[size_t(id)] = 1;
  };
  auto mark_ref = [&](int user, int slot, int id) {
    const int v = L.var_read(user, slot, id);
    if (v >= 0) {
      mark(L.vars[size_t(v)].init);
      mark(L.vars[size_t(v)].next);
    } else {
      mark(id);
    }
  };
  for (const auto& o : rec.outputs)
    for (int id : o) mark_ref(n, 0, id);
  mark_ref(n, 0, rec.kill);
  if (L.has_loop) {
    for (int k = L.b; k < L.m; ++k) live[size_t(k)] = 1;
    for (const LoopPlan::Carried& c : L.vars) mark(c.init);
    mark(L.lp.entry);
  }
  for (int i = n - 1; i >= 0; --i) {
    if (L.has_loop && i >= L.m && i < L.e) continue;
    if (live[size_t(i)])
      for (int slot = 0; slot < 3; ++slot) mark_ref(i, slot, operand(rec.nodes[size_t(i)], slot));
  }
  return live;
}

std::string loop_var(int v) {
  return "lv" + std::to_string(v);
}

// Step 3: the body of main(), one statement per live node. expr[i] is how later statements
// name node i: a temporary, a constant's k[] entry, a builtin or a swizzle.
struct BodyPrinter {
  const Program& p;
  const Recording& rec;
  const LoopPlan& L;
  const std::vector<char>& live;
  GlslProgram& out;
  std::map<int, int> sampler_of_unit;  // unit -> index in out.units
  std::vector<std::string> expr;
  std::string body;
  std::string indent = "  ";

  // The carried values, then the loop: at most max_iterations, left once no longer active.
  void open_loop() {
    for (size_t v = 0; v < L.vars.size(); ++v)
      body += indent +
              (value_of(rec.nodes[size_t(L.vars[v].next)].op) == Value::mask ? "bool " : "float ") +
              loop_var(int(v)) + " = " + expr[size_t(L.vars[v].init)] + ";\n";
    body += indent + "for (int it = 0; it < " + std::to_string(L.lp.max_iterations) + "; ++it) {\n";
    indent = "    ";
    body += indent + "if (!" + loop_var(L.var_of_next.at(L.m - 1)) + ") break;\n";
    out.statements += int(L.vars.size()) + 2;
  }

  // The carried values for the next iteration, and the loop's end.
  void close_loop() {
    for (size_t v = 0; v < L.vars.size(); ++v)
      body += indent + loop_var(int(v)) + " = " + expr[size_t(L.vars[v].next)] + ";\n";
    out.statements += int(L.vars.size());
    indent = "  ";
    body += indent + "}\n";
  }

  const std::string& sampler(int unit) {
    auto [it, fresh] = sampler_of_unit.try_emplace(unit, int(out.units.size()));
    if (fresh) {
      out.units.push_back(unit);
      out.samplers.push_back("tex_" + p.unit_name(unit));
    }
    return out.samplers[size_t(it->second)];
  }

  void node(int i);

  void print() {
    const int n = int(rec.nodes.size());
    expr.resize(size_t(n));
    for (int i = 0; i < n; ++i) {
      if (L.has_loop && i == L.b) open_loop();
      if (L.has_loop && i == L.m) close_loop();
      if (L.has_loop && i >= L.m && i < L.e) continue;
      if (!live[size_t(i)]) continue;
      node(i);
    }
  }
};

// The statement (or just the name) of live node i.
void BodyPrinter::node(int i) {
  const RecNode& nd = rec.nodes[size_t(i)];
  // Operand `id` in slot `slot` of this node: its expression, or the loop variable it reads.
  std::string op_text;
  auto ref = [&](int id) -> const std::string& {
    const int slot = id == nd.a ? 0 : id == nd.b ? 1 : 2;
    const int v = L.var_read(i, slot, id);
    if (v < 0) return expr[size_t(id)];
    op_text = loop_var(v);
    return op_text;
  };
  std::string ta, tb, tc;
  auto e = [&](int id) -> const std::string& {
    // Each slot keeps its own text: one expression may name several operands.
    std::string& keep = id == nd.a ? ta : id == nd.b ? tb : tc;
    keep = ref(id);
    return keep;
  };
  std::string t = std::to_string(i), mname = t;
  t.insert(0, 1, 't');
  mname.insert(0, 1, 'm');
  auto def_float = [&](const std::string& rhs) {
    body += indent + "EXACT float " + t + " = " + rhs + ";\n";
    expr[size_t(i)] = t;
    ++out.statements;
  };
  auto def_mask = [&](const std::string& rhs) {
    body += indent + "bool " + mname + " = " + rhs + ";\n";
    expr[size_t(i)] = mname;
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
      std::string v = "f";  // (not "f" + to_string: GCC 12's false -Wrestrict, PR 105651)
      v += std::to_string(i);
      const std::string at = nd.op == Op::fetch_own
                                 ? "own_texel(" + s + ")"
                                 : "texel_at(" + s + ", " + e(nd.a) + ", " + e(nd.b) + ")";
      body += indent + "vec4 " + v + " = texelFetch(" + s + ", " + at + ", 0);\n";
      expr[size_t(i)] = v;
      ++out.statements;
      break;
    }
    case Op::channel:
      expr[size_t(i)] = e(nd.a) + "." + "xyzw"[nd.unit];
      break;
  }
}

// Step 4: the end of main(): the discard, then the output registers. After the loop, a read of
// its second copy is a read of a loop variable.
void print_outputs(const Recording& rec, const LoopPlan& L, BodyPrinter& bp) {
  const int n = int(rec.nodes.size());
  auto final_ref = [&](int id) {
    const int v = L.var_read(n, 0, id);
    return v < 0 ? bp.expr[size_t(id)] : loop_var(v);
  };
  if (rec.kill >= 0) {
    bp.body += "  if (" + final_ref(rec.kill) + ") discard;\n";
    ++bp.out.statements;
  }
  for (size_t o = 0; o < rec.outputs.size(); ++o) {
    const auto& c = rec.outputs[o];
    bp.body += "  out" + std::to_string(o) + " = vec4(" + final_ref(c[0]) + ", " + final_ref(c[1]) +
               ", " + final_ref(c[2]) + ", " + final_ref(c[3]) + ");\n";
  }
}

// Step 5: what comes before main(): the header, the uniforms (samplers and k[]), the outputs and
// the texRECT helpers.
std::string declarations(const Program& p, const Recording& rec, const GlslProgram& out) {
  std::string s;
  s += "#version 330 core\n";
  s += std::string("// ") + p.name() + " (paper: " + p.paper_name() +
       "), generated from its recording (vgpu/record.h: a C++ functor run once on recording "
       "lanes, or a kernel written in Python).\n";
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
  return s;
}

}  // namespace

GlslProgram to_glsl(const Program& p, const Recording& rec, bool annotate) {
  const LoopPlan loop = plan_loop(p, rec);
  const std::vector<char> live = live_nodes(rec, loop);
  GlslProgram out;
  BodyPrinter bp{p, rec, loop, live, out, {}, {}, {}, "  "};
  bp.print();
  print_outputs(rec, loop, bp);
  // The declarations name the samplers and constants the body used.
  std::string s = declarations(p, rec, out);
  s += "void main() {\n" + bp.body + "}\n";
  if (annotate && !out.constants.empty()) {
    s += "// constants and uniforms, as this run set them:\n";
    for (size_t i = 0; i < out.constants.size(); ++i)
      s += "//   k[" + std::to_string(i) + "] = " + float_text(out.constants[i]) + "\n";
  }
  out.source = std::move(s);
  return out;
}

}  // namespace vgpu
