// Fixed-seed generators of test data: uniform, clustered and degenerate boxes and points.
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "loci/geom/box.hpp"

namespace loci::test {

enum class Shape { uniform, clustered, duplicates, zero_area, on_a_line };

inline std::string name(Shape s) {
  switch (s) {
    case Shape::uniform:
      return "uniform";
    case Shape::clustered:
      return "clustered";
    case Shape::duplicates:
      return "duplicates";
    case Shape::zero_area:
      return "zero_area";
    default:
      return "on_a_line";
  }
}

inline const Shape kAllShapes[] = {Shape::uniform, Shape::clustered, Shape::duplicates,
                                   Shape::zero_area, Shape::on_a_line};

template <int D>
Point<D> random_point(std::mt19937_64& rng, double lo = 0, double hi = 1000) {
  std::uniform_real_distribution<double> u(lo, hi);
  Point<D> p;
  for (int a = 0; a < D; ++a)
    p[a] = u(rng);
  return p;
}

template <int D>
std::vector<Box<D>> make_boxes(Shape shape, std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> size(0.0, 10.0);
  std::vector<Box<D>> out;
  out.reserve(n);
  std::vector<Point<D>> centres;
  for (int c = 0; c < 8; ++c)
    centres.push_back(random_point<D>(rng));
  std::normal_distribution<double> spread(0.0, 15.0);
  for (std::size_t i = 0; i < n; ++i) {
    Point<D> p;
    switch (shape) {
      case Shape::clustered: {
        const auto& c = centres[rng() % centres.size()];
        for (int a = 0; a < D; ++a)
          p[a] = c[a] + spread(rng);
        break;
      }
      case Shape::duplicates:
        // a handful of distinct boxes, each repeated many times
        if (i >= 7 && rng() % 4 != 0) {
          out.push_back(out[rng() % out.size()]);
          continue;
        }
        p = random_point<D>(rng);
        break;
      case Shape::on_a_line: {
        const double t = std::uniform_real_distribution<double>(0, 1000)(rng);
        for (int a = 0; a < D; ++a)
          p[a] = t;
        out.push_back({p, p});
        continue;
      }
      default:
        p = random_point<D>(rng);
    }
    Box<D> b{p, p};
    if (shape != Shape::zero_area)
      for (int a = 0; a < D; ++a)
        b.max[a] += size(rng);
    else if (rng() % 2)
      b.max[0] += size(rng);  // segments along x, and points
    out.push_back(b);
  }
  return out;
}

template <int D>
Box<D> random_window(std::mt19937_64& rng, double max_side = 80) {
  const Point<D> p = random_point<D>(rng, -20, 1000);
  std::uniform_real_distribution<double> side(0.0, max_side);
  Box<D> w{p, p};
  for (int a = 0; a < D; ++a)
    w.max[a] += side(rng);
  return w;
}

}  // namespace loci::test
