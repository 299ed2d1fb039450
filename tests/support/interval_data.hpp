// Fixed-seed 1D interval generators for the interval and segment tree tests, with the
// brute-force answers they are compared against.
#pragma once

#include <algorithm>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "loci/index/query.hpp"

namespace loci::test {

enum class IntervalShape { uniform, clustered, nested, duplicates, points, long_and_short };

inline const IntervalShape kAllIntervalShapes[] = {
    IntervalShape::uniform,    IntervalShape::clustered, IntervalShape::nested,
    IntervalShape::duplicates, IntervalShape::points,    IntervalShape::long_and_short};

inline std::string name(IntervalShape s) {
  switch (s) {
    case IntervalShape::uniform:
      return "uniform";
    case IntervalShape::clustered:
      return "clustered";
    case IntervalShape::nested:
      return "nested";
    case IntervalShape::duplicates:
      return "duplicates";
    case IntervalShape::points:
      return "points";
    default:
      return "long_and_short";
  }
}

inline std::vector<Interval> make_intervals(IntervalShape shape, std::size_t n,
                                            std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1000);
  std::uniform_real_distribution<double> len(0, 20);
  std::normal_distribution<double> spread(0, 5);
  std::vector<Interval> out;
  out.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    double lo = u(rng), hi = lo + len(rng);
    switch (shape) {
      case IntervalShape::clustered:
        lo = 100.0 * double(rng() % 5) + spread(rng);
        hi = lo + len(rng);
        break;
      case IntervalShape::nested: {
        // concentric around a few centres, whole-number radii so that bounds repeat
        const double c = 250.0 * double(rng() % 3 + 1);
        const double r = double(rng() % 200);
        lo = c - r;
        hi = c + r;
        break;
      }
      case IntervalShape::duplicates:
        if (i >= 5 && rng() % 4 != 0) {
          out.push_back(out[rng() % out.size()]);
          continue;
        }
        break;
      case IntervalShape::points:
        lo = hi = double(rng() % 100);  // zero-length, many on the same value
        break;
      case IntervalShape::long_and_short:
        if (rng() % 10 == 0) hi = lo + 10 * u(rng);
        break;
      default:
        break;
    }
    out.push_back({lo, hi});
  }
  return out;
}

inline std::vector<Id> brute_stab(const std::vector<Interval>& ivs, const std::vector<Id>& ids,
                                  double x) {
  std::vector<Id> out;
  for (std::size_t i = 0; i < ivs.size(); ++i)
    if (ivs[i].contains(x)) out.push_back(ids[i]);
  std::sort(out.begin(), out.end());
  return out;
}

inline std::vector<Id> brute_overlap(const std::vector<Interval>& ivs, const std::vector<Id>& ids,
                                     const Interval& q) {
  std::vector<Id> out;
  for (std::size_t i = 0; i < ivs.size(); ++i)
    if (ivs[i].overlaps(q)) out.push_back(ids[i]);
  std::sort(out.begin(), out.end());
  return out;
}

// Query values that hit the data's own endpoints half of the time (closedness matters there).
inline double query_value(std::mt19937_64& rng, const std::vector<Interval>& ivs) {
  if (!ivs.empty() && rng() % 2) {
    const Interval& iv = ivs[rng() % ivs.size()];
    return rng() % 2 ? iv.lo : iv.hi;
  }
  return std::uniform_real_distribution<double>(-50, 1100)(rng);
}

}  // namespace loci::test
