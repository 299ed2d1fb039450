// Every moving index against brute force: timeslice windows, windows over an interval, moving
// windows and nearest-n at a time, on fixed-seed fleets with the degenerate cases, through
// updates and erasures, and before the index's clock.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <limits>
#include <numeric>
#include <random>
#include <unordered_map>
#include <vector>

#include "loci/index/moving/moving_grid.hpp"
#include "loci/index/moving/moving_scan.hpp"
#include "loci/index/moving/star_tree.hpp"
#include "loci/index/moving/tpr_tree.hpp"
#include "support/fleet_data.hpp"

namespace loci::detail {

// What the Choose_Path test reads of a tree's internals.
struct MovingRTreeAccess {
  template <int D, int M, class P>
  static Tpbr<D> box_of(const MovingRTree<D, M, P>& t, const Motion<D>& m) {
    return Tpbr<D>::of(m, t.epoch_);
  }
  template <int D, int M, class P>
  static std::uint32_t choose_path(MovingRTree<D, M, P>& t, const Tpbr<D>& b, int level) {
    return t.choose_path(b, level);
  }
  template <int D, int M, class P>
  static std::uint32_t root(const MovingRTree<D, M, P>& t) {
    return t.root_;
  }
  template <int D, int M, class P>
  static std::uint32_t parent(const MovingRTree<D, M, P>& t, std::uint32_t x) {
    return t.nodes_[x].parent;
  }
  template <int D, int M, class P>
  static int level(const MovingRTree<D, M, P>& t, std::uint32_t x) {
    return t.nodes_[x].level;
  }
  // The summed rises of cost along the path from the root to node x, from the top down (the
  // order in which Choose_Path adds them).
  template <int D, int M, class P>
  static double path_cost(MovingRTree<D, M, P>& t, std::uint32_t x, const Tpbr<D>& b) {
    std::vector<std::pair<std::uint32_t, int>> steps;  // (node, entry leading down)
    for (; t.nodes_[x].parent != kNone; x = t.nodes_[x].parent)
      steps.push_back({t.nodes_[x].parent, t.slot_in_parent(x)});
    double key = 0;
    for (auto it = steps.rbegin(); it != steps.rend(); ++it) {
      double rise[M + 1];
      t.enlargements(t.nodes_[it->first], b, rise);
      key += rise[it->second];
    }
    return key;
  }
  // The largest difference between the rises enlargements() gives for the entries of node x
  // and those of detail::swept_cost on the entry's box before and after taking b, relative to
  // the costs involved.
  template <int D, int M, class P>
  static double rise_error(MovingRTree<D, M, P>& t, std::uint32_t x, const Tpbr<D>& b) {
    double rise[M + 1];
    auto& node = t.nodes_[x];
    t.enlargements(node, b, rise);
    const double c = t.rel_clock(), h = P::horizon(t.params());
    const Point<D> extent = P::extent(t.params());
    double worst = 0;
    for (int e = 0; e < node.count; ++e) {
      const Tpbr<D> before = node.box[e];
      Tpbr<D> after = before;
      after.enclose(b, c);
      const double cb = swept_cost(before, c, h, extent), ca = swept_cost(after, c, h, extent);
      // Relative to the costs (absolute where both are 0: areas of points); NaN fails.
      const double gap = std::abs(rise[e] - std::max(0.0, ca - cb));
      const double err = ca + cb > 0 ? gap / (ca + cb) : gap;
      if (!(err <= worst)) worst = err;
    }
    return worst;
  }
  // The largest rise of an entry of node x taking its own box: exactly 0 is expected.
  template <int D, int M, class P>
  static double own_rise(MovingRTree<D, M, P>& t, std::uint32_t x) {
    double worst = 0;
    auto& node = t.nodes_[x];
    for (int e = 0; e < node.count; ++e) {
      double rise[M + 1];
      t.enlargements(node, node.box[e], rise);
      worst = std::max(worst, rise[e]);
    }
    return worst;
  }
  // The least such sum over every node of `level`, by visiting all paths.
  template <int D, int M, class P>
  static double best_cost(MovingRTree<D, M, P>& t, const Tpbr<D>& b, int level) {
    double best = std::numeric_limits<double>::infinity();
    auto walk = [&](auto&& self, std::uint32_t x, double key) -> void {
      if (t.nodes_[x].level == level) {
        best = std::min(best, key);
        return;
      }
      double rise[M + 1];
      t.enlargements(t.nodes_[x], b, rise);
      for (int e = 0; e < t.nodes_[x].count; ++e)
        self(self, t.nodes_[x].child[e], key + rise[e]);
    };
    walk(walk, t.root_, 0.0);
    return best;
  }
};

}  // namespace loci::detail

namespace loci {
namespace {

using Objects = std::unordered_map<Id, Motion2>;

std::vector<Id> brute_window(const Objects& objs, const MovingWindow<2>& w) {
  std::vector<Id> out;
  for (const auto& [id, m] : objs)
    if (inside(m, w)) out.push_back(id);
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<double> brute_nearest(const Objects& objs, const Point2& q, double s, std::size_t k) {
  std::vector<double> d;
  for (const auto& [id, m] : objs)
    d.push_back(std::sqrt(squared_distance(position(m, s), q)));
  std::sort(d.begin(), d.end());
  d.resize(std::min(k, d.size()));
  return d;
}

// The TPR*-tree with every update an erasure and an insertion, as in the paper.
struct TprEraseInsert : TprTree<2, 8> {
  TprEraseInsert() : TprTree<2, 8>(params()) {}
  static TprParams<2> params() {
    TprParams<2> p;
    p.in_place_updates = false;
    p.query_extent = {50, 50};
    return p;
  }
};

template <class T>
class MovingIndexTest : public ::testing::Test {};

// The STAR-tree regrouping eagerly, so that the tests see many regroupings.
struct EagerStar : StarTree<2, 6> {
  EagerStar() : StarTree<2, 6>(StarParams<2>{1.05, 30, true}) {}
};

// The grid with one velocity band, cells of one object and no horizon (laid out at the
// clock, so queries ahead look far from its reference time), and with many bands.
struct FineGrid : MovingGrid<2> {
  FineGrid() : MovingGrid<2>(MovingGridParams<2>{0, 1, 1}) {}
};
struct BandedGrid : MovingGrid<2> {
  BandedGrid() : MovingGrid<2>(MovingGridParams<2>{30, 7, 4}) {}
};

using Structures = ::testing::Types<MovingScan<2>, TprTree<2>, TprTree<2, 6>, TprEraseInsert,
                                    StarTree<2>, EagerStar, MovingGrid<2>, FineGrid, BandedGrid>;
TYPED_TEST_SUITE(MovingIndexTest, Structures);

MovingWindow<2> random_window(std::mt19937_64& rng, double now, int kind) {
  std::uniform_real_distribution<double> u(-100, 1000), len(0, 150), ahead(0, 60), v(-3, 3);
  const double x = u(rng), y = u(rng), wx = len(rng), wy = len(rng);
  const Box2 b{{x, y}, {x + wx, y + wy}};
  const double t1 = now + ahead(rng);
  if (kind == 0) return MovingWindow<2>::at(b, t1);
  const double t2 = t1 + ahead(rng) / 4;
  if (kind == 1) return MovingWindow<2>::during(b, t1, t2);
  const double dx = v(rng) * (t2 - t1), dy = v(rng) * (t2 - t1);
  return {b, {{x + dx, y + dy}, {x + wx + dx, y + wy + dy}}, t1, t2};
}

void check_queries(const auto& index, const Objects& objs, double now, std::uint64_t seed,
                   const std::string& what) {
  std::mt19937_64 rng(seed);
  for (int q = 0; q < 60; ++q) {
    const MovingWindow<2> w = random_window(rng, now, q % 3);
    std::vector<Id> got = index.query(w);
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, brute_window(objs, w)) << what << " query " << q;
  }
  std::uniform_real_distribution<double> u(0, 1000), ahead(0, 60);
  for (int q = 0; q < 30; ++q) {
    const Point2 p{u(rng), u(rng)};
    const double s = now + ahead(rng);
    const std::size_t k = 1 + q % 12;
    const auto got = index.nearest(p, s, k);
    const auto want = brute_nearest(objs, p, s, k);
    ASSERT_EQ(got.size(), want.size()) << what;
    for (std::size_t i = 0; i < got.size(); ++i) {
      ASSERT_DOUBLE_EQ(got[i].distance, want[i]) << what << " nearest " << q << " rank " << i;
      ASSERT_DOUBLE_EQ(std::sqrt(squared_distance(position(objs.at(got[i].id), s), p)),
                       got[i].distance);
    }
  }
}

TYPED_TEST(MovingIndexTest, MatchesBruteForceOnEveryFleet) {
  for (test::Fleet f : test::kAllFleets) {
    const auto fleet = test::make_fleet(f, 1500, 42);
    TypeParam index;
    Objects objs;
    for (std::size_t i = 0; i < fleet.size(); ++i) {
      index.insert(Id(i * 7 + 3), fleet[i]);
      objs[Id(i * 7 + 3)] = fleet[i];
    }
    index.validate();
    EXPECT_EQ(index.size(), fleet.size());
    check_queries(index, objs, test::fleet_epoch(f), 5, test::name(f));
  }
}

// Windows at epoch-second times (an ulp of 1.7e9 is 2.4e-7 s): an object 1e-8 beyond an edge
// at t1 and moving away leaves the window 1e-8 s before t1, which rounded onto t1 in absolute
// time and held it (in the scan and a tree's leaves; not where a node's bounds pruned it).
// The answers are known by hand; far objects give the trees inner nodes.
TYPED_TEST(MovingIndexTest, EpochSecondWindowsHoldNoObjectMovingAway) {
  const double t = 1.7e9;
  TypeParam index;
  std::vector<Id> want;
  Id id = 1;
  for (int k = 0; k <= 3; ++k) {
    const double off = k * 1e-8;
    // Away beyond each edge (on it when k == 0: inside, touching counts); towards it: inside.
    const Motion2 away[] = {{t, {10 + off, 5}, {1, 0}},
                            {t, {-off, 5}, {-1, 0}},
                            {t, {5, 10 + off}, {0, 1}},
                            {t, {5, -off}, {0, -1}}};
    const Motion2 towards[] = {{t, {10 + off, 5}, {-1, 0}}, {t, {5, -off}, {0, 1}}};
    for (const Motion2& m : away) {
      if (k == 0) want.push_back(id);
      index.insert(id++, m);
    }
    for (const Motion2& m : towards) {
      want.push_back(id);
      index.insert(id++, m);
    }
  }
  for (int i = 0; i < 40; ++i)
    index.insert(1000 + i, Motion2{t, {1000.0 + i, 1000.0 - i}, {0, 0}});
  for (const MovingWindow<2>& w :
       {MovingWindow<2>::during(Box2{{0, 0}, {10, 10}}, t, t + 10),
        MovingWindow<2>{Box2{{0, 0}, {10, 10}}, Box2{{0, 0}, {10, 10}}, t, t + 0.5}}) {
    std::vector<Id> got = index.query(w);
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, want);
  }
}

// Reports long before the others at extreme magnitudes: an object reported 2e6 s before the
// tree's first report, 2e12 away and closing at 1e6 units a second, lies near the others at
// the epoch; its bounds there, p + v (epoch - t), round at the size of p and of its travel
// (2.4e-4), which the trees' pruning allowance counted only at the bounds' own size. Windows
// with an edge on such an object's position at the query time hold it (touching counts), and
// a nearest query at that position finds it before another object 1e-4 away.
TYPED_TEST(MovingIndexTest, AncientReportsOnTheWindowsEdgesAreFound) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, 1000), sign(-1, 1);
  TypeParam index;
  Objects objs;
  Id id = 1;
  for (int i = 0; i < 200; ++i) {
    const Motion2 m{0, {u(rng), u(rng)}, {sign(rng), sign(rng)}};
    index.insert(id, m);
    objs[id++] = m;
  }
  std::vector<Motion2> ancient;
  for (int i = 0; i < 50; ++i) {
    const double t = -2e6 - 1e4 * u(rng);
    const Point2 v{1e6 * sign(rng), 1e6 * sign(rng)}, at{u(rng), u(rng)};
    const Motion2 m{t, {at[0] - v[0] * (0 - t), at[1] - v[1] * (0 - t)}, v};
    index.insert(id, m);
    objs[id++] = m;
    ancient.push_back(m);
  }
  int held = 0;
  for (std::size_t i = 0; i < ancient.size(); ++i) {
    const double s = 1e-6 * u(rng);
    const Point2 p = position(ancient[i], s);
    // The object's position is a corner of the window, on one side or the other.
    const double wx = 10 * sign(rng), wy = 10 * sign(rng);
    const Box2 b{{std::min(p[0], p[0] + wx), std::min(p[1], p[1] + wy)},
                 {std::max(p[0], p[0] + wx), std::max(p[1], p[1] + wy)}};
    // A timeslice, or an interval from s (the object may leave the window at once).
    const MovingWindow<2> w =
        i % 2 ? MovingWindow<2>::during(b, s, s + 1e-9) : MovingWindow<2>::at(b, s);
    std::vector<Id> got = index.query(w);
    std::sort(got.begin(), got.end());
    const std::vector<Id> want = brute_window(objs, w);
    ASSERT_EQ(got, want) << "window " << i;
    held += int(want.size());
  }
  // Nearest to each such object's position, with another object standing 1e-4 from it: the
  // first is at distance 0 (pruning its bounds by the old allowance gave the other).
  for (std::size_t i = 0; i < ancient.size(); ++i) {
    const double s = 1e-6 * u(rng);
    const Point2 p = position(ancient[i], s);
    const Motion2 near_it{0, {p[0] + 1e-4 * sign(rng), p[1] + 1e-4 * sign(rng)}, {0, 0}};
    index.insert(id, near_it);
    objs[id++] = near_it;
    const auto near = index.nearest(p, s, 1);
    ASSERT_EQ(near.size(), 1u);
    EXPECT_EQ(near[0].distance, brute_nearest(objs, p, s, 1)[0]) << "nearest " << i;
    EXPECT_EQ(near[0].distance, 0.0) << "nearest " << i;
  }
  // Every timeslice holds its object (an interval may lose one that leaves it at once).
  EXPECT_GE(held, 25);
}

TYPED_TEST(MovingIndexTest, UpdatesErasuresAndTicks) {
  const auto fleet = test::make_fleet(test::Fleet::uniform, 3000, 9);
  TypeParam index;
  Objects objs;
  for (std::size_t i = 0; i < fleet.size(); ++i) {
    index.insert(i, fleet[i]);
    objs[i] = fleet[i];
  }
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<std::size_t> pick(0, fleet.size() + 200);
  std::uniform_real_distribution<double> v(-3, 3), jitter(-2, 2);
  double now = 0;
  for (int tick = 1; tick <= 20; ++tick) {
    now = tick * 1.0;
    for (int u = 0; u < 120; ++u) {
      const Id id = pick(rng);
      if (u % 11 == 0) {
        EXPECT_EQ(index.erase(id), objs.erase(id) == 1);
        continue;
      }
      // A new report: the object where it is now (plus noise), a new velocity, or (every
      // other report) nearly the old one, which the TPR*-tree writes in place.
      Motion2 m{now, {jitter(rng) + 500, jitter(rng) + 500}, {v(rng), v(rng)}};
      if (auto it = objs.find(id); it != objs.end()) {
        const Point2 p = position(it->second, now);
        m.p = {p[0] + jitter(rng) / 100, p[1] + jitter(rng) / 100};
        if (u % 2) m.v = {it->second.v[0] * 0.99, it->second.v[1] * 0.99};
      }
      index.update(id, m);
      objs[id] = m;
    }
    EXPECT_EQ(index.size(), objs.size());
    if (tick % 5 == 0) {
      index.validate();
      check_queries(index, objs, now, tick, "tick " + std::to_string(tick));
    }
  }
  // Queries before the clock are still exact.
  EXPECT_EQ(index.clock(), now);
  check_queries(index, objs, now - 15, 77, "before the clock");
  for (const auto& [id, m] : objs)
    EXPECT_TRUE(index.erase(id));
  EXPECT_TRUE(index.empty());
  index.validate();
}

TYPED_TEST(MovingIndexTest, RefusesBadInput) {
  TypeParam index;
  EXPECT_THROW(index.nearest(Point2{0, 0}, 0, 0), InvalidArgument);
  index.insert(1, Motion2{0, {0, 0}, {1, 1}});
  EXPECT_THROW(index.insert(1, Motion2{0, {0, 0}, {1, 1}}), InvalidArgument);
  EXPECT_THROW(index.insert(2, Motion2{std::nan(""), {0, 0}, {1, 1}}), InvalidGeometry);
  EXPECT_THROW(index.update(1, Motion2{0, {0, 0}, {INFINITY, 1}}), InvalidGeometry);
  EXPECT_THROW(index.query(MovingWindow<2>::during({{0, 0}, {1, 1}}, 3, 2)), InvalidGeometry);
  EXPECT_FALSE(index.erase(99));
  EXPECT_THROW(index.nearest(Point2{0, 0}, 0, 0), InvalidArgument);
  EXPECT_THROW(index.nearest(Point2{0, 0}, -5, 0), InvalidArgument);  // before the clock
  EXPECT_EQ(index.size(), 1u);
  index.validate();
}

// Positions at the time asked may lie beyond 1e150: the ranking stays exact while the
// distances fit a double, and an answer whose distance overflows is refused, never reported
// as infinite (nor two overflowed distances ranked as a tie), before and after the clock.
TYPED_TEST(MovingIndexTest, NearestFarAwayIsExactOrRefused) {
  TypeParam index;
  for (Id i = 1; i <= 40; ++i)
    index.insert(i, Motion2{0, {double(i), 0}, {1e148 * double(41 - i), 0}});
  index.update(41, Motion2{10, {0, 0}, {0, 0}});  // the clock moves to 10
  for (const double s : {5.0, 30.0}) {
    // Object 40 is the nearest after the still one: 1e148 * s away, squares finite.
    const auto got = index.nearest(Point2{0, 0}, s, 3);
    ASSERT_EQ(got.size(), 3u);
    EXPECT_EQ(got[0].id, 41u);
    EXPECT_EQ(got[1].id, 40u);
    EXPECT_EQ(got[2].id, 39u);
    EXPECT_LT(got[2].distance, INFINITY);
  }
  // At 1e8 every moving object's squared distance overflows: the still one is found, the
  // next refused.
  EXPECT_EQ(index.nearest(Point2{0, 0}, 1e8, 1).at(0).id, 41u);
  EXPECT_THROW(index.nearest(Point2{0, 0}, 1e8, 2), InvalidArgument);
  EXPECT_THROW(index.nearest(Point2{0, 0}, 1e160, 1), InvalidArgument);
  EXPECT_THROW(index.nearest(Point2{1e200, 0}, 20, 1), InvalidArgument);
  index.validate();
}

TYPED_TEST(MovingIndexTest, VisitorStopsEarly) {
  const auto fleet = test::make_fleet(test::Fleet::clustered, 500, 1);
  TypeParam index;
  for (std::size_t i = 0; i < fleet.size(); ++i)
    index.insert(i, fleet[i]);
  int seen = 0;
  index.query(MovingWindow<2>::during({{-1e4, -1e4}, {1e4, 1e4}}, 0, 10),
              [&](Id, const Motion2&) { return ++seen < 5; });
  EXPECT_EQ(seen, 5);
  seen = 0;
  index.nearest(Point2{500, 500}, 3, 50, [&](Id, const Motion2&, double) { return ++seen < 3; });
  EXPECT_EQ(seen, 3);
}

// A query from inside another's visitor, both visitors of one type (std::function), answers
// both in full: the R-trees' stack and the scan's hit buffer were once one per thread, and the
// inner query emptied the outer's.
TYPED_TEST(MovingIndexTest, QueriesNestInsideVisitors) {
  const auto fleet = test::make_fleet(test::Fleet::uniform, 1500, 3);
  TypeParam index;
  Objects objs;
  for (std::size_t i = 0; i < fleet.size(); ++i) {
    index.insert(Id(i), fleet[i]);
    objs[Id(i)] = fleet[i];
  }
  const double now = test::fleet_epoch(test::Fleet::uniform);
  std::mt19937_64 rng(9);
  for (int q = 0; q < 10; ++q) {
    const MovingWindow<2> outer = random_window(rng, now, q % 3);
    const MovingWindow<2> inner = random_window(rng, now, (q + 1) % 3);
    const std::vector<Id> want_inner = brute_window(objs, inner);
    using Visitor = std::function<bool(Id, const Motion2&)>;
    std::vector<Id> got_inner;
    Visitor in = [&](Id id, const Motion2&) {
      got_inner.push_back(id);
      return true;
    };
    std::vector<Id> got;
    Visitor out = [&](Id id, const Motion2&) {
      got.push_back(id);
      got_inner.clear();
      index.query(inner, in);
      std::sort(got_inner.begin(), got_inner.end());
      EXPECT_EQ(got_inner, want_inner) << q;
      return true;
    };
    index.query(outer, out);
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, brute_window(objs, outer)) << q;
  }
}

}  // namespace
}  // namespace loci

namespace loci {
namespace {

TEST(TprTreeBuild, PackedTreeAnswersLikeInsertedOne) {
  for (test::Fleet f : test::kAllFleets) {
    for (std::size_t n : {0, 1, 7, 25, 2000}) {
      const auto fleet = test::make_fleet(f, n, 8);
      std::vector<Id> ids(n);
      Objects objs;
      for (std::size_t i = 0; i < n; ++i) {
        ids[i] = 5 * i + 1;
        objs[ids[i]] = fleet[i];
      }
      TprTree<2> tree;
      tree.build(ids, fleet);
      tree.validate();
      ASSERT_EQ(tree.size(), n);
      check_queries(tree, objs, test::fleet_epoch(f), n, test::name(f) + " built");
      // It stays a valid dynamic tree.
      std::mt19937_64 rng(n);
      std::uniform_real_distribution<double> v(-3, 3);
      for (std::size_t u = 0; u < n / 3; ++u) {
        const Id id = ids[rng() % n];
        const Motion2 m{test::fleet_epoch(f) + 1,
                        position(objs[id], test::fleet_epoch(f) + 1),
                        {v(rng), v(rng)}};
        tree.update(id, m);
        objs[id] = m;
        if (u % 4 == 0) {
          EXPECT_TRUE(tree.erase(id));
          objs.erase(id);
        }
      }
      tree.validate();
      check_queries(tree, objs, test::fleet_epoch(f) + 1, n + 1, test::name(f) + " after");
    }
  }
}

// Rebuilt every tick, as the rebuild-per-tick strategy does: the same ids (the id map kept),
// then after updates and erasures, permuted, renamed, and a build refused for a duplicate id
// leaving the last one whole. Every build answers as brute force; 3D too.
template <int D>
void check_rebuilds() {
  std::mt19937_64 rng(D);
  std::uniform_real_distribution<double> pos(0, 1000), vel(-3, 3);
  const std::size_t n = 3000;
  std::vector<Motion<D>> fleet(n);
  std::vector<Id> ids(n);
  for (std::size_t i = 0; i < n; ++i) {
    fleet[i].t = 0;
    for (int a = 0; a < D; ++a)
      fleet[i].p[a] = pos(rng), fleet[i].v[a] = vel(rng);
    ids[i] = 3 * i + 7;
  }
  TprTree<D> tree;
  const auto check = [&](double now, const char* what) {
    tree.validate();
    ASSERT_EQ(tree.size(), n) << what;
    for (int q = 0; q < 30; ++q) {
      Box<D> w;
      for (int a = 0; a < D; ++a) {
        w.min[a] = pos(rng) - 100;
        w.max[a] = w.min[a] + 200;
      }
      const double t = now + 20 * (q % 4);
      std::vector<Id> got, want;
      tree.query(MovingWindow<D>::at(w, t), [&](Id id, const Motion<D>&) {
        got.push_back(id);
        return true;
      });
      for (std::size_t i = 0; i < n; ++i)
        if (intersects(w, position(fleet[i], t))) want.push_back(ids[i]);
      std::sort(got.begin(), got.end());
      std::sort(want.begin(), want.end());
      ASSERT_EQ(got, want) << what << " query " << q;
    }
  };
  for (int tick = 0; tick < 6; ++tick) {
    const double now = tick;
    for (std::size_t u = 0; u < n / 10; ++u) {  // new reports
      const std::size_t i = rng() % n;
      fleet[i] = {now, position(fleet[i], now), fleet[i].v};
      fleet[i].v[0] = vel(rng);
    }
    if (tick == 2) {  // updates and an erasure between builds: the map is made again
      tree.update(ids[0], fleet[0]);
      tree.erase(ids[1]);
    }
    if (tick == 3) {  // the same objects in another order
      std::vector<std::size_t> perm(n);
      std::iota(perm.begin(), perm.end(), std::size_t(0));
      std::shuffle(perm.begin(), perm.end(), rng);
      std::vector<Motion<D>> f2(n);
      std::vector<Id> i2(n);
      for (std::size_t i = 0; i < n; ++i)
        f2[i] = fleet[perm[i]], i2[i] = ids[perm[i]];
      fleet.swap(f2), ids.swap(i2);
    }
    if (tick == 4)
      for (Id& id : ids)
        id += 1;  // other names
    tree.build(ids, fleet);
    check(now, "rebuilt");
    if (tick == 5) {
      std::vector<Id> dup = ids;
      dup[n - 1] = dup[0];
      EXPECT_THROW(tree.build(dup, fleet), InvalidArgument);
      check(now, "after a refused build");
      EXPECT_FALSE(tree.contains(ids[n - 1] + 1000000));
    }
  }
}

TEST(TprTreeBuild, RebuiltEveryTickAnswersLikeBruteForce) {
  check_rebuilds<2>();
  check_rebuilds<3>();
}

// build() fills each node between the tree's minimum fill and M, whatever the count and the
// fan-out: for some M of 25 or more, kFill + 1 objects made two leaves of half that, below the
// minimum fill (validate() refused the tree build() had made).
template <class Tree>
void check_build_fill(std::size_t most) {
  for (std::size_t n = 1; n <= most; ++n) {
    std::vector<Id> ids(n);
    std::vector<Motion2> ms(n);
    Objects objs;
    for (std::size_t i = 0; i < n; ++i) {
      ids[i] = Id(i);
      ms[i] = Motion2{0, {double(i), double(i % 7)}, {1, 0}};
      objs[ids[i]] = ms[i];
    }
    Tree tree;
    tree.build(ids, ms);
    ASSERT_NO_THROW(tree.validate()) << n;
    if (n % 37 == 0) check_queries(tree, objs, 0, n, "fill " + std::to_string(n));
  }
}
TEST(TprTreeBuild, NodesKeepTheMinimumFillForEveryFanOut) {
  check_build_fill<TprTree<2, 4>>(200);
  check_build_fill<TprTree<2, 40>>(300);
  check_build_fill<TprTree<2, 63>>(400);
  check_build_fill<StarTree<2, 63>>(400);
}

TEST(TprTreeBuild, RefusesBadInput) {
  TprTree<2> tree;
  const std::vector<Motion2> two{{0, {0, 0}, {1, 1}}, {0, {1, 1}, {0, 0}}};
  const std::vector<Id> same{4, 4}, one{4};
  EXPECT_THROW(tree.build(same, two), InvalidArgument);
  EXPECT_THROW(tree.build(one, two), InvalidArgument);
  const std::vector<Motion2> bad{{0, {0, 0}, {1, 1}}, {0, {std::nan(""), 1}, {0, 0}}};
  const std::vector<Id> ok{1, 2};
  EXPECT_THROW(tree.build(ok, bad), InvalidGeometry);
  EXPECT_TRUE(tree.empty());
  tree.validate();
}

}  // namespace
}  // namespace loci

namespace loci {
namespace {

// As objects drift apart, the STAR-tree regroups nodes and stays exact.
TEST(StarTree, RegroupsAsNodesDeteriorate) {
  const auto fleet = test::make_fleet(test::Fleet::uniform, 3000, 31);
  StarTree<2, 8> tree(StarParams<2>{1.5, 30, false});
  Objects objs;
  for (std::size_t i = 0; i < fleet.size(); ++i) {
    tree.insert(i, fleet[i]);
    objs[i] = fleet[i];
  }
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> v(-3, 3);
  for (int tick = 1; tick <= 30; ++tick) {
    for (int u = 0; u < 50; ++u) {
      const Id id = rng() % fleet.size();
      const Motion2 m{double(tick), position(objs[id], tick), {v(rng), v(rng)}};
      tree.update(id, m);
      objs[id] = m;
    }
  }
  EXPECT_GT(tree.regroups(), 0u);
  tree.validate();
  check_queries(tree, objs, 30, 12, "star after drift");
  EXPECT_THROW(StarTree<2>(StarParams<2>{1.0, 30, true}), InvalidArgument);
}

// Reports within the accepted range, spread so widely that the costs of 3D boxes overflow to
// inf (and to NaN where an infinite area meets a zero speed): choosing paths, reinserting and
// splitting still make a valid tree whose answers are those of a scan.
template <class Tree>
void check_overflowing_costs() {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-1, 1);
  double now = 100;
  const auto report = [&](double p, double v) {
    return Motion<3>{
        now, {u(rng) * p, u(rng) * p, u(rng) * p}, {u(rng) * v, u(rng) * v, u(rng) * v}};
  };
  Tree tree;
  std::unordered_map<Id, Motion<3>> objs;
  for (Id id = 0; id < 200; ++id) {
    objs[id] = report(1e110, 0);
    ASSERT_NO_THROW(tree.insert(id, objs[id]));
  }
  for (int i = 0; i < 1500; ++i) {
    const Id id = rng() % 300;
    if (rng() % 3 == 0) {
      EXPECT_EQ(tree.erase(id), objs.erase(id) == 1);
    } else {
      objs[id] = report(1e140, 1e138);
      ASSERT_NO_THROW(tree.update(id, objs[id]));
    }
    if (i % 50 == 0) now += 1;
  }
  ASSERT_NO_THROW(tree.validate());
  ASSERT_EQ(tree.size(), objs.size());
  for (int q = 0; q < 20; ++q) {
    const double s = now + q % 4;
    const Point<3> c{u(rng) * 1e140, u(rng) * 1e140, u(rng) * 1e140};
    const Box<3> b{{c[0] - 6e139, c[1] - 6e139, c[2] - 6e139},
                   {c[0] + 6e139, c[1] + 6e139, c[2] + 6e139}};
    const MovingWindow<3> w =
        q % 2 ? MovingWindow<3>::during(b, s, s + 3) : MovingWindow<3>::at(b, s);
    std::vector<Id> got = tree.query(w), want;
    for (const auto& [id, m] : objs)
      if (inside(m, w)) want.push_back(id);
    std::sort(got.begin(), got.end());
    std::sort(want.begin(), want.end());
    ASSERT_EQ(got, want) << "query " << q;
    std::vector<double> d;
    for (const auto& [id, m] : objs)
      d.push_back(std::sqrt(squared_distance(position(m, s), c)));
    std::sort(d.begin(), d.end());
    const auto near = tree.nearest(c, s, 10);
    ASSERT_EQ(near.size(), 10u);
    for (std::size_t i = 0; i < near.size(); ++i)
      EXPECT_DOUBLE_EQ(near[i].distance, d[i]) << "nearest " << q << " rank " << i;
  }
}

// Choose_Path's branch and bound finds the path of least summed cost rise of the whole tree,
// the one a search of every path finds, at every level, through updates at moving clocks, on
// every fleet (the identical and stationary ones are all ties).
template <class Tree>
void check_choose_path() {
  using Access = detail::MovingRTreeAccess;
  for (test::Fleet f : test::kAllFleets) {
    const auto fleet = test::make_fleet(f, 1200, 11);
    Tree tree;
    for (std::size_t i = 0; i < fleet.size(); ++i)
      tree.insert(i, fleet[i]);
    ASSERT_GE(tree.height(), 3) << test::name(f);
    std::mt19937_64 rng(17);
    std::uniform_int_distribution<std::size_t> pick(0, fleet.size() - 1);
    std::uniform_real_distribution<double> u(-100, 1100), v(-4, 4);
    const double t0 = test::fleet_epoch(f);
    std::size_t checked = 0;
    for (int tick = 1; tick <= 4; ++tick) {
      const double now = t0 + tick;
      for (int k = 0; k < 150; ++k) {
        // Half of the probes are where an object of the fleet is now, half anywhere.
        const Motion2& near = fleet[pick(rng)];
        const Motion2 m = k % 2 ? Motion2{now, position(near, now), near.v}
                                : Motion2{now, {u(rng), u(rng)}, {v(rng), v(rng)}};
        tree.update(pick(rng), m);  // moves the clock and reshapes the tree
        const auto b = Access::box_of(tree, m);
        for (int level = 0; level + 1 < tree.height(); ++level) {
          const std::uint32_t got = Access::choose_path(tree, b, level);
          ASSERT_EQ(Access::level(tree, got), level);
          ASSERT_LE(Access::rise_error(tree, Access::root(tree), b), 1e-12);
          ASSERT_LE(Access::rise_error(tree, Access::parent(tree, got), b), 1e-12);
          ASSERT_EQ(Access::own_rise(tree, Access::parent(tree, got)), 0.0);
          ASSERT_EQ(Access::path_cost(tree, got, b), Access::best_cost(tree, b, level))
              << test::name(f) << " tick " << tick << " probe " << k << " level " << level;
          ++checked;
        }
      }
      tree.validate();
    }
    EXPECT_GE(checked, 4u * 150 * 2) << test::name(f);
  }
}

TEST(TprTree, ChoosePathFindsTheCheapestPath) {
  check_choose_path<TprEraseInsert>();
}
TEST(StarTree, ChoosePathFindsTheCheapestPath) {
  check_choose_path<StarTree<2, 6>>();
}

TEST(TprTree, CostsOverflowingInThreeDimensions) {
  check_overflowing_costs<TprTree<3>>();
}
TEST(StarTree, CostsOverflowingInThreeDimensions) {
  check_overflowing_costs<StarTree<3>>();
}

// The grid laid out again and again as its clock moves (each layout with its own reference
// time, cells and bands), with velocities ten times beyond the bands of the last layout,
// objects far outside its cells, erasures and new ids, in 2D and 3D: windows of every kind
// and nearest-n (from within the fleet and from far outside it, ahead of the clock and before
// it) answer as brute force.
template <int D>
void check_grid_layouts() {
  std::mt19937_64 rng(40 + D);
  std::uniform_real_distribution<double> pos(0, 1000), vel(-3, 3), len(0, 200), ahead(0, 20);
  MovingGridParams<D> params;
  params.horizon = 10;
  params.per_cell = 4;
  MovingGrid<D> grid(params);
  std::unordered_map<Id, Motion<D>> objs;
  auto random_motion = [&](double t) {
    Motion<D> m{};
    m.t = t;
    for (int a = 0; a < D; ++a)
      m.p[a] = pos(rng), m.v[a] = vel(rng);
    return m;
  };
  for (Id i = 0; i < 2000; ++i) {
    objs[i] = random_motion(0);
    grid.insert(i, objs[i]);
  }
  const std::size_t loaded = grid.layouts();
  auto check = [&](double now, const std::string& what) {
    grid.validate();
    ASSERT_EQ(grid.size(), objs.size()) << what;
    for (int q = 0; q < 45; ++q) {
      Box<D> b, to;
      for (int a = 0; a < D; ++a) {
        b.min[a] = pos(rng) - 100, b.max[a] = b.min[a] + len(rng);
        const double shift = 3 * vel(rng);
        to.min[a] = b.min[a] + shift, to.max[a] = b.max[a] + shift;
      }
      const double t1 = now + ahead(rng) - 5, t2 = t1 + ahead(rng) / 2;
      const MovingWindow<D> w = q % 3 == 0   ? MovingWindow<D>::at(b, t1)
                                : q % 3 == 1 ? MovingWindow<D>::during(b, t1, t2)
                                             : MovingWindow<D>{b, to, t1, t2};
      std::vector<Id> got = grid.query(w), want;
      for (const auto& [id, m] : objs)
        if (inside(m, w)) want.push_back(id);
      std::sort(got.begin(), got.end());
      std::sort(want.begin(), want.end());
      ASSERT_EQ(got, want) << what << " window " << q;
    }
    for (int q = 0; q < 24; ++q) {
      Point<D> p;
      for (int a = 0; a < D; ++a)
        p[a] = q % 6 == 5 ? 1e7 * vel(rng) : pos(rng);
      const double s = q % 4 == 3 ? now - 15 : now + ahead(rng);
      const std::size_t k = q % 8 == 7 ? 5000 : 1 + q % 13;
      std::vector<double> want;
      for (const auto& [id, m] : objs)
        want.push_back(std::sqrt(squared_distance(position(m, s), p)));
      std::sort(want.begin(), want.end());
      want.resize(std::min(k, want.size()));
      const auto got = grid.nearest(p, s, k);
      ASSERT_EQ(got.size(), want.size()) << what << " nearest " << q;
      for (std::size_t i = 0; i < got.size(); ++i) {
        ASSERT_EQ(got[i].distance, want[i]) << what << " nearest " << q << " rank " << i;
        ASSERT_EQ(std::sqrt(squared_distance(position(objs.at(got[i].id), s), p)), got[i].distance);
      }
    }
  };
  check(0, "loaded");
  std::uniform_int_distribution<Id> pick(0, 2400);
  for (int tick = 1; tick <= 24; ++tick) {
    const double now = 2.0 * tick;
    for (int u = 0; u < 300; ++u) {
      const Id id = pick(rng);
      if (u % 13 == 0) {
        EXPECT_EQ(grid.erase(id), objs.erase(id) == 1);
        continue;
      }
      Motion<D> m = random_motion(now);
      if (auto it = objs.find(id); it != objs.end()) m.p = position(it->second, now);
      if (u % 7 == 0)  // ten times faster than any velocity laid out
        for (int a = 0; a < D; ++a)
          m.v[a] *= 10;
      if (u % 29 == 0)  // far outside the grid's cells
        for (int a = 0; a < D; ++a)
          m.p[a] = 1e6 * vel(rng);
      grid.update(id, m);
      objs[id] = m;
    }
    if (tick % 4 == 0) check(now, "tick " + std::to_string(tick));
  }
  EXPECT_GE(grid.layouts(), loaded + 3);  // the clock passed several reference times
  EXPECT_EQ(grid.clock(), 48.0);
  // One object at 1e100 among the others: every query looks at most cells, still exact.
  Motion<D> far{};
  far.t = 48;
  for (int a = 0; a < D; ++a)
    far.p[a] = 1e100, far.v[a] = 1;
  grid.insert(99999, far);
  objs[99999] = far;
  check(48, "one object at 1e100");
  for (const auto& [id, m] : objs)
    ASSERT_TRUE(grid.erase(id));
  EXPECT_TRUE(grid.empty());
  grid.validate();
  EXPECT_TRUE(grid.query(MovingWindow<D>::at(Box<D>{}, 0)).empty());
  EXPECT_TRUE(grid.nearest(Point<D>{}, 0, 3).empty());
}

TEST(MovingGrid, RelayoutsFastVelocitiesAndFarObjectsMatchBruteForce) {
  check_grid_layouts<2>();
}
TEST(MovingGrid, RelayoutsInThreeDimensions) {
  check_grid_layouts<3>();
}

// One class of opposite velocities, asked about long after the reference time: an object's
// cell lies far (in cells) from where it is at the time asked, toward either side, and a query
// at the grid's edge has rings on one side only. Nearest-n must still find the nearest.
TEST(MovingGrid, NearestRingsReachAsFarAsVelocitiesSpread) {
  MovingGrid<2> grid(MovingGridParams<2>{0, 1, 1});
  std::unordered_map<Id, Motion2> objs;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> pos(0, 1000);
  for (Id i = 0; i < 400; ++i) {
    objs[i] = Motion2{0, {pos(rng), pos(rng)}, {i % 2 ? 10.0 : -10.0, 0}};
    grid.insert(i, objs[i]);
  }
  for (const double s : {50.0, -50.0})
    for (const Point2 q : {Point2{1000, 500}, Point2{0, 500}, Point2{1200, 700}}) {
      double want = INFINITY;
      for (const auto& [id, m] : objs)
        want = std::min(want, std::sqrt(squared_distance(position(m, s), q)));
      const auto got = grid.nearest(q, s, 1);
      ASSERT_EQ(got.size(), 1u);
      EXPECT_EQ(got[0].distance, want) << "at " << s << " from " << q[0];
    }
}

// An axis whose extent is tiny next to the others (objects on a line, drones over a plain
// with one far outlier) gets one cell, not thousands: the cells stay about size / per_cell.
TEST(MovingGrid, ThinAxesAndOutliersKeepTheCellsFew) {
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(0, 1000), h(0, 10), v(-1, 1);
  MovingGrid<2> line;
  std::unordered_map<Id, Motion2> on_line;
  for (Id i = 0; i < 3000; ++i) {
    on_line[i] = Motion2{0, {u(rng), 100 + 1e-9 * double(i)}, {v(rng), 0}};
    line.insert(i, on_line[i]);
  }
  EXPECT_LE(line.cells(), 4 * 3000 / 32 + 64u);
  MovingGrid<3> drones;
  std::vector<Motion<3>> fleet;
  for (Id i = 0; i < 5000; ++i) {
    fleet.push_back(Motion<3>{0, {u(rng), u(rng), h(rng)}, {v(rng), v(rng), v(rng) / 10}});
    drones.insert(i, fleet.back());
  }
  fleet.push_back(Motion<3>{0, {1e9, 1e9, 5}, {0, 0, 0}});
  drones.insert(5000, fleet.back());
  for (Id i = 0; i < 1000; ++i) {  // enough changes for a layout that sees the outlier
    fleet[i].t = 100;
    drones.update(i, fleet[i]);
  }
  EXPECT_GE(drones.layouts(), 2u);
  EXPECT_LE(drones.cells(), 8 * 5001 / 32 + 27 * 8u);
  for (int q = 0; q < 20; ++q) {
    const Box2 b{{u(rng), 99}, {0, 101}};
    const Box2 w{{b.min[0] - 50, b.min[1]}, {b.min[0] + 50, b.max[1]}};
    std::vector<Id> got = line.query(MovingWindow<2>::at(w, 10)), want;
    for (const auto& [id, m] : on_line)
      if (inside(m, MovingWindow<2>::at(w, 10))) want.push_back(id);
    std::sort(got.begin(), got.end());
    std::sort(want.begin(), want.end());
    ASSERT_EQ(got, want);
    const Box<3> c{{u(rng), u(rng), 0}, {0, 0, 10}};
    const Box<3> box{c.min, {c.min[0] + 100, c.min[1] + 100, 10}};
    std::vector<Id> got3 = drones.query(MovingWindow<3>::during(box, 100, 110)), want3;
    for (Id i = 0; i < fleet.size(); ++i)
      if (inside(fleet[i], MovingWindow<3>::during(box, 100, 110))) want3.push_back(i);
    std::sort(got3.begin(), got3.end());
    ASSERT_EQ(got3, want3);
  }
}

// A fleet that moves far away while the clock stands still (every report at the same time)
// is laid out again once an eighth of it has left the cells' extent.
TEST(MovingGrid, FleetLeavingTheCellsIsLaidOutAgain) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0, 1000), v(-1, 1);
  MovingGrid<2> grid;
  std::unordered_map<Id, Motion2> objs;
  for (Id i = 0; i < 4000; ++i) {
    objs[i] = Motion2{0, {u(rng), u(rng)}, {v(rng), v(rng)}};
    grid.insert(i, objs[i]);
  }
  const std::size_t before = grid.layouts();
  // Two rounds of reports there: the first layout comes an eighth of the way through the
  // first (over both places), another once the fleet has moved on.
  for (int round = 0; round < 2; ++round)
    for (Id i = 0; i < 4000; ++i) {
      objs[i] = Motion2{0, {1e5 + u(rng), 1e5 + u(rng)}, {v(rng), v(rng)}};
      grid.update(i, objs[i]);
    }
  EXPECT_EQ(grid.clock(), 0.0);
  EXPECT_GE(grid.layouts(), before + 2);
  grid.validate();
  std::size_t tested = 0;
  for (int q = 0; q < 20; ++q) {
    const double x = 1e5 + u(rng), y = 1e5 + u(rng);
    const auto w = MovingWindow<2>::at({{x, y}, {x + 50, y + 50}}, 5);
    std::vector<Id> got, want;
    tested += grid.query(w,
                         [&](Id id, const Motion2&) {
                           got.push_back(id);
                           return true;
                         })
                  .entries_tested;
    for (const auto& [id, m] : objs)
      if (inside(m, w)) want.push_back(id);
    std::sort(got.begin(), got.end());
    std::sort(want.begin(), want.end());
    ASSERT_EQ(got, want);
  }
  EXPECT_LT(tested / 20, 4000u / 10);  // a window looks at few cells, not the whole fleet
}

// Nearest-n from far outside the fleet on one axis: every object is at least that far on it,
// so the rings stop soon instead of visiting every cell.
TEST(MovingGrid, NearestFromFarOutsideVisitsFewCells) {
  std::mt19937_64 rng(10);
  std::uniform_real_distribution<double> u(0, 1000), v(-1, 1);
  MovingGrid<2> grid;
  std::vector<Motion2> fleet;
  for (Id i = 0; i < 20000; ++i) {
    fleet.push_back(Motion2{0, {u(rng), u(rng)}, {v(rng), v(rng)}});
    grid.insert(i, fleet.back());
  }
  for (const Point2 p : {Point2{1e6, 500}, Point2{500, -1e7}, Point2{3000, 3000}}) {
    double want = INFINITY;
    for (const Motion2& m : fleet)
      want = std::min(want, std::sqrt(squared_distance(position(m, 20), p)));
    std::vector<double> got;
    const QueryStats st = grid.nearest(p, 20, 1, [&](Id, const Motion2&, double d) {
      got.push_back(d);
      return true;
    });
    ASSERT_EQ(got.size(), 1u);
    EXPECT_EQ(got[0], want);
    EXPECT_LT(st.nodes_visited, grid.cells() / 3) << p[0] << " " << p[1];
  }
}

// At epoch-second times inside() solves for times in absolute time (a step of 2^-22 s, a
// position step of |v| 2^-22): a window over an interval that an object reaches by less than
// that is still answered as inside() decides.
TEST(MovingGrid, IntervalWindowsAtEpochSeconds) {
  for (const double t0 : {0.0, 1.7e9}) {
    MovingGrid<2> grid(MovingGridParams<2>{0, 1, 17.0 / 16});
    std::vector<Motion2> fleet;
    for (Id i = 0; i <= 16; ++i) {
      fleet.push_back(Motion2{t0, {double(i), 0}, {1000, 0}});
      grid.insert(i, fleet.back());
    }
    for (const double edge : {1008 - 5e-5, 1008 - 1e-6, 1008.0, 1008 + 1e-6}) {
      const auto w = MovingWindow<2>::during({{0, -1}, {edge, 1}}, t0 + 1, t0 + 2);
      std::vector<Id> got = grid.query(w), want;
      for (Id i = 0; i < fleet.size(); ++i)
        if (inside(fleet[i], w)) want.push_back(i);
      std::sort(got.begin(), got.end());
      EXPECT_EQ(got, want) << "at " << t0 << " edge " << edge;
    }
  }
  // The same through the window's own speed: still objects, a window moving at 1000/s.
  for (const double t0 : {0.0, 1.7e9}) {
    MovingGrid<2> grid(MovingGridParams<2>{0, 1, 17.0 / 16});
    std::vector<Motion2> fleet;
    for (Id i = 0; i <= 16; ++i) {
      fleet.push_back(Motion2{t0, {1092.0 + double(i), 0}, {0, 0}});
      grid.insert(i, fleet.back());
    }
    fleet.push_back(Motion2{t0, {1100 + 5e-5, 0}, {0, 0}});
    grid.insert(17, fleet.back());
    const MovingWindow<2> w{Box2{{0, -1}, {100 - 1e-6, 1}}, Box2{{1000, -1}, {1100 - 1e-6, 1}},
                            t0 + 1, t0 + 2};
    std::vector<Id> got = grid.query(w), want;
    for (Id i = 0; i < fleet.size(); ++i)
      if (inside(fleet[i], w)) want.push_back(i);
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, want) << "moving window at " << t0;
  }
}

// A class whose objects' squared distances overflow at the time asked: nearest-n goes on past
// the first ring and refuses the answer, as the scan does, rather than answering fewer.
TEST(MovingGrid, NearestBeyondOverflowingDistancesIsRefused) {
  MovingGrid<2> grid(MovingGridParams<2>{60, 2, 1});
  MovingScan<2> scan;
  for (Id i = 0; i < 3; ++i) {  // still, near the query point
    grid.insert(100 + i, Motion2{0, {double(i), 800}, {0, 0}});
    scan.insert(100 + i, Motion2{0, {double(i), 800}, {0, 0}});
  }
  for (Id i = 0; i < 14; ++i) {  // fast: about 1e160 away at 1e60
    const Motion2 m{
        0, {100.0 * double(i), i < 7 ? 10.0 * double(i) : 1600 - 10.0 * double(i - 7)}, {1e100, 0}};
    grid.insert(i, m);
    scan.insert(i, m);
  }
  EXPECT_EQ(grid.nearest(Point2{0, 800}, 1e60, 3).size(), 3u);
  for (const std::size_t k : {4, 17}) {
    EXPECT_THROW(scan.nearest(Point2{0, 800}, 1e60, k), InvalidArgument);
    EXPECT_THROW(grid.nearest(Point2{0, 800}, 1e60, k), InvalidArgument) << k;
  }
}

// A layout costs O(cells) as well as O(objects): a few objects among many classes (3D, 16
// bands a axis: 4,096 classes) are not laid out again every few updates.
TEST(MovingGrid, FewObjectsAmongManyClassesAreNotLaidOutOften) {
  MovingGrid<3> grid(MovingGridParams<3>{0, 16, 1});
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(0, 100), v(-5, 5);
  for (int step = 1; step <= 2000; ++step)
    grid.update(Id(step % 3),
                Motion<3>{double(step), {u(rng), u(rng), u(rng)}, {v(rng), v(rng), v(rng)}});
  EXPECT_EQ(grid.size(), 3u);
  EXPECT_LE(grid.layouts(), 8u);  // the growth to 3 objects, then about one per 512 updates
  grid.validate();
  EXPECT_EQ(grid.nearest(Point<3>{50, 50, 50}, 2000, 5).size(), 3u);
}

TEST(MovingGrid, RefusesBadParameters) {
  EXPECT_THROW(MovingGrid<2>(MovingGridParams<2>{-1, 3, 32}), InvalidArgument);
  EXPECT_THROW(MovingGrid<2>(MovingGridParams<2>{NAN, 3, 32}), InvalidArgument);
  EXPECT_THROW(MovingGrid<2>(MovingGridParams<2>{1e300, 3, 32}), InvalidArgument);
  EXPECT_NO_THROW(MovingGrid<2>(MovingGridParams<2>{1e150, 3, 32}));
  EXPECT_THROW(MovingGrid<2>(MovingGridParams<2>{60, 0, 32}), InvalidArgument);
  EXPECT_THROW(MovingGrid<2>(MovingGridParams<2>{60, 17, 32}), InvalidArgument);
  EXPECT_THROW(MovingGrid<2>(MovingGridParams<2>{60, 3, 0.5}), InvalidArgument);
  EXPECT_THROW(MovingGrid<2>(MovingGridParams<2>{60, 3, INFINITY}), InvalidArgument);
  EXPECT_NO_THROW(MovingGrid<3>(MovingGridParams<3>{0, 16, 1}));
}

}  // namespace
}  // namespace loci
