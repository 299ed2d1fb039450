// Fixed-seed moving fleets for the moving-object suites, with the degenerate cases a fleet
// meets: parallel and head-on courses, identical positions, stationary objects, reports at
// different times, epoch-second timestamps.
#pragma once

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "loci/geom/motion.hpp"

namespace loci::test {

enum class Fleet { uniform, clustered, parallel, head_on, identical, stationary, staggered, epoch };

inline const Fleet kAllFleets[] = {Fleet::uniform,   Fleet::clustered, Fleet::parallel,
                                   Fleet::head_on,   Fleet::identical, Fleet::stationary,
                                   Fleet::staggered, Fleet::epoch};

inline std::string name(Fleet f) {
  const char* names[] = {"uniform",   "clustered",  "parallel",  "head_on",
                         "identical", "stationary", "staggered", "epoch"};
  return names[int(f)];
}

// The time the fleet's reports are about (its "now"): 0, or 1.7e9 for the epoch fleet.
inline double fleet_epoch(Fleet f) {
  return f == Fleet::epoch ? 1.7e9 : 0.0;
}

// n reports in a 1000 x 1000 space, speeds up to 3 per time unit.
inline std::vector<Motion2> make_fleet(Fleet f, std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1000), vel(-3, 3), unit(0, 1);
  std::normal_distribution<double> near(0, 15);
  const double t0 = fleet_epoch(f);
  std::vector<Motion2> out;
  out.reserve(n);
  Point2 centres[5];
  for (auto& c : centres)
    c = {u(rng), u(rng)};
  for (std::size_t i = 0; i < n; ++i) {
    Motion2 m{t0, {u(rng), u(rng)}, {vel(rng), vel(rng)}};
    switch (f) {
      case Fleet::clustered: {
        const Point2& c = centres[i % 5];
        m.p = {c[0] + near(rng), c[1] + near(rng)};
        break;
      }
      case Fleet::parallel:  // all on the same course, in rows
        m.p = {double(i % 40) * 25, double(i / 40) * 7};
        m.v = {1.5, 0.5};
        break;
      case Fleet::head_on:  // pairs on one line, meeting head on
        m.p = {i % 2 ? 900.0 : 100.0, double(i / 2) * 3};
        m.v = {i % 2 ? -2.0 : 2.0, 0};
        break;
      case Fleet::identical:  // groups of 4 at the same place, some with the same velocity
        m.p = {double(i / 4 % 30) * 33, double(i / 120) * 33};
        if (i % 2) m.v = {1, -1};
        break;
      case Fleet::stationary:
        if (i % 3) m.v = {0, 0};
        break;
      case Fleet::staggered:  // reports from up to 50 time units ago
        m.t = -50 * unit(rng);
        break;
      case Fleet::epoch:  // epoch seconds, sub-second report times, slow motion
        m.t = t0 - unit(rng);
        m.v = {vel(rng) / 10, vel(rng) / 10};
        break;
      default:
        break;
    }
    out.push_back(m);
  }
  return out;
}

}  // namespace loci::test
