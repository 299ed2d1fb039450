// Every public header of geom/ and index/ in one translation unit, as a program that joins
// map layers and runs collisions or fleet conflicts includes them: no name is defined twice
// (PairVisitor was, by the broad phases and the joins), and each header stands on its own
// (the package test includes them one by one through find_package).
#include "loci/geom/boost_adapt.hpp"
#include "loci/geom/box.hpp"
#include "loci/geom/error.hpp"
#include "loci/geom/geom.hpp"
#include "loci/geom/motion.hpp"
#include "loci/geom/narrow_phase.hpp"
#include "loci/geom/point.hpp"
#include "loci/geom/predicates.hpp"
#include "loci/geom/segment.hpp"
#include "loci/geom/segment_intersection.hpp"
#include "loci/geom/swept.hpp"
#include "loci/index/axis_parallel_window_tree.hpp"
#include "loci/index/broadphase/broad_phase.hpp"
#include "loci/index/broadphase/bsp_tree.hpp"
#include "loci/index/broadphase/dynamic_aabb_tree.hpp"
#include "loci/index/broadphase/sweep_prune.hpp"
#include "loci/index/broadphase/uniform_grid.hpp"
#include "loci/index/centered_interval_tree.hpp"
#include "loci/index/grid_join.hpp"
#include "loci/index/interval_tree.hpp"
#include "loci/index/kd_tree.hpp"
#include "loci/index/moving/conflicts.hpp"
#include "loci/index/moving/fleet.hpp"
#include "loci/index/moving/moving_grid.hpp"
#include "loci/index/moving/moving_index.hpp"
#include "loci/index/moving/moving_scan.hpp"
#include "loci/index/moving/star_tree.hpp"
#include "loci/index/moving/tpr_tree.hpp"
#include "loci/index/packed_rtree.hpp"
#include "loci/index/pr_quadtree.hpp"
#include "loci/index/priority_search_tree.hpp"
#include "loci/index/query.hpp"
#include "loci/index/region_quadtree.hpp"
#include "loci/index/rstar_tree.hpp"
#include "loci/index/rtree.hpp"
#include "loci/index/segment_intersections.hpp"
#include "loci/index/segment_tree.hpp"
#include "loci/index/segment_window_tree.hpp"
#include "loci/index/slab_tree.hpp"
#include "loci/index/sweep_join.hpp"

#include <gtest/gtest.h>

namespace {

TEST(Headers, AllTogetherShareOnePairVisitor) {
  const auto visit = [](loci::Id, loci::Id) { return true; };
  static_assert(loci::PairVisitor<decltype(visit)>);
  loci::SweepPrune<2> broad;
  broad.add(1, loci::Box2{{0, 0}, {1, 1}});
  broad.add(2, loci::Box2{{1, 1}, {2, 2}});
  std::size_t pairs = 0;
  broad.pairs([&](loci::Id a, loci::Id b) {
    EXPECT_LT(a, b);
    ++pairs;
    return true;
  });
  EXPECT_EQ(pairs, 1u);
  const std::vector<loci::Box2> boxes{{{0, 0}, {1, 1}}, {{1, 1}, {2, 2}}, {{5, 5}, {6, 6}}};
  pairs = 0;
  loci::self_join(std::span<const loci::Box2>(boxes), [&](loci::Id, loci::Id) {
    ++pairs;
    return true;
  });
  EXPECT_EQ(pairs, 1u);
}

}  // namespace
