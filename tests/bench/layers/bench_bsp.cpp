// Moving circles of mixed radii against the land polygons of a layer (by default the bundled
// Natural Earth sample around Denmark, in degrees taken as planar units): the first impact of
// every move, three ways on the same moves in one process.
//
// - plane shifting: one BspTree for every radius (bsp_tree.hpp), traced with BspCircle{r};
// - per-radius offset trees: the polygons buffered by each radius (Boost.Geometry's buffer,
//   round joins of 36 points per circle), one BspTree per radius, traced with a point: what
//   one does without plane shifting (the paper's "extra copy of the environment for each
//   shape"); the polygonal circle sits inside the true one, so its hits may come a little late;
// - brute force: the exact first contact of the moving circle with every edge (capsule
//   entries) and a crossing-parity test of the start, on the first --brute moves (its time per
//   move is scaled to all of them).
//
// Moves start at sea (where the circle meets no land), head anywhere, and run up to 0.3
// degrees; radii are drawn from 0.002, 0.005, 0.01 and 0.02 degrees (about 0.2 to 2 km).
// Checks: every plane-shifting answer on the brute-force moves lies within the bevel error the
// header states (exit 1 when not); offset-tree disagreements are counted. Then a table of
// bevel angles: tree size, time, and the largest protrusion seen (how much further than r
// from the land a hit was reported, as a share of r) beside the bound 1 / cos(alpha / 2) - 1.
//
// Usage: bench_bsp [--layer PATH] [--moves N] [--brute B] [--repeat R]
#include <algorithm>
#include <boost/geometry.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "loci/index/broadphase/bsp_tree.hpp"
#include "support/layer_polygons.hpp"
#include "support/solid_reference.hpp"

namespace {

namespace bg = boost::geometry;
using loci::BspCircle;
using loci::BspHit;
using loci::BspParams;
using loci::BspPoint;
using loci::BspPolygon;
using loci::BspTree;
using loci::Point2;
using Clock = std::chrono::steady_clock;
using BPoint = bg::model::d2::point_xy<double>;
using BPolygon = bg::model::polygon<BPoint>;
using BMulti = bg::model::multi_polygon<BPolygon>;

constexpr double kRadii[] = {0.002, 0.005, 0.01, 0.02};

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

struct Move {
  Point2 from, to;
  int radius;  // index into kRadii
};

// Buffered polygons left out because Boost.Geometry's buffer made them invalid (edges crossing,
// which BspTree refuses), over all radii.
std::size_t invalid_buffers = 0;

// The polygons grown by r (each one on its own; BspTree takes overlapping polygons).
std::vector<BspPolygon> buffered(const std::vector<BspPolygon>& polys, double r) {
  std::vector<BspPolygon> out;
  const bg::strategy::buffer::distance_symmetric<double> dist(r);
  const bg::strategy::buffer::join_round join(36);
  const bg::strategy::buffer::end_round end(36);
  const bg::strategy::buffer::point_circle circle(36);
  const bg::strategy::buffer::side_straight side;
  for (const BspPolygon& p : polys) {
    BPolygon bp;
    for (const Point2& v : p.outer)
      bp.outer().push_back({v[0], v[1]});
    for (const auto& h : p.holes) {
      bp.inners().emplace_back();
      for (const Point2& v : h)
        bp.inners().back().push_back({v[0], v[1]});
    }
    bg::correct(bp);
    BMulti grown;
    bg::buffer(bp, grown, dist, side, join, end, circle);
    for (const BPolygon& g : grown) {
      if (!bg::is_valid(g)) {
        ++invalid_buffers;
        continue;
      }
      BspPolygon q;
      for (const BPoint& v : g.outer())
        q.outer.push_back({v.x(), v.y()});
      for (const auto& h : g.inners()) {
        q.holes.emplace_back();
        for (const BPoint& v : h)
          q.holes.back().push_back({v.x(), v.y()});
      }
      out.push_back(std::move(q));
    }
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::string layer = std::string(LOCI_DATASETS_DIR) + "/samples/coastline-denmark.geojson";
  std::size_t n = 100000, brute = 5000;
  int repeat = 5;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "bench_bsp: %s needs a value\n", a.c_str());
        std::exit(1);
      }
      return argv[++i];
    };
    if (a == "--layer") {
      layer = next();
    } else if (a == "--moves") {
      n = std::stoul(next());
    } else if (a == "--brute") {
      brute = std::stoul(next());
    } else if (a == "--repeat") {
      repeat = std::max(1, std::stoi(next()));
    } else {
      std::fprintf(stderr,
                   "usage: bench_bsp [--layer PATH] [--moves N] [--brute B] [--repeat R]\n");
      return 1;
    }
  }
  const std::vector<BspPolygon> polys = loci::test::read_polygons(layer);
  std::size_t edges = 0;
  loci::test::for_each_edge(std::span<const BspPolygon>(polys),
                            [&](const Point2&, const Point2&) { ++edges; });
  loci::Box2 bounds = loci::Box2::empty();
  for (const BspPolygon& p : polys)
    for (const Point2& v : p.outer)
      bounds.expand(v);
  std::printf("layer %s: %zu polygons, %zu edges\n", layer.c_str(), polys.size(), edges);

  // Plane shifting: one tree.
  auto t0 = Clock::now();
  const BspTree tree = BspTree::build(polys);
  const double build_ps = seconds_since(t0);
  tree.validate();

  // Per-radius offset trees.
  std::vector<BspTree> offset;
  double buffer_s = 0, build_off = 0;
  std::size_t offset_nodes = 0, offset_bytes = 0;
  for (const double r : kRadii) {
    t0 = Clock::now();
    const std::vector<BspPolygon> grown = buffered(polys, r);
    buffer_s += seconds_since(t0);
    t0 = Clock::now();
    offset.push_back(BspTree::build(grown));
    build_off += seconds_since(t0);
    offset_nodes += offset.back().node_count();
    offset_bytes += offset.back().memory_bytes();
  }

  // Moves starting at sea.
  std::mt19937_64 rng(20260);
  std::uniform_real_distribution<double> ux(bounds.min[0], bounds.max[0]),
      uy(bounds.min[1], bounds.max[1]), len(0, 0.3), ang(0, 2 * std::numbers::pi);
  std::vector<Move> moves;
  while (moves.size() < n) {
    const int k = static_cast<int>(rng() % 4);
    const Point2 from{ux(rng), uy(rng)};
    if (tree.overlaps(from, BspCircle{kRadii[k]})) continue;
    const double a = ang(rng), l = len(rng);
    moves.push_back({from, {from[0] + l * std::cos(a), from[1] + l * std::sin(a)}, k});
  }

  std::vector<BspHit> ps(n), off(n);
  std::vector<double> ps_s, off_s;
  loci::QueryStats ps_stats, off_stats;
  for (int rep = 0; rep < repeat; ++rep) {
    loci::QueryStats s1, s2;
    t0 = Clock::now();
    for (std::size_t i = 0; i < n; ++i)
      ps[i] = tree.trace(moves[i].from, moves[i].to, BspCircle{kRadii[moves[i].radius]}, &s1);
    ps_s.push_back(seconds_since(t0));
    t0 = Clock::now();
    for (std::size_t i = 0; i < n; ++i)
      off[i] = offset[static_cast<std::size_t>(moves[i].radius)].trace(moves[i].from, moves[i].to,
                                                                       BspPoint{}, &s2);
    off_s.push_back(seconds_since(t0));
    ps_stats = s1;
    off_stats = s2;
  }
  std::size_t ps_hits = 0, off_hits = 0;
  for (std::size_t i = 0; i < n; ++i)
    ps_hits += ps[i].hit, off_hits += off[i].hit;

  // Brute force on the first moves.
  brute = std::min(brute, n);
  const double grow = 1 / std::cos(BspParams{}.bevel_angle / 2);
  std::vector<double> exact(brute);
  t0 = Clock::now();
  for (std::size_t i = 0; i < brute; ++i)
    exact[i] = loci::test::first_contact_circle(polys, moves[i].from, moves[i].to,
                                                kRadii[moves[i].radius]);
  const double brute_s = seconds_since(t0);
  std::size_t ps_bad = 0, off_differ = 0, brute_hits = 0;
  double off_worst = 0;
  for (std::size_t i = 0; i < brute; ++i) {
    const double r = kRadii[moves[i].radius];
    const bool want = exact[i] <= 1;
    brute_hits += want;
    const double early =
        loci::test::first_contact_circle(polys, moves[i].from, moves[i].to, r * grow);
    if ((want && !(ps[i].hit && ps[i].t <= exact[i] + 1e-9)) ||
        (ps[i].hit && !(early <= ps[i].t + 1e-9)))
      ++ps_bad;
    if (off[i].hit != want || (want && std::fabs(off[i].t - exact[i]) > 1e-6)) {
      ++off_differ;
      if (want && off[i].hit) off_worst = std::max(off_worst, std::fabs(off[i].t - exact[i]));
    }
  }

  const double ps_us = median(ps_s) / static_cast<double>(n) * 1e6;
  const double off_us = median(off_s) / static_cast<double>(n) * 1e6;
  const double brute_us = brute_s / static_cast<double>(brute) * 1e6;
  std::printf("%zu moves (radii 0.002-0.02), %zu hit the land; medians of %d runs\n\n", n, ps_hits,
              repeat);
  std::printf("%-30s %10s %10s %12s %10s %12s\n", "method", "us/move", "x brute", "nodes", "MB",
              "build s");
  std::printf("%-30s %10.3f %10.0f %12zu %10.2f %12.3f\n", "plane shifting (one tree)", ps_us,
              brute_us / ps_us, tree.node_count(), tree.memory_bytes() / 1e6, build_ps);
  std::printf("%-30s %10.3f %10.0f %12zu %10.2f %12.3f\n", "offset trees (one per radius)", off_us,
              brute_us / off_us, offset_nodes, offset_bytes / 1e6, buffer_s + build_off);
  std::printf("%-30s %10.1f %10s %12s %10s %12s\n", "brute force over edges", brute_us, "1", "-",
              "-", "-");
  std::printf("\nnodes visited per move: plane shifting %.1f, offset trees %.1f\n",
              static_cast<double>(ps_stats.nodes_visited) / static_cast<double>(n),
              static_cast<double>(off_stats.nodes_visited) / static_cast<double>(n));
  std::printf(
      "offset trees: buffering %.3f s, building %.3f s (%zu invalid buffered polygons left "
      "out)\n",
      buffer_s, build_off, invalid_buffers);
  std::printf(
      "checked against brute force on %zu moves (%zu hits): plane shifting outside the "
      "bevel bound %zu; offset trees differing %zu (worst |dt| %.2e, from the polygonal "
      "circles)\n",
      brute, brute_hits, ps_bad, off_differ, off_worst);

  // Bevel angles: size, time and the protrusion seen.
  std::printf("\n%-12s %10s %10s %8s %10s %14s %10s\n", "bevel angle", "nodes", "bevels", "depth",
              "us/move", "protrusion/r", "bound");
  for (const double deg : {180.0, 90.0, 45.0, 30.0, 15.0}) {
    BspParams params;
    params.bevel_angle = deg * std::numbers::pi / 180;
    const BspTree t = BspTree::build(polys, params);
    std::vector<double> secs;
    std::vector<BspHit> hits(n);
    for (int rep = 0; rep < repeat; ++rep) {
      t0 = Clock::now();
      for (std::size_t i = 0; i < n; ++i)
        hits[i] = t.trace(moves[i].from, moves[i].to, BspCircle{kRadii[moves[i].radius]});
      secs.push_back(seconds_since(t0));
    }
    double worst = 0;
    for (std::size_t i = 0; i < brute; ++i) {
      if (!hits[i].hit || hits[i].started_inside) continue;
      const double r = kRadii[moves[i].radius];
      double d = loci::test::kNever;
      loci::test::for_each_edge(
          std::span<const BspPolygon>(polys), [&](const Point2& a, const Point2& b) {
            d = std::min(d, loci::test::segment_distance(hits[i].point, a, b));
          });
      worst = std::max(worst, d / r - 1);
    }
    const double bound = deg >= 180 ? INFINITY : 1 / std::cos(params.bevel_angle / 2) - 1;
    std::printf("%-12.0f %10zu %10zu %8zu %10.3f %14.4f %10.4f\n", deg, t.node_count(),
                t.bevel_count(), t.depth(), median(secs) / static_cast<double>(n) * 1e6, worst,
                bound);
  }
  return ps_bad == 0 ? 0 : 1;
}
