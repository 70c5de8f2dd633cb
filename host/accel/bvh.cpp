// The BVH's host build (see bvh.h): binned SAH splits, depth-first layout with escape indices.
#include "host/accel/bvh.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <stdexcept>
#include <string>

namespace host {

namespace {

struct Box {
  glm::vec3 lo{1e30f}, hi{-1e30f};
  void extend(const glm::vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void extend(const Box& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  bool empty() const { return lo.x > hi.x; }
  double area() const {
    if (empty()) return 0.0;
    const glm::dvec3 e = glm::dvec3(hi) - glm::dvec3(lo);
    return 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
  }
};

// Traversal and intersection cost of the SAH: a node visit and a triangle test are both about
// two passes of the multipass walk (a step and a query; a test and the next entry).
constexpr double kNodeCost = 1.0, kTriangleCost = 1.0;
constexpr int kMaxDepth = 64;

class Builder {
 public:
  Builder(const Scene& scene, const BvhSpec& spec, Bvh& out) : spec_(spec), out_(out) {
    const size_t n = scene.triangle_count();
    boxes_.resize(n);
    centroids_.resize(n);
    for (size_t i = 0; i < n; ++i) {
      Box b;
      b.extend(scene.p0[i]);
      b.extend(scene.p1[i]);
      b.extend(scene.p2[i]);
      boxes_[i] = b;
      centroids_[i] = 0.5f * (b.lo + b.hi);
    }
    const Bounds sb = scene.bounds();
    const double diag = sb.empty() ? 0.0 : glm::length(glm::dvec3(sb.hi) - glm::dvec3(sb.lo));
    double mag = 0.0;
    if (!sb.empty())
      for (int a = 0; a < 3; ++a)
        mag = std::max({mag, std::abs(double(sb.lo[a])), std::abs(double(sb.hi[a]))});
    pad_ = float(std::max(kBoxPadOfDiagonal * diag, 1e-6 * mag));
    ids_.resize(n);
    std::iota(ids_.begin(), ids_.end(), 0u);
    out_.lists.push_back(-1);
  }

  // Builds the subtree over ids_[begin, end), appending its nodes depth first; returns its SAH
  // cost (expected visits and tests for a ray that enters its box).
  double build(size_t begin, size_t end, int depth) {
    out_.depth = std::max(out_.depth, depth + 1);
    const size_t me = out_.nodes.size();
    out_.nodes.emplace_back();
    Box box, cbox;
    for (size_t i = begin; i < end; ++i) {
      box.extend(boxes_[ids_[i]]);
      cbox.extend(centroids_[ids_[i]]);
    }
    const size_t n = end - begin;
    size_t mid = 0;
    const bool split = n > 1 && depth < kMaxDepth && choose_split(begin, end, box, cbox, mid);
    double cost;
    if (!split) {
      cost = kNodeCost + kTriangleCost * double(n);
      BvhNode& node = out_.nodes[me];
      node.leaf = n ? int32_t(out_.lists.size()) : 0;
      node.count = int32_t(n);
      for (size_t i = begin; i < end; ++i) out_.lists.push_back(int32_t(ids_[i]));
      if (n) out_.lists.push_back(-1);
      ++out_.leaves;
      out_.max_leaf = std::max(out_.max_leaf, int(n));
    } else {
      const size_t left = out_.nodes.size();
      const double cl = build(begin, mid, depth + 1);
      const size_t right = out_.nodes.size();
      const double cr = build(mid, end, depth + 1);
      const double a = box.area();
      const double al = node_area(left), ar = node_area(right);
      cost = kNodeCost + (a > 0 ? (al * cl + ar * cr) / a : cl + cr);
    }
    BvhNode& node = out_.nodes[me];
    node.lo = box.empty() ? glm::vec3(0.0f) : box.lo - pad_;
    node.hi = box.empty() ? glm::vec3(0.0f) : box.hi + pad_;
    node.escape = int32_t(out_.nodes.size());  // -1 for the last ones, set by the caller
    return cost;
  }

 private:
  double node_area(size_t i) const {
    Box b;
    b.lo = out_.nodes[i].lo;
    b.hi = out_.nodes[i].hi;
    return b.area();
  }

  // The SAH's best plane over binned centroids; partitions ids_ and sets `mid`. False: a leaf
  // is cheaper (and allowed: at most max_leaf triangles) or no plane separates the centroids.
  bool choose_split(size_t begin, size_t end, const Box& box, const Box& cbox, size_t& mid) {
    const size_t n = end - begin;
    const int nb = std::max(2, spec_.bins);
    double best = 1e300;
    int best_axis = -1, best_bin = 0;
    for (int a = 0; a < 3; ++a) {
      const float lo = cbox.lo[a], ext = cbox.hi[a] - cbox.lo[a];
      if (!(ext > 0.0f)) continue;
      std::vector<Box> bb(static_cast<size_t>(nb));
      std::vector<size_t> cnt(size_t(nb), 0);
      for (size_t i = begin; i < end; ++i) {
        const int b = bin_of(centroids_[ids_[i]][a], lo, ext, nb);
        bb[size_t(b)].extend(boxes_[ids_[i]]);
        ++cnt[size_t(b)];
      }
      std::vector<double> right_area(size_t(nb), 0.0);
      std::vector<size_t> right_cnt(size_t(nb), 0);
      Box acc;
      size_t c = 0;
      for (int b = nb - 1; b > 0; --b) {
        acc.extend(bb[size_t(b)]);
        c += cnt[size_t(b)];
        right_area[size_t(b)] = acc.area();
        right_cnt[size_t(b)] = c;
      }
      acc = Box{};
      c = 0;
      for (int b = 0; b < nb - 1; ++b) {
        acc.extend(bb[size_t(b)]);
        c += cnt[size_t(b)];
        const size_t rc = right_cnt[size_t(b + 1)];
        if (c == 0 || rc == 0) continue;
        const double cost = acc.area() * double(c) + right_area[size_t(b + 1)] * double(rc);
        if (cost < best) {
          best = cost;
          best_axis = a;
          best_bin = b;
        }
      }
    }
    const double a = box.area();
    const double split_cost = kNodeCost + (a > 0 ? kTriangleCost * best / a : double(n));
    const double leaf_cost = kTriangleCost * double(n);
    if (best_axis < 0 || (int(n) <= spec_.max_leaf && leaf_cost <= split_cost)) {
      if (int(n) <= spec_.max_leaf) return false;
      if (best_axis < 0) {
        // Every centroid in one point: halve the list, so leaves stay bounded.
        mid = begin + n / 2;
        return true;
      }
    }
    const float lo = cbox.lo[best_axis], ext = cbox.hi[best_axis] - cbox.lo[best_axis];
    auto it = std::stable_partition(
        ids_.begin() + long(begin), ids_.begin() + long(end),
        [&](uint32_t id) { return bin_of(centroids_[id][best_axis], lo, ext, nb) <= best_bin; });
    mid = size_t(it - ids_.begin());
    return mid > begin && mid < end;
  }

  static int bin_of(float c, float lo, float ext, int nb) {
    const int b = int(float(nb) * ((c - lo) / ext));
    return std::clamp(b, 0, nb - 1);
  }

  const BvhSpec& spec_;
  Bvh& out_;
  std::vector<Box> boxes_;
  std::vector<glm::vec3> centroids_;
  std::vector<uint32_t> ids_;
  float pad_ = 0.0f;
};

}  // namespace

uint64_t Bvh::references() const {
  uint64_t r = 0;
  for (const BvhNode& n : nodes) r += uint64_t(std::max(0, n.count));
  return r;
}

Bvh build_bvh(const Scene& scene, const BvhSpec& spec) {
  const auto t0 = std::chrono::steady_clock::now();
  Bvh bvh;
  Builder b(scene, spec, bvh);
  b.build(0, scene.triangle_count(), 0);
  for (BvhNode& n : bvh.nodes)
    if (n.escape >= int32_t(bvh.nodes.size())) n.escape = -1;
  // The SAH cost as refit_bvh computes it (from the unpadded boxes), so a refit of an unmoved
  // scene reproduces the build exactly, boxes and cost.
  refit_bvh(bvh, scene);
  bvh.build_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return bvh;
}

void refit_bvh(Bvh& bvh, const Scene& scene) {
  const auto t0 = std::chrono::steady_clock::now();
  if (bvh.references() != scene.triangle_count() && !(bvh.nodes.size() == 1 && !bvh.nodes[0].count))
    throw std::invalid_argument("refit: the BVH holds " + std::to_string(bvh.references()) +
                                " triangles, the scene " + std::to_string(scene.triangle_count()));
  const Bounds sb = scene.bounds();
  double mag = 0.0, diag = 0.0;
  if (!sb.empty()) {
    diag = glm::length(glm::dvec3(sb.hi) - glm::dvec3(sb.lo));
    for (int a = 0; a < 3; ++a)
      mag = std::max({mag, std::abs(double(sb.lo[a])), std::abs(double(sb.hi[a]))});
  }
  const float pad = float(std::max(kBoxPadOfDiagonal * diag, 1e-6 * mag));
  std::vector<Box> box(bvh.nodes.size());
  std::vector<double> cost(bvh.nodes.size(), 0.0);
  // Children follow their parent in the layout: visiting nodes last to first meets every child
  // before its parent. An inner node's right child is its left child's escape.
  for (size_t k = bvh.nodes.size(); k-- > 0;) {
    BvhNode& n = bvh.nodes[k];
    Box b;
    if (n.leaf >= 0) {
      for (int32_t e = n.leaf; bvh.lists[size_t(e)] >= 0; ++e) {
        const auto t = size_t(bvh.lists[size_t(e)]);
        b.extend(scene.p0[t]);
        b.extend(scene.p1[t]);
        b.extend(scene.p2[t]);
      }
      cost[k] = kNodeCost + kTriangleCost * double(n.count);
    } else {
      const size_t l = k + 1, r = size_t(bvh.nodes[l].escape);
      b.extend(box[l]);
      b.extend(box[r]);
      const double a = b.area();
      cost[k] = kNodeCost + (a > 0 ? (box[l].area() * cost[l] + box[r].area() * cost[r]) / a
                                   : cost[l] + cost[r]);
    }
    box[k] = b;
    n.lo = b.empty() ? glm::vec3(0.0f) : b.lo - pad;
    n.hi = b.empty() ? glm::vec3(0.0f) : b.hi + pad;
  }
  bvh.sah_cost = cost.empty() ? 0.0 : cost[0];
  bvh.build_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::string describe(const Bvh& bvh) {
  char line[160];
  std::snprintf(line, sizeof line, "bvh: %zu nodes, depth %d, %d leaves of at most %d triangles",
                bvh.nodes.size(), bvh.depth, bvh.leaves, bvh.max_leaf);
  return line;
}

}  // namespace host
