// All intersecting segment pairs against brute force (every pair through the exact test):
// random polylines on a small grid (shared vertices, collinear overlaps, T-junctions, spikes
// doubling back, zero-length segments), random long segments, and two sets.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <random>
#include <tuple>
#include <vector>

#include "loci/index/segment_intersections.hpp"

namespace loci::test {
namespace {

struct Found {
  Id i, j;
  SegmentIntersection x;
  friend bool operator<(const Found& p, const Found& q) {
    return std::tie(p.i, p.j) < std::tie(q.i, q.j);
  }
  friend bool operator==(const Found& p, const Found& q) {
    return p.i == q.i && p.j == q.j && p.x == q.x;
  }
};

// Polylines of `len` segments on a grid of `cells`; chain[i] names segment i's line.
struct Linework {
  std::vector<Segment2> segs;
  std::vector<std::size_t> chain;
};

Linework polylines(std::size_t lines, std::size_t len, int cells, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> c(0, cells);
  Linework w;
  for (std::size_t l = 0; l < lines; ++l) {
    Point2 p{double(c(rng)), double(c(rng))};
    for (std::size_t k = 0; k < len; ++k) {
      const Point2 q{double(c(rng)), double(c(rng))};
      w.segs.push_back({p, q});
      w.chain.push_back(l);
      p = q;
    }
  }
  return w;
}

// Every pair through the exact test, consecutive segments of a chain meeting only at their
// shared vertex left out.
std::vector<Found> brute_one_set(const Linework& w) {
  std::vector<Found> ref;
  for (std::size_t i = 0; i < w.segs.size(); ++i)
    for (std::size_t j = i + 1; j < w.segs.size(); ++j) {
      const SegmentIntersection x = intersection(w.segs[i], w.segs[j]);
      if (x.kind == SegmentMeet::none) continue;
      const bool shared_only = x.kind == SegmentMeet::point && j == i + 1 &&
                               w.chain[i] == w.chain[j] && x.a == w.segs[i].b;
      if (!shared_only) ref.push_back({i, j, x});
    }
  return ref;
}

TEST(SegmentIntersections, OneSetMatchesBruteForce) {
  for (auto [lines, len, cells] :
       {std::tuple{40, 6, 6}, std::tuple{30, 10, 50}, std::tuple{1, 1, 3}}) {
    const Linework w = polylines(lines, len, cells, 11 + lines);
    auto adjacent = [&](Id i, Id j) {
      return w.chain[i] == w.chain[j] && (j == i + 1 || i == j + 1);
    };
    std::vector<Found> got, ref;
    segment_intersections(std::span<const Segment2>(w.segs), adjacent,
                          [&](Id i, Id j, const SegmentIntersection& x) {
                            EXPECT_LT(i, j);
                            return got.push_back({i, j, x}), true;
                          });
    ref = brute_one_set(w);
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, ref) << lines << " lines of " << len;
  }
}

TEST(SegmentIntersections, TwoSetsMatchBruteForce) {
  const Linework a = polylines(20, 8, 30, 5), b = polylines(25, 7, 30, 6);
  std::vector<Found> got, ref;
  segment_intersections(std::span<const Segment2>(a.segs), std::span<const Segment2>(b.segs),
                        [&](Id i, Id j, const SegmentIntersection& x) {
                          return got.push_back({i, j, x}), true;
                        });
  for (std::size_t i = 0; i < a.segs.size(); ++i)
    for (std::size_t j = 0; j < b.segs.size(); ++j) {
      const SegmentIntersection x = intersection(a.segs[i], b.segs[j]);
      if (x.kind != SegmentMeet::none) ref.push_back({i, j, x});
    }
  std::sort(got.begin(), got.end());
  EXPECT_EQ(got, ref);
}

TEST(SegmentIntersections, SpikeAlongItselfIsReportedAndNaNRefused) {
  // 0-2 then back 2-1: adjacent, overlapping on [1, 2]
  const std::vector<Segment2> spike = {{{0, 0}, {2, 0}}, {{2, 0}, {1, 0}}};
  std::size_t n = 0;
  segment_intersections(
      std::span<const Segment2>(spike), [](Id, Id) { return true; },
      [&](Id, Id, const SegmentIntersection& x) {
        EXPECT_EQ(x.kind, SegmentMeet::overlap);
        return ++n, true;
      });
  EXPECT_EQ(n, 1u);
  const std::vector<Segment2> bad = {{{0, 0}, {std::nan(""), 0}}};
  EXPECT_THROW(segment_intersections(
                   std::span<const Segment2>(bad), [](Id, Id) { return false; },
                   [](Id, Id, const SegmentIntersection&) { return true; }),
               InvalidGeometry);
}

// Segments whose boxes span more than a double reaches (the extent overflows on both axes).
TEST(SegmentIntersections, ExtentBeyondTheRangeOfDoubles) {
  Linework w = polylines(30, 8, 30, 9);
  for (Segment2& s : w.segs)
    for (Point2* p : {&s.a, &s.b})
      for (int a = 0; a < 2; ++a)
        (*p)[a] = ((*p)[a] - 15) * 1e307;
  w.segs.push_back({{-1.7e308, -1.7e308}, {-1.7e308, -1.7e308}});
  w.segs.push_back({{1.7e308, 1.7e308}, {1.7e308, 1.7e308}});
  w.chain.push_back(30);
  w.chain.push_back(31);
  std::vector<Found> got;
  segment_intersections(
      std::span<const Segment2>(w.segs),
      [&](Id i, Id j) { return j == i + 1 && w.chain[i] == w.chain[j]; },
      [&](Id i, Id j, const SegmentIntersection& x) {
        return got.push_back({i, j, x}), true;
      });
  std::sort(got.begin(), got.end());
  EXPECT_EQ(got, brute_one_set(w));
}

TEST(SegmentIntersections, ThreadsGiveTheSameAnswersOnManyTiles) {
  // Enough segments for many tiles, with long ones crossing several, searched on 1 to 3
  // threads: the same pairs as brute force each time; a stop from one thread stops all.
  // Random walks of short integer steps (shared vertices, overlaps and T-junctions occur) over
  // [0, 400]^2, plus a few long segments.
  auto walks = [](std::size_t lines, std::size_t len, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_int_distribution<int> start(0, 400), step(-6, 6);
    Linework w;
    for (std::size_t l = 0; l < lines; ++l) {
      Point2 p{double(start(rng)), double(start(rng))};
      for (std::size_t k = 0; k < len; ++k) {
        const Point2 q{std::clamp(p[0] + step(rng), 0.0, 400.0),
                       std::clamp(p[1] + step(rng), 0.0, 400.0)};
        w.segs.push_back({p, q});
        w.chain.push_back(l);
        p = q;
      }
    }
    return w;
  };
  Linework w = walks(300, 10, 21);
  std::mt19937_64 rng(22);
  std::uniform_int_distribution<int> c(0, 400);
  for (int k = 0; k < 20; ++k) {
    w.segs.push_back({{double(c(rng)), double(c(rng))}, {double(c(rng)), double(c(rng))}});
    w.chain.push_back(1000 + k);
  }
  auto adjacent = [&](Id i, Id j) {
    return w.chain[i] == w.chain[j] && (j == i + 1 || i == j + 1);
  };
  const std::vector<Found> ref = brute_one_set(w);
  ASSERT_GT(ref.size(), 500u);
  const Linework b = walks(200, 8, 23);
  std::vector<Found> ref2;
  for (std::size_t i = 0; i < w.segs.size(); ++i)
    for (std::size_t j = 0; j < b.segs.size(); ++j) {
      const SegmentIntersection x = intersection(w.segs[i], b.segs[j]);
      if (x.kind != SegmentMeet::none) ref2.push_back({i, j, x});
    }
  for (unsigned threads : {1u, 2u, 3u}) {
    std::vector<std::vector<Found>> parts(threads);
    const QueryStats s = segment_intersections_parallel(
        std::span<const Segment2>(w.segs), adjacent, threads, [&](unsigned k) {
          return [&, k](Id i, Id j, const SegmentIntersection& x) {
            return parts[k].push_back({i, j, x}), true;
          };
        });
    std::vector<Found> got;
    for (const auto& p : parts)
      got.insert(got.end(), p.begin(), p.end());
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, ref) << threads << " threads";
    EXPECT_EQ(s.results, ref.size());

    for (auto& p : parts)
      p.clear();
    segment_intersections_parallel(std::span<const Segment2>(w.segs),
                                   std::span<const Segment2>(b.segs), threads, [&](unsigned k) {
                                     return [&, k](Id i, Id j, const SegmentIntersection& x) {
                                       return parts[k].push_back({i, j, x}), true;
                                     };
                                   });
    got.clear();
    for (const auto& p : parts)
      got.insert(got.end(), p.begin(), p.end());
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, ref2) << threads << " threads, two sets";

    std::atomic<std::size_t> calls{0};
    segment_intersections_parallel(
        std::span<const Segment2>(w.segs), adjacent, threads,
        [&](unsigned) { return [&](Id, Id, const SegmentIntersection&) { return ++calls < 3; }; });
    EXPECT_LE(calls.load(), 3u + 2 * threads) << threads << " threads";
  }
}

}  // namespace
}  // namespace loci::test
