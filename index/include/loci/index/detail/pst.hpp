// Priority search trees as arrays: the machinery of PrioritySearchTree and of the trees
// CenteredIntervalTree keeps at each node (McCreight, "Priority search trees", SIAM J.
// Computing 14(2), 1985). A tree of m nodes is heap-shaped in an array (children of i at
// 2i + 1 and 2i + 2), a heap on x towards the open side and a search tree on y; build_pst
// arranges points into one, query_pst answers a three-sided query on it, validate_pst checks
// both orders. Many trees can share one array: each is a subspan.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "loci/geom/error.hpp"
#include "loci/geom/point.hpp"
#include "loci/index/query.hpp"

namespace loci {

namespace detail {

// Which side of a three-sided query is open: left asks x <= qx (the tree is a min-heap on
// x), right asks x >= qx (a max-heap).
enum class PstSide : std::uint8_t { left, right };

struct PstNode {
  Point<2> p;
  double split;      // y of the left subtree <= split <= y of the right subtree
  std::uint32_t id;  // whatever the owner numbers its points by
};

template <PstSide S>
constexpr bool pst_admits(double x, double qx) {
  return S == PstSide::left ? x <= qx : x >= qx;
}

// Nodes in the left subtree of a heap-shaped tree of m nodes.
inline std::size_t pst_left_size(std::size_t m) {
  if (m <= 1) return 0;
  const int h = std::bit_width(m) - 1;  // depth of the last level
  const std::size_t half = std::size_t(1) << (h - 1);
  const std::size_t last_level = m - ((std::size_t(1) << h) - 1);
  return (half - 1) + std::min(last_level, half);
}

// Arranges `items` (reordered on the way) as a priority search tree into `out`, which has
// the same size. Recursion depth is the tree height, log2 of the size.
template <PstSide S>
void build_pst(std::span<PstNode> items, std::span<PstNode> out, std::size_t at = 0) {
  while (!items.empty()) {
    const auto top = std::min_element(items.begin(), items.end(), [](const auto& a, const auto& b) {
      return S == PstSide::left ? a.p[0] < b.p[0] : a.p[0] > b.p[0];
    });
    std::iter_swap(items.begin(), top);
    out[at] = items[0];
    out[at].split = items[0].p[1];
    const std::size_t left = pst_left_size(items.size());
    const std::span<PstNode> rest = items.subspan(1);
    if (left == 0) return;
    std::nth_element(rest.begin(), rest.begin() + (left - 1), rest.end(),
                     [](const auto& a, const auto& b) { return a.p[1] < b.p[1]; });
    out[at].split = rest[left - 1].p[1];
    build_pst<S>(rest.first(left), out, 2 * at + 1);
    items = rest.subspan(left);
    at = 2 * at + 2;
  }
}

// Calls f(node) for every node of tree t admitted by qx with y in [y1, y2]; returns false as
// soon as f does. `stack` is the caller's scratch; it is left as it was found.
template <PstSide S, class F>
bool query_pst(std::span<const PstNode> t, double qx, double y1, double y2,
               std::vector<std::uint32_t>& stack, QueryStats& s, F&& f) {
  if (t.empty()) return true;
  ++s.entries_tested;
  if (!pst_admits<S>(t[0].p[0], qx)) return true;
  const std::size_t base = stack.size();
  stack.push_back(0);
  while (stack.size() > base) {
    const std::size_t i = stack.back();
    stack.pop_back();
    const PstNode& n = t[i];
    ++s.nodes_visited;
    if (y1 <= n.p[1] && n.p[1] <= y2 && !f(n)) {
      stack.resize(base);
      return false;
    }
    // children are tested before they are pushed: most fail on x, and then cost no push
    const std::size_t c = 2 * i + 1;
    if (c + 1 < t.size() && n.split <= y2) {
      ++s.entries_tested;
      if (pst_admits<S>(t[c + 1].p[0], qx)) stack.push_back(std::uint32_t(c + 1));
    }
    if (c < t.size() && y1 <= n.split) {
      ++s.entries_tested;
      if (pst_admits<S>(t[c].p[0], qx)) stack.push_back(std::uint32_t(c));
    }
  }
  return true;
}

// Throws loci::Error, its message starting with `owner`, for a broken heap or split order.
template <PstSide S>
void validate_pst(std::span<const PstNode> t, const std::string& owner) {
  auto fail = [&](const std::string& what, std::size_t i) {
    throw Error(owner + what + " at node " + std::to_string(i));
  };
  // y-range of every subtree, children before parents
  std::vector<double> lo(t.size()), hi(t.size());
  for (std::size_t i = t.size(); i-- > 0;) {
    lo[i] = hi[i] = t[i].p[1];
    for (std::size_t c = 2 * i + 1; c <= 2 * i + 2 && c < t.size(); ++c) {
      if (!pst_admits<S>(t[i].p[0], t[c].p[0])) fail("heap order on x broken", i);
      lo[i] = std::min(lo[i], lo[c]);
      hi[i] = std::max(hi[i], hi[c]);
    }
    if (2 * i + 1 < t.size() && !(hi[2 * i + 1] <= t[i].split))
      fail("left subtree reaches above the y split", i);
    if (2 * i + 2 < t.size() && !(t[i].split <= lo[2 * i + 2]))
      fail("right subtree reaches below the y split", i);
  }
}

}  // namespace detail

}  // namespace loci
