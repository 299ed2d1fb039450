// Conflicts (pairs within D during a horizon) against every pair's exact closest approach, on
// fixed-seed fleets with the degenerate cases, for several slicings of the horizon.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <unordered_map>
#include <utility>
#include <vector>

#include "loci/index/moving/conflicts.hpp"
#include "support/fleet_data.hpp"

namespace loci {
namespace {

std::vector<Conflict> brute(const std::vector<Id>& ids, const std::vector<Motion2>& objs,
                            double within, double now, double horizon) {
  std::vector<Conflict> out;
  for (std::size_t i = 0; i < objs.size(); ++i)
    for (std::size_t j = i + 1; j < objs.size(); ++j)
      if (auto ap = closest_approach(objs[i], objs[j], now, horizon, within))
        out.push_back({std::min(ids[i], ids[j]), std::max(ids[i], ids[j]), *ap});
  sort_conflicts(out);
  return out;
}

void expect_same(const std::vector<Conflict>& got, const std::vector<Conflict>& want,
                 const std::string& what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  for (std::size_t i = 0; i < got.size(); ++i) {
    ASSERT_EQ(got[i].a, want[i].a) << what;
    ASSERT_EQ(got[i].b, want[i].b) << what;
    EXPECT_EQ(got[i].approach.tcpa, want[i].approach.tcpa) << what;
    EXPECT_EQ(got[i].approach.dcpa, want[i].approach.dcpa) << what;
    EXPECT_EQ(got[i].approach.t_enter, want[i].approach.t_enter) << what;
    EXPECT_EQ(got[i].approach.t_exit, want[i].approach.t_exit) << what;
  }
}

// The same pairs; times and distances equal to rounding (relative to the magnitudes of the
// times and of the distance threshold).
void expect_close(const std::vector<Conflict>& got, const std::vector<Conflict>& want,
                  double within, const std::string& what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  for (std::size_t i = 0; i < got.size(); ++i) {
    ASSERT_EQ(got[i].a, want[i].a) << what;
    ASSERT_EQ(got[i].b, want[i].b) << what;
    const Approach &g = got[i].approach, &w = want[i].approach;
    const double tt = 1e-9 * (1 + std::abs(w.tcpa));
    EXPECT_NEAR(g.tcpa, w.tcpa, tt) << what;
    EXPECT_NEAR(g.dcpa, w.dcpa, 1e-9 * (1 + within)) << what;
    EXPECT_NEAR(g.t_enter, w.t_enter, tt) << what;
    EXPECT_NEAR(g.t_exit, w.t_exit, tt) << what;
    EXPECT_LE(g.t_enter, g.tcpa) << what;
    EXPECT_LE(g.tcpa, g.t_exit) << what;
  }
}

TEST(Conflicts, MatchBruteForceOnEveryFleet) {
  for (test::Fleet f : test::kAllFleets) {
    const auto fleet = test::make_fleet(f, 900, 17);
    std::vector<Id> ids(fleet.size());
    for (std::size_t i = 0; i < ids.size(); ++i)
      ids[i] = 1000 - i;  // ids in the other order than the objects
    const double now = test::fleet_epoch(f);
    for (double within : {0.0, 4.0, 25.0})
      for (double horizon : {0.0, 10.0, 60.0}) {
        const auto want = brute(ids, fleet, within, now, horizon);
        for (std::size_t slices : {0, 1, 3, 16}) {
          std::vector<Conflict> got;
          find_conflicts<2>(
              fleet, within, now, horizon,
              [&](std::uint32_t i, std::uint32_t j, const Approach& ap) {
                EXPECT_LT(i, j);
                got.push_back({std::min(ids[i], ids[j]), std::max(ids[i], ids[j]), ap});
                return true;
              },
              slices);
          sort_conflicts(got);
          expect_same(got, want,
                      test::name(f) + " D=" + std::to_string(within) +
                          " H=" + std::to_string(horizon) + " slices=" + std::to_string(slices));
        }
        if (f == test::Fleet::head_on && within == 4.0 && horizon == 60.0)
          EXPECT_GT(want.size(), 0u);
      }
  }
}

// One-off searches on a thread reuse its finder (detail::Lease): fleets that shrink and grow,
// other distances, horizons and slicings, a search run from inside another's visitor, and
// searches after one whose visitor threw all give brute force's answer.
TEST(Conflicts, RepeatedSearchesOnOneThread) {
  auto search = [](const std::vector<Motion2>& fleet, double within, double now, double horizon,
                   std::size_t slices, auto&& also) {
    std::vector<Id> ids(fleet.size());
    for (std::size_t i = 0; i < ids.size(); ++i)
      ids[i] = i;
    std::vector<Conflict> got;
    find_conflicts<2>(
        fleet, within, now, horizon,
        [&](std::uint32_t i, std::uint32_t j, const Approach& ap) {
          got.push_back({i, j, ap});
          also();
          return true;
        },
        slices);
    sort_conflicts(got);
    expect_same(got, brute(ids, fleet, within, now, horizon),
                std::to_string(fleet.size()) + " objects, D=" + std::to_string(within));
    return got.size();
  };
  auto nothing = [] {};
  const std::size_t sizes[] = {900, 37, 2, 1500, 0, 400, 1, 900};
  std::size_t found = 0;
  for (std::size_t round = 0; round < std::size(sizes); ++round) {
    const auto f = test::kAllFleets[round % std::size(test::kAllFleets)];
    const auto fleet = test::make_fleet(f, sizes[round], 30 + round);
    found += search(fleet, 5.0 + double(round), test::fleet_epoch(f), 20.0 * double(round % 3),
                    round % 4, nothing);
  }
  EXPECT_GT(found, 0u);
  // A search inside a visitor's call, once.
  const auto outer = test::make_fleet(test::Fleet::clustered, 300, 50);
  const auto inner = test::make_fleet(test::Fleet::uniform, 700, 51);
  bool nested = false;
  search(outer, 10, 0, 30, 0, [&] {
    if (nested) return;
    nested = true;
    search(inner, 20, 0, 10, 2, nothing);
  });
  EXPECT_TRUE(nested);
  // A visitor that throws halfway, then searches on other fleets.
  const auto big = test::make_fleet(test::Fleet::head_on, 1200, 52);
  int calls = 0;
  EXPECT_THROW(find_conflicts<2>(big, 25, 0, 60,
                                 [&](std::uint32_t, std::uint32_t, const Approach&) -> bool {
                                   if (++calls == 5) throw std::runtime_error("visitor");
                                   return true;
                                 }),
               std::runtime_error);
  search(test::make_fleet(test::Fleet::staggered, 800, 53), 15, 0, 40, 0, nothing);
  search(big, 25, 0, 60, 3, nothing);
  // A search stopped by its visitor, then a full one.
  int seen = 0;
  find_conflicts<2>(big, 25, 0, 60,
                    [&](std::uint32_t, std::uint32_t, const Approach&) { return ++seen < 3; });
  EXPECT_EQ(seen, 3);
  search(big, 25, 0, 60, 0, nothing);
}

// The pairs a search visits, in the order it visits them.
std::vector<std::pair<std::uint32_t, std::uint32_t>> visits(const std::vector<Motion2>& fleet,
                                                            double within, double horizon) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
  find_conflicts<2>(fleet, within, 0, horizon,
                    [&](std::uint32_t i, std::uint32_t j, const Approach&) {
                      out.push_back({i, j});
                      return true;
                    });
  return out;
}

// The order of the visits does not depend on the searches a thread ran before: a fleet
// searched on a fresh thread and again after larger (striped) and smaller searches on this
// one, with ties in the sweep (identical and stationary fleets).
TEST(Conflicts, VisitOrderIgnoresEarlierSearches) {
  for (const test::Fleet f : {test::Fleet::identical, test::Fleet::stationary,
                              test::Fleet::parallel, test::Fleet::uniform}) {
    const auto fleet = test::make_fleet(f, 5000, 60);
    const double within = f == test::Fleet::identical  ? 0.5
                          : f == test::Fleet::parallel ? 8.0
                                                       : 3.0;
    const double horizon = 5;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> fresh;
    std::thread([&] { fresh = visits(fleet, within, horizon); }).join();
    visits(test::make_fleet(test::Fleet::uniform, 7000, 61), 3, 5);  // striped, larger
    const auto small = test::make_fleet(f, 300, 62);
    EXPECT_EQ(visits(small, within, horizon).size(),
              brute(std::vector<Id>(small.size()), small, within, 0, horizon).size())
        << test::name(f);
    EXPECT_GT(fresh.size(), 0u) << test::name(f);
    EXPECT_EQ(visits(fleet, within, horizon), fresh) << test::name(f);
  }
}

TEST(Conflicts, ByIdsSortedAndChecked) {
  const auto fleet = test::make_fleet(test::Fleet::clustered, 400, 2);
  std::vector<Id> ids(fleet.size());
  for (std::size_t i = 0; i < ids.size(); ++i)
    ids[i] = i * 13 % 401;
  const auto got = find_conflicts<2>(ids, fleet, 10, 0, 30);
  expect_same(got, brute(ids, fleet, 10, 0, 30), "by ids");
  EXPECT_GT(got.size(), 0u);
  EXPECT_THROW(find_conflicts<2>(std::span<const Id>(ids).first(3), fleet, 10, 0, 30),
               InvalidArgument);
  EXPECT_THROW(find_conflicts<2>(ids, fleet, -1, 0, 30), InvalidArgument);
  EXPECT_THROW(find_conflicts<2>(ids, fleet, 1, 0, std::nan("")), InvalidArgument);
  EXPECT_TRUE(
      find_conflicts<2>(std::span<const Id>(), std::span<const Motion2>(), 1, 0, 1).empty());
}

// Reports that check_motion refuses everywhere else are refused in its words: a NaN was
// called a position "beyond 1e150 in the time searched", and a time of 1e300 was taken.
TEST(Conflicts, InvalidReportsAreRefusedAsReports) {
  const double nan = std::nan(""), inf = INFINITY;
  const std::vector<std::pair<Motion2, std::string>> cases{
      {{nan, {1, 0}, {0, 0}}, "conflicts: id 42 has a NaN or infinite time"},
      {{inf, {1, 0}, {0, 0}}, "conflicts: id 42 has a NaN or infinite time"},
      {{1e300, {1, 0}, {0, 0}}, "conflicts: id 42 has a time beyond 1e150"},
      {{0, {nan, 0}, {0, 0}}, "conflicts: id 42 has a NaN or infinite coordinate"},
      {{0, {1, 0}, {0, nan}}, "conflicts: id 42 has a NaN or infinite coordinate"},
      {{0, {1, 0}, {0, 2e150}}, "conflicts: id 42 has a velocity beyond 1e150"},
      // Beyond the range at its report, back in it at the time searched: a report refused.
      {{0, {2e150, 0}, {-1e150, 0}}, "conflicts: id 42 has a position or velocity beyond 1e150"},
  };
  for (const auto& [m, want] : cases) {
    const std::vector<Motion2> fleet{{0, {0, 0}, {0, 0}}, m};
    try {
      find_conflicts<2>(std::vector<Id>{7, 42}, fleet, 2, 1, 1);
      ADD_FAILURE() << want << ": taken";
    } catch (const InvalidArgument& e) {
      EXPECT_EQ(std::string(e.what()).substr(0, want.size()), want);
    }
  }
}

// Objects whose positions leave +-1e150 during the horizon would overflow the closest
// approaches: refused, by find_conflicts and by a monitor, which keeps its last answer.
TEST(Conflicts, PositionsBeyondTheRangeAreRefused) {
  const std::vector<Motion2> fleet{{0, {0, 0}, {1e140, 0}}, {0, {1, 0}, {1e140, 0}}};
  EXPECT_EQ(find_conflicts<2>(std::vector<Id>{1, 2}, fleet, 2, 0, 1e9).size(), 1u);
  EXPECT_THROW(find_conflicts<2>(std::vector<Id>{1, 2}, fleet, 2, 0, 1e11), InvalidArgument);
  EXPECT_THROW(find_conflicts<2>(std::vector<Id>{1, 2}, fleet, 2, 1e11, 1), InvalidArgument);
  try {
    find_conflicts<2>(std::vector<Id>{8, 9}, fleet, 2, 0, 1e11);
    ADD_FAILURE() << "a position beyond 1e150 was taken";
  } catch (const InvalidArgument& e) {
    EXPECT_EQ(std::string(e.what()), "conflicts: id 8 moves beyond 1e150 in the time searched");
  }
  // Velocities beyond 1e150 are refused even where the positions stay in range (a horizon of
  // 0): their differences could overflow. 1e150 itself is taken.
  for (const double v : {1e150, std::nextafter(1e150, 2e150), -1e300, 1e308}) {
    const std::vector<Motion2> fast{{0, {0, 0}, {0, 0}}, {0, {1, 0}, {0, v}}};
    if (std::abs(v) <= 1e150) {
      EXPECT_EQ(find_conflicts<2>(std::vector<Id>{1, 2}, fast, 2, 0, 0).size(), 1u);
      continue;
    }
    try {  // by index into the input
      find_conflicts<2>(std::span<const Motion2>(fast), 2, 0, 0,
                        [](std::uint32_t, std::uint32_t, const Approach&) { return true; });
      ADD_FAILURE() << "a velocity of " << v << " was taken";
    } catch (const InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find("object 1 of the input has a velocity beyond 1e150"),
                std::string::npos)
          << e.what();
    }
    // Named by id where the search is given ids.
    try {
      find_conflicts<2>(std::vector<Id>{7, 42}, fast, 2, 0, 0);
      ADD_FAILURE() << "a velocity of " << v << " was taken";
    } catch (const InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find("conflicts: id 42 has a velocity beyond 1e150"),
                std::string::npos)
          << e.what();
    }
    // Alone too, where there is no pair to search.
    EXPECT_THROW(find_conflicts<2>(std::vector<Id>{2}, std::span(fast).subspan(1), 2, 0, 0),
                 InvalidArgument);
  }
  ConflictMonitor<2> monitor(2, 1e9, 1e9);
  monitor.report(1, fleet[0]);
  monitor.report(2, fleet[1]);
  monitor.refresh(0);
  ASSERT_EQ(monitor.conflicts().size(), 1u);
  // A new report that leaves the range within the span searched (incremental), then a time
  // whose span leaves it (full): refused, naming the object, the answer of time 0 kept.
  monitor.report(3, Motion2{0, {5, 0}, {2e141, 0}});
  try {
    monitor.refresh(1);
    ADD_FAILURE() << "refresh took a report beyond 1e150";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("id 3 "), std::string::npos) << e.what();
  }
  monitor.remove(3);
  EXPECT_THROW(monitor.refresh(1e11), InvalidArgument);
  EXPECT_EQ(monitor.conflicts().size(), 1u);
  monitor.refresh(1);
  EXPECT_EQ(monitor.conflicts().size(), 1u);
  // A known object's bad report: its pairs wait with the report; a good report of it brings
  // its pair back.
  monitor.report(2, Motion2{1, {2, 0}, {2e141, 0}});
  EXPECT_THROW(monitor.refresh(2), InvalidArgument);
  EXPECT_TRUE(monitor.conflicts().empty());
  monitor.report(2, fleet[1]);
  monitor.refresh(2);
  EXPECT_EQ(monitor.conflicts().size(), 1u);
}

// Pairs that only graze the D-circle (parallel courses exactly D apart, head-on passes offset
// by exactly D, a closest approach of exactly D at the end of the horizon) beside pairs that
// miss it by a little, at magnitudes from 1e-100 to 1e140: the quick test before the exact
// one must never drop a pair the exact test keeps, whatever the scale, and the entry times
// must stay right where the contact equation's terms pass 1e300 (a head-on pair entering
// at the horizon's end, given an entry time of 0, was lost by the slices that hold 0).
TEST(Conflicts, GrazingPairsAtEveryScale) {
  for (double scale : {1e-100, 1.0, 1e12, 1e138}) {
    for (double offset : {0.0, 3e5}) {
      const double d = 4 * scale, o = offset * scale;
      std::vector<Motion2> fleet;
      auto add = [&](double x, double y, double vx, double vy) {
        fleet.push_back({0, {o + x * scale, o + y * scale}, {vx * scale, vy * scale}});
      };
      for (int k = 0; k < 40; ++k) {
        const double x = 100.0 * k;
        add(x, 0, 1, 0.5);  // parallel, exactly D apart (4 = 4 * 1 on the y axis)
        add(x, 4, 1, 0.5);
        add(x + 30, 20, 1, 0);  // head-on, offset exactly D
        add(x + 50, 24, -1, 0);
        add(x + 60, 40, 0, 0);  // closest at the end of the horizon (10), exactly D
        add(x + 60, 54, 0, -1);
        add(x + 80, 60, 1, 0);  // a hair beyond D all along
        add(x + 80, 64 + 1e-9, 1, 0);
      }
      std::vector<Id> ids(fleet.size());
      for (std::size_t i = 0; i < ids.size(); ++i)
        ids[i] = i;
      const std::string what = "scale " + std::to_string(scale) + " offset " + std::to_string(o);
      const auto want = brute(ids, fleet, d, 0, 10);
      // Exactly the three grazing kinds where the inputs are exact; far from the origin the
      // positions round, and some grazing pairs end a hair beyond D.
      if (scale == 1.0 && offset == 0.0) EXPECT_EQ(want.size(), 120u) << what;
      EXPECT_GE(want.size(), 40u) << what;
      for (std::size_t slices : {0, 1, 3}) {
        std::vector<Conflict> got;
        find_conflicts<2>(
            fleet, d, 0, 10,
            [&](std::uint32_t i, std::uint32_t j, const Approach& ap) {
              got.push_back({ids[i], ids[j], ap});
              return true;
            },
            slices);
        sort_conflicts(got);
        expect_same(got, want, what + " slices " + std::to_string(slices));
      }
    }
  }
}

// Pairs that graze D in general position (2D and 3D), at magnitudes where the quick test's
// products near the subnormal range (lengths of 1e-60 to 1e-120), against the exact test;
// and two pairs that it once dropped: a relative speed whose square underflows, and a 3D
// pair at 1e-67.
template <int D>
void expect_grazing_in_general_position(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1), lg(-120, 60);
  for (int round = 0; round < 40; ++round) {
    const double scale = std::pow(10.0, lg(rng)), horizon = std::pow(10.0, lg(rng) / 6);
    const double within = scale * std::pow(10.0, u(rng));
    std::vector<Motion<D>> fleet;
    for (int k = 0; k < 25; ++k) {
      // b passes a at distance within * (1 +- 1e-9) at a time inside or beyond the horizon.
      Point<D> dir, side, pa, va, pb, vb;
      for (int i = 0; i < D; ++i)
        dir[i] = u(rng), side[i] = u(rng);
      double dot = 0, dn = 0, sn = 0;
      for (int i = 0; i < D; ++i)
        dot += dir[i] * side[i], dn += dir[i] * dir[i];
      for (int i = 0; i < D; ++i)
        side[i] -= dot / dn * dir[i], sn += side[i] * side[i];
      const double at = horizon * (0.2 + 1.1 * (u(rng) + 1) / 2);
      const double off = within * (1 + 1e-9 * u(rng)) / std::sqrt(sn);
      for (int i = 0; i < D; ++i) {
        const double w = dir[i] * scale / horizon;
        pa[i] = 1e3 * scale * (k + u(rng)), va[i] = u(rng) * scale / horizon;
        pb[i] = pa[i] - w * at + side[i] * off, vb[i] = va[i] + w;
      }
      fleet.push_back({0, pa, va});
      fleet.push_back({0, pb, vb});
    }
    std::size_t want = 0;
    for (std::size_t i = 0; i < fleet.size(); ++i)
      for (std::size_t j = i + 1; j < fleet.size(); ++j)
        want += bool(closest_approach(fleet[i], fleet[j], 0.0, horizon, within));
    for (std::size_t slices : {1, 4}) {
      std::size_t got = 0;
      find_conflicts<D>(
          fleet, within, 0, horizon,
          [&](std::uint32_t, std::uint32_t, const Approach&) { return ++got, true; }, slices);
      EXPECT_EQ(got, want) << "D " << D << " round " << round << " scale " << scale;
    }
  }
}

TEST(Conflicts, GrazingInGeneralPosition) {
  expect_grazing_in_general_position<2>(21);
  expect_grazing_in_general_position<3>(22);
  const std::vector<Motion2> slow{{0, {0, 0}, {1e-170, 0}}, {0, {0.5, 0}, {0, 0}}};
  EXPECT_EQ(find_conflicts<2>(std::vector<Id>{1, 2}, slow, 1, 0, 1e300).size(), 1u);
  const std::vector<Motion<3>> tiny{
      {0,
       {-1.5411274592206388e-67, 1.0743316230688597e-67, 2.2433971993613862e-68},
       {3.595844584064295e-91, 2.210333233838407e-91, 2.1966860670337807e-91}},
      {0,
       {-1.5410184458802649e-67, 1.0749543087614888e-67, 2.2536425475648634e-68},
       {3.456947881201562e-91, 1.0558370491966411e-92, -5.2989627518512658e-92}}};
  const double h = 8.4419069874504949e+21, d = 1.478470266883014e-71;
  ASSERT_TRUE(closest_approach(tiny[0], tiny[1], 0.0, h, d));
  for (std::size_t slices : {1, 4}) {
    int got = 0;
    find_conflicts<3>(
        tiny, d, 0, h, [&](std::uint32_t, std::uint32_t, const Approach&) { return ++got, true; },
        slices);
    EXPECT_EQ(got, 1) << slices;
  }
}

#if defined(__SSE2__)
// The quick test on two lanes gives, lane by lane, the answer of the one-lane test it stands
// for, on values of every magnitude the range allows (products that overflow or reach the
// subnormal range included), equal points and velocities, and both signs of zero; and on
// pairs built where one branch of the test decides alone.
template <int D>
void expect_two_lanes_agree(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  // 3e-151 brackets |w|^2 and |d|^2 = 2^-1000, 5.6e-73 |d|^2 |w|^2 = 2^-960: the bounds of
  // the products the test trusts.
  const double scales[] = {0, 1e-300, 1e-160, 3e-151, 5.6e-73, 1e-5, 1, 200, 1e5, 1e75, 1e150};
  std::uniform_int_distribution<int> pick(0, 10), coin(0, 1), sixth(0, 5);
  std::uniform_real_distribution<double> unit(0.5, 1);
  auto value = [&] {
    const double v = scales[pick(rng)] * unit(rng);
    return coin(rng) ? -v : v;
  };
  auto kinematics = [&] {
    detail::Kinematics<D> k;
    for (int a = 0; a < D; ++a)
      k.p[a] = value(), k.v[a] = value();
    return k;
  };
  const double reaches[] = {0, 1, 4e4, 1e300};
  const double horizons[] = {0, 1, 600, 1e10};
  int apart = 0, kept = 0;
  auto check = [&](const detail::Kinematics<D>& p, const detail::Kinematics<D>(&q)[2], double r2,
                   double h) {
    const int bits = detail::clearly_apart2(p, q[0], q[1], r2, h);
    for (int l = 0; l < 2; ++l) {
      const bool one = detail::clearly_apart(p, q[l], r2, h);
      ASSERT_EQ((bits >> l & 1) != 0, one) << "D " << D << " lane " << l;
      (one ? apart : kept) += 1;
    }
  };
  for (int t = 0; t < 200000; ++t) {
    const detail::Kinematics<D> p = kinematics();
    detail::Kinematics<D> q[2] = {kinematics(), kinematics()};
    for (detail::Kinematics<D>& k : q) {
      const int c = sixth(rng);
      if (c == 0) k = p;      // the same object
      if (c == 1) k.v = p.v;  // parallel courses
      if (c == 2) k.p = p.p;  // at the same place now
    }
    check(p, q, reaches[t % 4], horizons[t / 4 % 4]);
  }
  // Both answers are common, so the agreement is not that of a constant.
  EXPECT_GT(apart, 40000);
  EXPECT_GT(kept, 40000);
  // Closest approach exactly at the horizon (-d.w = H |w|^2, every product exact), passing
  // a few ulps outside the reach: the end of the horizon decides "apart", where the middle
  // formula, within its slack, would not.
  for (const double a : {0.5, 1.0, 3.0})
    for (const double h : {1.0, 600.0})
      for (int k = 1; k <= 8; ++k) {
        detail::Kinematics<D> p{}, q[2] = {};
        q[0].v[0] = a;
        q[0].p[0] = -a * h;
        q[0].p[1] = 200 * (1 + k * 0x1p-52);
        q[1] = q[0];
        q[1].p[1] = -q[0].p[1];
        ASSERT_TRUE(detail::clearly_apart(p, q[0], 40000, h)) << a << " " << h << " " << k;
        check(p, q, 40000, h);
      }
}

TEST(Conflicts, QuickTestOnTwoLanesAgreesWithOneLane) {
  expect_two_lanes_agree<2>(41);
  expect_two_lanes_agree<3>(42);
}
#endif

// Pairs that touch (D = 0) exactly when measured from `now`, reported long before it: the
// position at a slice's start, computed from the report, rounds differently from the position
// at now carried forward by the exact test, by an amount that grows with the time since the
// report. Every touching pair is found whichever slice its touch falls in.
TEST(Conflicts, TouchingPairsReportedLongBeforeNowInEverySlice) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u01(0, 1);
  const double now = 0, horizon = 10;
  for (const double ago : {1e6, 1e9}) {
    std::size_t touching = 0, found = 0;
    std::vector<Motion2> fleet;
    for (int i = 0; i < 6000; ++i) {
      // a moves along +x; b is placed 2 tau ahead of it at now (as far as rounding lets the
      // report say so), moving 2 slower: they meet at now + tau, exactly or not at all.
      const double tau = std::ldexp(std::floor(u01(rng) * 1280), -7);  // k / 128 in [0, 10)
      Motion2 a{-ago * u01(rng), {0, 0}, {1 + u01(rng), 0.5 * u01(rng)}};
      a.p = {10 * u01(rng) - a.v[0] * (now - a.t), 10 * u01(rng) - a.v[1] * (now - a.t)};
      const Point2 pa = position(a, now);
      Motion2 b{-ago * u01(rng), {0, 0}, {a.v[0] - 2, a.v[1]}};
      b.p = {pa[0] + 2 * tau - b.v[0] * (now - b.t), pa[1] - b.v[1] * (now - b.t)};
      if (!closest_approach(a, b, now, horizon, 0.0)) continue;
      ++touching;
      const std::vector<Motion2> pair{a, b};
      for (std::size_t slices : {4, 16}) {
        bool seen = false;
        find_conflicts<2>(
            pair, 0.0, now, horizon,
            [&](std::uint32_t, std::uint32_t, const Approach&) { return seen = true; }, slices);
        found += seen;
      }
    }
    EXPECT_GE(touching, 3000u);
    EXPECT_EQ(found, 2 * touching) << "reports up to " << ago << " s before now";
  }
}

// At epoch-second times a pair's entry time, now plus its time from now, rounds to the
// clock's step there (2^-22 s near 1.7e9): a head-on pair entering less than half a step
// after a slice's end is given that slice, whose boxes must still meet. Far out (1e17,
// 1e150) a slice is shorter than the step and the first slices are a single instant.
TEST(Conflicts, EntryTimesRoundingOntoASliceBoundary) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u01(0, 1);
  const double horizon = 60, within = 10, speed = 24;
  for (const std::size_t slices : {2, 7}) {
    const double now = 1.7e9, step = horizon / double(slices);
    std::size_t want = 0, found = 0;
    for (int trial = 0; trial < 400; ++trial) {
      const double t1 = now + step * double(1 + trial % (slices - 1));  // an inner slice end
      const double u = (t1 - now) + u01(rng) * 0.5 * (std::nextafter(t1, INFINITY) - t1);
      const std::vector<Motion2> pair{{now, {0, 0}, {0, 0}},
                                      {now, {within + speed * u, 0}, {-speed, 0}}};
      if (!closest_approach(pair[0], pair[1], now, horizon, within)) continue;
      ++want;
      find_conflicts<2>(
          pair, within, now, horizon,
          [&](std::uint32_t, std::uint32_t, const Approach&) { return ++found, true; }, slices);
    }
    EXPECT_GE(want, 300u);
    EXPECT_EQ(found, want) << slices << " slices";
  }
  for (const double now : {1e17, 1e150})
    for (const std::size_t slices : {1, 2, 16}) {
      const std::vector<Motion2> pair{{now, {0, 0}, {0, 0}},
                                      {now, {within + speed * 5, 0}, {-speed, 0}}};
      ASSERT_TRUE(closest_approach(pair[0], pair[1], now, 10, within));
      int found = 0;
      find_conflicts<2>(
          pair, within, now, 10,
          [&](std::uint32_t, std::uint32_t, const Approach&) { return ++found, true; }, slices);
      EXPECT_EQ(found, 1) << "now " << now << ", " << slices << " slices";
    }
}

TEST(Conflicts, VisitorStops) {
  const auto fleet = test::make_fleet(test::Fleet::identical, 300, 2);
  int seen = 0;
  find_conflicts<2>(fleet, 1, 0, 10,
                    [&](std::uint32_t, std::uint32_t, const Approach&) { return ++seen < 4; });
  EXPECT_EQ(seen, 4);
}

}  // namespace
}  // namespace loci

namespace loci {
namespace {

// A stream of reports: the monitor's answer after each batch is a computation from scratch
// over the reports in force (the same pairs, the same approaches to rounding), through
// incremental refreshes and full ones.
TEST(ConflictMonitor, MatchesComputationFromScratch) {
  for (test::Fleet f : {test::Fleet::uniform, test::Fleet::clustered, test::Fleet::head_on,
                        test::Fleet::identical, test::Fleet::epoch}) {
    auto fleet = test::make_fleet(f, 700, 23);
    const double t0 = test::fleet_epoch(f);
    ConflictMonitor<2> monitor(12, 30, 5);
    std::unordered_map<Id, Motion2> state;
    for (std::size_t i = 0; i < fleet.size(); ++i) {
      monitor.report(i * 3, fleet[i]);
      state[i * 3] = fleet[i];
    }
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> v(-3, 3), u(0, 1);
    for (int tick = 0; tick <= 14; ++tick) {
      const double now = t0 + tick;
      if (tick > 0)
        for (int k = 0; k < 25; ++k) {
          const Id id = (rng() % 760) * 3;  // some new ids, most known
          if (k % 9 == 0) {
            EXPECT_EQ(monitor.remove(id), state.erase(id) == 1);
            continue;
          }
          Motion2 m{now, {u(rng) * 1000, u(rng) * 1000}, {v(rng), v(rng)}};
          if (auto it = state.find(id); it != state.end()) m.p = position(it->second, now);
          monitor.report(id, m);
          state[id] = m;
        }
      monitor.refresh(now);
      std::vector<Id> ids;
      std::vector<Motion2> objs;
      for (const auto& [id, m] : state)
        ids.push_back(id), objs.push_back(m);
      const auto want = find_conflicts<2>(ids, objs, 12, now, 30);
      const auto got = monitor.conflicts();
      expect_close(got, want, 12, test::name(f) + " tick " + std::to_string(tick));
    }
    EXPECT_EQ(monitor.size(), state.size());
    EXPECT_GE(monitor.full_computations(), 3u);  // slack 5: a full computation every 6 ticks
    EXPECT_GE(monitor.incremental_refreshes(), 10u);
  }
}

// Two objects reported to a monitor that is refreshed at base and then at now: the pairs it
// holds, how many of its refreshes were incremental, and the pairs a computation from scratch
// gives at now.
struct TwoObjects {
  std::vector<Conflict> monitored, from_scratch;
  std::size_t incremental_refreshes;
};

TwoObjects two_objects(const Motion2& a, const Motion2& b, double within, double horizon,
                       double slack, double base, double now) {
  ConflictMonitor<2> monitor(within, horizon, slack);
  monitor.report(1, a);
  monitor.report(2, b);
  monitor.refresh(base);
  monitor.refresh(now);
  const std::vector<Id> ids{1, 2};
  const std::vector<Motion2> objects{a, b};
  return {monitor.conflicts(), find_conflicts<2>(ids, objects, within, now, horizon),
          monitor.incremental_refreshes()};
}

// At epoch-second times now + H rounds to a step of 2^-22 s; a pair that comes within D in the
// last instants of the window is still found, by the search and by the monitor, as
// closest_approach (which measures the window from now) decides it. One vessel lies still,
// the other closes on it at 20 units a second and reaches D within a few steps of the
// window's end, on either side of it.
TEST(ConflictMonitor, WindowEndsAtEpochSecondsAsClosestApproachDecides) {
  const double within = 12, slack = 5;
  int found = 0, tried = 0;
  for (double horizon : {30.1, 0.3}) {
    for (int f = 0; f < 6; ++f) {
      const double base = 1.7e9 + 0.0371 * f;
      for (double step : {1.0, 0.7, 3.3}) {
        const double now = base + step;
        for (int k = -30; k <= 30; ++k) {
          const double x = within + 20 * (step + horizon) + k * 1e-7;
          const Motion2 a{base, {0, 0}, {0, 0}}, b{base, {x, 0}, {-20, 0}};
          const bool want = closest_approach(a, b, now, horizon, within).has_value();
          const TwoObjects two = two_objects(a, b, within, horizon, slack, base, now);
          const std::string at = "horizon " + std::to_string(horizon) + " step " +
                                 std::to_string(step) + " offset " + std::to_string(k);
          EXPECT_EQ(two.from_scratch.size(), want ? 1u : 0u) << at;
          EXPECT_EQ(two.monitored.size(), want ? 1u : 0u) << at;
          found += want;
          ++tried;
        }
      }
    }
  }
  // Both sides of the window's end were tried.
  EXPECT_GT(found, 0);
  EXPECT_LT(found, tried);
}

// Reports long before the base (1e12 s): their positions are extrapolated with rounding at the
// size of their travel, which the monitor's margin for kept pairs now counts. Two objects
// moving alongside, about D apart: the monitor gave a pair at 11.996 that a computation from
// scratch puts at 12.00036, and missed others (381 of 20,000 such cases differed before).
TEST(ConflictMonitor, OldReportsAnswerAsAComputationFromScratch) {
  const double within = 12, horizon = 30, slack = 5;
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(0, 1);
  int pairs = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const double base = 1000 * u(rng), now = base + slack * u(rng);
    const double age = 1e12 * (1 + u(rng)), v = 10 + 20 * u(rng);
    const double x = within + (u(rng) - 0.5) * 0.02;
    const Motion2 a{base, {0, 0}, {v, 0}}, b{base - age, {x - v * age, 0}, {v, 0}};
    const TwoObjects two = two_objects(a, b, within, horizon, slack, base, now);
    const auto &want = two.from_scratch, &got = two.monitored;
    ASSERT_EQ(got.size(), want.size()) << trial;
    expect_close(got, want, within, "trial " + std::to_string(trial));
    pairs += int(want.size());
  }
  // Pairs on both sides of D were tried.
  EXPECT_GT(pairs, 100);
  EXPECT_LT(pairs, 2900);
}

// The times the monitor reports lie in [now, now + H] and equal the window's ends where they
// are clamped, as a computation from scratch gives them, also where the span's times, kept
// from an earlier base, do not add back to now exactly (a clock of tenths of a second, a
// base below 0 and now above it).
TEST(ConflictMonitor, ClampedTimesAreTheWindowsEnds) {
  struct Case {
    double base, now, slack;
    Motion2 a, b;
  };
  const double base1 = 147 * 0.1, now1 = base1 + 22 * 0.1;
  const double base2 = -0x1.1c7ec10e745e1p+2, now2 = 0x1.dc02a09dd4a7bp+1;
  const Case cases[] = {
      // Closest approach long after the window: tcpa and t_exit are now + H.
      {base1, now1, 5, {base1, {0, 0}, {0, 0}}, {base1, {11.5, 0}, {-1e-3, 0}}},
      // At rest within D: tcpa and t_enter are now.
      {base2, now2, 10, {-4, {0, 0}, {0, 0}}, {-4, {5, 0}, {0, 0}}},
      {-3.3, 0.5000002, 5, {-3.3, {0, 0}, {0, 0}}, {-3.3, {5, 0}, {0, 0}}},
  };
  const double within = 12, horizon = 30.1;
  for (const Case& c : cases) {
    const TwoObjects two = two_objects(c.a, c.b, within, horizon, c.slack, c.base, c.now);
    ASSERT_EQ(two.incremental_refreshes, 1u);
    const auto &want = two.from_scratch, &got = two.monitored;
    ASSERT_EQ(got.size(), 1u);
    ASSERT_EQ(want.size(), 1u);
    const Approach &g = got[0].approach, &w = want[0].approach;
    const double end = c.now + horizon;
    for (double t : {g.tcpa, g.t_enter, g.t_exit}) {
      EXPECT_GE(t, c.now);
      EXPECT_LE(t, end);
    }
    // Where scratch reports an end of the window, the monitor reports the same double.
    for (auto [x, y] : {std::pair{g.tcpa, w.tcpa}, std::pair{g.t_enter, w.t_enter},
                        std::pair{g.t_exit, w.t_exit}})
      if (y == c.now || y == end) EXPECT_EQ(x, y);
  }
}

}  // namespace
}  // namespace loci
