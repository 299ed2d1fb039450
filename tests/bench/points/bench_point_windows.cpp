// bench_point_windows [N]: window queries on N points (default 1,000,000; real coastline
// vertices and uniform points) in the loci bucket PR quadtree and kd-tree, against loci's
// PackedRTree (Hilbert) and Boost.Geometry's rtree (packing constructor, rstar<16>) over the
// same points. Windows are centred on data points and sized for about 100 hits (the last
// calibration round may leave the mean a little off); every
// structure must report the same number of hits. Prints build times, queries per second and
// each structure's speed relative to PackedRTree.
#include <boost/geometry.hpp>
#include <boost/geometry/index/rtree.hpp>
#include <boost/iterator/function_output_iterator.hpp>
#include <cstdio>
#include <random>

#include "bench_common.hpp"
#include "loci/geom/boost_adapt.hpp"
#include "loci/index/kd_tree.hpp"
#include "loci/index/packed_rtree.hpp"
#include "loci/index/pr_quadtree.hpp"

namespace {

using namespace loci;
namespace bgi = boost::geometry::index;

// Windows centred on data points, their side calibrated on `ref` so that they hold about
// `hits` points on average (real data is far denser near its points than on average).
template <class Ref>
std::vector<Box2> windows_for(const std::vector<Point2>& pts, const Ref& ref, std::size_t q,
                              double hits) {
  Box2 b = Box2::empty();
  for (const auto& p : pts)
    b.expand(p);
  double side = std::sqrt(hits / double(pts.size()) * b.content());
  std::vector<Box2> out(q);
  for (int round = 0; round < 4; ++round) {
    std::mt19937_64 rng(5);
    for (auto& w : out) {
      const Point2 c = pts[rng() % pts.size()];
      w = {{c[0] - side / 2, c[1] - side / 2}, {c[0] + side / 2, c[1] + side / 2}};
    }
    std::size_t got = 0;
    for (std::size_t i = 0; i < std::min<std::size_t>(q, 2000); ++i)
      ref.query(out[i], [&](Id, const Box2&) { return ++got, true; });
    const double mean = double(got) / double(std::min<std::size_t>(q, 2000));
    side *= std::sqrt(hits / std::max(mean, 1.0));
  }
  return out;
}

void run(const char* label, const std::vector<Point2>& pts) {
  constexpr std::size_t kQueries = 20000;
  std::vector<Box2> boxes;
  for (const auto& p : pts)
    boxes.push_back(Box2::of_point(p));

  PackedRTree2 packed;
  KdTree2 kd;
  PrQuadtree2 quad;
  using Value = std::pair<Point2, std::uint32_t>;
  bgi::rtree<Value, bgi::rstar<16>> boost_tree;
  const double b_packed = bench::median_seconds(1, [&] { packed = PackedRTree2::build(boxes); });
  const auto ws = windows_for(pts, packed, kQueries, 100);
  const double b_kd = bench::median_seconds(1, [&] { kd = KdTree2::build(pts); });
  const double b_quad = bench::median_seconds(1, [&] { quad = PrQuadtree2::build(pts, 16); });
  const double b_boost = bench::median_seconds(1, [&] {
    std::vector<Value> vals;
    vals.reserve(pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i)
      vals.push_back({pts[i], std::uint32_t(i)});
    boost_tree = bgi::rtree<Value, bgi::rstar<16>>(vals);
  });

  std::size_t h_packed = 0, h_kd = 0, h_quad = 0, h_boost = 0;
  const double q_packed = bench::median_seconds(3, [&] {
    h_packed = 0;
    for (const auto& w : ws)
      packed.query(w, [&](Id, const Box2&) { return ++h_packed, true; });
  });
  const double q_kd = bench::median_seconds(3, [&] {
    h_kd = 0;
    for (const auto& w : ws)
      kd.query(w, [&](Id, const Box2&) { return ++h_kd, true; });
  });
  const double q_quad = bench::median_seconds(3, [&] {
    h_quad = 0;
    for (const auto& w : ws)
      quad.query(w, [&](Id, const Box2&) { return ++h_quad, true; });
  });
  const double q_boost = bench::median_seconds(3, [&] {
    h_boost = 0;
    for (const auto& w : ws)
      boost_tree.query(bgi::intersects(w),
                       boost::make_function_output_iterator([&](const Value&) { ++h_boost; }));
  });
  if (h_kd != h_packed || h_quad != h_packed || h_boost != h_packed) {
    std::printf("MISMATCH: hits packed %zu kd %zu quadtree %zu boost %zu\n", h_packed, h_kd, h_quad,
                h_boost);
    std::exit(1);
  }
  std::printf("%-10s n=%zu, %zu windows, %.1f hits/window\n", label, pts.size(), kQueries,
              double(h_packed) / kQueries);
  auto row = [&](const char* name, double build, double q) {
    std::printf("  %-22s build %.3f s  %9.0f windows/s  speed vs PackedRTree %.2fx\n", name, build,
                kQueries / q, q_packed / q);
  };
  row("loci PackedRTree", b_packed, q_packed);
  row("loci KdTree", b_kd, q_kd);
  row("loci PrQuadtree b=16", b_quad, q_quad);
  row("Boost rtree rstar16", b_boost, q_boost);
}

}  // namespace

int main(int argc, char** argv) {
  const std::size_t n = bench::size_argument(argc, argv, 1000000);
  const auto segs = bench::coastline_segments();
  if (!segs.empty()) run("coastline", bench::coastline_vertices(segs, n));
  run("uniform", bench::uniform_points(n, 2));
  return 0;
}
