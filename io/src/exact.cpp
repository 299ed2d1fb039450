// Exact refinement on flattened geometries; see exact.hpp for the semantics.
#include "loci/io/exact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>

#include "loci/geom/predicates.hpp"
#include "loci/geom/segment_intersection.hpp"
#include "loci/index/packed_rtree.hpp"
#include "loci/index/sweep_join.hpp"

namespace loci::io {
namespace {

template <class F>
bool any_edge(const FlatGeometry& g, F&& f) {
  for (const Part& part : g.parts) {
    if (part.kind == PartKind::point) continue;
    for (std::uint32_t i = part.begin; i + 1 < part.end; ++i)
      if (f(Segment2{g.points[i], g.points[i + 1]})) return true;
  }
  return false;
}

// True when p is strictly inside one of g's polygons: an odd number of that polygon's rings
// cross the ray from p towards +x. Points on a ring may answer either way; callers test the
// boundary separately.
bool inside_polygon(const FlatGeometry& g, const Point2& p) {
  if (g.polygons == 0) return false;
  bool odd_one = false;  // one polygon: a count's parity
  OddPolygons odd;
  for (const Part& part : g.parts) {
    if (part.kind != PartKind::ring) continue;
    for (std::uint32_t i = part.begin; i + 1 < part.end; ++i)
      if (ray_crosses(g.points[i], g.points[i + 1], p)) {
        if (g.polygons == 1)
          odd_one = !odd_one;
        else
          odd.toggle(part.polygon);
      }
  }
  return g.polygons == 1 ? odd_one : odd.any();
}

}  // namespace

Box2 FlatGeometry::envelope() const {
  Box2 b = Box2::empty();
  for (const auto& p : points)
    b.expand(p);
  return b;
}

bool ray_crosses(const Point2& a, const Point2& b, const Point2& p) {
  if ((a[1] > p[1]) == (b[1] > p[1])) return false;
  // The edge spans p's horizontal line; the crossing lies to the right of p exactly when p is
  // left of the edge directed upwards.
  const Orientation o = a[1] < b[1] ? orientation(a, b, p) : orientation(b, a, p);
  return o == Orientation::counterclockwise;
}

bool OddPolygons::any() {
  // An odd number of crossings in all has an odd number in some polygon.
  if (n_ & 1) return true;
  if (n_ == 0) return false;
  if (n_ == 2) return small_[0] != small_[1];
  // Whether a polygon was noted an odd number of times: sorted, a run of odd length.
  const auto odd_run = [](std::span<std::uint32_t> ids) {
    std::sort(ids.begin(), ids.end());
    for (std::size_t i = 0; i < ids.size();) {
      std::size_t j = i + 1;
      while (j < ids.size() && ids[j] == ids[i])
        ++j;
      if ((j - i) & 1) return true;
      i = j;
    }
    return false;
  };
  if (n_ <= small_.size()) return odd_run(std::span(small_.data(), n_));
  std::vector<std::uint32_t> all(more_);
  all.insert(all.end(), small_.begin(), small_.end());
  return odd_run(all);
}

bool meets(const FlatGeometry& g, const Box2& box) {
  if (g.empty() || !intersects(g.envelope(), box)) return false;
  for (const Part& part : g.parts)
    for (std::uint32_t i = part.begin; i < part.end; ++i)
      if (intersects(box, g.points[i])) return true;
  if (any_edge(g, [&](const Segment2& e) { return intersects(box, e); })) return true;
  // No point and no edge of g meets the box: the box is either inside a polygon or outside g
  // altogether, and one corner decides which.
  return inside_polygon(g, box.min);
}

bool meets(const FlatGeometry& g, const Segment2& s) {
  if (g.empty()) return false;
  for (const Part& part : g.parts) {
    if (part.end - part.begin == 1 || part.kind == PartKind::point) {
      for (std::uint32_t i = part.begin; i < part.end; ++i)
        if (intersects(Segment2{g.points[i], g.points[i]}, s)) return true;
    }
  }
  if (any_edge(g, [&](const Segment2& e) { return intersects(e, s); })) return true;
  return inside_polygon(g, s.a);
}

namespace {
// The parameter of point x on the line of s, clamped to [0, 1] (x lies on s). Differences far
// from 1 are scaled by a power of two first (exactly, to the same quotient): the squares of a
// segment's coordinates below about 1e-154 underflow (at 1e-200 the squared length was 0 and
// every parameter 0), and those above 1e154 overflow (inf / inf).
double parameter(const Segment2& s, const Point2& x) {
  double dx = s.b[0] - s.a[0], dy = s.b[1] - s.a[1];
  double wx = x[0] - s.a[0], wy = x[1] - s.a[1];
  const double m = std::max(std::fabs(dx), std::fabs(dy));
  if (m == 0) return 0;
  if (m < 0x1p-400 || m > 0x1p400) {  // else the squares neither underflow nor overflow
    const int e = std::ilogb(m);
    dx = std::ldexp(dx, -e), dy = std::ldexp(dy, -e);
    wx = std::ldexp(wx, -e), wy = std::ldexp(wy, -e);
  }
  const double t = (wx * dx + wy * dy) / (dx * dx + dy * dy);
  return std::clamp(t, 0.0, 1.0);
}
}  // namespace

std::optional<Meet> first_meeting(const Segment2& e, const Segment2& s) {
  const SegmentIntersection x = intersection(e, s);
  switch (x.kind) {
    case SegmentMeet::none:
      return std::nullopt;
    case SegmentMeet::point:
      return Meet{parameter(s, x.a), x.a};
    default: {
      const double ta = parameter(s, x.a), tb = parameter(s, x.b);
      return tb < ta ? Meet{tb, x.b} : Meet{ta, x.a};
    }
  }
}

std::optional<Meet> first_meeting(const FlatGeometry& g, const Segment2& s) {
  if (g.empty()) return std::nullopt;
  std::optional<Meet> best;
  auto offer = [&](std::optional<Meet> m) {
    if (m && (!best || m->t < best->t)) best = m;
  };
  for (const Part& part : g.parts) {
    if (part.end - part.begin == 1 || part.kind == PartKind::point) {
      for (std::uint32_t i = part.begin; i < part.end; ++i)
        offer(first_meeting(Segment2{g.points[i], g.points[i]}, s));
      continue;
    }
    for (std::uint32_t i = part.begin; i + 1 < part.end; ++i)
      offer(first_meeting(Segment2{g.points[i], g.points[i + 1]}, s));
  }
  if (best && best->t == 0) return best;
  if (inside_polygon(g, s.a)) return Meet{0.0, s.a};
  return best;
}

std::optional<double> first_meet(const FlatGeometry& g, const Segment2& s) {
  const auto m = first_meeting(g, s);
  return m ? std::optional<double>(m->t) : std::nullopt;
}

namespace {
// The edges of g (isolated points as edges of length zero) whose boxes, grown by `grow`, meet
// `window`, with those boxes. Restricting a pair test to the other geometry's envelope keeps a
// big feature met by a small one at the cost of its edges near the small one.
struct Edges {
  std::vector<Segment2> segs;
  std::vector<Box2> boxes;
  std::vector<bool> ring;              // the edge bounds a polygon
  std::vector<std::uint32_t> polygon;  // which (rings only)
  Edges(const FlatGeometry& g, double grow, const Box2& window) {
    auto add = [&](const Segment2& e, bool of_ring, std::uint32_t of_polygon) {
      const Box2 box = grow > 0 ? outset(e.box(), grow) : e.box();
      if (!intersects(box, window)) return;
      segs.push_back(e);
      boxes.push_back(box);
      ring.push_back(of_ring);
      polygon.push_back(of_polygon);
    };
    for (const Part& part : g.parts) {
      if (part.end - part.begin == 1 || part.kind == PartKind::point) {
        for (std::uint32_t i = part.begin; i < part.end; ++i)
          add({g.points[i], g.points[i]}, false, 0);
        continue;
      }
      for (std::uint32_t i = part.begin; i + 1 < part.end; ++i)
        add({g.points[i], g.points[i + 1]}, part.kind == PartKind::ring, part.polygon);
    }
  }
};

// Cut parameters along one segment and the stretches of it that run along other linework.
struct Cuts {
  std::vector<double> at;
  std::vector<std::pair<double, double>> along;

  // Calls f(t) with the middle parameter of every piece of the segment between its cuts that
  // does not run along the other linework, until f returns false; false then.
  template <class F>
  bool each_piece(F&& f) {
    at.push_back(0);
    at.push_back(1);
    std::sort(at.begin(), at.end());
    // The stretches merged into disjoint ones in order, walked alongside the pieces (a piece
    // lies between consecutive cuts, so within one merged stretch or outside all).
    std::sort(along.begin(), along.end());
    std::size_t m = 0;
    for (std::size_t k = 0; k < along.size(); ++k) {
      if (m > 0 && along[k].first <= along[m - 1].second)
        along[m - 1].second = std::max(along[m - 1].second, along[k].second);
      else
        along[m++] = along[k];
    }
    along.resize(m);
    std::size_t j = 0;
    for (std::size_t k = 0; k + 1 < at.size(); ++k) {
      const double t0 = at[k], t1 = at[k + 1];
      if (!(t1 > t0)) continue;
      while (j < along.size() && along[j].second < t1)
        ++j;
      const bool on_other = j < along.size() && along[j].first <= t0 && t1 <= along[j].second;
      if (!on_other && !f((t0 + t1) / 2)) return false;
    }
    return true;
  }
};

// A point strictly inside the polygon bounded by `rings` (parts of g, one polygon's rings),
// found on a horizontal line between two of its vertices' heights and checked exactly against
// g; nothing when rounding leaves no such point (a polygon thinner than the rounding).
std::optional<Point2> interior_point(const FlatGeometry& g, std::span<const std::uint32_t> rings,
                                     const PreparedGeometry& pg) {
  std::vector<double> ys;
  for (const std::uint32_t r : rings)
    for (std::uint32_t i = g.parts[r].begin; i < g.parts[r].end; ++i)
      ys.push_back(g.points[i][1]);
  std::sort(ys.begin(), ys.end());
  ys.erase(std::unique(ys.begin(), ys.end()), ys.end());
  // Heights between consecutive vertex heights, widest gaps first.
  std::vector<std::pair<double, double>> gaps;
  for (std::size_t k = 0; k + 1 < ys.size(); ++k)
    gaps.emplace_back(ys[k + 1] - ys[k], ys[k] + (ys[k + 1] - ys[k]) / 2);
  // Widest first; a polygon so thin that 256 of its widest bands hold no point of a double
  // is passed over (its inside is within rounding of its boundary).
  std::sort(gaps.begin(), gaps.end(), std::greater<>());
  if (gaps.size() > 256) gaps.resize(256);
  std::vector<double> xs;
  for (const auto& [gap, y] : gaps) {
    xs.clear();
    for (const std::uint32_t r : rings) {
      const Part& part = g.parts[r];
      for (std::uint32_t i = part.begin; i + 1 < part.end; ++i) {
        const Point2& a = g.points[i];
        const Point2& b = g.points[i + 1];
        if ((a[1] > y) == (b[1] > y)) continue;
        xs.push_back(a[0] + (y - a[1]) / (b[1] - a[1]) * (b[0] - a[0]));
      }
    }
    std::sort(xs.begin(), xs.end());
    for (std::size_t k = 0; k + 1 < xs.size(); k += 2) {
      const Point2 p{xs[k] + (xs[k + 1] - xs[k]) / 2, y};
      if (pg.locate(p) == Location::inside) return p;
    }
  }
  return std::nullopt;
}

// True when q lies on a ring of g, exactly.
bool on_ring(const FlatGeometry& g, const Point2& q) {
  for (const Part& part : g.parts) {
    if (part.kind != PartKind::ring) continue;
    for (std::uint32_t i = part.begin; i + 1 < part.end; ++i)
      if (intersects(Segment2{g.points[i], g.points[i + 1]}, Segment2{q, q})) return true;
  }
  return false;
}

Box2 common(const Box2& a, const Box2& b) {
  return {{std::max(a.min[0], b.min[0]), std::max(a.min[1], b.min[1])},
          {std::min(a.max[0], b.max[0]), std::min(a.max[1], b.max[1])}};
}

double box_gap(const Box2& a, const Box2& b) {
  return std::hypot(std::max({0.0, a.min[0] - b.max[0], b.min[0] - a.max[0]}),
                    std::max({0.0, a.min[1] - b.max[1], b.min[1] - a.max[1]}));
}
}  // namespace

bool meets(const PreparedGeometry& pa, const PreparedGeometry& pb) {
  const FlatGeometry& a = pa.geometry();
  const FlatGeometry& b = pb.geometry();
  if (a.empty() || b.empty() || !intersects(pa.envelope(), pb.envelope())) return false;
  // Edges that meet lie in both envelopes.
  const Box2 both = common(pa.envelope(), pb.envelope());
  const Edges ea(a, 0, both), eb(b, 0, both);
  bool found = false;
  join(std::span<const Box2>(ea.boxes), std::span<const Box2>(eb.boxes), [&](Id i, Id j) {
    found = intersects(ea.segs[i], eb.segs[j]);
    return !found;
  });
  if (found) return true;
  // No edges meet: each connected part of one lies inside the other's polygons or outside.
  auto part_inside = [](const FlatGeometry& g, const PreparedGeometry& other) {
    if (other.geometry().polygons == 0) return false;
    for (const Part& part : g.parts)
      if (other.locate(g.points[part.begin]) != Location::outside) return true;
    return false;
  };
  return part_inside(a, pb) || part_inside(b, pa);
}

bool meets(const FlatGeometry& a, const FlatGeometry& b) {
  if (a.empty() || b.empty() || !intersects(a.envelope(), b.envelope())) return false;
  return meets(PreparedGeometry(a), PreparedGeometry(b));
}

bool covers(const PreparedGeometry& pa, const PreparedGeometry& pb) {
  const FlatGeometry& a = pa.geometry();
  const FlatGeometry& b = pb.geometry();
  if (a.empty() || b.empty() || !within(pb.envelope(), pa.envelope())) return false;
  const Edges ea(a, 0, pb.envelope()), eb(b, 0, pb.envelope());
  const bool areas = b.polygons > 0;
  if (areas && a.polygons == 0) return false;  // linework and points cover no area
  // Where the edges of a and b meet: cut parameters on b's edges, and on a's ring edges when b
  // has polygons, with the stretches where they run along each other; kept flat, then
  // gathered edge by edge.
  struct Cut {
    std::uint32_t edge;
    double u, v;  // u == v: a crossing; else a stretch along the other's edge
    bool operator<(const Cut& o) const { return edge < o.edge; }
  };
  // Cuts at an edge's ends divide nothing, and an edge running wholly along the other's has no
  // piece to test: neither is kept (for a feature joined with itself, that is nearly all).
  std::vector<Cut> on_b, on_a;
  std::vector<bool> along_b(eb.segs.size()), along_a(areas ? ea.segs.size() : 0);
  join(std::span<const Box2>(eb.boxes), std::span<const Box2>(ea.boxes), [&](Id i, Id j) {
    const Segment2& s = eb.segs[i];
    const Segment2& e = ea.segs[j];
    const SegmentIntersection x = intersection(s, e);
    if (x.kind == SegmentMeet::none) return true;
    auto record = [&](std::vector<Cut>& cuts, std::vector<bool>& along, std::uint32_t edge,
                      const Segment2& on) {
      if (along[edge]) return;
      const double u = parameter(on, x.a);
      const double v = x.kind == SegmentMeet::point ? u : parameter(on, x.b);
      const double lo = std::min(u, v), hi = std::max(u, v);
      if (lo == 0 && hi == 1 && x.kind != SegmentMeet::point) along[edge] = true;
      if (lo == hi && (lo == 0 || lo == 1)) return;
      cuts.push_back({edge, lo, hi});
    };
    record(on_b, along_b, std::uint32_t(i), s);
    if (areas && ea.ring[j]) record(on_a, along_a, std::uint32_t(j), e);
    return true;
  });
  if (areas && a.polygons > 1) {
    // a's ring edges cut each other too, so that each piece lies wholly inside or outside every
    // other polygon and its middle speaks for it (below), on no edge across it: those of other
    // polygons, and those of its own that touch it (a hole touching its outer ring).
    const std::span<const Box2> boxes(ea.boxes);
    join(boxes, boxes, [&](Id i, Id j) {
      if (!ea.ring[i] || !ea.ring[j] || i == j) return true;
      const SegmentIntersection x = intersection(ea.segs[i], ea.segs[j]);
      if (x.kind == SegmentMeet::none) return true;
      for (int k = 0; k < (x.kind == SegmentMeet::point ? 1 : 2); ++k) {
        const double u = parameter(ea.segs[i], k == 0 ? x.a : x.b);
        if (u > 0 && u < 1) on_a.push_back({std::uint32_t(i), u, u});
      }
      return true;
    });
  }
  std::sort(on_b.begin(), on_b.end());
  std::sort(on_a.begin(), on_a.end());
  // Calls f(t) for the middle of every piece of edge `edge` between its cuts that does not run
  // along the other's edges; false when f does.
  Cuts pieces;
  auto each_piece = [&pieces](const std::vector<Cut>& cuts, std::size_t& k, std::uint32_t edge,
                              auto&& f) {
    pieces.at.clear();
    pieces.along.clear();
    for (; k < cuts.size() && cuts[k].edge == edge; ++k) {
      pieces.at.push_back(cuts[k].u);
      if (cuts[k].v != cuts[k].u) {
        pieces.at.push_back(cuts[k].v);
        pieces.along.emplace_back(cuts[k].u, cuts[k].v);
      }
    }
    return pieces.each_piece(f);
  };
  // Every point of b's linework lies in a: its vertices, and the middle of each piece between
  // cuts (pieces running along a's edges do).
  std::size_t k = 0;
  for (std::uint32_t i = 0; i < eb.segs.size(); ++i) {
    const Segment2& s = eb.segs[i];
    if (!pa.meets(s.a) || !pa.meets(s.b)) return false;
    if (s.a == s.b || along_b[i]) {
      while (k < on_b.size() && on_b[k].edge == i)
        ++k;
      continue;
    }
    if (!each_piece(on_b, k, i, [&](double t) { return pa.locate_at(s, t) != Location::outside; }))
      return false;
  }
  if (!areas) return true;
  // No point of the boundary of a's area lies strictly inside b's polygons: a piece of a ring
  // edge between its cuts with b's edges (a hole or notch of a inside b; the boundary of a
  // has a's outside beside it), unless a's polygons hold both its sides (the edge of one of
  // two polygons that overlap, inside the other, or an edge two adjacent polygons share).
  // Every point of that boundary inside b lies on such a piece; for a single polygon a vertex
  // there says so sooner.
  const Box2& env = pb.envelope();
  if (a.polygons < 2)
    for (const Point2& v : a.points)
      if (intersects(env, v) && pb.locate(v) == Location::inside) return false;
  k = 0;
  for (std::uint32_t j = 0; j < ea.segs.size(); ++j) {
    const Segment2& e = ea.segs[j];
    if (!ea.ring[j] || e.a == e.b || along_a[j]) {
      while (k < on_a.size() && on_a[k].edge == j)
        ++k;
      continue;
    }
    if (!each_piece(on_a, k, j, [&](double t) {
          return pb.locate_at(e, t) != Location::inside ||
                 (a.polygons > 1 && pa.holds_both_sides(e, t));
        }))
      return false;
  }
  // So the inside of each polygon of b lies wholly inside a or wholly outside it (say, a's hole
  // filled exactly by b), and one point strictly inside it decides which.
  std::vector<std::vector<std::uint32_t>> rings(b.polygons);
  for (std::uint32_t r = 0; r < b.parts.size(); ++r)
    if (b.parts[r].kind == PartKind::ring && b.parts[r].polygon < b.polygons)
      rings[b.parts[r].polygon].push_back(r);
  for (const std::vector<std::uint32_t>& polygon : rings) {
    const std::optional<Point2> p = interior_point(b, polygon, pb);
    if (!p) continue;
    const Location where = pa.locate(*p);
    if (where == Location::outside) return false;
    // On a ring of a: inside a's area, every piece of its boundary inside b having passed.
    if (where == Location::boundary && !inside_polygon(a, *p) && !on_ring(a, *p)) return false;
  }
  return true;
}

bool covers(const FlatGeometry& a, const FlatGeometry& b) {
  if (a.empty() || b.empty() || !within(b.envelope(), a.envelope())) return false;
  return covers(PreparedGeometry(a), PreparedGeometry(b));
}

std::optional<double> distance_within(const PreparedGeometry& pa, const PreparedGeometry& pb,
                                      double d) {
  const FlatGeometry& a = pa.geometry();
  const FlatGeometry& b = pb.geometry();
  if (a.empty() || b.empty() || box_gap(pa.envelope(), pb.envelope()) > d) return std::nullopt;
  if (meets(pa, pb)) return 0.0;
  // Only edges within d of the other's envelope can come within d of its edges.
  const Edges ea(a, d, pb.envelope()), eb(b, 0, outset(pa.envelope(), d));
  const std::span<const Box2> boxes_a(ea.boxes), boxes_b(eb.boxes);
  double best = std::numeric_limits<double>::infinity();
  join(boxes_a, boxes_b, [&](Id i, Id j) {
    const Segment2& s = ea.segs[i];
    const Segment2& t = eb.segs[j];
    // The segments do not meet: the nearest points include an end point of one of them.
    const double d2 =
        std::min({accurate_squared_distance(s.a, t), accurate_squared_distance(s.b, t),
                  accurate_squared_distance(t.a, s), accurate_squared_distance(t.b, s)});
    best = std::min(best, d2);
    return true;
  });
  const double dist = std::sqrt(best);
  // The distance is good to a bound of the coordinates' rounding (segment.hpp); within it of
  // d, the end points decide exactly whether one comes within d.
  const double margin =
      1e-14 * 6 * std::max(magnitude(pa.envelope()), magnitude(pb.envelope())) + 1e-150 + 4e-16 * d;
  if (dist > d + margin) return std::nullopt;
  if (dist < d - margin) return dist;
  bool within = false;
  join(boxes_a, boxes_b, [&](Id i, Id j) {
    const Segment2& s = ea.segs[i];
    const Segment2& t = eb.segs[j];
    within = compare_distance(s.a, t, d) <= 0 || compare_distance(s.b, t, d) <= 0 ||
             compare_distance(t.a, s, d) <= 0 || compare_distance(t.b, s, d) <= 0;
    return !within;
  });
  if (!within) return std::nullopt;
  return std::min(dist, d);  // the true distance is at most d, so is its rounding
}

std::optional<double> distance_within(const FlatGeometry& a, const FlatGeometry& b, double d) {
  if (a.empty() || b.empty()) return std::nullopt;
  return distance_within(PreparedGeometry(a), PreparedGeometry(b), d);
}

double distance(const PreparedGeometry& a, const PreparedGeometry& b, double bound) {
  if (a.geometry().empty() || b.geometry().empty()) return bound;
  if (meets(a, b)) return 0;
  // Apart: the distance is reached at a vertex of one and a point of the other's edges (or
  // isolated points). Each vertex browses the other's edges, in a packed R-tree, nearest box
  // first, until the boxes are farther than the best distance so far.
  double best = bound;
  const Box2 everywhere{{-kMaxCoordinate, -kMaxCoordinate}, {kMaxCoordinate, kMaxCoordinate}};
  auto side = [&](const FlatGeometry& from, const FlatGeometry& to) {
    const Edges edges(to, 0, everywhere);
    PackedRTree2::Builder builder(edges.boxes.size());
    for (const Box2& box : edges.boxes)
      builder.add(box);
    const PackedRTree2 tree = std::move(builder).finish();
    for (const Point2& p : from.points)
      tree.browse(p, [&](Id k, const Box2&, double box_distance) {
        if (box_distance >= best) return false;
        best = std::min(best, std::sqrt(accurate_squared_distance(p, edges.segs[k])));
        return true;
      });
  };
  side(a.geometry(), b.geometry());
  side(b.geometry(), a.geometry());
  return best;
}

// The grid. A ray from p towards +x crosses the ring edges of p's cell (tested exactly) and
// ring edges lying entirely right of the cell: those whose leftmost cell column is greater
// than p's. For such an edge e the crossing only depends on y: it happens exactly when
// ylo(e) <= p.y < yhi(e), whose parity is [ylo(e) <= p.y] xor [yhi(e) <= p.y]. Over the set S
// of those edges of one polygon in p's row, that polygon's parity is that of the number of end
// values (ylo and yhi of every edge of S) at most p.y. A value below the row counts for every
// p of the row (the polygons odd by those go into the cell's base), a value above it never,
// and two equal values of one polygon cancel: a vertex between two edges of S appears twice.
// What is left per cell is a handful of values, each with its polygon (where the boundary
// passes from the cell's side of the row to its right), sorted. Rows and columns are compared
// through the same monotone functions row() and col() that list the edges, so "below the row"
// and "right of the cell" are exact statements about the coordinates.
PreparedGeometry::PreparedGeometry(const FlatGeometry& g) : g_(&g), envelope_(g.envelope()) {
  for (const Part& part : g.parts) {
    if (part.end - part.begin == 1 || part.kind == PartKind::point) {
      for (std::uint32_t i = part.begin; i < part.end; ++i)
        edges_.push_back({i, 0, kPoint});
      continue;
    }
    const std::uint32_t kind = part.kind == PartKind::ring ? kRing : kLine;
    for (std::uint32_t i = part.begin; i + 1 < part.end; ++i)
      edges_.push_back({i, part.polygon, kind});
  }
  build(std::clamp<std::size_t>(edges_.size() / 2, 1, std::size_t(1) << 22));
}

bool PreparedGeometry::near_boundary(const Point2& p, double delta) const {
  const Box2 box{{p[0] - delta, p[1] - delta}, {p[0] + delta, p[1] + delta}};
  if (!intersects(envelope_, box)) return false;
  const std::vector<Point2>& pts = g_->points;
  for (std::uint32_t r = row(box.min[1]), r1 = row(box.max[1]); r <= r1; ++r)
    for (std::uint32_t c = col(box.min[0]), c1 = col(box.max[0]); c <= c1; ++c) {
      const std::size_t cell = std::size_t(r) * nx_ + c;
      for (std::uint32_t i = cell_start_[cell]; i < cell_start_[cell + 1]; ++i) {
        const Edge& e = edges_[cell_edges_[i]];
        const Point2& a = pts[e.first];
        if (e.kind == kPoint ? intersects(box, a) : intersects(box, Segment2{a, pts[e.first + 1]}))
          return true;
      }
    }
  return false;
}

Location PreparedGeometry::locate_at(const Segment2& s, double t) const {
  const Point2 m = point_at(s, t);
  const double hair = point_at_rounding(s);
  if (t == 0 || t == 1 || !near_boundary(m, hair)) return locate(m);
  // The real point p lies within `hair` of m in x and y, and g passes that near: p is located
  // by the parity, polygon by polygon, of the ring edges its rightward ray crosses, each
  // decided exactly. An edge on p or crossing that ray meets p's row at or right of p, so it
  // is listed in a cell of the rows m's y +- hair falls in, from m's x - hair rightwards.
  const std::vector<Point2>& pts = g_->points;
  // The sign of v minus p's coordinate on `axis`, exactly; the rounded point decides when v
  // lies farther from it than the rounding.
  auto above = [&](int axis, double v) {
    if (v > m[axis] + hair) return 1;
    if (v < m[axis] - hair) return -1;
    return -compare_coordinate_at(s, t, axis, v);
  };
  OddPolygons odd;
  // Whether p lies on edge k (then true), else its effect on the parity.
  auto on_edge = [&](std::uint32_t k) {
    const Edge& e = edges_[k];
    const Point2& a = pts[e.first];
    if (e.kind == kPoint) return above(0, a[0]) == 0 && above(1, a[1]) == 0;
    const Point2& b = pts[e.first + 1];
    const int ya = above(1, a[1]), yb = above(1, b[1]);
    if ((ya > 0 && yb > 0) || (ya < 0 && yb < 0)) return false;  // wholly above or below p
    const int x0 = above(0, std::min(a[0], b[0])), x1 = above(0, std::max(a[0], b[0]));
    if (x1 < 0) return false;  // wholly left of p
    const Orientation o = orientation_at(a, b, s, t);
    if (o == Orientation::collinear && x0 <= 0) return true;
    // Half-open in y, as ray_crosses: the crossing is right of p when p is left of the edge
    // directed upwards.
    if (e.kind == kRing && (ya > 0) != (yb > 0) &&
        o == (a[1] < b[1] ? Orientation::counterclockwise : Orientation::clockwise))
      odd.toggle(e.polygon);
    return false;
  };
  // When p lies in one cell, or within rounding of a cell's border: as locate, the edges
  // starting right of the cells by their end values below p (those within rounding of m's y
  // compared exactly), the edges of the cells each exactly. Else every edge listed in those
  // rows from c0 rightwards.
  const std::uint32_t r0 = row(m[1] - hair), r1 = row(m[1] + hair), c0 = col(m[0] - hair);
  const bool near = r1 <= r0 + 1;
  const std::uint32_t c1 = near ? col(m[0] + hair) : nx_ - 1;
  if (near)
    right_of(
        r0, r1, c1, m[1], hair, [&](double v) { return above(1, v) <= 0; }, odd);
  bool on = false;
  each_edge_in(r0, r1, c0, c1, [&](std::uint32_t k) { return !(on = on_edge(k)); });
  if (on) return Location::boundary;
  return odd.any() ? Location::inside : Location::outside;
}

bool PreparedGeometry::holds_both_sides(const Segment2& s, double t) const {
  const std::vector<Point2>& pts = g_->points;
  const Point2 m = point_at(s, t);
  const double hair = point_at_rounding(s);
  // The sign of v minus p's coordinate on `axis`, exactly.
  auto above = [&](int axis, double v) {
    if (v > m[axis] + hair) return 1;
    if (v < m[axis] - hair) return -1;
    return -compare_coordinate_at(s, t, axis, v);
  };
  // The signs of s's direction (dx, dy); the step to its left is along (-dy, dx).
  const int dx = (s.b[0] > s.a[0]) - (s.b[0] < s.a[0]);
  const int dy = (s.b[1] > s.a[1]) - (s.b[1] < s.a[1]);
  // Each side is located as locate does, polygon by polygon, for p moved an infinitesimal step
  // across s's line: the polygons holding the point stepped left, and right.
  OddPolygons side[2];
  // False when undecided: p on a ring edge across s's line.
  auto crossings = [&](const Edge& e) {
    const Point2& a = pts[e.first];
    const Point2& b = pts[e.first + 1];
    const int ya = above(1, a[1]), yb = above(1, b[1]);
    if ((ya > 0 && yb > 0) || (ya < 0 && yb < 0)) return true;  // wholly above or below p
    if (above(0, std::max(a[0], b[0])) < 0) return true;        // wholly left of p
    const bool up = a[1] < b[1];
    const Orientation o = orientation_at(up ? a : b, up ? b : a, s, t);
    if (o == Orientation::collinear && (orientation(s.a, s.b, a) != Orientation::collinear ||
                                        orientation(s.a, s.b, b) != Orientation::collinear))
      // p lies on the line of an edge across s's: on the edge itself when within its extent,
      // else the edge misses both stepped points' rays.
      return !(std::min(ya, yb) <= 0 && std::max(ya, yb) >= 0 &&
               above(0, std::min(a[0], b[0])) <= 0);
    for (int k = 0; k < 2; ++k) {
      // The step's y has the sign of dx to the left, of -dx to the right: an end at p's height
      // lies above the stepped point when the step goes down.
      const int step_y = k == 0 ? dx : -dx;
      const bool above_a = ya > 0 || (ya == 0 && step_y < 0);
      const bool above_b = yb > 0 || (yb == 0 && step_y < 0);
      if (above_a == above_b) continue;
      // The crossing lies right of the stepped point when that point is left of the edge
      // directed upwards. On s's line that is so for the step left when s runs upwards (the
      // step's cross product with the edge has the sign of their dot product).
      const bool right = o != Orientation::collinear ? o == Orientation::counterclockwise
                                                     : (k == 0 ? dy > 0 : dy < 0);
      if (right) side[k].toggle(e.polygon);
    }
    return true;
  };
  // p lies in one cell, or within rounding of a cell's border, and so do the stepped points:
  // as locate_at, the edges starting right of the cells by their end values below the stepped
  // point (an end at p's height is below the point stepped up, or sideways, and above the
  // point stepped down), then the edges of the cells, each once. Else the edges listed in the
  // rows p's y falls in, from p's column rightwards.
  const std::uint32_t r0 = row(m[1] - hair), r1 = row(m[1] + hair), c0 = col(m[0] - hair);
  const bool near = r1 <= r0 + 1;
  const std::uint32_t c1 = near ? col(m[0] + hair) : nx_ - 1;
  for (int k = 0; near && k < 2; ++k) {
    const int step_y = k == 0 ? dx : -dx;
    right_of(
        r0, r1, c1, m[1], hair,
        [&](double v) {
          const int a = above(1, v);
          return a < 0 || (a == 0 && step_y >= 0);
        },
        side[k]);
  }
  bool decided = true;
  each_edge_in(r0, r1, c0, c1, [&](std::uint32_t k) {
    const Edge& e = edges_[k];
    return e.kind != kRing || (decided = crossings(e));
  });
  return decided && side[0].any() && side[1].any();
}

template <class Below>
void PreparedGeometry::right_of(std::uint32_t r0, std::uint32_t r1, std::uint32_t c, double y,
                                double hair, Below below, OddPolygons& odd) const {
  // Cell (r1, c)'s base holds the ends below row r1, its values those in it, sorted.
  const std::size_t cell = std::size_t(r1) * nx_ + c;
  for (std::uint32_t i = base_start_[cell]; i < base_start_[cell + 1]; ++i)
    odd.toggle(base_[i]);
  for (std::uint32_t i = value_start_[cell]; i < value_start_[cell + 1]; ++i) {
    const double v = values_[i];
    if (v > y + hair) break;
    if (v < y - hair || below(v)) odd.toggle(value_polygons_[i]);
  }
  if (r0 == r1) return;
  // The point may lie in row r0, below r1's border: the base took every end of row r0 for
  // below it, and those that are not are taken back (from the top of row r0's values).
  const std::size_t under = cell - nx_;
  for (std::uint32_t i = value_start_[under + 1]; i-- > value_start_[under];) {
    const double v = values_[i];
    if (v < y - hair) break;
    if (v > y + hair || !below(v)) odd.toggle(value_polygons_[i]);
  }
}

template <class F>
void PreparedGeometry::each_edge_in(std::uint32_t r0, std::uint32_t r1, std::uint32_t c0,
                                    std::uint32_t c1, F&& f) const {
  const std::vector<Point2>& pts = g_->points;
  const bool one = r0 == r1 && c0 == c1;
  for (std::uint32_t r = r0; r <= r1; ++r)
    for (std::uint32_t c = c0; c <= c1; ++c) {
      const std::size_t cell = std::size_t(r) * nx_ + c;
      for (std::uint32_t i = cell_start_[cell]; i < cell_start_[cell + 1]; ++i) {
        if (!one) {
          // Each edge once: in the first of the cells that lists it.
          const Edge& e = edges_[cell_edges_[i]];
          const Point2& a = pts[e.first];
          const Point2& b = e.kind == kPoint ? a : pts[e.first + 1];
          if (std::max(row(std::min(a[1], b[1])), r0) != r ||
              std::max(col(std::min(a[0], b[0])), c0) != c)
            continue;
        }
        if (!f(cell_edges_[i])) return;
      }
    }
}

std::uint32_t PreparedGeometry::col(double x) const {
  const double f = (x - envelope_.min[0]) * sx_;
  return f > 0 ? std::min<std::uint32_t>(nx_ - 1, std::uint32_t(std::min(f, 4.0e9))) : 0;
}

std::uint32_t PreparedGeometry::row(double y) const {
  const double f = (y - envelope_.min[1]) * sy_;
  return f > 0 ? std::min<std::uint32_t>(ny_ - 1, std::uint32_t(std::min(f, 4.0e9))) : 0;
}

void PreparedGeometry::build(std::size_t cells) {
  const std::vector<Point2>& pts = g_->points;
  const double w = envelope_.max[0] - envelope_.min[0], h = envelope_.max[1] - envelope_.min[1];
  auto box_of = [&](const Edge& e) {
    const Point2& a = pts[e.first];
    const Point2& b = e.kind == kPoint ? a : pts[e.first + 1];
    return Box2{{std::min(a[0], b[0]), std::min(a[1], b[1])},
                {std::max(a[0], b[0]), std::max(a[1], b[1])}};
  };
  for (;;) {
    nx_ = ny_ = 1;
    if (w > 0 && h > 0) {
      // At most `cells` columns: a flat envelope would otherwise get more cells than asked
      // (one cell: one column and one row, so that each edge is listed once).
      const double nx = std::clamp(std::round(std::sqrt(double(cells) * w / h)), 1.0,
                                   std::min(65536.0, double(cells)));
      nx_ = std::uint32_t(nx);
      ny_ = std::uint32_t(std::clamp(std::round(double(cells) / nx), 1.0, 65536.0));
    } else if (w > 0) {
      nx_ = std::uint32_t(std::min<std::size_t>(cells, 65536));
    } else if (h > 0) {
      ny_ = std::uint32_t(std::min<std::size_t>(cells, 65536));
    }
    sx_ = w > 0 ? nx_ / w : 0;
    sy_ = h > 0 ? ny_ / h : 0;
    // Each edge is listed in every cell of its box; long diagonal edges make that quadratic in
    // their length, so a grid listing too much is made coarser.
    const std::size_t n = std::size_t(nx_) * ny_;
    cell_start_.assign(n + 1, 0);
    std::size_t listed = 0;
    bool too_many = false;
    for (const Edge& e : edges_) {
      const Box2 b = box_of(e);
      const std::uint32_t c0 = col(b.min[0]), c1 = col(b.max[0]);
      const std::uint32_t r0 = row(b.min[1]), r1 = row(b.max[1]);
      listed += std::size_t(c1 - c0 + 1) * (r1 - r0 + 1);
      if (listed > 8 * edges_.size() + n) {
        too_many = true;
        break;
      }
      for (std::uint32_t r = r0; r <= r1; ++r)
        for (std::uint32_t c = c0; c <= c1; ++c)
          ++cell_start_[std::size_t(r) * nx_ + c + 1];
    }
    if (too_many) {  // never with one cell, which lists each edge once
      cells = std::max<std::size_t>(cells / 4, 1);
      continue;
    }
    for (std::size_t k = 0; k < n; ++k)
      cell_start_[k + 1] += cell_start_[k];
    cell_edges_.resize(cell_start_[n]);
    std::vector<std::uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
    for (std::uint32_t k = 0; k < edges_.size(); ++k) {
      const Box2 b = box_of(edges_[k]);
      for (std::uint32_t r = row(b.min[1]), r1 = row(b.max[1]); r <= r1; ++r)
        for (std::uint32_t c = col(b.min[0]), c1 = col(b.max[0]); c <= c1; ++c)
          cell_edges_[fill[std::size_t(r) * nx_ + c]++] = k;
    }
    break;
  }
  // Per row, right to left: the ring edges whose leftmost column is right of the cell, as
  // their end values with their polygons, those of one polygon at one y cancelling in pairs;
  // an end below the row toggles its polygon in the cell's base.
  const std::size_t n = std::size_t(nx_) * ny_;
  base_start_.assign(n + 1, 0);
  base_.clear();
  std::vector<std::vector<std::pair<double, std::uint32_t>>> per_cell(nx_);
  std::vector<std::vector<std::uint32_t>> base_per_cell(nx_);
  value_start_.assign(n + 1, 0);
  values_.clear();
  value_polygons_.clear();
  std::vector<std::pair<double, std::uint32_t>> open;  // each present an odd number of times
  std::vector<std::uint32_t> odd;                      // the polygons odd by ends below the row
  const auto toggle = [](auto& set, const auto& x) {
    const auto it = std::find(set.begin(), set.end(), x);
    if (it == set.end()) {
      set.push_back(x);
    } else {
      *it = set.back();
      set.pop_back();
    }
  };
  for (std::uint32_t r = 0; r < ny_; ++r) {
    open.clear();
    odd.clear();
    for (std::uint32_t c = nx_; c-- > 0;) {
      const std::size_t cell = std::size_t(r) * nx_ + c;
      base_per_cell[c] = odd;
      per_cell[c] = open;
      std::sort(per_cell[c].begin(), per_cell[c].end());
      // Then the edges starting in this cell join the set for the cells to its left.
      for (std::uint32_t i = cell_start_[cell]; i < cell_start_[cell + 1]; ++i) {
        const Edge& e = edges_[cell_edges_[i]];
        if (e.kind != kRing) continue;
        const Box2 b = box_of(e);
        if (col(b.min[0]) != c) continue;  // listed here, but starts in a cell to the left
        for (const double v : {b.min[1], b.max[1]}) {
          const std::uint32_t vr = row(v);
          if (vr < r)
            toggle(odd, e.polygon);
          else if (vr == r)
            toggle(open, std::pair{v, e.polygon});
        }
      }
    }
    for (std::uint32_t c = 0; c < nx_; ++c) {
      const std::size_t cell = std::size_t(r) * nx_ + c;
      for (const auto& [v, polygon] : per_cell[c]) {
        values_.push_back(v);
        value_polygons_.push_back(polygon);
      }
      value_start_[cell + 1] = std::uint32_t(values_.size());
      base_.insert(base_.end(), base_per_cell[c].begin(), base_per_cell[c].end());
      base_start_[cell + 1] = std::uint32_t(base_.size());
    }
  }
}

Location PreparedGeometry::locate(const Point2& p) const {
  if (!intersects(envelope_, p)) return Location::outside;
  const std::vector<Point2>& pts = g_->points;
  const std::size_t cell = std::size_t(row(p[1])) * nx_ + col(p[0]);
  // The crossings: the cell's base, its values at most p.y (by binary search) and its own
  // edges. An odd number in all is odd in some polygon (inside), none is outside; only an
  // even number over several polygons needs them polygon by polygon.
  const double* v0 = values_.data() + value_start_[cell];
  const double* v1 = values_.data() + value_start_[cell + 1];
  const std::size_t below = std::size_t(std::upper_bound(v0, v1, p[1]) - v0);
  std::size_t crossings = base_start_[cell + 1] - base_start_[cell] + below;
  const bool several = g_->polygons > 1;
  OddPolygons odd;
  for (std::uint32_t i = cell_start_[cell]; i < cell_start_[cell + 1]; ++i) {
    const Edge& e = edges_[cell_edges_[i]];
    const Point2& a = pts[e.first];
    if (e.kind == kPoint) {
      if (a == p) return Location::boundary;
      continue;
    }
    const Point2& b = pts[e.first + 1];
    if (p[1] < std::min(a[1], b[1]) || p[1] > std::max(a[1], b[1])) continue;
    if (std::min(a[0], b[0]) <= p[0] && p[0] <= std::max(a[0], b[0]) &&
        orientation(a, b, p) == Orientation::collinear)
      return Location::boundary;
    if (e.kind == kRing && ray_crosses(a, b, p)) {
      ++crossings;
      if (several) odd.toggle(e.polygon);
    }
  }
  if (crossings & 1) return Location::inside;
  if (crossings == 0 || !several) return Location::outside;
  for (std::uint32_t i = base_start_[cell]; i < base_start_[cell + 1]; ++i)
    odd.toggle(base_[i]);
  for (std::size_t k = 0; k < below; ++k)
    odd.toggle(value_polygons_[value_start_[cell] + k]);
  return odd.any() ? Location::inside : Location::outside;
}

std::size_t PreparedGeometry::memory_bytes() const {
  return edges_.capacity() * sizeof(Edge) +
         (cell_start_.capacity() + cell_edges_.capacity() + value_start_.capacity()) *
             sizeof(std::uint32_t) +
         values_.capacity() * sizeof(double) +
         (value_polygons_.capacity() + base_start_.capacity() + base_.capacity()) *
             sizeof(std::uint32_t);
}

double distance(const FlatGeometry& g, const Point2& p) {
  // Floating point, except for the edges passing within rounding of p, measured exactly: 0
  // exactly when p lies on g.
  const double near2 = near_zone_squared(p, g.envelope());
  double best = std::numeric_limits<double>::infinity();
  auto offer = [&](Segment2 s) {
    // Measured from its lesser end, as a per-segment index recovers it from its box: the two
    // granularities report the same double (ties between features that share an edge stay
    // ties, ranked by FID alike).
    if (s.b[0] < s.a[0] || (s.b[0] == s.a[0] && s.b[1] < s.a[1])) std::swap(s.a, s.b);
    const double d2 = squared_distance(p, s);
    best = std::min(best, d2 > near2 ? d2 : accurate_squared_distance(p, s));
  };
  for (const Part& part : g.parts) {
    if (part.end - part.begin == 1 || part.kind == PartKind::point) {
      for (std::uint32_t i = part.begin; i < part.end; ++i)
        offer({g.points[i], g.points[i]});
      continue;
    }
    for (std::uint32_t i = part.begin; i + 1 < part.end; ++i)
      offer({g.points[i], g.points[i + 1]});
  }
  if (best > 0 && inside_polygon(g, p)) return 0;
  return std::sqrt(best);
}

bool within_distance(const FlatGeometry& g, const Point2& p, double d) {
  for (const Part& part : g.parts) {
    if (part.end - part.begin == 1 || part.kind == PartKind::point) {
      for (std::uint32_t i = part.begin; i < part.end; ++i)
        if (compare_distance(p, {g.points[i], g.points[i]}, d) <= 0) return true;
      continue;
    }
    for (std::uint32_t i = part.begin; i + 1 < part.end; ++i)
      if (compare_distance(p, {g.points[i], g.points[i + 1]}, d) <= 0) return true;
  }
  return inside_polygon(g, p);
}

}  // namespace loci::io
