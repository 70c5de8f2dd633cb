// How a walk's pass sequence runs, apart from which passes it issues. A walk (the grid's in
// host/trace/walks/grid_walk.h) is written once as a template over X and runs three ways:
//   DeviceWalker  pass by pass on the device (the emulator or the GL device), or as the replay
//                 of a batch walk's tallies (the emulator's statistics, loads and read-backs);
//   BatchWalker   one batch of 8 neighbouring pixels through every pass, its ray state in
//                 registers (vgpu/batch.h), tallying each pass for the replay;
//   CheckWalker   every pass site once, to check the bindings allow a batch walk.
// run_walk() picks: batches, then the replay, where they apply; pass by pass elsewhere.
//
// A walk is a class with
//   struct Cursor;                        where the walk is (current texture of each pair)
//   template <class X> void walk(X& x, Cursor& c);   the pass sequence; each pass and query
//       goes through x.pass(key, program, inputs, targets, work) and x.count(key, program,
//       input, work, write) with a PassKey naming it; x.fill / x.copy set masks, x.traced /
//       x.unfinished count rays, X::any(n) says whether a count is non-zero;
//   WriteBack write_back(const Cursor& c) const;     the state a batch hands back.
// Include this only where a walk is instantiated (one .cpp per walk).
#pragma once
#define VGPU_WALK_H_INSIDE

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cstdint>
#include <exception>
#include <initializer_list>
#include <memory>
#include <mutex>
#include <vector>

#include "host/common/parallel.h"
#include "host/trace/passes.h"
#include "vgpu/batch.h"
#include "vgpu/gpu.h"

namespace host::walk {

using vgpu::Stencil;
using vgpu::Texture;

// Sites a walk may name (each walk numbers its own from 0).
inline constexpr int kMaxSites = 16;

// A pass of the walk: the site of the call, the step (-1 before the first) and the index k
// within a step (-1 outside an inner loop) name one pass of the walk's sequence; `parity` says
// which texture of each ping-pong pair is current (bit 0 traversal, 1 voxel state, 2
// intersection), which fixes the bindings.
struct PassKey {
  int step, k;
  int site;  // one of the walk's sites, below kMaxSites
  uint8_t parity = 0;
};

// Names the passes of a walk at cursor c (a ListWalk::Cursor: current traversal, list state
// and intersection textures): key(step, k, site) is the PassKey with c's parity as it is when
// the key is made.
template <class Cursor>
auto keys(const Cursor& c) {
  return [&c](int step, int k, int site) {
    return PassKey{step, k, site,
                   uint8_t(c.trav.which() | c.vs.which() << 1 | c.isect.which() << 2)};
  };
}

// Per pass of the walk (by PassKey), a T: grown on first use, cheap to look up.
template <class T>
class Keyed {
 public:
  [[gnu::always_inline]] T& at(const PassKey& key) {
    // A walk asks for one step's passes in a row: each site's row of the last step is kept.
    auto& [step, row] = rows_[size_t(key.site)];
    if (step != key.step || !row) [[unlikely]]
      row = &step_row(key, step);
    const size_t j = size_t(key.k + 1);
    if (row->size() <= j) [[unlikely]]
      row->resize(j + 1);
    return (*row)[j];
  }
  // The host memory its rows hold, bytes.
  uint64_t bytes() const {
    uint64_t b = 0;
    for (const auto& by_step : v_) {
      b += by_step.capacity() * sizeof(std::vector<T>);
      for (const std::vector<T>& row : by_step) b += row.capacity() * sizeof(T);
    }
    return b;
  }
  // f(key, value) for every pass seen.
  template <class Fn>
  void for_each(Fn&& f) {
    for (int site = 0; site < kMaxSites; ++site)
      for (size_t i = 0; i < v_[size_t(site)].size(); ++i)
        for (size_t j = 0; j < v_[size_t(site)][i].size(); ++j)
          f(PassKey{int(i) - 1, int(j) - 1, site}, v_[size_t(site)][i][j]);
  }

 private:
  std::vector<T>& step_row(const PassKey& key, int& step) {
    auto& by_step = v_[size_t(key.site)];
    const size_t i = size_t(key.step + 1);
    if (by_step.size() <= i) by_step.resize(i + 1);
    step = key.step;
    return by_step[i];
  }

  std::array<std::vector<std::vector<T>>, kMaxSites> v_;
  // Per site, the step asked last and its row (by_step's vectors move when it grows, but only
  // when a new step of the same site is asked for, and that refreshes the row).
  std::array<std::pair<int, std::vector<T>*>, kMaxSites> rows_{};
};

// The walk on the device, pass by pass; with `replay`, each pass charges what a batch walk
// tallied for it instead of running (the device is then the vgpu).
struct DeviceWalker {
  PassRunner& r;
  Keyed<vgpu::PassTally>* replay = nullptr;
  using Count = uint64_t;
  static bool any(Count n) { return n > 0; }
  // The masks: as the walk changes them, or left as the batch walk finished them.
  void fill(Stencil& m, uint8_t v) {
    if (!replay) m.fill(v);
  }
  void copy(Stencil& to, const Stencil& from) {
    if (!replay) to = from;
  }
  void traced(Count n) { r.counts.rays_traced += n; }
  void unfinished(Count n) { r.counts.rays_unfinished += n; }
  void arm(const PassKey& key) {
    if (replay) static_cast<vgpu::Gpu&>(r.device()).replay_next(replay->at(key));
  }
  void pass(const PassKey& key, const vgpu::Program& p, std::initializer_list<const Texture*> in,
            std::initializer_list<Texture*> out, const Stencil* work) {
    arm(key);
    r.pass(p, in, out, work);
  }
  Count count(const PassKey& key, const vgpu::Program& p, const Texture& in, const Stencil* work,
              Stencil* write) {
    arm(key);
    return r.count(p, in, work, write);
  }
};

}  // namespace host::walk

// The batch fast path: an emulator shortcut, not modelled hardware (it changes the host's time,
// never a count or a texel). Read it after this file: host/trace/walks/batch_walk.h.
#include "host/trace/walks/batch_walk.h"

namespace host::walk {

// Runs the walk from c: in batches where that applies, otherwise pass by pass on the device.
template <class Walk>
void run_walk(PassRunner& r, Walk& walk, typename Walk::Cursor& c) {
  if (run_in_batches(r, walk, c)) return;
  DeviceWalker x{r};
  walk.walk(x, c);
}

}  // namespace host::walk
