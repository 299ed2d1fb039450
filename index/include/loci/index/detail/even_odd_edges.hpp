// even_odd_edges: the edges of polygons given as rings, each turned so that the polygon's
// inside lies on its left, the inside read by the even-odd rule over the polygon's rings (a
// point is inside when a ray from it crosses the rings an odd number of times), exactly. The
// layer queries read polygons so, and structures that build on edges with the inside on their
// left (BspTree) need them so: a ring's orientation alone does not say it for a hole outside
// its outer ring (an island, by the rule), a hole inside another hole or a ring winding twice
// round a region (a lake in it).
//
// Within each polygon, an edge that appears an even number of times (either way: a spike
// going out and back, a side a hole shares with its outer ring) is left out and one that
// appears an odd number of times is kept once: crossing it changes nothing, or once. Two edges
// that cross at a point inside both, or run along each other over a stretch without being the
// same edge, are refused (InvalidGeometry, naming the polygon and its rings): the crossing
// point, where the inside changes sides along the edge, has no exact place as a double. Rings
// may touch at points (a hole touching its outer ring, an outer ring touching itself round a
// hole it makes).
//
// Without crossings, the two sides of a kept edge have, all along it, crossing counts of
// different parity, and the count on its left is the same as on the left of the edge before it
// in its ring unless other edges meet where the two join. So the count is found where it can
// change: around every point where edges of other rings, or of its own ring elsewhere, meet
// (and around the first vertex of every ring), the sectors between the edges there, turning
// counter-clockwise from the direction +x, are counted: the first, just right of the point and
// above it, by crossings of the ray towards +x (the edges through the point do not cross it),
// then one more crossing across each edge. Every test is exact (orientation, comparisons of
// coordinates); the pairs of edges that meet come from the tiled sweep of
// segment_intersections.
#pragma once

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "loci/geom/error.hpp"
#include "loci/geom/point.hpp"
#include "loci/geom/predicates.hpp"
#include "loci/geom/segment.hpp"
#include "loci/index/detail/y_bands.hpp"
#include "loci/index/query.hpp"
#include "loci/index/segment_intersections.hpp"

namespace loci::detail {

// One ring of a polygon, in either orientation, without repeated vertices: ring 0 of a polygon
// is its outer ring, ring h + 1 its hole h.
struct PolygonRing {
  std::span<const Point<2>> vertices;
  std::uint32_t polygon;
  std::uint32_t ring;
};

inline std::string ring_name(std::uint32_t ring) {
  return ring == 0 ? "the outer ring" : "hole " + std::to_string(ring - 1);
}

inline std::string ring_point(const Point<2>& p) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "(%.17g, %.17g)", p[0], p[1]);
  return buf;
}

// An edge of a polygon, its inside on the left.
struct PolygonEdge {
  Point<2> a, b;
  std::uint32_t polygon;
};

// The edges of the polygons' rings (the rings of polygon 0 first, then those of polygon 1, ...),
// turned and thinned as the even-odd rule has them. Throws InvalidGeometry, naming the polygon (by
// index, after `what`) and the rings, where two edges of a polygon cross or run along each other.
inline std::vector<PolygonEdge> even_odd_edges(std::span<const PolygonRing> rings,
                                               const std::string& what = "polygon ") {
  struct Edge {
    Point<2> a, b;
    std::uint32_t polygon, ring, ring_index;  // ring_index: which of `rings`
    std::uint32_t at;                         // position in its ring
  };
  std::vector<Edge> all;
  for (std::uint32_t r = 0; r < rings.size(); ++r) {
    const auto& v = rings[r].vertices;
    for (std::uint32_t i = 0; i < v.size(); ++i)
      all.push_back({v[i], v[(i + 1) % v.size()], rings[r].polygon, rings[r].ring, r, i});
  }
  auto name = [&](std::uint32_t polygon) { return what + std::to_string(polygon); };

  // Within a polygon, copies of one edge (either way) cancel in pairs.
  std::vector<char> gone(all.size(), 0);
  {
    auto key = [&](const Edge& e) {
      const bool ab = e.a[0] < e.b[0] || (e.a[0] == e.b[0] && e.a[1] < e.b[1]);
      return ab ? std::tuple{e.polygon, e.a[0], e.a[1], e.b[0], e.b[1]}
                : std::tuple{e.polygon, e.b[0], e.b[1], e.a[0], e.a[1]};
    };
    std::vector<std::uint32_t> order(all.size());
    for (std::uint32_t i = 0; i < order.size(); ++i)
      order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::uint32_t x, std::uint32_t y) {
      return key(all[x]) < key(all[y]) || (key(all[x]) == key(all[y]) && x < y);
    });
    for (std::size_t i = 0; i < order.size();) {
      std::size_t j = i + 1;
      while (j < order.size() && key(all[order[j]]) == key(all[order[i]]))
        ++j;
      for (std::size_t k = i + (j - i) % 2; k < j; ++k)
        gone[order[k]] = 1;
      i = j;
    }
  }
  std::vector<std::uint32_t> kept;  // indices into all
  std::vector<std::uint32_t> kept_at(all.size(), kNone);
  std::vector<Segment<2>> segs;
  for (std::uint32_t i = 0; i < all.size(); ++i)
    if (!gone[i]) {
      kept_at[i] = static_cast<std::uint32_t>(kept.size());
      kept.push_back(i);
      segs.push_back({all[i].a, all[i].b});
    }

  // Crossings and overlaps refused; points where edges touch, with the edges meeting there.
  struct Touch {
    Point<2> p;
    std::uint32_t polygon, edge;  // edge: index into kept
  };
  std::vector<Touch> touches;
  auto adjacent = [&](Id i, Id j) {
    const Edge& s = all[kept[i]];
    const Edge& t = all[kept[j]];
    if (s.ring_index != t.ring_index) return false;
    const auto n = static_cast<std::uint32_t>(rings[s.ring_index].vertices.size());
    return (s.at + 1) % n == t.at || (t.at + 1) % n == s.at;
  };
  segment_intersections(
      std::span<const Segment<2>>(segs), adjacent, [&](Id i, Id j, const SegmentIntersection& x) {
        const Edge& s = all[kept[i]];
        const Edge& t = all[kept[j]];
        if (s.polygon != t.polygon) return true;
        const std::string rings_of =
            s.ring == t.ring ? ring_name(s.ring) + " of " + name(s.polygon)
                             : ring_name(std::min(s.ring, t.ring)) + " and " +
                                   ring_name(std::max(s.ring, t.ring)) + " of " + name(s.polygon);
        if (x.kind == SegmentMeet::overlap)
          throw InvalidGeometry(
              rings_of + (s.ring == t.ring ? " runs along itself" : " run along each other") +
              " from " + ring_point(x.a) + " to " + ring_point(x.b));
        const int sa = sign(orientation(s.a, s.b, t.a));
        const int sb = sign(orientation(s.a, s.b, t.b));
        const int ta = sign(orientation(t.a, t.b, s.a));
        const int tb = sign(orientation(t.a, t.b, s.b));
        if (sa * sb < 0 && ta * tb < 0)
          throw InvalidGeometry(rings_of + (s.ring == t.ring ? " crosses itself" : " cross") +
                                " near " + ring_point(x.a));
        // Touching: the point is an end of one of them, exactly.
        touches.push_back({x.a, s.polygon, static_cast<std::uint32_t>(i)});
        touches.push_back({x.a, s.polygon, static_cast<std::uint32_t>(j)});
        return true;
      });

  // Locating: the kept edges of one polygon at a time, in bands of y.
  struct Located {
    std::uint32_t polygon = kNone;
    std::vector<std::uint32_t> edges;  // kept indices
    YBands bands;
  } here;
  auto locate = [&](std::uint32_t polygon) -> Located& {
    if (here.polygon == polygon) return here;
    here.polygon = polygon;
    here.edges.clear();
    // Kept edges come polygon after polygon.
    const auto first = std::partition_point(
        kept.begin(), kept.end(), [&](std::uint32_t k) { return all[k].polygon < polygon; });
    double y0 = std::numeric_limits<double>::infinity(), y1 = -y0;
    for (auto it = first; it != kept.end() && all[*it].polygon == polygon; ++it) {
      const auto k = static_cast<std::uint32_t>(it - kept.begin());
      here.edges.push_back(k);
      y0 = std::min({y0, segs[k].a[1], segs[k].b[1]});
      y1 = std::max({y1, segs[k].a[1], segs[k].b[1]});
    }
    here.bands = YBands(
        here.edges.size(),
        [&](std::size_t i) {
          const Segment<2>& s = segs[here.edges[i]];
          return std::pair{std::min(s.a[1], s.b[1]), std::max(s.a[1], s.b[1])};
        },
        y0, y1, std::clamp<std::size_t>(here.edges.size() / 8, 1, 1 << 14));
    return here;
  };
  // Crossings of the ray towards +x from just right of v and above it: the edges through v
  // do not count (they meet the line just above v left of the point).
  auto crossings = [&](std::uint32_t polygon, const Point<2>& v) {
    Located& l = locate(polygon);
    int c = 0;
    for (const std::uint32_t i : l.bands.at(v[1])) {
      const Segment<2>& s = segs[l.edges[i]];
      const Point<2>& lo = s.a[1] < s.b[1] ? s.a : s.b;
      const Point<2>& hi = s.a[1] < s.b[1] ? s.b : s.a;
      if (!(lo[1] <= v[1] && v[1] < hi[1])) continue;
      if (orientation(lo, hi, v) == Orientation::counterclockwise) ++c;
    }
    return c;
  };
  // The parity on the left of each kept edge, found around the points where it can change.
  std::vector<int> left(kept.size(), -1);
  struct Ray {
    Point<2> to;
    std::uint32_t edge;  // kept index
    bool leaving;
  };
  std::vector<Ray> rays;
  auto count_around = [&](std::uint32_t polygon, const Point<2>& v,
                          std::span<const std::uint32_t> edges) {
    rays.clear();
    for (const std::uint32_t k : edges) {
      const Segment<2>& s = segs[k];
      if (!(s.b == v)) rays.push_back({s.b, k, true});
      if (!(s.a == v)) rays.push_back({s.a, k, false});
    }
    // Counter-clockwise from the direction +x (included).
    auto upper = [&](const Point<2>& q) { return q[1] > v[1] || (q[1] == v[1] && q[0] > v[0]); };
    std::sort(rays.begin(), rays.end(), [&](const Ray& x, const Ray& y) {
      const bool ux = upper(x.to), uy = upper(y.to);
      if (ux != uy) return ux;
      return orientation(v, x.to, y.to) == Orientation::counterclockwise;
    });
    const std::size_t start = !rays.empty() && rays[0].to[1] == v[1] && rays[0].to[0] > v[0];
    int c = crossings(polygon, v);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const Ray& r = rays[(start + i) % rays.size()];
      ++c;
      // Turning counter-clockwise across an edge leaving v enters its left.
      if (r.leaving) left[r.edge] = c & 1;
    }
  };

  // Around every point where edges touch.
  std::sort(touches.begin(), touches.end(), [](const Touch& x, const Touch& y) {
    return std::tuple{x.polygon, x.p[0], x.p[1], x.edge} <
           std::tuple{y.polygon, y.p[0], y.p[1], y.edge};
  });
  std::vector<std::uint32_t> meeting;
  for (std::size_t i = 0; i < touches.size();) {
    std::size_t j = i;
    meeting.clear();
    while (j < touches.size() && touches[j].polygon == touches[i].polygon &&
           touches[j].p == touches[i].p) {
      if (meeting.empty() || meeting.back() != touches[j].edge) meeting.push_back(touches[j].edge);
      ++j;
    }
    count_around(touches[i].polygon, touches[i].p, meeting);
    i = j;
  }
  // Around the first vertex of every ring whose edges there are kept and not counted yet, then
  // along the ring: an edge not counted starts where only its ring's two edges meet, and has
  // the face on the left of the edge before it on its left.
  std::uint32_t base = 0;
  for (const PolygonRing& r : rings) {
    const auto n = static_cast<std::uint32_t>(r.vertices.size());
    const std::uint32_t first = kept_at[base], last = kept_at[base + n - 1];
    if (first != kNone && last != kNone && left[first] < 0) {
      const std::uint32_t two[] = {first, last};
      count_around(r.polygon, r.vertices[0], two);
    }
    std::uint32_t from = kNone;  // a counted edge of the ring
    for (std::uint32_t i = 0; i < n && from == kNone; ++i)
      if (const std::uint32_t k = kept_at[base + i]; k != kNone && left[k] >= 0) from = i;
    if (from != kNone)
      for (std::uint32_t s = 1, prev = kept_at[base + from]; s < n; ++s) {
        const std::uint32_t k = kept_at[base + (from + s) % n];
        if (k == kNone) continue;
        if (left[k] < 0) left[k] = left[prev];
        prev = k;
      }
    base += n;
  }

  std::vector<PolygonEdge> out;
  out.reserve(kept.size());
  for (std::uint32_t k = 0; k < kept.size(); ++k) {
    const Segment<2>& s = segs[k];
    assert(left[k] >= 0);  // every ring with kept edges has one counted
    if (left[k] == 1)
      out.push_back({s.a, s.b, all[kept[k]].polygon});
    else
      out.push_back({s.b, s.a, all[kept[k]].polygon});
  }
  return out;
}

}  // namespace loci::detail
