// `loci bench`: see bench.hpp.
#include "bench.hpp"

#include <algorithm>
#include <boost/geometry.hpp>
#include <boost/geometry/index/rtree.hpp>
#include <chrono>
#include <cstdio>
#include <random>
#include <vector>

#include "loci/geom/boost_adapt.hpp"
#include "loci/geom/error.hpp"
#include "loci/index/packed_rtree.hpp"

namespace loci::io {
namespace {

namespace bgi = boost::geometry::index;
using BoostValue = std::pair<Box2, std::uint32_t>;
using BoostTree = bgi::rtree<BoostValue, bgi::rstar<16>>;

template <class F>
double time_ms(F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::string row(const char* what, double loci_ms, double boost_ms) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%-28s %12.2f %12.2f %9.2fx\n", what, loci_ms, boost_ms,
                boost_ms / std::max(loci_ms, 1e-9));
  return buf;
}

}  // namespace

std::string bench_layer(const BenchOptions& o) {
  const LayerItems items = read_items(o.layer_path, o.layer_name, o.per, o.progress);
  if (items.boxes.empty()) throw Error(o.layer_path + ": the layer has no geometry to index");
  const auto& boxes = items.boxes;

  PackedRTree2 tree;
  const double loci_build = time_ms([&] { tree = PackedRTree2::build(boxes, Packing::hilbert); });
  BoostTree rtree;
  const double boost_build = time_ms([&] {
    std::vector<BoostValue> values;
    values.reserve(boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i)
      values.emplace_back(boxes[i], std::uint32_t(i));
    rtree = BoostTree(values.begin(), values.end());
  });

  std::mt19937_64 rng(20240601);
  const Box2 extent = tree.bounds();
  const double span = std::max(extent.extent(0), extent.extent(1));
  std::vector<Box2> windows(o.queries);
  std::vector<Point2> points(o.queries);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (std::size_t i = 0; i < o.queries; ++i) {
    const Point2 c = boxes[rng() % boxes.size()].center();
    const double r = span * 0.002 * std::pow(10.0, unit(rng) * 1.5);
    windows[i] = {{c[0] - r, c[1] - r}, {c[0] + r, c[1] + r}};
    points[i] = {extent.min[0] + unit(rng) * extent.extent(0),
                 extent.min[1] + unit(rng) * extent.extent(1)};
  }

  std::size_t loci_hits = 0, boost_hits = 0;
  const double loci_window = time_ms([&] {
    for (const auto& w : windows)
      tree.query(w, [&](Id, const Box2&) { return ++loci_hits, true; });
  });
  const double boost_window = time_ms([&] {
    std::vector<BoostValue> out;
    for (const auto& w : windows) {
      out.clear();
      rtree.query(bgi::intersects(w), std::back_inserter(out));
      boost_hits += out.size();
    }
  });
  if (loci_hits != boost_hits)
    throw Error("window answers differ: loci " + std::to_string(loci_hits) + ", Boost " +
                std::to_string(boost_hits));

  double loci_sum = 0, boost_sum = 0;
  const double loci_nearest = time_ms([&] {
    for (const auto& p : points)
      tree.nearest(p, o.k, [&](Id, const Box2&, double d) { return loci_sum += d, true; });
  });
  const double boost_nearest = time_ms([&] {
    std::vector<BoostValue> out;
    for (const auto& p : points) {
      out.clear();
      rtree.query(bgi::nearest(p, unsigned(o.k)), std::back_inserter(out));
      for (const auto& v : out)
        boost_sum += std::sqrt(boost::geometry::comparable_distance(p, v.first));
    }
  });
  if (std::abs(loci_sum - boost_sum) > 1e-9 * std::max(1.0, std::abs(boost_sum)))
    throw Error("nearest-n distances differ between loci and Boost");

  // A point layer's entries are its points (segments of length 0 to the index).
  const bool all_points =
      std::all_of(boxes.begin(), boxes.end(), [](const Box2& b) { return b.min == b.max; });
  char head[200];  // the layer's path goes around it: it may be of any length
  std::snprintf(head, sizeof head,
                ": %zu boxes (per %s), %zu windows (%zu hits), %zu nearest-%zu queries\n"
                "%-28s %12s %12s %10s\n",
                boxes.size(),
                o.per == Per::feature ? "feature"
                : all_points          ? "point"
                                      : "segment",
                o.queries, loci_hits, o.queries, o.k, "", "loci ms", "Boost ms", "Boost/loci");
  return o.layer_path + head + row("build (packed)", loci_build, boost_build) +
         row("window queries", loci_window, boost_window) +
         row("nearest-n queries", loci_nearest, boost_nearest);
}

}  // namespace loci::io
