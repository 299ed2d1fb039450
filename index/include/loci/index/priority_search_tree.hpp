// PrioritySearchTree: a static set of 2D points answering three-sided queries, "every point
// with x <= qx and y1 <= y <= y2" (query_left) and "x >= qx and y1 <= y <= y2" (query_right),
// after McCreight, "Priority search trees", SIAM Journal on Computing 14(2), 1985 (also de
// Berg et al., "Computational Geometry", chapter 10.2).
//
// Structure. One binary tree is at once a heap on x and a search tree on y. The root holds the
// point nearest the open side (smallest x for query_left); the remaining points are cut at a
// y rank into the two subtrees, and the node keeps the y at the cut as its split value. A
// query walks down from the root, dropping a subtree as soon as its top point fails the x
// test (every point below fails it too) and a child whose y-range misses [y1, y2]; a visited
// node that passes x either reports its point or lies on one of the two search paths of y1
// and y2, which bounds the work by the height plus the output.
//
// Layout. The tree is heap-shaped: node i has children 2i + 1 and 2i + 2 in one flat array,
// so there are no child links, and the sizes of both subtrees follow from the node count
// alone; the y cut is made at that rank. Cutting by rank, never by value, lets duplicate
// points and equal y values land on both sides of a split; queries then enter both children
// when [y1, y2] contains the split, so ties cost nothing in correctness. The two query sides
// use two trees over the same points (a min-heap and a max-heap on x). The tree code is
// detail/pst.hpp, shared with CenteredIntervalTree, which keeps many small trees in one
// array.
//
// Invariants (checked by validate()): on each tree, no child comes before its parent in x
// (in the heap's order); every y in a left subtree is <= the node's split <= every y in the
// right subtree; every point is stored exactly once, with its own coordinates.
//
// Complexity: build O(n log n); a query O(log n + k) for k results; memory 80 bytes per
// point. Point i of build() is reported with id i. Thread-safety: immutable after build; any
// number of concurrent queries (they use thread-local scratch).
#pragma once

#include <algorithm>
#include <bit>
#include <concepts>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "loci/geom/error.hpp"
#include "loci/geom/point.hpp"
#include "loci/index/detail/pst.hpp"
#include "loci/index/detail/scratch.hpp"
#include "loci/index/query.hpp"

namespace loci {

class PrioritySearchTree {
 public:
  PrioritySearchTree() = default;
  PrioritySearchTree(const PrioritySearchTree&) = default;
  PrioritySearchTree& operator=(const PrioritySearchTree&) = default;
  // Moving leaves `other` empty, as if default-constructed.
  PrioritySearchTree(PrioritySearchTree&& other) noexcept : PrioritySearchTree() { swap(other); }
  PrioritySearchTree& operator=(PrioritySearchTree&& other) noexcept {
    PrioritySearchTree(std::move(other)).swap(*this);
    return *this;
  }

  // Point i gets id i. Throws InvalidGeometry on a NaN or infinite coordinate,
  // InvalidArgument for 2^32 - 1 points or more.
  static PrioritySearchTree build(std::span<const Point<2>> points);

  std::size_t size() const { return points_.size(); }
  bool empty() const { return points_.empty(); }
  // Throws InvalidArgument for an id the tree does not hold.
  const Point<2>& point(Id id) const {
    if (id >= points_.size())
      throw InvalidArgument("PrioritySearchTree: no point with id " + std::to_string(id));
    return points_[std::size_t(id)];
  }
  std::size_t memory_bytes() const {
    return points_.size() * sizeof(Point<2>) +
           (left_.size() + right_.size()) * sizeof(detail::PstNode);
  }

  // Calls visit(id, point) for every point with x <= qx and y1 <= y <= y2; stops when it
  // returns false. Throws InvalidGeometry for a NaN or infinite bound or y1 > y2.
  template <PointVisitor Visit>
  QueryStats query_left(double qx, double y1, double y2, Visit&& visit) const {
    return run<detail::PstSide::left>(left_, qx, y1, y2, visit);
  }
  std::vector<Id> query_left(double qx, double y1, double y2) const {
    return collect_ids([&](auto&& v) { return query_left(qx, y1, y2, v); });
  }

  // Calls visit(id, point) for every point with x >= qx and y1 <= y <= y2; stops when it
  // returns false. Throws InvalidGeometry for a NaN or infinite bound or y1 > y2.
  template <PointVisitor Visit>
  QueryStats query_right(double qx, double y1, double y2, Visit&& visit) const {
    return run<detail::PstSide::right>(right_, qx, y1, y2, visit);
  }
  std::vector<Id> query_right(double qx, double y1, double y2) const {
    return collect_ids([&](auto&& v) { return query_right(qx, y1, y2, v); });
  }

  // Throws loci::Error describing the first broken invariant.
  void validate() const;

 private:
  template <detail::PstSide S, class Visit>
  QueryStats run(const std::vector<detail::PstNode>& t, double qx, double y1, double y2,
                 Visit& visit) const {
    check_coordinate(qx, "query x");
    check_interval({y1, y2}, "query y-range");
    QueryStats s;
    detail::Scratch<std::uint32_t> scratch;
    detail::query_pst<S>(t, qx, y1, y2, *scratch, s, [&](const detail::PstNode& n) {
      ++s.results;
      return bool(visit(Id(n.id), n.p));
    });
    return s;
  }

  void swap(PrioritySearchTree& other) noexcept {
    points_.swap(other.points_);
    left_.swap(other.left_);
    right_.swap(other.right_);
  }
  std::vector<Point<2>> points_;        // by id
  std::vector<detail::PstNode> left_;   // min-heap on x, for query_left
  std::vector<detail::PstNode> right_;  // max-heap on x, for query_right
};

inline PrioritySearchTree PrioritySearchTree::build(std::span<const Point<2>> points) {
  if (points.size() >= std::numeric_limits<std::uint32_t>::max())
    throw InvalidArgument("PrioritySearchTree holds at most 2^32 - 2 points");
  PrioritySearchTree t;
  t.points_.assign(points.begin(), points.end());
  std::vector<detail::PstNode> items(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    check_point(points[i], ("point " + std::to_string(i)).c_str());
    items[i] = {points[i], 0.0, std::uint32_t(i)};
  }
  t.left_.resize(items.size());
  t.right_.resize(items.size());
  detail::build_pst<detail::PstSide::left>(items, t.left_);
  detail::build_pst<detail::PstSide::right>(items, t.right_);
  return t;
}

inline void PrioritySearchTree::validate() const {
  const std::string owner = "PrioritySearchTree invalid: ";
  auto check = [&](const std::vector<detail::PstNode>& t, const char* which) {
    if (t.size() != points_.size())
      throw Error(owner + which + " tree holds " + std::to_string(t.size()) + " of " +
                  std::to_string(points_.size()) + " points");
    std::vector<bool> seen(points_.size(), false);
    for (const detail::PstNode& n : t) {
      if (n.id >= points_.size() || seen[n.id])
        throw Error(owner + which + " tree stores point " + std::to_string(n.id) +
                    " twice or out of range");
      seen[n.id] = true;
      if (!(n.p == points_[n.id]))
        throw Error(owner + which + " tree moved point " + std::to_string(n.id));
    }
  };
  check(left_, "left");
  check(right_, "right");
  detail::validate_pst<detail::PstSide::left>(left_, owner + "left tree: ");
  detail::validate_pst<detail::PstSide::right>(right_, owner + "right tree: ");
}

}  // namespace loci
