// bench_windowing [N]: windowing on map segments. loci SegmentWindowTree (exact, reports the
// segments meeting the window) against loci PackedRTree over the segments' boxes followed by
// the exact box/segment test on each candidate. Data: the first N coastline segments (default
// 300,000), N random short segments, and N/10 random long diagonal segments (boxes much
// larger than the segments). Windows are centred on segment endpoints with
// three sizes (about 10, 100 and 1000 hits); both methods must report the same segments.
#include <cstdio>
#include <random>

#include "bench_common.hpp"
#include "loci/index/packed_rtree.hpp"
#include "loci/index/segment_window_tree.hpp"

namespace {

using namespace loci;

void run(const char* label, const std::vector<Segment2>& segs) {
  std::vector<Box2> boxes;
  Box2 ext = Box2::empty();
  for (const auto& s : segs) {
    boxes.push_back(s.box());
    ext.expand(s.box());
  }
  SegmentWindowTree swt;
  PackedRTree2 packed;
  const double b_swt = bench::median_seconds(1, [&] { swt = SegmentWindowTree::build(segs); });
  const double b_packed = bench::median_seconds(1, [&] { packed = PackedRTree2::build(boxes); });
  std::printf(
      "%-10s n=%zu segments; build: SegmentWindowTree %.3f s (%.0f MB), PackedRTree "
      "%.3f s (%.0f MB)\n",
      label, segs.size(), b_swt, swt.memory_bytes() / 1e6, b_packed, packed.memory_bytes() / 1e6);
  for (const double hits : {10.0, 100.0, 1000.0}) {
    constexpr std::size_t kQueries = 10000;
    // side calibrated on the data: real layers are far denser near their segments
    double side = std::sqrt(hits / double(segs.size()) * ext.content());
    std::vector<Box2> ws(kQueries);
    for (int round = 0; round < 4; ++round) {
      std::mt19937_64 rng(11);
      for (auto& w : ws) {
        const Point2 c = segs[rng() % segs.size()].a;
        w = {{c[0] - side / 2, c[1] - side / 2}, {c[0] + side / 2, c[1] + side / 2}};
      }
      std::size_t got = 0;
      for (std::size_t i = 0; i < 1000; ++i)
        packed.query(ws[i],
                     [&](Id id, const Box2&) { return got += intersects(ws[i], segs[id]), true; });
      side *= std::sqrt(hits / std::max(double(got) / 1000, 1.0));
    }
    std::size_t h_swt = 0, h_packed = 0, candidates = 0;
    const double q_swt = bench::median_seconds(3, [&] {
      h_swt = 0;
      for (const auto& w : ws)
        swt.query(w, [&](Id, const Segment2&) { return ++h_swt, true; });
    });
    const double q_packed = bench::median_seconds(3, [&] {
      h_packed = candidates = 0;
      for (const auto& w : ws)
        packed.query(w, [&](Id id, const Box2&) {
          ++candidates;
          h_packed += intersects(w, segs[id]);
          return true;
        });
    });
    if (h_swt != h_packed) {
      std::printf("MISMATCH: SegmentWindowTree %zu hits, PackedRTree + exact %zu\n", h_swt,
                  h_packed);
      std::exit(1);
    }
    std::printf(
        "  %7.1f hits/window (%.1f box candidates): SegmentWindowTree %8.0f q/s, "
        "PackedRTree+exact %8.0f q/s, speed ratio %.2fx\n",
        double(h_swt) / kQueries, double(candidates) / kQueries, kQueries / q_swt,
        kQueries / q_packed, q_packed / q_swt);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const std::size_t n = bench::size_argument(argc, argv, 300000);
  auto segs = bench::coastline_segments();
  if (!segs.empty()) {
    if (segs.size() > n) segs.resize(n);
    run("coastline", segs);
  }
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(0, 1000), d(-1, 1), far(-100, 100);
  std::vector<Segment2> random(n), long_diagonal(n / 10);
  for (auto& s : random) {
    s.a = {u(rng), u(rng)};
    s.b = {s.a[0] + d(rng), s.a[1] + d(rng)};
  }
  run("short", random);
  // long diagonal segments: boxes far larger than the segments, the case box filters miss
  for (auto& s : long_diagonal) {
    s.a = {u(rng), u(rng)};
    const double t = far(rng);
    s.b = {s.a[0] + t, s.a[1] + (rng() % 2 ? t : -t)};
  }
  run("long", long_diagonal);
  return 0;
}
