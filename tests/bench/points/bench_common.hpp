// What the point and interval benchmarks share: a clock, medians of repetitions, the size
// argument, and the real data (Natural Earth coastlines) they run on when it is present.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "loci/geom/segment.hpp"
#include "loci/io/layer_reader.hpp"

namespace loci::bench {

inline const std::string kCoastline =
    std::string(LOCI_DATASETS_DIR) + "/cache/countries-coastline-1m/map.geo.json";

// Seconds taken by f(), median of `reps` runs.
template <class F>
double median_seconds(int reps, F&& f) {
  std::vector<double> t;
  for (int r = 0; r < reps; ++r) {
    const auto start = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

// First positional argument: the data size; anything unparsable falls back to `fallback`.
inline std::size_t size_argument(int argc, char** argv, std::size_t fallback) {
  if (argc > 1) {
    const long long v = std::atoll(argv[1]);
    if (v > 0) return std::size_t(v);
  }
  return fallback;
}

// The coastline segments, or nothing when the cache is absent.
inline std::vector<Segment<2>> coastline_segments() {
  std::vector<Segment<2>> out;
  if (!std::filesystem::exists(kCoastline)) {
    std::printf("(no %s: real-data rows skipped; run datasets/fetch.sh)\n", kCoastline.c_str());
    return out;
  }
  for (const auto& r : io::read_segments(kCoastline))
    out.push_back(r.segment);
  return out;
}

// n coastline vertices (each segment's first point), a fixed-seed sample when there are more.
inline std::vector<Point<2>> coastline_vertices(const std::vector<Segment<2>>& segs,
                                                std::size_t n) {
  std::vector<Point<2>> pts;
  pts.reserve(segs.size());
  for (const auto& s : segs)
    pts.push_back(s.a);
  std::mt19937_64 rng(7);
  std::shuffle(pts.begin(), pts.end(), rng);
  if (pts.size() > n) pts.resize(n);
  return pts;
}

inline std::vector<Point<2>> uniform_points(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1000);
  std::vector<Point<2>> pts(n);
  for (auto& p : pts)
    p = {u(rng), u(rng)};
  return pts;
}

}  // namespace loci::bench
