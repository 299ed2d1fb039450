// Queries allocate nothing per call in steady state (DESIGN.md: their buffers are leased per
// thread): after warm-up calls, the same query through its visitor form is counted by a
// replaced global operator new and must allocate nothing, on every structure.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdlib>
#include <new>
#include <typeinfo>
#include <vector>

#include "loci/index/axis_parallel_window_tree.hpp"
#include "loci/index/broadphase/bsp_tree.hpp"
#include "loci/index/broadphase/dynamic_aabb_tree.hpp"
#include "loci/index/broadphase/sweep_prune.hpp"
#include "loci/index/broadphase/uniform_grid.hpp"
#include "loci/index/interval_tree.hpp"
#include "loci/index/kd_tree.hpp"
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

namespace {
thread_local std::size_t g_allocations = 0;
}  // namespace

void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  return operator new(n);
}
// The replaced operators pair malloc with free; GCC, seeing new and free meet once they are
// inlined, warns of a mismatch that is not one.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}

namespace loci {
namespace {

// Allocations made by f's third call (the first ones warm the leases up, and an incremental
// sweep sorts from scratch on its first tick only).
template <class F>
std::size_t allocations(F&& f) {
  f();
  f();
  const std::size_t before = g_allocations;
  f();
  return g_allocations - before;
}

std::vector<Box2> boxes(int n, unsigned seed) {
  return test::make_boxes<2>(test::Shape::uniform, static_cast<std::size_t>(n), seed);
}

const Box2 kWindow{{200, 200}, {500, 600}};
const Point2 kHere{400, 300};
auto any_box = [](Id, const Box2&) { return true; };
auto any_near = [](Id, const Box2&, double) { return true; };

template <class T>
void expect_box_tree_quiet(const T& t) {
  EXPECT_EQ(allocations([&] { t.query(kWindow, any_box); }), 0u);
  EXPECT_EQ(allocations([&] { t.nearest(kHere, 10, any_near); }), 0u);
  int n = 0;
  EXPECT_EQ(
      allocations([&] { t.browse(kHere, [&](Id, const Box2&, double) { return ++n % 50; }); }), 0u);
}

TEST(SteadyStateQueries, RTrees) {
  const auto b = boxes(5000, 1);
  RStarTree2 rstar;
  RTree<2, LinearSplit> linear;
  for (std::size_t i = 0; i < b.size(); ++i)
    rstar.insert(b[i], Id(i)), linear.insert(b[i], Id(i));
  expect_box_tree_quiet(rstar);
  expect_box_tree_quiet(linear);
  expect_box_tree_quiet(PackedRTree2::build(b));
  expect_box_tree_quiet(PackedRTree2::build(b, Packing::str));
}

TEST(SteadyStateQueries, Points) {
  std::vector<Point2> p;
  for (const Box2& b : boxes(5000, 2))
    p.push_back(b.min);
  const auto kd = KdTree2::build(p);
  const auto pr = PrQuadtree2::build(p, 4);
  auto near_point = [](Id, const Box2&, double) { return true; };
  EXPECT_EQ(allocations([&] { kd.query(kWindow, any_box); }), 0u);
  EXPECT_EQ(allocations([&] { kd.nearest(kHere, 10, near_point); }), 0u);
  EXPECT_EQ(allocations([&] { kd.radius(kHere, 50, near_point); }), 0u);
  EXPECT_EQ(allocations([&] { pr.query(kWindow, any_box); }), 0u);
  EXPECT_EQ(allocations([&] { pr.nearest(kHere, 10, near_point); }), 0u);
  const auto pst = PrioritySearchTree::build(p);
  EXPECT_EQ(
      allocations([&] { pst.query_left(400, 100, 700, [](Id, const Point2&) { return true; }); }),
      0u);
}

TEST(SteadyStateQueries, IntervalsAndWindowing) {
  std::vector<Interval> iv;
  std::vector<Segment2> segs, axis;
  for (const Box2& b : boxes(3000, 3)) {
    iv.push_back({b.min[0], b.max[0]});
    segs.push_back({b.min, b.max});
    axis.push_back({b.min, {b.max[0], b.min[1]}});
  }
  IntervalTree it;
  for (std::size_t i = 0; i < iv.size(); ++i)
    it.insert(iv[i], Id(i));
  auto any_id = [](Id, const Interval&) { return true; };
  EXPECT_EQ(allocations([&] { it.stab(500, any_id); }), 0u);
  EXPECT_EQ(allocations([&] { it.overlap({300, 400}, any_id); }), 0u);
  const auto st = SegmentTree::build(iv);
  EXPECT_EQ(allocations([&] { st.stab(500, any_id); }), 0u);
  auto any_seg = [](Id, const Segment2&) { return true; };
  const auto swt = SegmentWindowTree::build(segs);
  EXPECT_EQ(allocations([&] { swt.query(kWindow, any_seg); }), 0u);
  const auto apt = AxisParallelWindowTree::build(axis);
  EXPECT_EQ(allocations([&] { apt.query(kWindow, any_seg); }), 0u);
}

TEST(SteadyStateQueries, RegionsAndBsp) {
  const auto rq = RegionQuadtree::build(Box2{{0, 0}, {1000, 1000}}, 8, [](const Box2& b) {
    return b.max[0] <= 400 ? Cover::inside : b.min[0] >= 400 ? Cover::outside : Cover::boundary;
  });
  EXPECT_EQ(allocations([&] { rq.query(kWindow, [](const QuadCell&) { return true; }); }), 0u);
  std::vector<BspPolygon> polys;
  for (const Box2& b : boxes(200, 4))
    polys.push_back({{b.min, {b.max[0], b.min[1]}, b.max, {b.min[0], b.max[1]}}, {}});
  const auto bsp = BspTree::build(polys);
  EXPECT_EQ(allocations([&] { bsp.trace({0, 0}, {1000, 900}, BspCircle{3}); }), 0u);
  EXPECT_EQ(allocations([&] { bsp.slide({0, 0}, {1000, 900}, BspBox{{2, 2}}); }), 0u);
}

template <class T>
void expect_broad_phase_quiet() {
  SCOPED_TRACE(typeid(T).name());
  const auto b = boxes(3000, 5);
  T t;
  for (std::size_t i = 0; i < b.size(); ++i)
    t.add(Id(i), b[i]);
  auto any_pair = [](Id, Id) { return true; };
  EXPECT_EQ(allocations([&] { t.pairs(any_pair); }), 0u);
  EXPECT_EQ(allocations([&] { t.query(kWindow, any_box); }), 0u);
}

TEST(SteadyStateQueries, BroadPhases) {
  expect_broad_phase_quiet<SweepPrune<2>>();
  expect_broad_phase_quiet<IncrementalSweepPrune<2>>();
  expect_broad_phase_quiet<UniformGrid<2>>();
  expect_broad_phase_quiet<DynamicAabbTree<2>>();
}

template <class T>
void expect_moving_index_quiet() {
  const auto b = boxes(3000, 6);
  T t;
  for (std::size_t i = 0; i < b.size(); ++i)
    t.insert(Id(i), Motion2{double(i % 4), b[i].min, {b[i].max[0] - 10, b[i].max[1] - 10}});
  auto any_motion = [](Id, const Motion2&) { return true; };
  auto any_near_motion = [](Id, const Motion2&, double) { return true; };
  EXPECT_EQ(allocations([&] { t.query(MovingWindow<2>::at(kWindow, 5), any_motion); }), 0u);
  EXPECT_EQ(allocations([&] { t.nearest(kHere, 5, 10, any_near_motion); }), 0u);
}

TEST(SteadyStateQueries, MovingIndexes) {
  expect_moving_index_quiet<TprTree<2>>();
  expect_moving_index_quiet<StarTree<2>>();
  expect_moving_index_quiet<MovingGrid<2>>();
  expect_moving_index_quiet<MovingScan<2>>();
  // A fleet's history: nearest before the clock scans the reports in force then.
  Fleet<MovingGrid<2>> fleet;
  const auto b = boxes(2000, 7);
  for (std::size_t i = 0; i < b.size(); ++i)
    fleet.report(Id(i % 500), Motion2{double(i / 500), b[i].min, {1, -1}});
  auto any_near_motion = [](Id, const Motion2&, double) { return true; };
  EXPECT_EQ(allocations([&] { fleet.nearest(kHere, 1.5, 10, any_near_motion); }), 0u);
  EXPECT_EQ(allocations([&] {
              fleet.query(MovingWindow<2>::at(kWindow, 1.5),
                          [](Id, const Motion2&) { return true; });
            }),
            0u);
}

}  // namespace
}  // namespace loci
