// bench_intervals [N]: stabbing and overlap queries on N 1D intervals (default 1,000,000; time
// ranges of reports: uniform starts over [0, 1e6], exponential lengths of mean 50, one in a
// hundred a thousand times longer). loci IntervalTree (dynamic; bulk-built, and built by
// inserting one interval at a time) and
// SegmentTree (static, stabbing only) against a sorted array scanned linearly (sorted by
// start; binary search, then every interval that starts before the query end is tested)
// and against loci's PackedRTree over degenerate 2D boxes [lo, hi] x [0, 0]. Every structure
// must report the same number of hits. Prints queries per second and speed relative to the
// R-tree.
#include <cstdio>
#include <random>

#include "bench_common.hpp"
#include "loci/index/interval_tree.hpp"
#include "loci/index/packed_rtree.hpp"
#include "loci/index/segment_tree.hpp"

namespace {

using namespace loci;

std::vector<Interval> make(std::size_t n) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> start(0, 1e6);
  std::exponential_distribution<double> len(1.0 / 50);
  std::vector<Interval> out(n);
  for (auto& iv : out) {
    iv.lo = start(rng);
    iv.hi = iv.lo + len(rng) * (rng() % 100 == 0 ? 1000 : 1);
  }
  return out;
}

struct SortedScan {
  std::vector<Interval> by_lo;
  explicit SortedScan(std::vector<Interval> v) : by_lo(std::move(v)) {
    std::sort(by_lo.begin(), by_lo.end(),
              [](const Interval& a, const Interval& b) { return a.lo < b.lo; });
  }
  std::size_t overlap(double a, double b) const {
    const auto end = std::upper_bound(by_lo.begin(), by_lo.end(), b,
                                      [](double v, const Interval& iv) { return v < iv.lo; });
    std::size_t hits = 0;
    for (auto it = by_lo.begin(); it != end; ++it)
      hits += it->hi >= a;
    return hits;
  }
};

}  // namespace

int main(int argc, char** argv) {
  const std::size_t n = bench::size_argument(argc, argv, 1000000);
  const auto ivs = make(n);
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(0, 1e6);
  constexpr std::size_t kQueries = 20000, kScanQueries = 300;
  std::vector<double> xs(kQueries);
  for (auto& x : xs)
    x = u(rng);

  IntervalTree itree, inserted;
  SegmentTree stree;
  PackedRTree2 rtree;
  std::vector<Box2> boxes;
  for (const auto& iv : ivs)
    boxes.push_back({{iv.lo, 0}, {iv.hi, 0}});
  const double b_itree = bench::median_seconds(1, [&] { itree = IntervalTree::build(ivs); });
  const double b_inserted = bench::median_seconds(1, [&] {
    for (std::size_t i = 0; i < ivs.size(); ++i)
      inserted.insert(ivs[i], Id(i));
  });
  const double b_stree = bench::median_seconds(1, [&] { stree = SegmentTree::build(ivs); });
  const double b_rtree = bench::median_seconds(1, [&] { rtree = PackedRTree2::build(boxes); });
  const SortedScan scan(ivs);
  std::printf(
      "n=%zu intervals; build: IntervalTree %.3f s (build), %.3f s (one by one), SegmentTree "
      "%.3f s, PackedRTree %.3f s\n",
      n, b_itree, b_inserted, b_stree, b_rtree);

  for (const double width : {0.0, 200.0}) {
    const bool stab = width == 0;
    std::size_t h_it = 0, h_ins = 0, h_st = 0, h_rt = 0, h_scan = 0, h_rt_small = 0;
    const double q_it = bench::median_seconds(3, [&] {
      h_it = 0;
      for (double x : xs)
        itree.overlap({x, x + width}, [&](Id, const Interval&) { return ++h_it, true; });
    });
    const double q_ins = bench::median_seconds(1, [&] {
      h_ins = 0;
      for (double x : xs)
        inserted.overlap({x, x + width}, [&](Id, const Interval&) { return ++h_ins, true; });
    });
    const double q_rt = bench::median_seconds(3, [&] {
      h_rt = 0;
      for (double x : xs)
        rtree.query(Box2{{x, 0}, {x + width, 0}}, [&](Id, const Box2&) { return ++h_rt, true; });
    });
    double q_st = 0;
    if (stab) {
      q_st = bench::median_seconds(3, [&] {
        h_st = 0;
        for (double x : xs)
          stree.stab(x, [&](Id, const Interval&) { return ++h_st, true; });
      });
    }
    // the scan is too slow for every query: time it on the first kScanQueries
    const double q_scan = bench::median_seconds(1, [&] {
      h_scan = 0;
      for (std::size_t i = 0; i < kScanQueries; ++i)
        h_scan += scan.overlap(xs[i], xs[i] + width);
    });
    for (std::size_t i = 0; i < kScanQueries; ++i)
      rtree.query(Box2{{xs[i], 0}, {xs[i] + width, 0}},
                  [&](Id, const Box2&) { return ++h_rt_small, true; });
    if (h_it != h_rt || h_ins != h_rt || (stab && h_st != h_rt) || h_scan != h_rt_small) {
      std::printf("MISMATCH: hits interval %zu/%zu segment %zu rtree %zu scan %zu/%zu\n", h_it,
                  h_ins, h_st, h_rt, h_scan, h_rt_small);
      return 1;
    }
    std::printf("%s (%.1f hits/query):\n", stab ? "stabbing" : "overlap, ranges of 200",
                double(h_rt) / kQueries);
    auto row = [&](const char* name, double qps) {
      std::printf("  %-26s %11.0f q/s  speed vs PackedRTree %.2fx\n", name, qps,
                  qps / (kQueries / q_rt));
    };
    row("loci IntervalTree (build)", kQueries / q_it);
    row("loci IntervalTree (inserted)", kQueries / q_ins);
    if (stab) row("loci SegmentTree", kQueries / q_st);
    row("loci PackedRTree (boxes)", kQueries / q_rt);
    row("sorted array + scan", kScanQueries / q_scan);
  }
  return 0;
}
