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

bool fetch_op(Op o) {
  return o == Op::fetch || o == Op::fetch_own;
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
    if (fetch_op(n.op))
      ++t.fetches;
    else
      ++t.units;
    end = later(end, t);
  }
  return {end.fetches, end.units};
}

int loop_dependent_operations(const Recording& r) {
  if (r.loops.empty()) return 0;
  const RecLoop& lp = r.loops.front();
  const int b = lp.begin, e = lp.mid;
  // after[i]: node i depends on a fetch of the iteration; before[i]: a fetch of it depends on i.
  std::vector<char> after(size_t(e - b), 0), before(size_t(e - b), 0);
  for (int i = b; i < e; ++i) {
    const RecNode& n = r.nodes[size_t(i)];
    for (int o : {n.a, n.b, n.c})
      if (o >= b && o < i)
        after[size_t(i - b)] |= char(after[size_t(o - b)] || fetch_op(r.nodes[size_t(o)].op));
  }
  // A fetch whose address passes through a select's value is a fetch the driver's code makes
  // only on that select's side (it turns each select into an IF/ELSE block): what feeds it
  // through the select waits only on the lanes and iterations that take that side. Only the
  // select's mask is followed back.
  for (int i = e - 1; i >= b; --i) {
    const RecNode& n = r.nodes[size_t(i)];
    const char feeds = char(before[size_t(i - b)] || fetch_op(n.op));
    for (int o : {n.a, n.b, n.c})
      if (o >= b && o < i && (n.op != Op::select || o == n.a)) before[size_t(o - b)] |= feeds;
  }
  int count = 0;
  for (int i = b; i < e; ++i) {
    const Op o = r.nodes[size_t(i)].op;
    if (!free_op(o) && !fetch_op(o) && after[size_t(i - b)] && before[size_t(i - b)]) ++count;
  }
  return count;
}

}  // namespace vgpu
