// The recorded-program executor: a recording compiled into register instructions, run over any
// lane family through Fragments<L> (vgpu/recorded_program.h says why that way).
#include "vgpu/recorded_program.h"

#include <atomic>
#include <bit>
#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

namespace vgpu {

namespace {

int operand(const RecNode& nd, int slot) {
  return slot == 0 ? nd.a : slot == 1 ? nd.b : nd.c;
}

// A stamp no program's constants had before (vgpu::RecordedProgram::stamp_).
uint64_t next_stamp() {
  static std::atomic<uint64_t> next{1};
  return next.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace

RecordedProgram::RecordedProgram(Recording rec, std::string name, std::string paper_name,
                                 int outputs, std::vector<std::string> units)
    : rec_(std::move(rec)),
      name_(std::move(name)),
      paper_name_(std::move(paper_name)),
      outputs_(outputs),
      units_(std::move(units)),
      stamp_(next_stamp()) {
  compile();
}

std::vector<std::string> RecordedProgram::uniform_names() const {
  std::vector<std::string> names;
  for (const RecUniform& u : rec_.uniforms) names.push_back(u.name);
  return names;
}

bool RecordedProgram::has_uniform(std::string_view name) const {
  for (const RecUniform& u : rec_.uniforms)
    if (u.name == name) return true;
  return false;
}

float RecordedProgram::uniform(std::string_view name) const {
  for (size_t i = 0; i < rec_.uniforms.size(); ++i)
    if (rec_.uniforms[i].name == name) return values_[i];
  throw std::invalid_argument("program '" + name_ + "' has no uniform '" + std::string(name) + "'");
}

void RecordedProgram::set_uniform(std::string_view name, float value) {
  size_t i = 0;
  while (i < rec_.uniforms.size() && rec_.uniforms[i].name != name) ++i;
  if (i == rec_.uniforms.size())
    throw std::invalid_argument("program '" + name_ + "' has no uniform '" + std::string(name) +
                                "'");
  if (std::isnan(value))
    throw std::invalid_argument("program '" + name_ + "': uniform '" + std::string(name) +
                                "' set to NaN");
  if (std::bit_cast<uint32_t>(values_[i]) == std::bit_cast<uint32_t>(value)) return;
  values_[i] = value;
  for (int node : rec_.uniforms[i].nodes) rec_.nodes[size_t(node)].value = value;
  for (std::vector<Instr>* list : {&code_, &constants_})
    for (Instr& in : *list)
      if (in.op == Op::constant) in.value = rec_.nodes[size_t(in.node)].value;
  stamp_ = next_stamp();
}

std::unique_ptr<RecordedProgram> RecordedProgram::of(const Program& p) {
  std::vector<std::string> units;
  for (int u = 0; u < kMaxTextureUnits; ++u) units.push_back(p.unit_name(u));
  auto r = std::make_unique<RecordedProgram>(p.record(), p.name(), p.paper_name(), p.outputs(),
                                             std::move(units));
  r->set_precision(p.precision());
  r->has_passthrough_ = p.has_passthrough();
  r->idle_discards_ = p.idle_discards();
  for (int o = 0; o < p.outputs(); ++o) r->passthrough_[size_t(o)] = p.passthrough(o);
  return r;
}

std::string RecordedProgram::unit_name(int unit) const {
  if (unit >= 0 && unit < int(units_.size())) return units_[size_t(unit)];
  return "unit" + std::to_string(unit);
}

// Checks the recording, finds the loop's carried values (as vgpu/glsl.cpp's plan_loop does: where
// the second recorded iteration reads a node of the first where the first read one from before
// the loop), gives every value a register and writes the instruction list.
void RecordedProgram::compile() {
  auto fail = [&](const std::string& why) {
    throw std::invalid_argument("recorded program '" + name_ + "': " + why);
  };
  const std::vector<RecNode>& nodes = rec_.nodes;
  const int n = int(nodes.size());
  if (outputs_ < 1 || outputs_ > kMaxOutputs)
    fail(std::to_string(outputs_) + " outputs (1 to " + std::to_string(kMaxOutputs) + ")");
  if (int(rec_.outputs.size()) != outputs_)
    fail("the recording has " + std::to_string(rec_.outputs.size()) + " outputs, not " +
         std::to_string(outputs_));
  if (rec_.loops.size() > 1) fail("more than one loop");

  // Every operand names an earlier node of the kind the operation takes.
  for (int i = 0; i < n; ++i) {
    const RecNode& nd = nodes[size_t(i)];
    if (uint8_t(nd.op) > uint8_t(Op::channel)) fail("node " + std::to_string(i) + ": no such op");
    const std::array<Value, 3> want = operands_of(nd.op);
    for (int slot = 0; slot < 3; ++slot) {
      if (want[size_t(slot)] == Value::none) continue;
      const int id = operand(nd, slot);
      if (id < 0 || id >= i || value_of(nodes[size_t(id)].op) != want[size_t(slot)])
        fail("node " + std::to_string(i) + ": operand " + std::to_string(slot) +
             " is not an earlier node of the right kind");
    }
    if ((nd.op == Op::fetch || nd.op == Op::fetch_own) &&
        (nd.unit < 0 || nd.unit >= kMaxTextureUnits))
      fail("node " + std::to_string(i) + ": texture unit " + std::to_string(nd.unit));
    if (nd.op == Op::channel && (nd.unit < 0 || nd.unit > 3))
      fail("node " + std::to_string(i) + ": channel " + std::to_string(nd.unit));
  }
  // Each named uniform's nodes are constants holding one value.
  for (size_t u = 0; u < rec_.uniforms.size(); ++u) {
    const RecUniform& un = rec_.uniforms[u];
    if (un.name.empty()) fail("uniform " + std::to_string(u) + " has no name");
    for (size_t v = 0; v < u; ++v)
      if (rec_.uniforms[v].name == un.name) fail("two uniforms named '" + un.name + "'");
    if (un.nodes.empty()) {
      values_.push_back(0.0f);
      continue;
    }
    for (int id : un.nodes)
      if (id < 0 || id >= n || nodes[size_t(id)].op != Op::constant ||
          std::bit_cast<uint32_t>(nodes[size_t(id)].value) !=
              std::bit_cast<uint32_t>(nodes[size_t(un.nodes[0])].value))
        fail("uniform '" + un.name + "': node " + std::to_string(id) +
             " is not a constant of its value");
    values_.push_back(nodes[size_t(un.nodes[0])].value);
  }

  // The loop: body [b, m) and its second copy [m, e), each ending with the mask_and of the lanes
  // still looping (Fragments<RecordingLanes>::loop).
  has_loop_ = !rec_.loops.empty();
  const RecLoop lp = has_loop_ ? rec_.loops[0] : RecLoop{};
  const int b = lp.begin, m = lp.mid, e = has_loop_ ? lp.end : 0, d = m - b;
  struct Var {
    int init, next;
  };
  std::vector<Var> vars;
  std::map<int, int> var_of_next;  // next node -> variable
  std::map<int, int> var_at;       // 4 * node + slot of the first copy -> variable read there
  if (has_loop_) {
    auto loop_fail = [&](const std::string& why) { fail("its loop cannot be run (" + why + ")"); };
    if (!(0 <= lp.entry && lp.entry < b && b < m && e - m == d && e <= n)) loop_fail("bad bounds");
    if (value_of(nodes[size_t(lp.entry)].op) != Value::mask) loop_fail("the entry is not a mask");
    if (lp.max_iterations < 0) loop_fail("a negative iteration budget");
    const RecNode &next = nodes[size_t(m - 1)], &after = nodes[size_t(e - 1)];
    if (next.op != Op::mask_and || next.a != lp.entry || after.op != Op::mask_and ||
        after.a != m - 1)
      loop_fail("an iteration does not end with the mask of the lanes still looping");
    for (int k = b; k < m; ++k) {
      const RecNode &na = nodes[size_t(k)], &nb = nodes[size_t(k + d)];
      if (na.op != nb.op || na.unit != nb.unit) loop_fail("the two recorded iterations differ");
      for (int slot = 0; slot < 3; ++slot) {
        const int oa = operand(na, slot), ob = operand(nb, slot);
        if (oa == ob) continue;                           // a value from before the loop, or none
        if (oa >= b && oa < m && ob == oa + d) continue;  // within the iteration
        if (oa >= 0 && oa < b && ob >= b && ob < m) {     // carried
          auto [it, fresh] = var_of_next.try_emplace(ob, int(vars.size()));
          if (fresh) vars.push_back({oa, ob});
          if (vars[size_t(it->second)].init != oa) loop_fail("one value, two starting values");
          var_at[4 * k + slot] = it->second;
          continue;
        }
        loop_fail("an operand read from neither the iteration nor before the loop");
      }
    }
    // The loop's own mask_and nodes make the lanes still looping a carried value (the entry
    // first, m - 1 after each iteration).
    if (!var_of_next.count(m - 1) || vars[size_t(var_of_next.at(m - 1))].init != lp.entry)
      loop_fail("no loop mask");
  }

  // Registers: one per value computed outside the second copy (and its closing mask_and, the
  // active lanes' variable), a fetch's four channels in a row, a channel the fetch's own.
  std::vector<int32_t> reg(size_t(n), -1);
  auto skipped = [&](int i) { return has_loop_ && i >= m - 1 && i < e; };
  for (int i = 0; i < n; ++i) {
    if (skipped(i)) continue;
    const RecNode& nd = nodes[size_t(i)];
    if (nd.op == Op::channel) {
      if (reg[size_t(nd.a)] < 0)
        fail("node " + std::to_string(i) + ": a channel of a fetch it cannot see");
      reg[size_t(i)] = reg[size_t(nd.a)] + nd.unit;
      continue;
    }
    switch (value_of(nd.op)) {
      case Value::mask:
        reg[size_t(i)] = mask_regs_++;
        break;
      case Value::texel:
        reg[size_t(i)] = float_regs_;
        float_regs_ += 4;
        break;
      default:
        reg[size_t(i)] = float_regs_++;
        break;
    }
  }
  std::vector<int32_t> var_reg(vars.size());
  std::vector<bool> var_mask(vars.size());
  for (size_t v = 0; v < vars.size(); ++v) {
    var_mask[v] = value_of(nodes[size_t(vars[v].next)].op) == Value::mask;
    var_reg[v] = var_mask[v] ? mask_regs_++ : float_regs_++;
  }

  // The register that node `user` (n: the outputs and the discard) reads in operand `slot`.
  auto resolve = [&](int user, int slot, int id) -> int32_t {
    if (has_loop_ && user >= b && user < m) {
      auto it = var_at.find(4 * user + slot);
      if (it != var_at.end()) return var_reg[size_t(it->second)];
    }
    if (has_loop_ && user >= e && id >= m && id < e) {
      auto it = var_of_next.find(id - d);
      if (it == var_of_next.end())
        fail("a value of its loop body, not carried, read after the loop");
      return var_reg[size_t(it->second)];
    }
    if (has_loop_ && user >= e && id >= b && id < m)
      fail("a node of its loop body's first iteration read after the loop");
    return reg[size_t(id)];
  };

  for (int i = 0; i < n; ++i) {
    if (has_loop_ && i == b) body_begin_ = int(code_.size());
    if (has_loop_ && i == m - 1) body_end_ = int(code_.size());
    if (skipped(i)) continue;
    const RecNode& nd = nodes[size_t(i)];
    if (nd.op == Op::channel) continue;  // a register of its fetch
    Instr in;
    in.op = nd.op;
    in.unit = int8_t(nd.unit);
    in.dst = reg[size_t(i)];
    in.value = nd.value;
    in.node = i;
    const std::array<Value, 3> want = operands_of(nd.op);
    if (want[0] != Value::none) in.a = resolve(i, 0, nd.a);
    if (want[1] != Value::none) in.b = resolve(i, 1, nd.b);
    if (want[2] != Value::none) in.c = resolve(i, 2, nd.c);
    code_.push_back(in);
  }

  for (int k = 0; k <= int(code_.size()); ++k) {
    if (k == body_begin_) computed_body_begin_ = int(computed_.size());
    if (k == body_end_) computed_body_end_ = int(computed_.size());
    if (k == int(code_.size())) break;
    (code_[size_t(k)].op == Op::constant ? constants_ : computed_).push_back(code_[size_t(k)]);
  }

  if (has_loop_) {
    max_iterations_ = lp.max_iterations;
    entry_ = reg[size_t(lp.entry)];
    const int active_var = var_of_next.at(m - 1);
    active_ = var_reg[size_t(active_var)];
    more_ = resolve(m - 1, 1, nodes[size_t(m - 1)].b);
    for (size_t v = 0; v < vars.size(); ++v) {
      if (int(v) == active_var) continue;  // the body's parameter
      starts_.push_back({var_reg[v], reg[size_t(vars[v].init)], var_mask[v]});
      carries_.push_back({var_reg[v], reg[size_t(vars[v].next)], var_mask[v]});
    }
  }
  for (const std::array<int, 4>& o : rec_.outputs) {
    std::array<int32_t, 4> r{};
    for (int c = 0; c < 4; ++c) {
      const int id = o[size_t(c)];
      if (id < 0 || id >= n || value_of(nodes[size_t(id)].op) != Value::number)
        fail("an output channel that is not a float node");
      r[size_t(c)] = resolve(n, 0, id);
    }
    out_regs_.push_back(r);
  }
  if (rec_.kill >= 0) {
    if (rec_.kill >= n || value_of(nodes[size_t(rec_.kill)].op) != Value::mask)
      fail("a discard that is not a mask node");
    kill_ = resolve(n, 0, rec_.kill);
  }
}

// Instructions [from, to) over the registers fr (floats) and mr (masks). Each is the operation a
// functor's code performs on L's lanes (the same overloads: vgpu's min, max, select, rsqrt), so it
// rounds, counts and records as the functor's does.
template <class L>
void RecordedProgram::step(Fragments<L>& f, typename L::F* fr, typename L::M* mr, const Instr* code,
                           int from, int to, int prefix) const {
  using F = typename L::F;
  using M = typename L::M;
  for (int k = from; k < to; ++k) {
    const Instr& in = code[k];
    switch (in.op) {
      case Op::constant:
        if constexpr (L::recording) {
          // The constants Fragments::reset made before the run (the cleared outputs) are already
          // in the recording being made, at the same places: reused, so that recording a
          // recorded program gives back the recording it was made from.
          const std::vector<RecNode>& now = Recorder::current->nodes;
          if (in.node < prefix && now[size_t(in.node)].op == Op::constant &&
              std::bit_cast<uint32_t>(now[size_t(in.node)].value) ==
                  std::bit_cast<uint32_t>(in.value)) {
            fr[in.dst] = F::node(in.node);
            break;
          }
        }
        fr[in.dst] = F(in.value);
        break;
      case Op::frag_x:
        fr[in.dst] = f.x;
        break;
      case Op::frag_y:
        fr[in.dst] = f.y;
        break;
      case Op::add:
        fr[in.dst] = fr[in.a] + fr[in.b];
        break;
      case Op::sub:
        fr[in.dst] = fr[in.a] - fr[in.b];
        break;
      case Op::mul:
        fr[in.dst] = fr[in.a] * fr[in.b];
        break;
      case Op::div:
        fr[in.dst] = fr[in.a] / fr[in.b];
        break;
      case Op::neg:
        fr[in.dst] = -fr[in.a];
        break;
      case Op::min:
        fr[in.dst] = min(fr[in.a], fr[in.b]);
        break;
      case Op::max:
        fr[in.dst] = max(fr[in.a], fr[in.b]);
        break;
      case Op::abs:
        fr[in.dst] = abs(fr[in.a]);
        break;
      case Op::floor:
        fr[in.dst] = floor(fr[in.a]);
        break;
      case Op::sqrt:
        fr[in.dst] = sqrt(fr[in.a]);
        break;
      case Op::rsqrt:
        fr[in.dst] = rsqrt(fr[in.a]);
        break;
      case Op::select:
        fr[in.dst] = select(mr[in.a], fr[in.b], fr[in.c]);
        break;
      case Op::lt:
        mr[in.dst] = fr[in.a] < fr[in.b];
        break;
      case Op::le:
        mr[in.dst] = fr[in.a] <= fr[in.b];
        break;
      case Op::gt:
        mr[in.dst] = fr[in.a] > fr[in.b];
        break;
      case Op::ge:
        mr[in.dst] = fr[in.a] >= fr[in.b];
        break;
      case Op::eq:
        mr[in.dst] = fr[in.a] == fr[in.b];
        break;
      case Op::ne:
        mr[in.dst] = fr[in.a] != fr[in.b];
        break;
      case Op::mask_const:
        mr[in.dst] = M(in.value != 0);
        break;
      case Op::mask_and:
        mr[in.dst] = mr[in.a] && mr[in.b];
        break;
      case Op::mask_or:
        mr[in.dst] = mr[in.a] || mr[in.b];
        break;
      case Op::mask_not:
        mr[in.dst] = !mr[in.a];
        break;
      case Op::fetch:
      case Op::fetch_own: {
        const Vec4<F> t =
            in.op == Op::fetch_own ? f.fetch_own(in.unit) : f.fetch(in.unit, fr[in.a], fr[in.b]);
        fr[in.dst] = t.x;
        fr[in.dst + 1] = t.y;
        fr[in.dst + 2] = t.z;
        fr[in.dst + 3] = t.w;
        break;
      }
      case Op::channel:  // never an instruction: a register of its fetch
        break;
    }
  }
}

template <class L>
void RecordedProgram::execute(Fragments<L>& f) const {
  using F = typename L::F;
  using M = typename L::M;
  // The register file, per thread and lane family (row workers run batches concurrently), grown
  // to the largest program this thread has run: no allocation per batch.
  thread_local std::vector<F> fregs;
  thread_local std::vector<M> mregs;
  if (fregs.size() < size_t(float_regs_)) fregs.resize(size_t(float_regs_));
  if (mregs.size() < size_t(mask_regs_)) mregs.resize(size_t(mask_regs_));
  F* fr = fregs.data();
  M* mr = mregs.data();
  int prefix = 0;
  if constexpr (L::recording) prefix = int(Recorder::current->nodes.size());
  // The recording and counting runs go through every node in order (the recording keeps each
  // constant's place); the computing families set the constants only where the thread's
  // registers last held another program's or other values (stamps are never reused).
  constexpr bool hoisted = !L::recording && !L::counting;
  const std::vector<Instr>& list = hoisted ? computed_ : code_;
  const Instr* code = list.data();
  const int end = int(list.size());
  const int body_begin = hoisted ? computed_body_begin_ : body_begin_;
  const int body_end = hoisted ? computed_body_end_ : body_end_;
  if constexpr (hoisted) {
    thread_local uint64_t loaded = 0;  // the stamp whose constants the registers hold
    if (loaded != stamp_) {
      for (const Instr& in : constants_) fr[in.dst] = F(in.value);
      loaded = stamp_;
    }
  }
  auto copy = [&](const Copy& c) {
    if (c.mask)
      mr[c.var] = mr[c.from];
    else
      fr[c.var] = fr[c.from];
  };
  if (!has_loop_) {
    step(f, fr, mr, code, 0, end, prefix);
  } else {
    step(f, fr, mr, code, 0, body_begin, prefix);
    for (const Copy& c : starts_) copy(c);
    // Fragments::loop decides the iterations (and counts them, or records the body twice); the
    // body is one pass over the first recorded iteration, reading the carried values' registers.
    const M still = f.loop(max_iterations_, mr[entry_], [&](const M& active) -> M {
      mr[active_] = active;
      step(f, fr, mr, code, body_begin, body_end, prefix);
      const M more = mr[more_];  // read before the carried values move on (it may be one)
      for (const Copy& c : carries_) copy(c);
      return more;
    });
    mr[active_] = still;
    step(f, fr, mr, code, body_end, end, prefix);
  }
  for (int o = 0; o < outputs_; ++o) {
    const std::array<int32_t, 4>& r = out_regs_[size_t(o)];
    f.out(o) = Vec4<F>{fr[r[0]], fr[r[1]], fr[r[2]], fr[r[3]]};
  }
  if (kill_ >= 0) f.discard(mr[kill_]);
}

void RecordedProgram::run(Fragments<SimdLanes<1>>& f) const {
  execute(f);
}
void RecordedProgram::run(Fragments<SimdLanes<4>>& f) const {
  execute(f);
}
void RecordedProgram::run(Fragments<SimdLanes<8>>& f) const {
  execute(f);
}
void RecordedProgram::run(Fragments<SimdLanes<16>>& f) const {
  execute(f);
}
void RecordedProgram::run(Fragments<CountingLanes>& f) const {
  execute(f);
}
void RecordedProgram::run(Fragments<RoundedLanes<1, Format::fp24>>& f) const {
  execute(f);
}
void RecordedProgram::run(Fragments<RoundedLanes<8, Format::fp24>>& f) const {
  execute(f);
}
void RecordedProgram::run(Fragments<RoundedLanes<1, Format::fp16>>& f) const {
  execute(f);
}
void RecordedProgram::run(Fragments<RoundedLanes<8, Format::fp16>>& f) const {
  execute(f);
}
void RecordedProgram::run(Fragments<RecordingLanes>& f) const {
  execute(f);
}

}  // namespace vgpu
