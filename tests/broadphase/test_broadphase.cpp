// Every broad phase against brute force, tick by tick, over random motion with fixed seeds:
// all pairs, begin/end pairs against the difference of consecutive brute-force answers,
// window queries, and validate() after every tick.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "loci/index/broadphase/dynamic_aabb_tree.hpp"
#include "loci/index/broadphase/sweep_prune.hpp"
#include "loci/index/broadphase/uniform_grid.hpp"

namespace loci {
namespace {

// Variants with non-default settings, so that the grid's large-box path and a tree without
// margins get the same workout.
template <int D>
struct FineGrid : UniformGrid<D> {
  FineGrid() : UniformGrid<D>(0.05) {}
};
template <int D>
struct StripedSweep : SweepPrune<D> {
  StripedSweep() : SweepPrune<D>(16) {}
};
template <int D>
struct TightTree : DynamicAabbTree<D> {
  TightTree() : DynamicAabbTree<D>(AabbTreeOptions{0, 0, 0}) {}
};
template <int D>
struct UnpredictedTree : DynamicAabbTree<D> {
  UnpredictedTree() : DynamicAabbTree<D>(AabbTreeOptions{0, 0.1, 0}) {}
};

enum class Scene { mixed, identical, sizes, line, points, sparse_ids };

std::string name(Scene s) {
  switch (s) {
    case Scene::mixed:
      return "mixed";
    case Scene::identical:
      return "identical";
    case Scene::sizes:
      return "sizes";
    case Scene::line:
      return "line";
    case Scene::points:
      return "points";
    default:
      return "sparse_ids";
  }
}

// Objects moving at constant velocity through a world of side 60 they are free to leave,
// some teleporting, some added and removed every tick.
template <int D>
class World {
 public:
  World(Scene scene, std::uint64_t seed) : scene_(scene), rng_(seed) {}

  struct Obj {
    Id id;
    Box<D> box;
    Point<D> v;
  };

  Obj make() {
    Obj o;
    o.id = scene_ == Scene::sparse_ids ? Id(rng_()) : next_id_++;
    Point<D> c, h;
    for (int a = 0; a < D; ++a) {
      c[a] = uniform(0, 60);
      o.v[a] = uniform(-1.5, 1.5);
      h[a] = uniform(0.2, 2.5);
    }
    switch (scene_) {
      case Scene::identical:
        for (int a = 0; a < D; ++a)
          c[a] = 10 + 5 * double(rng_() % 3), h[a] = 1, o.v[a] = 0.3;
        break;
      case Scene::sizes:
        for (int a = 0; a < D; ++a)
          h[a] = rng_() % 20 == 0 ? uniform(10, 40) : uniform(0.001, 0.3);
        break;
      case Scene::line:
        for (int a = 1; a < D; ++a)
          c[a] = 0, h[a] = 0, o.v[a] = 0;
        break;
      case Scene::points:
        for (int a = 0; a < D; ++a)
          h[a] = 0, c[a] = std::round(c[a] / 12) * 12, o.v[a] = std::round(o.v[a]);
        break;
      default:
        break;
    }
    for (int a = 0; a < D; ++a) {
      o.box.min[a] = c[a] - h[a];
      o.box.max[a] = c[a] + h[a];
    }
    return o;
  }

  // One tick of motion on every object, teleports included.
  void step() {
    for (Obj& o : objs) {
      Point<D> d = o.v;
      if (rng_() % 100 == 0)
        for (int a = 0; a < D; ++a)
          d[a] = uniform(-50, 50);
      if (scene_ == Scene::line)
        for (int a = 1; a < D; ++a)
          d[a] = 0;
      for (int a = 0; a < D; ++a) {
        o.box.min[a] += d[a];
        o.box.max[a] += d[a];
      }
    }
  }

  std::vector<IdPair> brute_pairs() const {
    std::vector<IdPair> out;
    for (std::size_t i = 0; i < objs.size(); ++i)
      for (std::size_t j = i + 1; j < objs.size(); ++j)
        if (intersects(objs[i].box, objs[j].box))
          out.push_back({std::min(objs[i].id, objs[j].id), std::max(objs[i].id, objs[j].id)});
    std::sort(out.begin(), out.end());
    return out;
  }

  std::vector<Id> brute_query(const Box<D>& w) const {
    std::vector<Id> out;
    for (const Obj& o : objs)
      if (intersects(o.box, w)) out.push_back(o.id);
    std::sort(out.begin(), out.end());
    return out;
  }

  double uniform(double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng_);
  }
  std::uint64_t next() { return rng_(); }

  std::vector<Obj> objs;

 private:
  Scene scene_;
  std::mt19937_64 rng_;
  Id next_id_ = 0;
};

std::vector<IdPair> sorted(std::vector<IdPair> v) {
  std::sort(v.begin(), v.end());
  return v;
}

// The pairs of `now` not in `before` (both sorted).
std::vector<IdPair> minus(const std::vector<IdPair>& now, const std::vector<IdPair>& before) {
  std::vector<IdPair> out;
  std::set_difference(now.begin(), now.end(), before.begin(), before.end(),
                      std::back_inserter(out));
  return out;
}

template <class BP>
void run(Scene scene, std::uint64_t seed, int n = 200, int ticks = 40) {
  constexpr int D = BP::dimension;
  SCOPED_TRACE(name(scene) + " seed " + std::to_string(seed));
  World<D> world(scene, seed);
  BP bp;
  auto add_one = [&] {
    auto o = world.make();
    for (const auto& p : world.objs)
      if (p.id == o.id) return;
    bp.add(o.id, o.box);
    world.objs.push_back(o);
  };
  for (int i = 0; i < n; ++i)
    add_one();
  std::vector<IdPair> before;
  std::size_t total = 0;
  for (int tick = 0; tick < ticks; ++tick) {
    SCOPED_TRACE("tick " + std::to_string(tick));
    world.step();
    for (const auto& o : world.objs)
      bp.move(o.id, o.box);
    // Removals and additions mid-run, some reusing the slots just freed.
    for (int k = 0; k < 4 && !world.objs.empty(); ++k) {
      const std::size_t i = world.next() % world.objs.size();
      ASSERT_TRUE(bp.remove(world.objs[i].id));
      world.objs.erase(world.objs.begin() + std::ptrdiff_t(i));
    }
    for (int k = 0; k < 4; ++k)
      add_one();
    ASSERT_EQ(bp.size(), world.objs.size());

    const auto expect = world.brute_pairs();
    ASSERT_EQ(sorted(bp.pairs()), expect);
    ASSERT_NO_THROW(bp.validate());

    std::vector<IdPair> began, ended;
    bp.update(
        [&](Id a, Id b) {
          return began.push_back({a, b}), true;
        },
        [&](Id a, Id b) {
          return ended.push_back({a, b}), true;
        });
    ASSERT_EQ(sorted(began), minus(expect, before));
    ASSERT_EQ(sorted(ended), minus(before, expect));
    before = expect;
    total += expect.size();

    Box<D> w;
    for (int a = 0; a < D; ++a) {
      const double c = world.uniform(-10, 70), h = world.uniform(0, 15);
      w.min[a] = c - h, w.max[a] = c + h;
    }
    auto got = bp.query(w);
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, world.brute_query(w));
    ASSERT_NO_THROW(bp.validate());
  }
  EXPECT_GT(total, std::size_t(ticks)) << "the scene should keep objects in contact";
}

template <class BP>
class BroadPhaseTest : public ::testing::Test {};

using Structures = ::testing::Types<SweepPrune<2>, SweepPrune<3>, StripedSweep<2>, StripedSweep<3>,
                                    IncrementalSweepPrune<2>, IncrementalSweepPrune<3>,
                                    UniformGrid<2>, UniformGrid<3>, FineGrid<2>, DynamicAabbTree<2>,
                                    DynamicAabbTree<3>, TightTree<2>, UnpredictedTree<2>>;
TYPED_TEST_SUITE(BroadPhaseTest, Structures);

TYPED_TEST(BroadPhaseTest, RandomMotion) {
  for (std::uint64_t seed : {1, 2, 3})
    run<TypeParam>(Scene::mixed, seed);
}

TYPED_TEST(BroadPhaseTest, IdenticalBoxes) {
  run<TypeParam>(Scene::identical, 4, 60, 20);
}

TYPED_TEST(BroadPhaseTest, VeryDifferentSizes) {
  run<TypeParam>(Scene::sizes, 5);
}

TYPED_TEST(BroadPhaseTest, AllOnOneLine) {
  run<TypeParam>(Scene::line, 6);
}

TYPED_TEST(BroadPhaseTest, PointBoxes) {
  run<TypeParam>(Scene::points, 7);
}

TYPED_TEST(BroadPhaseTest, SparseIds) {
  run<TypeParam>(Scene::sparse_ids, 8);
}

TYPED_TEST(BroadPhaseTest, EmptyAndSingle) {
  TypeParam bp;
  EXPECT_TRUE(bp.empty());
  EXPECT_TRUE(bp.pairs().empty());
  bp.validate();
  Box<TypeParam::dimension> b;
  for (int a = 0; a < TypeParam::dimension; ++a)
    b.min[a] = 0, b.max[a] = 1;
  bp.add(7, b);
  EXPECT_TRUE(bp.pairs().empty());
  EXPECT_EQ(bp.query(b), std::vector<Id>{7});
  bp.add(3, b);
  EXPECT_EQ(bp.pairs(), (std::vector<IdPair>{{3, 7}}));
  bp.validate();
  EXPECT_TRUE(bp.remove(7));
  EXPECT_TRUE(bp.pairs().empty());
  EXPECT_TRUE(bp.remove(3));
  EXPECT_TRUE(bp.empty());
  bp.validate();
}

TYPED_TEST(BroadPhaseTest, TouchingCounts) {
  constexpr int D = TypeParam::dimension;
  TypeParam bp;
  Box<D> a, b, c;
  for (int k = 0; k < D; ++k) {
    a.min[k] = 0, a.max[k] = 1;
    b.min[k] = 1, b.max[k] = 2;  // touches a at a corner
    c.min[k] = 1.5, c.max[k] = 2;
  }
  c.min[0] = 2.5, c.max[0] = 3;
  bp.add(0, a);
  bp.add(1, b);
  bp.add(2, c);
  EXPECT_EQ(bp.pairs(), (std::vector<IdPair>{{0, 1}}));
  c.min[0] = 2;  // now touches b on a face
  bp.move(2, c);
  EXPECT_EQ(sorted(bp.pairs()), (std::vector<IdPair>{{0, 1}, {1, 2}}));
}

// Boxes of subnormal extent (1e-310) touching in a row, and a subnormal fixed cell: the grid's
// cell side became subnormal, its inverse infinite and a coordinate of 0 a NaN cell (bad_alloc
// or undefined behaviour).
TYPED_TEST(BroadPhaseTest, SubnormalExtents) {
  constexpr int D = TypeParam::dimension;
  TypeParam bp;
  const double e = 1e-310;
  for (int i = 0; i < 3; ++i) {
    Box<D> b;
    for (int k = 0; k < D; ++k)
      b.min[k] = 0, b.max[k] = e;
    b.min[0] = i * e, b.max[0] = i * e + e;
    bp.add(Id(i), b);
  }
  EXPECT_EQ(sorted(bp.pairs()), (std::vector<IdPair>{{0, 1}, {1, 2}}));
  bp.validate();
}

// Boxes whose extent overflows (from -1e308 to 1e308: every coordinate finite, max - min
// infinite) among small ones: the grid's median extent was infinite, its cells infinitely
// wide, and validate() refused the grid although the pairs were right.
TYPED_TEST(BroadPhaseTest, ExtentsBeyondTheLargestDouble) {
  constexpr int D = TypeParam::dimension;
  std::vector<Box<D>> boxes(5);
  for (int k = 0; k < D; ++k) {
    boxes[0].min[k] = -1e308, boxes[0].max[k] = 1e308;
    boxes[1].min[k] = -1.7e308, boxes[1].max[k] = 1.5e308;
    boxes[2].min[k] = 0, boxes[2].max[k] = 1;
    boxes[3].min[k] = -1e308, boxes[3].max[k] = 1.7e308;
    boxes[4].min[k] = 5, boxes[4].max[k] = 6;
  }
  TypeParam bp;
  std::vector<IdPair> expected;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    bp.add(Id(i), boxes[i]);
    for (std::size_t j = 0; j < i; ++j)
      if (intersects(boxes[i], boxes[j])) expected.push_back({Id(j), Id(i)});
  }
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(sorted(bp.pairs()), expected);
  bp.validate();
  bp.remove(0);
  bp.remove(1);
  std::erase_if(expected, [](const IdPair& p) { return p.a <= 1; });
  EXPECT_EQ(sorted(bp.pairs()), expected);
  bp.validate();
}

// A move across the whole range of doubles (its displacement overflows): with a prediction of
// 0 the tree's fat box became NaN (0 * inf), and queries and pairs missed the proxy.
TYPED_TEST(BroadPhaseTest, MoveWhoseDisplacementOverflows) {
  constexpr int D = TypeParam::dimension;
  Box<D> west, east, small;
  for (int k = 0; k < D; ++k) {
    west.min[k] = west.max[k] = k == 0 ? -1e308 : 0;
    east.min[k] = east.max[k] = k == 0 ? 1e308 : 0;
    small.min[k] = -5, small.max[k] = -4;
  }
  TypeParam bp;
  bp.add(1, west);
  bp.add(3, small);
  bp.update([](Id, Id) { return true; }, [](Id, Id) { return true; });
  bp.move(1, east);
  bp.add(2, east);
  EXPECT_EQ(sorted(bp.pairs()), (std::vector<IdPair>{{1, 2}}));
  auto got = bp.query(east);
  std::sort(got.begin(), got.end());
  EXPECT_EQ(got, (std::vector<Id>{1, 2}));
  bp.validate();
}

// clear() removes every proxy as remove() would: the next update() reports their pairs as
// ended (it forgot them, and a caller keeping contacts from the reports kept them open).
TYPED_TEST(BroadPhaseTest, ClearEndsEveryPair) {
  constexpr int D = TypeParam::dimension;
  TypeParam bp;
  if constexpr (requires { bp.clear(); }) {
    auto cube = [](double lo, double hi) {
      Box<D> b;
      for (int k = 0; k < D; ++k)
        b.min[k] = lo, b.max[k] = hi;
      return b;
    };
    const auto tick = [&] {
      std::vector<IdPair> begun, ended;
      bp.update(
          [&](Id a, Id b) {
            return begun.push_back({a, b}), true;
          },
          [&](Id a, Id b) {
            return ended.push_back({a, b}), true;
          });
      return std::pair{sorted(begun), sorted(ended)};
    };
    const std::vector<IdPair> all{{1, 2}, {2, 3}};
    bp.add(1, cube(0, 2));
    bp.add(2, cube(1, 3));
    bp.add(3, cube(3, 4));
    EXPECT_EQ(tick(), (std::pair{all, std::vector<IdPair>{}}));
    bp.clear();
    EXPECT_EQ(bp.size(), 0u);
    EXPECT_EQ(tick(), (std::pair{std::vector<IdPair>{}, all}));
    bp.add(2, cube(1, 3));
    bp.add(3, cube(3, 4));
    EXPECT_EQ(tick(), (std::pair{std::vector<IdPair>{{2, 3}}, std::vector<IdPair>{}}));
    bp.validate();
  }
}

TEST(UniformGrid, SubnormalFixedCell) {
  UniformGrid<2> g(1e-310);
  g.add(1, Box2{{0, 0}, {1, 1}});
  g.add(2, Box2{{1, 1}, {2, 2}});
  g.add(3, Box2{{-1e-310, -1e-310}, {0, 0}});
  EXPECT_EQ(sorted(g.pairs()), (std::vector<IdPair>{{1, 2}, {1, 3}}));
  g.validate();
}

TYPED_TEST(BroadPhaseTest, Errors) {
  constexpr int D = TypeParam::dimension;
  TypeParam bp;
  Box<D> b;
  for (int k = 0; k < D; ++k)
    b.min[k] = 0, b.max[k] = 1;
  bp.add(1, b);
  EXPECT_THROW(bp.add(1, b), InvalidArgument);
  EXPECT_THROW(bp.move(2, b), InvalidArgument);
  EXPECT_FALSE(bp.remove(2));
  Box<D> bad = b;
  bad.min[0] = 2;
  EXPECT_THROW(bp.add(3, bad), InvalidGeometry);
  EXPECT_THROW(bp.move(1, bad), InvalidGeometry);
  bad.min[0] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(bp.add(3, bad), InvalidGeometry);
  // Query windows are checked as proxies are: a NaN window would meet every proxy and an
  // inverted one some.
  EXPECT_THROW(bp.query(bad), InvalidGeometry);
  bad.min[0] = 0.8, bad.max[0] = 0.2;
  EXPECT_THROW(bp.query(bad), InvalidGeometry);
  bad.min[0] = -std::numeric_limits<double>::infinity();
  EXPECT_THROW(bp.query(bad, [](Id, const Box<D>&) { return true; }), InvalidGeometry);
  bp.validate();
}

TYPED_TEST(BroadPhaseTest, EarlyStop) {
  constexpr int D = TypeParam::dimension;
  TypeParam bp;
  Box<D> b;
  for (int k = 0; k < D; ++k)
    b.min[k] = 0, b.max[k] = 1;
  for (Id i = 0; i < 10; ++i)
    bp.add(i, b);
  int seen = 0;
  const QueryStats st = bp.pairs([&](Id, Id) { return ++seen < 5; });
  EXPECT_EQ(seen, 5);
  EXPECT_EQ(st.results, 5u);
  EXPECT_EQ(bp.pairs().size(), 45u);
  bp.validate();
}

// entry_pairs against pairs(): the ids it lays out, mapped through the partners it hands
// over, are the same pairs, each once, partners after their entry, separators never visited;
// with and without stripes, in 2 and 3 dimensions; a visit returning false stops the sweep.
template <class BP, bool kStriped>
void expect_entry_pairs_match(Scene scene, std::uint64_t seed, int n) {
  constexpr int D = BP::dimension;
  SCOPED_TRACE(name(scene) + " seed " + std::to_string(seed));
  World<D> world(scene, seed);
  BP bp;
  for (int i = 0; i < n; ++i) {
    const auto o = world.make();
    if (bp.contains(o.id)) continue;
    bp.add(o.id, o.box);
    world.objs.push_back(o);
  }
  std::vector<Id> laid;
  std::vector<IdPair> got;
  const QueryStats st =
      bp.entry_pairs([&](std::span<const Id> ids) { laid.assign(ids.begin(), ids.end()); },
                     [&](std::size_t e, std::span<const std::uint32_t> partners) {
                       EXPECT_LT(e, laid.size());
                       EXPECT_NE(laid[e], BP::kSeparator);
                       EXPECT_FALSE(partners.empty());
                       for (const std::uint32_t f : partners) {
                         EXPECT_GT(f, e);
                         EXPECT_NE(laid[f], BP::kSeparator);
                         got.push_back({std::min(laid[e], laid[f]), std::max(laid[e], laid[f])});
                       }
                       return true;
                     });
  EXPECT_EQ(st.results, got.size());
  EXPECT_EQ(sorted(got), world.brute_pairs());
  // The separators: one after each stripe, the last entry among them; without stripes every
  // proxy once and one separator.
  ASSERT_FALSE(laid.empty());
  EXPECT_EQ(laid.back(), BP::kSeparator);
  const auto separators = std::count(laid.begin(), laid.end(), BP::kSeparator);
  std::vector<Id> proxies;
  for (const Id id : laid)
    if (id != BP::kSeparator) proxies.push_back(id);
  std::sort(proxies.begin(), proxies.end());
  std::vector<Id> live;
  for (const auto& o : world.objs)
    live.push_back(o.id);
  std::sort(live.begin(), live.end());
  std::vector<Id> distinct = proxies;
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  EXPECT_EQ(distinct, live);
  if (!kStriped) {
    EXPECT_EQ(separators, 1);
    EXPECT_EQ(proxies, live);
  }
  ASSERT_FALSE(got.empty());
  int runs = 0;
  bp.entry_pairs([](std::span<const Id>) {},
                 [&](std::size_t, std::span<const std::uint32_t>) { return ++runs < 3; });
  EXPECT_EQ(runs, 3);
}

TEST(SweepPrune, EntryPairsMatchPairs) {
  for (Scene scene : {Scene::mixed, Scene::identical, Scene::sizes, Scene::sparse_ids}) {
    expect_entry_pairs_match<SweepPrune<2>, false>(scene, 7, 300);
    expect_entry_pairs_match<StripedSweep<2>, true>(scene, 8, 300);
    expect_entry_pairs_match<StripedSweep<3>, true>(scene, 9, 300);
    expect_entry_pairs_match<IncrementalSweepPrune<2>, false>(scene, 10, 300);
  }
}

// Adds boxes[i] as proxy i and expects pairs() to be the pairs of boxes that meet.
template <class BP, int D>
void expect_pairs_of(BP& bp, const std::vector<Box<D>>& boxes) {
  std::vector<IdPair> want;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    bp.add(i, boxes[i]);
    for (std::size_t j = i + 1; j < boxes.size(); ++j)
      if (intersects(boxes[i], boxes[j])) want.push_back({i, j});
  }
  EXPECT_EQ(sorted(bp.pairs()), want);
}

// The sweep orders runs by mins rounded down to floats: boxes that touch exactly at a value
// a float rounds up (0.1, 1/3), rounds to -0 (-1e-50) or to infinity (1e39), or where floats
// are sparse (1e30 plus a few ulps), are still paired, as in brute force.
TEST(SweepPrune, TouchingWhereFloatsRound) {
  for (double x : {0.1, 1.0 / 3, -1e-50, 1e-50, 1e39, -1e39, 1e30, -0.7, 1e300, -1e300}) {
    SCOPED_TRACE(x);
    for (bool striped : {false, true}) {
      SweepPrune<2> bp(striped ? 4 : 4096);
      std::vector<Box2> boxes;
      const double u = std::nextafter(x, std::numeric_limits<double>::infinity());
      for (int k = 0; k < 6; ++k) {
        const double y = k * 1e-3;                  // x varies most: the sweep runs along x
        boxes.push_back({{x - 1, y}, {x, y + 1}});  // ends exactly at x
        boxes.push_back({{x, y}, {x + 1, y + 1}});  // starts exactly at x
        boxes.push_back({{u, y}, {u, y + 2}});      // starts an ulp after x
        boxes.push_back({{std::nextafter(u, u + 1), y}, {u + 1, y}});
      }
      expect_pairs_of(bp, boxes);
    }
  }
}

// Boxes whose bounds all come from a few values where floats round (a value, its double
// neighbours, values a float step apart, beyond the float range, the largest float): on
// every axis, the sweep's float tests are decided exactly, as brute force decides them.
template <class BP, int D>
void expect_pairs_at_float_steps(BP bp, std::uint64_t seed) {
  const double f = 1.0 + 0x1p-23;  // the float after 1
  const double hard[] = {1.0,
                         std::nextafter(1.0, 2.0),
                         std::nextafter(1.0, 0.0),
                         f,
                         std::nextafter(f, 0.0),
                         0.1,
                         -0.1,
                         0.0,
                         -1e-50,
                         double(std::numeric_limits<float>::max()),
                         std::nextafter(double(std::numeric_limits<float>::max()), 1e300),
                         1e39,
                         -1e39,
                         1e300,
                         -1e300};
  constexpr int kHard = sizeof(hard) / sizeof(hard[0]);
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> pick(0, kHard - 1);
  std::vector<Box<D>> boxes;
  for (int n = 0; n < 300; ++n) {
    Box<D> b;
    for (int a = 0; a < D; ++a) {
      const double x = hard[pick(rng)], y = hard[pick(rng)];
      b.min[a] = std::min(x, y);
      b.max[a] = std::max(x, y);
    }
    boxes.push_back(b);
  }
  expect_pairs_of(bp, boxes);
}

TEST(SweepPrune, PairsAtFloatStepsOnEveryAxis) {
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    expect_pairs_at_float_steps<SweepPrune<2>, 2>(SweepPrune<2>(), seed);
    expect_pairs_at_float_steps<SweepPrune<2>, 2>(SweepPrune<2>(4), seed);
    expect_pairs_at_float_steps<SweepPrune<3>, 3>(SweepPrune<3>(4), seed);
    expect_pairs_at_float_steps<IncrementalSweepPrune<2>, 2>(IncrementalSweepPrune<2>(), seed);
    expect_pairs_at_float_steps<IncrementalSweepPrune<3>, 3>(IncrementalSweepPrune<3>(), seed);
  }
}

}  // namespace
}  // namespace loci
