// Fixed-seed point sets for the point structures (kd-tree, PR quadtree): the shapes of
// random_data.hpp plus the degenerate sets that break naive splitting (all points equal, all
// on an axis-parallel line, points closer than the coordinates' precision), and brute-force
// answers for them.
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "loci/index/query.hpp"
#include "support/random_data.hpp"

namespace loci::test {

enum class PointShape {
  uniform,
  clustered,
  duplicates,
  diagonal,
  horizontal,
  identical,
  tiny_gaps
};

inline const PointShape kAllPointShapes[] = {
    PointShape::uniform,    PointShape::clustered, PointShape::duplicates, PointShape::diagonal,
    PointShape::horizontal, PointShape::identical, PointShape::tiny_gaps};

inline std::string name(PointShape s) {
  switch (s) {
    case PointShape::uniform:
      return "uniform";
    case PointShape::clustered:
      return "clustered";
    case PointShape::duplicates:
      return "duplicates";
    case PointShape::diagonal:
      return "diagonal";
    case PointShape::horizontal:
      return "horizontal";
    case PointShape::identical:
      return "identical";
    default:
      return "tiny_gaps";
  }
}

template <int D>
std::vector<Point<D>> make_points(PointShape shape, std::size_t n, std::uint64_t seed) {
  std::vector<Point<D>> out;
  out.reserve(n);
  auto from_boxes = [&](Shape s) {
    for (const auto& b : make_boxes<D>(s, n, seed))
      out.push_back(b.min);
  };
  std::mt19937_64 rng(seed);
  switch (shape) {
    case PointShape::uniform:
      from_boxes(Shape::uniform);
      break;
    case PointShape::clustered:
      from_boxes(Shape::clustered);
      break;
    case PointShape::duplicates:
      from_boxes(Shape::duplicates);
      break;
    case PointShape::diagonal:
      from_boxes(Shape::on_a_line);
      break;
    case PointShape::horizontal:
      for (std::size_t i = 0; i < n; ++i) {
        Point<D> p = random_point<D>(rng);
        for (int a = 1; a < D; ++a)
          p[a] = 500;
        out.push_back(p);
      }
      break;
    case PointShape::identical:
      out.assign(n, random_point<D>(rng));
      break;
    case PointShape::tiny_gaps: {
      // neighbours one or two ulps apart around a few centres
      for (std::size_t i = 0; i < n; ++i) {
        Point<D> p{};
        for (int a = 0; a < D; ++a) {
          double v = 100.0 * double(rng() % 3 + 1);
          for (std::uint64_t s = rng() % 6; s > 0; --s)
            v = std::nextafter(v, 1e9);
          p[a] = v;
        }
        out.push_back(p);
      }
      break;
    }
  }
  return out;
}

template <int D>
std::vector<Box<D>> point_boxes(const std::vector<Point<D>>& pts) {
  std::vector<Box<D>> out;
  out.reserve(pts.size());
  for (const auto& p : pts)
    out.push_back(Box<D>::of_point(p));
  return out;
}

// Ids (positions in pts) of the points at distance <= r from q.
template <int D>
std::vector<Id> brute_radius(const std::vector<Point<D>>& pts, const Point<D>& q, double r) {
  std::vector<Id> out;
  for (std::size_t i = 0; i < pts.size(); ++i)
    if (squared_distance(q, pts[i]) <= r * r) out.push_back(i);
  return out;
}

// A query window around one of the data points half of the time, so that windows touching
// points on their boundary and windows inside dense clusters both occur.
template <int D>
Box<D> window_near(std::mt19937_64& rng, const std::vector<Point<D>>& pts) {
  if (pts.empty() || rng() % 2) return random_window<D>(rng);
  const Point<D>& c = pts[rng() % pts.size()];
  Box<D> w{c, c};
  std::uniform_real_distribution<double> side(0.0, 30.0);
  for (int a = 0; a < D; ++a) {
    if (rng() % 3) w.min[a] -= side(rng);
    if (rng() % 3) w.max[a] += side(rng);
  }
  return w;
}

}  // namespace loci::test
