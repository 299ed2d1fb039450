// What the windowing tests share: the exact brute-force answer of a window over segments, and
// windows that stress it (on a small integer grid, with zero width or height, or with a corner
// or an edge on some segment's endpoint).
#pragma once

#include <algorithm>
#include <random>
#include <vector>

#include "loci/geom/segment.hpp"
#include "loci/index/query.hpp"
#include "support/random_data.hpp"

namespace loci::test {

inline std::vector<Id> brute_segments(const std::vector<Segment2>& segs, const Box2& w) {
  std::vector<Id> out;
  for (std::size_t i = 0; i < segs.size(); ++i)
    if (intersects(w, segs[i])) out.push_back(i);
  return out;
}

// `grid`: corners on the integers of [-2, 42], for layers on the integer grid [0, 40].
inline Box2 segment_window(std::mt19937_64& rng, const std::vector<Segment2>& segs, bool grid) {
  if (grid) {
    auto g = [&] { return double(rng() % 45) - 2; };
    double x0 = g(), x1 = g(), y0 = g(), y1 = g();
    if (rng() % 8 == 0) x1 = x0;  // zero width
    if (rng() % 8 == 0) y1 = y0;  // zero height
    return {{std::min(x0, x1), std::min(y0, y1)}, {std::max(x0, x1), std::max(y0, y1)}};
  }
  if (rng() % 2) {
    // a corner or an edge on an endpoint of some segment
    const Segment2& s = segs[rng() % segs.size()];
    const Point2 c = rng() % 2 ? s.a : s.b;
    const double wx = double(rng() % 60), wy = double(rng() % 60);
    return {{c[0] - (rng() % 2 ? wx : 0), c[1] - (rng() % 2 ? wy : 0)},
            {c[0] + (rng() % 2 ? wx : 0), c[1] + (rng() % 2 ? wy : 0)}};
  }
  return random_window<2>(rng, 120);
}

}  // namespace loci::test
