// Reference answers by exhaustive scan, and the checks that compare an index with them.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <utility>
#include <vector>

#include "loci/index/query.hpp"

namespace loci::test {

template <int D>
std::vector<Id> brute_window(const std::vector<Box<D>>& boxes, const std::vector<Id>& ids,
                             const Box<D>& w, Relation rel) {
  std::vector<Id> out;
  for (std::size_t i = 0; i < boxes.size(); ++i)
    if (relates(rel, boxes[i], w)) out.push_back(ids[i]);
  std::sort(out.begin(), out.end());
  return out;
}

template <int D>
std::vector<double> brute_distances(const std::vector<Box<D>>& boxes, const Point<D>& p) {
  std::vector<double> d;
  for (const auto& b : boxes)
    d.push_back(std::sqrt(squared_distance(p, b)));
  std::sort(d.begin(), d.end());
  return d;
}

inline std::vector<Id> sorted(std::vector<Id> v) {
  std::sort(v.begin(), v.end());
  return v;
}

// Nearest-n answers agree when the distances agree rank by rank and every returned id is at
// its reported distance (ties may come in any order).
template <int D>
void expect_nearest(const std::vector<Neighbor>& got, const std::vector<Box<D>>& boxes_by_id,
                    const Point<D>& p, std::size_t k) {
  const auto ref = brute_distances(boxes_by_id, p);
  ASSERT_EQ(got.size(), std::min(k, boxes_by_id.size()));
  std::vector<Id> seen;
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_DOUBLE_EQ(got[i].distance, ref[i]) << "rank " << i;
    ASSERT_LT(got[i].id, boxes_by_id.size());
    EXPECT_DOUBLE_EQ(got[i].distance, std::sqrt(squared_distance(p, boxes_by_id[got[i].id])));
    seen.push_back(got[i].id);
  }
  std::sort(seen.begin(), seen.end());
  EXPECT_TRUE(std::adjacent_find(seen.begin(), seen.end()) == seen.end()) << "duplicate id";
}

// Every intersecting pair i < j of one set of boxes, and every (i of a, j of b), in order.
using BoxPairs = std::vector<std::pair<Id, Id>>;

inline BoxPairs brute_self_pairs(const std::vector<Box<2>>& b) {
  BoxPairs out;
  for (std::size_t i = 0; i < b.size(); ++i)
    for (std::size_t j = i + 1; j < b.size(); ++j)
      if (intersects(b[i], b[j])) out.push_back({Id(i), Id(j)});
  return out;
}

inline BoxPairs brute_join_pairs(const std::vector<Box<2>>& a, const std::vector<Box<2>>& b) {
  BoxPairs out;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = 0; j < b.size(); ++j)
      if (intersects(a[i], b[j])) out.push_back({Id(i), Id(j)});
  return out;
}

}  // namespace loci::test
