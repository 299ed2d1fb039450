// bench_axis_parallel [N]: windowing on axis-parallel segments. loci AxisParallelWindowTree
// (centered interval trees with priority search trees) against loci SegmentWindowTree (the
// general windowing structure) and loci PackedRTree over the segments' boxes; for an
// axis-parallel segment the box is the segment itself, so the box-level answer is already
// exact. Data, N segments each (default 300,000): a street grid (pieces of grid lines one to
// four blocks long, overlapping and meeting at crossings), random short horizontal and
// vertical segments, and long ones (a tenth of the domain). Windows are centred on segment
// endpoints, sized for about 10, 100 and 1000 hits; all three must report the same number.
#include <cmath>
#include <cstdio>
#include <random>

#include "bench_common.hpp"
#include "loci/index/axis_parallel_window_tree.hpp"
#include "loci/index/packed_rtree.hpp"
#include "loci/index/segment_window_tree.hpp"

namespace {

using namespace loci;

constexpr double kDomain = 1000;

std::vector<Segment2> street_grid(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const std::size_t lines = std::size_t(std::ceil(std::sqrt(double(n))));
  const double block = kDomain / double(lines);
  std::vector<Segment2> out(n);
  for (auto& s : out) {
    const double x = block * double(rng() % lines), y = block * double(rng() % lines);
    const double len = block * double(rng() % 4 + 1);
    s = rng() % 2 ? Segment2{{x, y}, {x + len, y}} : Segment2{{x, y}, {x, y + len}};
  }
  return out;
}

// Horizontal or vertical at random, lengths uniform in [shortest, longest], either direction.
std::vector<Segment2> random_axis_segments(std::size_t n, double shortest, double longest,
                                           std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, kDomain), len(shortest, longest);
  std::vector<Segment2> out(n);
  for (auto& s : out) {
    s.a = {u(rng), u(rng)};
    s.b = s.a;
    const int axis = int(rng() % 2);
    const double l = len(rng);
    s.b[axis] += rng() % 2 ? l : -l;
  }
  return out;
}

// Windows centred on segment endpoints whose side is tuned on the data (through the exact
// box answer) until they average about `hits` segments.
std::vector<Box2> calibrated_windows(const std::vector<Segment2>& segs, const PackedRTree2& packed,
                                     const Box2& ext, double hits, std::size_t count) {
  double side = std::sqrt(hits / double(segs.size()) * ext.content());
  std::vector<Box2> ws(count);
  for (int round = 0; round < 4; ++round) {
    std::mt19937_64 rng(11);
    for (auto& w : ws) {
      const Point2 c = rng() % 2 ? segs[rng() % segs.size()].a : segs[rng() % segs.size()].b;
      w = {{c[0] - side / 2, c[1] - side / 2}, {c[0] + side / 2, c[1] + side / 2}};
    }
    std::size_t got = 0;
    for (std::size_t i = 0; i < 1000; ++i)
      packed.query(ws[i], [&](Id, const Box2&) { return ++got, true; });
    side *= std::sqrt(hits / std::max(double(got) / 1000, 1.0));
  }
  return ws;
}

void run(const char* label, const std::vector<Segment2>& segs) {
  std::vector<Box2> boxes;
  Box2 ext = Box2::empty();
  for (const auto& s : segs) {
    boxes.push_back(s.box());
    ext.expand(s.box());
  }
  AxisParallelWindowTree apw;
  SegmentWindowTree swt;
  PackedRTree2 packed;
  const double b_apw = bench::median_seconds(1, [&] { apw = AxisParallelWindowTree::build(segs); });
  const double b_swt = bench::median_seconds(1, [&] { swt = SegmentWindowTree::build(segs); });
  const double b_packed = bench::median_seconds(1, [&] { packed = PackedRTree2::build(boxes); });
  std::printf(
      "%-8s n=%zu segments; build: AxisParallelWindowTree %.3f s (%.0f MB), SegmentWindowTree "
      "%.3f s (%.0f MB), PackedRTree %.3f s (%.0f MB)\n",
      label, segs.size(), b_apw, apw.memory_bytes() / 1e6, b_swt, swt.memory_bytes() / 1e6,
      b_packed, packed.memory_bytes() / 1e6);
  for (const double hits : {10.0, 100.0, 1000.0}) {
    constexpr std::size_t kQueries = 10000;
    const auto ws = calibrated_windows(segs, packed, ext, hits, kQueries);
    std::size_t h_apw = 0, h_swt = 0, h_packed = 0;
    const double q_apw = bench::median_seconds(3, [&] {
      h_apw = 0;
      for (const auto& w : ws)
        apw.query(w, [&](Id, const Segment2&) { return ++h_apw, true; });
    });
    const double q_swt = bench::median_seconds(3, [&] {
      h_swt = 0;
      for (const auto& w : ws)
        swt.query(w, [&](Id, const Segment2&) { return ++h_swt, true; });
    });
    const double q_packed = bench::median_seconds(3, [&] {
      h_packed = 0;
      for (const auto& w : ws)
        packed.query(w, [&](Id, const Box2&) { return ++h_packed, true; });
    });
    if (h_apw != h_swt || h_apw != h_packed) {
      std::printf(
          "MISMATCH: AxisParallelWindowTree %zu hits, SegmentWindowTree %zu, PackedRTree %zu\n",
          h_apw, h_swt, h_packed);
      std::exit(1);
    }
    std::printf(
        "  %7.1f hits/window: AxisParallelWindowTree %8.0f q/s, SegmentWindowTree %8.0f q/s, "
        "PackedRTree %8.0f q/s; AxisParallelWindowTree speed ratio %.2fx over "
        "SegmentWindowTree, %.2fx over PackedRTree\n",
        double(h_apw) / kQueries, kQueries / q_apw, kQueries / q_swt, kQueries / q_packed,
        q_swt / q_apw, q_packed / q_apw);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const std::size_t n = bench::size_argument(argc, argv, 300000);
  run("streets", street_grid(n, 4));
  run("short", random_axis_segments(n, 0, 2, 5));
  run("long", random_axis_segments(n, kDomain / 10, kDomain / 10, 6));
  return 0;
}
