// The longest wait of one lane through one iteration of a program's loop: what a lane costs
// however many lanes run beside it (the span of the pass, in the work-span sense: a pass takes
// at least its work over the processors and at least its longest lane; a greedy scheduler
// finishes within the sum, Brent 1974). The cost model adds it to a looping pass's work.
//
// One iteration of the recorded loop body (Recording::loops, the first copy) is issued in the
// order the functor performed it, one operation per time unit, on one lane: an operation
// issues one unit after the one before, or when its operands are ready if later; an
// arithmetic result is ready one unit after it issues, a fetched texel `fetch_units` units
// after. The iteration ends when its last result is ready. Operands from before the loop, or
// carried from the previous iteration, are ready when it starts. The answer is split into the
// fetch waits and the operation units the schedule's end is made of, so that a profile prices
// it with its own latencies: fetches x fetch latency + operations x operation latency.
#pragma once

#include "vgpu/record.h"

namespace vgpu {

struct LoopChain {
  int fetches = 0;     // fetch latencies the iteration's end waits through
  int operations = 0;  // operation units (issue and arithmetic latency) it waits through
};

// The loop of `r` (its first recorded copy); zeros without a loop. fetch_units: how many
// operation units a fetch's latency lasts in the schedule (the split depends on it only where
// two paths come close; the H200's measured ratio is about 100, docs/studies/structures.md).
LoopChain loop_chain(const Recording& r, int fetch_units = 100);

// The operations of one iteration of the loop of `r` (its first recorded copy) that depend on a
// texel fetched in the same iteration and that a later fetch of it depends on: the arithmetic
// between two fetches, an address computed from a fetched texel in the same iteration (the
// two-level grid's sub-cell from its coarse cell, then the sub-cell's list). A lane cannot issue
// it before its fetch returns, nor its next fetch before it is done, so it does not overlap
// with that lane's fetches. Within one iteration only: an address carried to the next
// iteration (the BVH's next node, the vertices of the triangle a list entry named) waits across
// iterations, which loop_chain's longest lane prices. A fetch whose address passes through a
// select's value is made on that side only (the driver turns selects into IF/ELSE blocks): what
// feeds it through the select is not counted. Operations that cost nothing (constants, a
// texel's channels) are not counted; 0 without a loop.
int loop_dependent_operations(const Recording& r);

}  // namespace vgpu
