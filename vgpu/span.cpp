// In-order issue of one loop iteration on one lane (see span.h).
#include "vgpu/span.h"

#include <algorithm>
#include <vector>

namespace vgpu {

namespace {

// A time in the schedule, kept as the fetch latencies and operation units it is made of.
struct Time {
  int fetches = 0, units = 0;
  long at(int fetch_units) const { return long(fetches) * fetch_units + units; }
};

// Operations that cost nothing: values and components of a texel already fetched.
bool free_op(Op o) {
  return o == Op::constant || o == Op::frag_x || o == Op::frag_y || o == Op::channel ||
         o == Op::mask_const;
}

}  // namespace

LoopChain loop_chain(const Recording& r, int fetch_units) {
  if (r.loops.empty()) return {};
  const RecLoop& lp = r.loops.front();
  std::vector<Time> ready(size_t(lp.mid - lp.begin));
  auto later = [&](const Time& a, const Time& b) {
    return b.at(fetch_units) > a.at(fetch_units) ? b : a;
  };
  Time issue, end;
  for (int i = lp.begin; i < lp.mid; ++i) {
    const RecNode& n = r.nodes[size_t(i)];
    Time operands;  // the latest operand of this iteration (earlier values are ready at 0)
    for (int o : {n.a, n.b, n.c})
      if (o >= lp.begin && o < i) operands = later(operands, ready[size_t(o - lp.begin)]);
    Time& t = ready[size_t(i - lp.begin)];
    if (free_op(n.op)) {
      t = operands;
      continue;
    }
    Time next = issue;
    ++next.units;
    issue = later(next, operands);
    t = issue;
    if (n.op == Op::fetch || n.op == Op::fetch_own)
      ++t.fetches;
    else
      ++t.units;
    end = later(end, t);
  }
  return {end.fetches, end.units};
}

}  // namespace vgpu
