// The kd-tree's host build (see kdtree.h): SAH over clipped bounding-box events, depth first.
#include "host/accel/kdtree.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace host {

namespace {

struct Box {
  glm::dvec3 lo, hi;
  double area() const {
    const glm::dvec3 e = glm::max(hi - lo, glm::dvec3(0.0));
    return 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
  }
};

class Builder {
 public:
  Builder(const Scene& scene, const KdSpec& spec, KdTree& out) : spec_(spec), out_(out) {
    const size_t n = scene.triangle_count();
    tri_lo_.resize(n);
    tri_hi_.resize(n);
    side_.resize(n);
    for (size_t i = 0; i < n; ++i) {
      const glm::dvec3 a(scene.p0[i]), b(scene.p1[i]), c(scene.p2[i]);
      // The sweep below needs every position to compare equal to itself.
      auto finite = [](const glm::dvec3& v) {
        return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
      };
      if (!finite(a) || !finite(b) || !finite(c))
        throw std::invalid_argument("kd-tree: triangle " + std::to_string(i) +
                                    " has a vertex that is not finite");
      // + 0.0 makes a -0 a +0, so that a plane at 0 is stored with one sign whichever of its
      // events a sort puts first.
      tri_lo_[i] = glm::min(a, glm::min(b, c)) + 0.0;
      tri_hi_[i] = glm::max(a, glm::max(b, c)) + 0.0;
    }
    max_depth_ = spec.max_depth > 0
                     ? spec.max_depth
                     : int(std::lround(8.0 + 1.3 * std::log2(double(std::max<size_t>(n, 1)))));
    out_.lists.push_back(-1);
  }

  // The node's triangles: in the order the leaf lists keep (the input's), and per axis sorted by
  // their boxes' low and high ends. Clamping a box to the node's (max with its low end, min with
  // its high end) keeps both orders, so each node's events come sorted from its parent's lists
  // (filtered, in order): no node sorts (KdSpec::events).
  struct End {
    float at;    // the box's end on the list's axis, unclamped (a vertex's float: exact)
    uint32_t t;  // the triangle
  };
  struct Tris {
    std::vector<uint32_t> order;
    std::array<std::vector<End>, 3> by_lo, by_hi;  // each sorted by `at`
  };

  Tris root(size_t n) const {
    Tris t;
    t.order.resize(n);
    for (size_t i = 0; i < n; ++i) t.order[i] = uint32_t(i);
    if (!presorted()) return t;
    auto by = [](const End& x, const End& y) { return x.at < y.at; };
    for (int a = 0; a < 3; ++a) {
      for (uint32_t i : t.order) {
        t.by_lo[a].push_back({float(tri_lo_[i][a]), i});
        t.by_hi[a].push_back({float(tri_hi_[i][a]), i});
      }
      std::sort(t.by_lo[a].begin(), t.by_lo[a].end(), by);
      std::sort(t.by_hi[a].begin(), t.by_hi[a].end(), by);
    }
    return t;
  }

  // Builds the node and its subtree; `node_tris` is emptied once its children's are made.
  double build(Tris&& node_tris, const Box& box, int depth) {
    const std::vector<uint32_t>& tris = node_tris.order;
    out_.depth = std::max(out_.depth, depth + 1);
    const size_t me = out_.nodes.size();
    out_.nodes.emplace_back();
    const double n = double(tris.size());
    const double leaf_cost = spec_.triangle_cost * n;
    int axis = -1;
    double split = 0, best = leaf_cost;
    if (may_split(tris.size(), depth)) {
      if (presorted())
        find_split(node_tris, box, axis, split, best);
      else
        find_split_sorting(tris, box, axis, split, best);
    }
    if (axis < 0) {
      KdNode& node = out_.nodes[me];
      node.axis = 3;
      node.count = int32_t(tris.size());
      node.leaf = tris.empty() ? 0 : int32_t(out_.lists.size());
      for (uint32_t t : tris) out_.lists.push_back(int32_t(t));
      if (!tris.empty()) out_.lists.push_back(-1);
      ++out_.leaves;
      out_.empty_leaves += tris.empty();
      out_.max_leaf = std::max(out_.max_leaf, int(tris.size()));
      return leaf_cost;
    }
    // The split is stored as a float: partition by the float plane, so the walk and the build
    // agree on which side a point lies.
    const float fsplit = float(split);
    const double s = double(fsplit);
    Tris left, right;
    for (uint32_t t : tris) {
      const double lo = std::max(tri_lo_[t][axis], box.lo[axis]);
      const double hi = std::min(tri_hi_[t][axis], box.hi[axis]);
      side_[t] = uint8_t((lo <= s ? 1 : 0) | (hi >= s ? 2 : 0));
      if (lo <= s) left.order.push_back(t);
      if (hi >= s) right.order.push_back(t);
    }
    // The children's sorted lists, for a child that may split (one at the depth limit, or of a
    // single triangle, is a leaf and needs only its order).
    const bool fill_left = presorted() && may_split(left.order.size(), depth + 1);
    const bool fill_right = presorted() && may_split(right.order.size(), depth + 1);
    if (fill_left || fill_right) {
      auto split_list = [&](const std::vector<End>& in, std::vector<End>& l, std::vector<End>& r) {
        if (fill_left) l.reserve(left.order.size());
        if (fill_right) r.reserve(right.order.size());
        for (const End& e : in) {
          if (fill_left && (side_[e.t] & 1)) l.push_back(e);
          if (fill_right && (side_[e.t] & 2)) r.push_back(e);
        }
      };
      for (int a = 0; a < 3; ++a) {
        split_list(node_tris.by_lo[a], left.by_lo[a], right.by_lo[a]);
        split_list(node_tris.by_hi[a], left.by_hi[a], right.by_hi[a]);
      }
    }
    node_tris = Tris{};  // `tris` is gone with it: what follows reads the children's
    Box lb = box, rb = box;
    lb.hi[axis] = s;
    rb.lo[axis] = s;
    out_.nodes[me].axis = axis;
    out_.nodes[me].split = fsplit;
    const double cl = build(std::move(left), lb, depth + 1);
    out_.nodes[me].right = int32_t(out_.nodes.size());
    const double cr = build(std::move(right), rb, depth + 1);
    const double a = box.area();
    return spec_.node_cost + (a > 0 ? (lb.area() * cl + rb.area() * cr) / a : cl + cr);
  }

 private:
  bool presorted() const { return spec_.events != KdEvents::per_node; }
  bool may_split(size_t triangles, int depth) const { return depth < max_depth_ && triangles > 1; }

  // The SAH's cheapest plane among the triangles' clipped box faces (strictly inside the box):
  // each axis's events sorted here (KdEvents::per_node, the reference).
  void find_split_sorting(const std::vector<uint32_t>& tris, const Box& box, int& best_axis,
                          double& best_split, double& best) const {
    const double area = box.area();
    if (!(area > 0)) return;
    const size_t n = tris.size();
    std::vector<std::pair<double, int>> ev;  // (position, 0 = a box ends, 1 = a box starts)
    ev.reserve(2 * n);
    for (int a = 0; a < 3; ++a) {
      if (!(box.hi[a] > box.lo[a])) continue;
      ev.clear();
      for (uint32_t t : tris) {
        ev.emplace_back(std::max(tri_lo_[t][a], box.lo[a]), 1);
        ev.emplace_back(std::min(tri_hi_[t][a], box.hi[a]), 0);
      }
      std::sort(ev.begin(), ev.end());
      size_t nl = 0, nr = n;
      for (size_t i = 0; i < ev.size();) {
        const double p = ev[i].first;
        size_t ends = 0, starts = 0;
        for (; i < ev.size() && ev[i].first == p; ++i) (ev[i].second ? starts : ends) += 1;
        nr -= ends;  // boxes ending at p lie left of a plane just after it
        if (p > box.lo[a] && p < box.hi[a])
          consider(box, area, a, p, nl + starts, nr + ends, best_axis, best_split, best);
        nl += starts;
      }
    }
    no_float_split(box, best_axis, best_split);
  }

  // The same plane from the node's presorted lists (KdEvents::presorted): the events of each
  // axis merged in order of position, those at one position taken together, as the sort above
  // leaves them: the same candidates in the same order, the same costs.
  void find_split(const Tris& t, const Box& box, int& best_axis, double& best_split,
                  double& best) const {
    const double area = box.area();
    if (!(area > 0)) return;
    const size_t n = t.order.size();
    for (int a = 0; a < 3; ++a) {
      if (!(box.hi[a] > box.lo[a])) continue;
      const std::vector<End>& starts_at = t.by_lo[a];
      const std::vector<End>& ends_at = t.by_hi[a];
      const double lo = box.lo[a], hi = box.hi[a];
      auto start = [&](size_t i) { return std::max(double(starts_at[i].at), lo); };
      auto end = [&](size_t i) { return std::min(double(ends_at[i].at), hi); };
      size_t nl = 0, nr = n, i = 0, j = 0;
      while (i < n || j < n) {
        // The sort above puts an end before a start at one position.
        const double p = j < n && (i == n || end(j) <= start(i)) ? end(j) : start(i);
        size_t ends = 0, starts = 0;
        for (; j < n && end(j) == p; ++j) ++ends;
        for (; i < n && start(i) == p; ++i) ++starts;
        nr -= ends;
        if (p > box.lo[a] && p < box.hi[a])
          consider(box, area, a, p, nl + starts, nr + ends, best_axis, best_split, best);
        nl += starts;
      }
    }
    no_float_split(box, best_axis, best_split);
  }

  // One candidate plane at p on axis a, with cl triangles' boxes on its left and cr on its right.
  void consider(const Box& box, double area, int a, double p, size_t cl, size_t cr, int& best_axis,
                double& best_split, double& best) const {
    Box lb = box, rb = box;
    lb.hi[a] = p;
    rb.lo[a] = p;
    // Boxes touching the plane go to both sides (as the partition does).
    double cost = spec_.node_cost +
                  spec_.triangle_cost * (lb.area() * double(cl) + rb.area() * double(cr)) / area;
    if (cl == 0 || cr == 0) cost *= 1.0 - spec_.empty_bonus;
    if (cost < best) {
      best = cost;
      best_axis = a;
      best_split = p;
    }
  }

  // A plane that would not move through float unchanged, or splits nothing off, is no split.
  static void no_float_split(const Box& box, int& best_axis, double best_split) {
    if (best_axis >= 0) {
      const double s = double(float(best_split));
      if (!(s > box.lo[best_axis] && s < box.hi[best_axis])) best_axis = -1;
    }
  }

  const KdSpec& spec_;
  KdTree& out_;
  std::vector<glm::dvec3> tri_lo_, tri_hi_;
  std::vector<uint8_t> side_;  // per triangle, the node being split's: 1 left, 2 right, 3 both
  int max_depth_ = 0;
};

}  // namespace

uint64_t KdTree::references() const {
  uint64_t r = 0;
  for (const KdNode& n : nodes) r += uint64_t(n.axis == 3 ? n.count : 0);
  return r;
}

KdTree build_kdtree(const Scene& scene, glm::vec3 lo, glm::vec3 hi, const KdSpec& spec) {
  const auto t0 = std::chrono::steady_clock::now();
  KdTree kd;
  kd.lo = lo;
  kd.hi = hi;
  Builder b(scene, spec, kd);
  kd.sah_cost =
      b.build(b.root(scene.triangle_count()), Box{glm::dvec3(lo) + 0.0, glm::dvec3(hi) + 0.0}, 0);
  kd.build_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return kd;
}

bool same_tree(const KdTree& a, const KdTree& b) {
  if (a.nodes.size() != b.nodes.size() || a.lists != b.lists || a.depth != b.depth ||
      a.leaves != b.leaves || a.empty_leaves != b.empty_leaves || a.max_leaf != b.max_leaf ||
      a.sah_cost != b.sah_cost || a.lo != b.lo || a.hi != b.hi)
    return false;
  for (size_t i = 0; i < a.nodes.size(); ++i) {
    const KdNode &x = a.nodes[i], &y = b.nodes[i];
    if (std::bit_cast<uint32_t>(x.split) != std::bit_cast<uint32_t>(y.split) || x.axis != y.axis ||
        x.right != y.right || x.leaf != y.leaf || x.count != y.count)
      return false;
  }
  return true;
}

std::string describe(const KdTree& kd) {
  char line[200];
  std::snprintf(line, sizeof line,
                "kd-tree: %zu nodes, depth %d, %d leaves (%d empty) of at most %d triangles",
                kd.nodes.size(), kd.depth, kd.leaves, kd.empty_leaves, kd.max_leaf);
  return line;
}

}  // namespace host
