// Point<D>: a location in D-dimensional Euclidean space (D = 2 or 3), stored as D doubles.
//
// A plain aggregate (`Point<2>{x, y}`), trivially copyable so that index arrays holding points
// can be saved and memory-mapped as they are. Registered with Boost.Geometry in
// boost_adapt.hpp.
#pragma once

#include <charconv>
#include <cmath>
#include <cstddef>
#include <string>

#include "loci/geom/error.hpp"

namespace loci {

template <int D>
struct Point {
  static_assert(D == 2 || D == 3, "loci supports 2 and 3 dimensions");
  static constexpr int dimension = D;

  double c[D];

  constexpr double& operator[](int i) { return c[i]; }
  constexpr double operator[](int i) const { return c[i]; }
  friend constexpr bool operator==(const Point&, const Point&) = default;
};

using Point2 = Point<2>;
using Point3 = Point<3>;

template <int D>
constexpr bool is_finite(const Point<D>& p) {
  for (int i = 0; i < D; ++i)
    if (!std::isfinite(p[i])) return false;
  return true;
}

// "(x, y)", each coordinate in the shortest text that reads back as it (std::to_string's six
// decimals showed 2e-9 as 0.000000 and 1e100 in a hundred digits).
template <int D>
std::string to_string(const Point<D>& p) {
  std::string s = "(";
  for (int i = 0; i < D; ++i) {
    if (i) s += ", ";
    char buf[32];
    s.append(buf, std::to_chars(buf, buf + sizeof buf, p[i]).ptr);
  }
  return s + ")";
}

// The largest coordinate magnitude read from layers and query arguments. Squared distances
// between points within it stay finite (8 * 1e300 < 1.8e308), so distances and nearest-n
// rankings never overflow; larger values are refused with a message rather than misranked.
inline constexpr double kMaxCoordinate = 1e150;

template <int D>
constexpr bool within_coordinate_range(const Point<D>& p) {
  for (int i = 0; i < D; ++i)
    if (!(p[i] >= -kMaxCoordinate && p[i] <= kMaxCoordinate)) return false;
  return true;
}

// Throws InvalidGeometry naming `what` when a coordinate is NaN or infinite.
template <int D>
void check_point(const Point<D>& p, const char* what = "point") {
  if (!is_finite(p))
    throw InvalidGeometry(std::string(what) + " has a NaN or infinite coordinate: " + to_string(p));
}

template <int D>
constexpr double squared_distance(const Point<D>& a, const Point<D>& b) {
  double s = 0;
  for (int i = 0; i < D; ++i) {
    const double d = a[i] - b[i];
    s += d * d;
  }
  return s;
}

}  // namespace loci
