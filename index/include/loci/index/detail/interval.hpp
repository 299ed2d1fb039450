// Interval: a closed 1D interval [lo, hi], the entry type of the interval and segment trees.
//
// Closed like Box<D>: intervals sharing an endpoint overlap and a point at an endpoint stabs.
// A degenerate interval (lo == hi) is valid; lo > hi is an error, as are NaN and infinities.
// An interval visitor is called as `bool visit(Id id, const Interval& iv)` and returns false
// to stop the query.
#pragma once

#include <cmath>
#include <concepts>
#include <string>

#include "loci/geom/error.hpp"
#include "loci/index/query.hpp"

namespace loci {

struct Interval {
  double lo;
  double hi;

  constexpr bool contains(double x) const { return lo <= x && x <= hi; }
  constexpr bool overlaps(const Interval& o) const { return lo <= o.hi && o.lo <= hi; }
  friend constexpr bool operator==(const Interval&, const Interval&) = default;
};

inline std::string to_string(const Interval& iv) {
  return "[" + std::to_string(iv.lo) + ", " + std::to_string(iv.hi) + "]";
}

// Throws InvalidGeometry naming `what` for a NaN/infinite bound or lo > hi.
inline void check_interval(const Interval& iv, const char* what = "interval") {
  if (!std::isfinite(iv.lo) || !std::isfinite(iv.hi))
    throw InvalidGeometry(std::string(what) + " has a NaN or infinite bound: " + to_string(iv));
  if (iv.lo > iv.hi)
    throw InvalidGeometry(std::string(what) + " is inverted (lo > hi): " + to_string(iv));
}

inline void check_coordinate(double x, const char* what = "query value") {
  if (!std::isfinite(x)) throw InvalidGeometry(std::string(what) + " is NaN or infinite");
}

template <class F>
concept IntervalVisitor = std::predicate<F&, Id, const Interval&>;

}  // namespace loci
