// Ping-pong pairs: how a multipass tracer keeps per-pixel state that a pass both reads and
// replaces.
//
// A fragment program of a 2004 card cannot read the texture it is writing: the texels it reads
// might already hold this pass's results for some fragments and not yet for others, so the
// answer would depend on the order the card happens to draw in. So every piece of state that a
// pass updates (the rays, the intersection so far, the colour, a walk's position in the grid)
// lives in two textures, A and B. A pass reads the current one and writes the next one; then the
// two swap roles, and the texture just written is current for the following pass. Nothing is
// copied: only which of the two is "current" changes.
//
// PingPong<T> owns the two (made and counted by name: pair[0] is A, pair[1] is B) and remembers
// which is current. PingPongRef<T> is the same current/next/swap over a pair it does not own: a
// value that copies cheaply, for a walk's cursor (host/trace/walks/walk.h runs one copy per batch
// of pixels), written back into its PingPong when the walk ends.
#pragma once

namespace host {

template <class T>
class PingPong {
 public:
  PingPong() = default;
  // A pair of handles to textures kept elsewhere (PingPong<vgpu::Texture*>), A current.
  PingPong(T a, T b) : pair{a, b} {}

  T& current() { return pair[which_]; }
  const T& current() const { return pair[which_]; }
  // The one the next pass writes.
  T& next() { return pair[which_ ^ 1]; }
  const T& next() const { return pair[which_ ^ 1]; }
  // After a pass wrote next(), it becomes current.
  void swap() { which_ ^= 1; }
  // Which is current: 0 for A, 1 for B.
  int which() const { return which_; }
  void make_current(int which) { which_ = which; }

  // A and B by name, for making, uploading and counting the textures.
  T& operator[](int i) { return pair[i]; }
  const T& operator[](int i) const { return pair[i]; }

  T pair[2];

 private:
  int which_ = 0;
};

template <class T>
class PingPongRef {
 public:
  PingPongRef() = default;
  explicit PingPongRef(PingPong<T>& p) : pair_(p.pair), which_(p.which()) {}
  T& current() const { return pair_[which_]; }
  T& next() const { return pair_[which_ ^ 1]; }
  void swap() { which_ ^= 1; }
  int which() const { return which_; }

 private:
  T* pair_ = nullptr;
  int which_ = 0;
};

}  // namespace host
