// Moving every structure, as a C++ user does (std::move, std::swap, a growing std::vector):
// the target answers as the source did, and the source is left empty, valid and usable, as
// if default-constructed (one built with parameters keeps them). Each structure is filled
// from fixed-seed data with erasures (free lists, holes) so that a field left behind by a
// move shows.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

#include "loci/index/axis_parallel_window_tree.hpp"
#include "loci/index/broadphase/bsp_tree.hpp"
#include "loci/index/broadphase/dynamic_aabb_tree.hpp"
#include "loci/index/broadphase/sweep_prune.hpp"
#include "loci/index/broadphase/uniform_grid.hpp"
#include "loci/index/interval_tree.hpp"
#include "loci/index/kd_tree.hpp"
#include "loci/index/moving/conflicts.hpp"
#include "loci/index/moving/fleet.hpp"
#include "loci/index/moving/moving_grid.hpp"
#include "loci/index/moving/moving_scan.hpp"
#include "loci/index/moving/star_tree.hpp"
#include "loci/index/moving/tpr_tree.hpp"
#include "loci/index/packed_rtree.hpp"
#include "loci/index/pr_quadtree.hpp"
#include "loci/index/priority_search_tree.hpp"
#include "loci/index/region_quadtree.hpp"
#include "loci/index/rstar_tree.hpp"
#include "loci/index/rtree.hpp"
#include "loci/index/segment_tree.hpp"
#include "loci/index/segment_window_tree.hpp"
#include "support/random_data.hpp"

namespace loci {
namespace {

constexpr int kCount = 300;
const Box2 kAll{{-1e6, -1e6}, {1e6, 1e6}};

std::vector<Box2> boxes(unsigned seed) {
  return test::make_boxes<2>(test::Shape::uniform, kCount, seed);
}
std::vector<Point2> points(unsigned seed) {
  std::vector<Point2> out;
  for (const Box2& b : boxes(seed))
    out.push_back(b.min);
  out[7] = out[3];  // a repeated point
  return out;
}
std::vector<Interval> intervals(unsigned seed) {
  std::vector<Interval> out;
  for (const Box2& b : boxes(seed))
    out.push_back({b.min[0], b.max[0]});
  return out;
}
std::vector<Id> sorted(std::vector<Id> v) {
  std::sort(v.begin(), v.end());
  return v;
}
Id pair_id(Id a, Id b) {
  return std::min(a, b) * 1000000 + std::max(a, b);
}
template <class Pairs>
std::vector<Id> pair_ids(const Pairs& pairs) {
  std::vector<Id> out;
  for (const auto& p : pairs)
    out.push_back(pair_id(p.a, p.b));
  return sorted(out);
}

// One adapter per structure: make(seed) fills one, answer(t) is what it holds as sorted ids
// (empty for an empty structure), refill(t, seed) makes a moved-from one hold something again
// by its own operations (insertions, or assigning a fresh build for a static structure).

// make() of an adapter whose structure starts default-constructed and is filled by refill().
template <class T, class Self>
struct Filled {
  using Type = T;
  static T make(unsigned seed) {
    T t;
    Self::refill(t, seed);
    return t;
  }
};
// refill() of an adapter whose structure is static: a fresh build assigned over it.
template <class T, class Self>
struct Rebuilt {
  using Type = T;
  static void refill(T& t, unsigned seed) { t = Self::make(seed); }
};

template <class T>
struct DynamicBoxes : Filled<T, DynamicBoxes<T>> {
  static void refill(T& t, unsigned seed) {
    const auto b = boxes(seed);
    for (int i = 0; i < kCount; ++i)
      t.insert(b[i], Id(i));
    for (int i = 0; i < kCount; i += 3)
      t.erase(b[i], Id(i));
  }
  static std::vector<Id> answer(const T& t) { return sorted(t.query(kAll)); }
};
template <class T>
struct DynamicPoints : Filled<T, DynamicPoints<T>> {
  static void refill(T& t, unsigned seed) {
    const auto p = points(seed);
    for (int i = 0; i < kCount; ++i)
      t.insert(p[i], Id(i));
    for (int i = 0; i < kCount; i += 3)
      t.erase(p[i], Id(i));
  }
  static std::vector<Id> answer(const T& t) { return sorted(t.query(kAll)); }
};
struct Packed : Rebuilt<PackedRTree2, Packed> {
  using Type = PackedRTree2;
  static Type make(unsigned seed) { return Type::build(boxes(seed)); }
  static std::vector<Id> answer(const Type& t) { return sorted(t.query(kAll)); }
};
struct Intervals : Filled<IntervalTree, Intervals> {
  static void refill(Type& t, unsigned seed) {
    const auto iv = intervals(seed);
    for (int i = 0; i < kCount; ++i)
      t.insert(iv[i], Id(i));
    for (int i = 0; i < kCount; i += 3)
      t.erase(iv[i], Id(i));
  }
  static std::vector<Id> answer(const Type& t) { return sorted(t.overlap({-1e6, 1e6})); }
};
struct Segments : Rebuilt<SegmentTree, Segments> {
  using Type = SegmentTree;
  static Type make(unsigned seed) { return Type::build(intervals(seed)); }
  static std::vector<Id> answer(const Type& t) {
    std::vector<Id> out;
    for (double x = 0; x <= 1030; x += 10)
      for (const Id id : t.stab(x))
        out.push_back(id);
    out = sorted(out);
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }
};
struct Pst : Rebuilt<PrioritySearchTree, Pst> {
  using Type = PrioritySearchTree;
  static Type make(unsigned seed) { return Type::build(points(seed)); }
  static std::vector<Id> answer(const Type& t) { return sorted(t.query_left(500, 0, 700)); }
};
template <class T, bool AxisParallel>
struct Windowing : Rebuilt<T, Windowing<T, AxisParallel>> {
  using Type = T;
  static std::vector<Segment2> segments(unsigned seed) {
    std::vector<Segment2> out;
    for (const Box2& b : boxes(seed))
      out.push_back(AxisParallel && out.size() % 2 ? Segment2{b.min, {b.min[0], b.max[1]}}
                    : AxisParallel                 ? Segment2{b.min, {b.max[0], b.min[1]}}
                                                   : Segment2{b.min, b.max});
    return out;
  }
  static Type make(unsigned seed) { return Type::build(segments(seed)); }
  static std::vector<Id> answer(const Type& t) {
    return sorted(t.query(Box2{{200, 200}, {600, 600}}));
  }
};
struct Regions : Rebuilt<RegionQuadtree, Regions> {
  using Type = RegionQuadtree;
  static Type make(unsigned seed) {
    const double r = 200 + seed % 7 * 20;
    return Type::build(Box2{{0, 0}, {1000, 1000}}, 6, [r](const Box2& b) {
      double near2 = 0, far2 = 0;
      for (int a = 0; a < 2; ++a) {
        const double lo = b.min[a] - 500, hi = b.max[a] - 500;
        const double n = lo > 0 ? lo : hi < 0 ? -hi : 0;
        const double f = std::max(std::abs(lo), std::abs(hi));
        near2 += n * n, far2 += f * f;
      }
      return far2 <= r * r ? Cover::inside : near2 >= r * r ? Cover::outside : Cover::boundary;
    });
  }
  static std::vector<Id> answer(const Type& t) {
    std::vector<Id> out;
    for (const QuadCell& c : t.query(kAll))
      out.push_back((Id(c.level) << 40) | (Id(c.x) << 20) | Id(c.y) | (Id(c.cover) << 50));
    return sorted(out);
  }
};
struct Bsp : Rebuilt<BspTree, Bsp> {
  using Type = BspTree;
  static Type make(unsigned seed) {
    std::vector<BspPolygon> polys;
    for (const Box2& b : boxes(seed)) {
      if (polys.size() == 20) break;
      polys.push_back({{b.min, {b.max[0], b.min[1]}, b.max, {b.min[0], b.max[1]}}, {}});
    }
    return Type::build(polys);
  }
  static std::vector<Id> answer(const Type& t) {
    std::vector<Id> out;
    for (int i = 0; i < 100; ++i)
      for (int j = 0; j < 100; ++j)
        if (t.solid({i * 10.0 + 0.5, j * 10.0 + 0.5})) out.push_back(Id(i * 100 + j));
    return out;
  }
};
template <class T>
struct BroadPhases : Filled<T, BroadPhases<T>> {
  static void refill(T& t, unsigned seed) {
    const auto b = boxes(seed);
    for (int i = 0; i < kCount; ++i)
      t.add(Id(i), b[i]);
    t.pairs();
    for (int i = 0; i < kCount; i += 3)
      t.remove(Id(i));
  }
  static std::vector<Id> answer(T& t) {
    std::vector<Id> out = pair_ids(t.pairs());
    for (const Id id : t.query(kAll))
      out.push_back(id);
    return sorted(out);
  }
};
Motion2 motion(const Box2& b, int i) {
  return {double(i % 5), b.min, {b.max[0] - b.min[0] - 15, b.max[1] - b.min[1] - 15}};
}
template <class T>
struct Moving : Filled<T, Moving<T>> {
  static void refill(T& t, unsigned seed) {
    const auto b = boxes(seed);
    for (int i = 0; i < kCount; ++i)
      t.insert(Id(i), motion(b[i], i));
    for (int i = 0; i < kCount; i += 3)
      t.erase(Id(i));
  }
  static std::vector<Id> answer(const T& t) {
    return sorted(t.query(MovingWindow<2>::at(Box2{{0, 0}, {800, 800}}, 6)));
  }
};
struct Fleets : Filled<Fleet<MovingGrid<2>>, Fleets> {
  static void refill(Type& t, unsigned seed) {
    const auto b = boxes(seed);
    for (int i = 0; i < kCount; ++i)
      t.report(Id(i), motion(b[i], i));
  }
  static std::vector<Id> answer(const Type& t) {
    return sorted(t.query(MovingWindow<2>::at(Box2{{0, 0}, {800, 800}}, 6)));
  }
};

template <class C>
class MovedFrom : public ::testing::Test {};

using Cases = ::testing::Types<
    DynamicBoxes<RTree<2, LinearSplit>>, DynamicBoxes<RTree2>, DynamicBoxes<RStarTree2>,
    DynamicPoints<KdTree2>, DynamicPoints<PrQuadtree2>, Packed, Intervals, Segments, Pst,
    Windowing<SegmentWindowTree, false>, Windowing<AxisParallelWindowTree, true>, Regions, Bsp,
    BroadPhases<SweepPrune<2>>, BroadPhases<IncrementalSweepPrune<2>>, BroadPhases<UniformGrid<2>>,
    BroadPhases<DynamicAabbTree<2>>, Moving<TprTree<2>>, Moving<StarTree<2>>, Moving<MovingGrid<2>>,
    Moving<MovingScan<2>>, Fleets>;
TYPED_TEST_SUITE(MovedFrom, Cases);

// Checks that `t` is empty, valid and usable again, then that it holds what a fresh one does.
template <class C>
void expect_fresh(typename C::Type& t, unsigned seed) {
  EXPECT_NO_THROW(t.validate());
  if constexpr (requires { t.empty(); }) EXPECT_TRUE(t.empty());
  EXPECT_TRUE(C::answer(t).empty());
  C::refill(t, seed);
  EXPECT_NO_THROW(t.validate());
  auto fresh = C::make(seed);
  EXPECT_EQ(C::answer(t), C::answer(fresh));
}

TYPED_TEST(MovedFrom, ConstructionLeavesTheSourceEmptyAndUsable) {
  using C = TypeParam;
  static_assert(std::is_nothrow_move_constructible_v<typename C::Type>);
  static_assert(std::is_nothrow_move_assignable_v<typename C::Type>);
  auto a = C::make(1);
  const auto held = C::answer(a);
  ASSERT_FALSE(held.empty());
  auto b = std::move(a);
  EXPECT_EQ(C::answer(b), held);
  EXPECT_NO_THROW(b.validate());
  expect_fresh<C>(a, 2);
}

TYPED_TEST(MovedFrom, AssignmentOverAFullTarget) {
  using C = TypeParam;
  auto a = C::make(3);
  auto b = C::make(4);
  const auto held = C::answer(a);
  b = std::move(a);
  EXPECT_EQ(C::answer(b), held);
  EXPECT_NO_THROW(b.validate());
  expect_fresh<C>(a, 5);
}

TYPED_TEST(MovedFrom, SelfMoveAndSwapKeepTheContents) {
  using C = TypeParam;
  auto a = C::make(6);
  auto b = C::make(7);
  const auto in_a = C::answer(a), in_b = C::answer(b);
  auto& alias = a;  // through a reference, as generic code meets it
  a = std::move(alias);
  EXPECT_EQ(C::answer(a), in_a);
  EXPECT_NO_THROW(a.validate());
  std::swap(a, b);
  EXPECT_EQ(C::answer(a), in_b);
  EXPECT_EQ(C::answer(b), in_a);
  EXPECT_NO_THROW(a.validate());
  EXPECT_NO_THROW(b.validate());
}

TYPED_TEST(MovedFrom, AGrowingVectorMovesThemIntact) {
  using C = TypeParam;
  std::vector<typename C::Type> v;
  std::vector<std::vector<Id>> held;
  for (unsigned seed = 10; seed < 15; ++seed) {
    v.push_back(C::make(seed));
    held.push_back(C::answer(v.back()));
  }
  v.erase(v.begin() + 1);
  held.erase(held.begin() + 1);
  for (std::size_t i = 0; i < v.size(); ++i) {
    EXPECT_EQ(C::answer(v[i]), held[i]);
    EXPECT_NO_THROW(v[i].validate());
  }
}

// A structure built with parameters keeps them when moved from (as a derived type's own
// default would expect): it is empty, not reset to the defaults.
TEST(MovedFrom, ParametersStayWithTheSource) {
  KdTree2 kd(KdSplit::sliding_midpoint);
  kd.insert({1, 2}, 1);
  KdTree2 kd2 = std::move(kd);
  EXPECT_EQ(kd.split(), KdSplit::sliding_midpoint);
  EXPECT_EQ(kd2.split(), KdSplit::sliding_midpoint);
  PrQuadtree2 quad(5, 20);
  quad.insert({1, 2}, 1);
  PrQuadtree2 quad2(2, 30);
  quad2 = std::move(quad);
  EXPECT_EQ(quad.bucket(), 5u);
  EXPECT_EQ(quad.max_depth(), 20);
  EXPECT_EQ(quad2.bucket(), 5u);
  EXPECT_TRUE(quad.empty());
  MovingGridParams<2> params;
  params.horizon = 7;
  params.bands = 2;
  MovingGrid<2> grid(params);
  grid.insert(1, Motion2{0, {1, 1}, {1, 0}});
  MovingGrid<2> grid2 = std::move(grid);
  EXPECT_EQ(grid.params().horizon, 7);
  EXPECT_EQ(grid.params().bands, 2);
  EXPECT_EQ(grid2.params().bands, 2);
  TprParams<2> tpr;
  tpr.horizon = 9;
  TprTree<2> tree(tpr);
  TprTree<2> tree2 = std::move(tree);
  EXPECT_EQ(tree.params().horizon, 9);
  EXPECT_EQ(tree2.params().horizon, 9);
  Fleet<TprTree<2>> fleet(TprTree<2>{tpr});
  fleet.report(1, Motion2{0, {1, 1}, {1, 0}});
  Fleet<TprTree<2>> fleet2 = std::move(fleet);
  EXPECT_TRUE(fleet.empty());
  EXPECT_EQ(fleet.index().params().horizon, 9);
  EXPECT_EQ(fleet2.size(), 1u);
}

// The conflict monitor has no default: a moved-from one keeps its parameters and holds nothing.
TEST(MovedFrom, ConflictMonitorKeepsItsParameters) {
  const auto b = boxes(8);
  auto fill = [&](ConflictMonitor<2>& m) {
    for (int i = 0; i < kCount; ++i)
      m.report(Id(i), motion(b[i], i));
    m.refresh(5);
  };
  ConflictMonitor<2> a(20, 10, 2);
  fill(a);
  const auto held = pair_ids(a.conflicts());
  ASSERT_FALSE(held.empty());
  ConflictMonitor<2> c(1, 1, 0);
  c = std::move(a);
  EXPECT_EQ(pair_ids(c.conflicts()), held);
  EXPECT_EQ(a.size(), 0u);
  EXPECT_TRUE(a.conflicts().empty());
  fill(a);  // same parameters: the same conflicts
  EXPECT_EQ(pair_ids(a.conflicts()), held);
}

// A finder keeps proxies between searches: a moved-from one must not trust the count it had.
TEST(MovedFrom, ConflictFinderSearchesAfresh) {
  const auto b = boxes(9);
  std::vector<Motion2> objects;
  for (int i = 0; i < kCount; ++i)
    objects.push_back(motion(b[i], i));
  auto search = [&](ConflictFinder<2>& f, std::size_t n) {
    std::vector<Id> out;
    f.find(std::span<const Motion2>(objects.data(), n), 20, 5, 10,
           [&](std::size_t i, std::size_t j, const Approach&) {
             return out.push_back(pair_id(Id(i), Id(j))), true;
           });
    return sorted(out);
  };
  ConflictFinder<2> a;
  const auto all = search(a, objects.size());
  ASSERT_FALSE(all.empty());
  ConflictFinder<2> b2 = std::move(a);
  EXPECT_EQ(search(b2, objects.size()), all);
  ConflictFinder<2> fresh;
  EXPECT_EQ(search(a, 50), search(fresh, 50));
  EXPECT_EQ(search(a, objects.size()), all);
}

}  // namespace
}  // namespace loci
