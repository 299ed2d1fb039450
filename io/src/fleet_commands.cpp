// The library side of `loci fleet`: see fleet_commands.hpp.
#include "loci/io/fleet_commands.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <numbers>
#include <random>

#include "block_writer.hpp"
#include "gdal_layer.hpp"
#include "loci/geom/error.hpp"
#include "loci/index/moving/conflicts.hpp"
#include "loci/index/moving/moving_scan.hpp"
#include "loci/index/packed_rtree.hpp"
#include "loci/io/commands.hpp"
#include "loci/io/exact.hpp"
#include "svg.hpp"

namespace loci::io {

// The moving index the fleet commands use; any MovingIndex fits (TprTree<2> passes the same
// tests). A command answers one query from a fleet it has just read, and for one query a scan
// (O(n)) costs less than building a tree (O(n log n)) and querying it.
using FleetIndex = MovingScan<2>;

namespace {

constexpr double kNauticalMile = 1852.0;
constexpr double kKnot = kNauticalMile / 3600.0;

std::string fixed(double d, int decimals) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, d);
  return buf;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

const char* kAisUnits =
    "AIS input: positions lon/lat (WGS 84), distances in metres (dcpa, distance) and nautical "
    "miles (_nm), times in epoch seconds UTC (_utc: ISO dates, _min: minutes from now)";

struct Loaded {
  FleetData data;
  double now = 0;
  bool ais() const { return data.format == FleetFormat::ais; }
};

Loaded load(const std::string& path, std::optional<double> at) {
  Loaded l{read_fleet_file(path), 0};
  // Rows, none of them usable: nothing could be answered, and an empty answer would hide it.
  // (A header alone is a fleet of no objects.)
  if (l.data.reports.empty() && l.data.skipped.total() > 0)
    throw Error(printable(path) + ": no usable " + (l.ais() ? "AIS report" : "report") + ", " +
                l.data.skipped.summary());
  if (at)
    l.now = *at;
  else
    l.now = l.data.reports.empty() ? 0.0 : l.data.latest();
  return l;
}

FleetRun run_of(const Loaded& l) {
  FleetRun r;
  r.summary = l.data.summary();
  if (l.ais()) r.units = kAisUnits;
  r.now = l.now;
  return r;
}

FleetIndex index_of(std::span<const FleetReport> reports) {
  FleetIndex ix;
  for (const FleetReport& r : reports)
    ix.update(r.id, r.m);
  return ix;
}

void check_lonlat(const Point2& p, const char* what) {
  if (!(std::abs(p[0]) <= 180 && std::abs(p[1]) <= 90))
    throw InvalidArgument(std::string(what) +
                          " must be lon/lat for AIS input (lon in [-180, 180], lat in [-90, 90])");
}

// A lon/lat box as a polygon in the local frame, a vertex every 0.01 degree of its edges.
FlatGeometry lonlat_window(const LocalFrame& frame, const Box2& b) {
  check_lonlat(b.min, "the window");
  check_lonlat(b.max, "the window");
  FlatGeometry g;
  const Point2 corners[] = {b.min, {b.max[0], b.min[1]}, b.max, {b.min[0], b.max[1]}};
  for (int c = 0; c < 4; ++c) {
    const Point2 a = corners[c], z = corners[(c + 1) % 4];
    const double span = std::max(std::abs(z[0] - a[0]), std::abs(z[1] - a[1]));
    const int n = int(std::clamp(std::ceil(span / 0.01), 1.0, 36000.0));
    for (int i = 0; i < n; ++i) {
      const double f = double(i) / n;
      g.points.push_back(frame.to_local(a[0] + (z[0] - a[0]) * f, a[1] + (z[1] - a[1]) * f));
    }
  }
  g.points.push_back(g.points.front());
  g.parts.push_back({0, std::uint32_t(g.points.size()), PartKind::ring, 0});
  g.polygons = 1;
  return g;
}

// A window's polygon in the local frame (lonlat_window: one ring of up to 144,000 points),
// its edges in a packed R-tree: a path is tested against the few edges near it, not all.
class IndexedWindow {
 public:
  explicit IndexedWindow(const FlatGeometry& g) : g_(g), prepared_(g) {
    std::vector<Box2> boxes;
    for (std::size_t i = 0; i + 1 < g.points.size(); ++i) {
      Box2 b = Box2::of_point(g.points[i]);
      b.expand(g.points[i + 1]);
      boxes.push_back(b);
    }
    edges_ = PackedRTree<2>::build(boxes);
  }
  // Whether the segment s meets the polygon: meets(g, s).
  bool meets(const Segment2& s) const {
    if (prepared_.meets(s.a)) return true;  // inside, or on the boundary
    bool met = false;
    each_edge(s.box(), [&](const Segment2& e) { return !(met = intersects(e, s)); });
    return met;
  }
  // The first parameter along s at which s meets the ring's edges, taken as lines (first_meet
  // of the ring as a line layer); nullopt when none does.
  std::optional<double> first_meet_of_edges(const Segment2& s) const {
    std::optional<double> best;
    each_edge(s.box(), [&](const Segment2& e) {
      if (const auto m = first_meeting(e, s); m && (!best || m->t < *best)) best = m->t;
      return true;
    });
    return best;
  }
  // The first time in [lo, hi] at which the straight path of m is inside the polygon (a hit
  // known to meet it): lo when it starts inside, else where it first crosses an edge.
  double first_time_in(const Motion2& m, double lo, double hi) const {
    const Point2 a = position(m, lo), b = position(m, hi);
    if (prepared_.meets(a) || lo == hi) return lo;
    double best = 1;
    const double dx = b[0] - a[0], dy = b[1] - a[1];
    // Edges whose boxes miss the path's by a hair could still pass the rounded test below.
    Box2 reach = Box2::of_point(a);
    reach.expand(b);
    const double hair = 1e-9 * (std::abs(reach.min[0]) + std::abs(reach.max[0]) +
                                std::abs(reach.min[1]) + std::abs(reach.max[1])) +
                        1e-300;
    reach = {{reach.min[0] - hair, reach.min[1] - hair},
             {reach.max[0] + hair, reach.max[1] + hair}};
    each_edge(reach, [&](const Segment2& e) {
      const Point2 p = e.a, q = e.b;
      const double ex = q[0] - p[0], ey = q[1] - p[1];
      const double den = dx * ey - dy * ex;
      if (den == 0) return true;
      const double s = ((p[0] - a[0]) * ey - (p[1] - a[1]) * ex) / den;
      const double u = ((p[0] - a[0]) * dy - (p[1] - a[1]) * dx) / den;
      if (s >= 0 && s <= 1 && u >= 0 && u <= 1) best = std::min(best, s);
      return true;
    });
    return lo + (hi - lo) * best;
  }

 private:
  // f(edge) for each edge whose box meets `box`, until f returns false.
  template <class F>
  void each_edge(const Box2& box, F&& f) const {
    edges_.query(box, [&](Id i, const Box2&) {
      return f(Segment2{g_.points[std::size_t(i)], g_.points[std::size_t(i) + 1]});
    });
  }
  const FlatGeometry& g_;
  PreparedGeometry prepared_;
  PackedRTree<2> edges_;
};

// A piece of an object's trajectory: the report in force over [lo, hi].
struct Piece {
  Id id;
  Motion2 m;
  double lo, hi;
  bool open = false;  // hi excluded: the object's next report holds from hi
};

// The pieces of every trajectory over [t1, t2]: each report in force at some time of it.
std::vector<Piece> pieces_during(std::span<const FleetReport> sorted, double t1, double t2) {
  std::vector<Piece> out;
  for (std::size_t i = 0; i < sorted.size(); ++i) {
    const bool last = i + 1 == sorted.size() || sorted[i + 1].id != sorted[i].id;
    const double from = std::max(t1, sorted[i].m.t);
    const double to = last ? t2 : std::min(t2, sorted[i + 1].m.t);
    if (sorted[i].m.t > t2 || (!last && sorted[i + 1].m.t <= t1)) continue;
    // A piece ending where the next report begins is open: that instant is the next one's.
    const bool open = !last && sorted[i + 1].m.t <= t2;
    if (from < to || (from == to && !open))
      out.push_back({sorted[i].id, sorted[i].m, from, to, open});
  }
  return out;
}

// A conflict, with the reports of its two objects in force at its closest approach (for the
// positions shown).
struct FoundConflict {
  Conflict c;
  Motion2 ma, mb;
};

// The conflicts over [now, now + H] (DESIGN.md section 5: a report holds until the next one
// of its id, so a report within the horizon changes what follows it; conflicts before the
// latest reports are answered from the reports in force at each time, as windows over an
// interval are), sorted by (a, b). Without such reports: one find_conflicts over the reports
// in force at now. With them: every pair of pieces of two objects whose times overlap gets
// the closest approach over the overlap (candidates from the pieces' swept boxes grown by
// D/2), and a pair's answer is its least distance over them all (the earliest such time),
// entered at its first entry and left at its last exit.
std::vector<FoundConflict> conflicts_of(const Loaded& l, double within, double horizon) {
  const std::vector<FleetReport>& reports = l.data.reports;
  const double now = l.now, end = now + horizon;
  std::vector<FoundConflict> out;
  const bool changes = std::any_of(reports.begin(), reports.end(), [&](const FleetReport& r) {
    return r.m.t > now && r.m.t <= end;
  });
  if (!changes) {
    const auto in = in_force(reports, now);
    std::vector<Id> ids;
    std::vector<Motion2> motions;
    for (const FleetReport& r : in) {
      ids.push_back(r.id);
      motions.push_back(r.m);
    }
    check_conflict_objects<2>(std::span<const Motion2>(motions), now, horizon,
                              [&](std::size_t i) { return "id " + std::to_string(ids[i]); });
    // By index into the reports (sorted by id, one per id), in the order of (id_a, id_b).
    std::vector<std::pair<std::uint64_t, Approach>> found;
    find_conflicts<2>(std::span<const Motion2>(motions), within, now, horizon,
                      [&](std::uint32_t i, std::uint32_t j, const Approach& ap) {
                        if (j < i) std::swap(i, j);
                        found.push_back({std::uint64_t(i) << 32 | j, ap});
                        return true;
                      });
    std::sort(found.begin(), found.end(),
              [](const auto& x, const auto& y) { return x.first < y.first; });
    out.reserve(found.size());
    for (const auto& [key, ap] : found) {
      const std::size_t a = std::size_t(key >> 32), b = std::uint32_t(key);
      out.push_back({{ids[a], ids[b], ap}, motions[a], motions[b]});
    }
    return out;
  }
  const std::vector<Piece> pieces = pieces_during(reports, now, end);
  std::vector<Box2> boxes;
  boxes.reserve(pieces.size());
  for (const Piece& p : pieces) {
    check_conflict_objects<2>(std::span<const Motion2>(&p.m, 1), p.lo, p.hi - p.lo,
                              [&](std::size_t) { return "id " + std::to_string(p.id); });
    boxes.push_back(loci::detail::grown_sweep(p.m, p.lo, p.hi, 0.5 * within));
  }
  const PackedRTree<2> tree = PackedRTree<2>::build(boxes);
  for (std::size_t i = 0; i < pieces.size(); ++i)
    tree.query(boxes[i], [&](Id k, const Box2&) {
      const Piece *p = &pieces[i], *q = &pieces[k];
      if (k <= i || p->id == q->id) return true;
      if (q->id < p->id) std::swap(p, q);
      const double s0 = std::max(p->lo, q->lo), s1 = std::min(p->hi, q->hi);
      if (!(s0 <= s1)) return true;
      // Pieces meeting at one instant where one of them gives way to its object's next report
      // do not overlap (a report and the one before it of another object, made at the same
      // time, were paired at that instant).
      const bool open = (p->open && p->hi == s1) || (q->open && q->hi == s1);
      if (s0 == s1 && open) return true;
      // To the horizon's end as find_conflicts measures it (from now), not a rounded sum.
      const double h = s1 == end ? std::max(0.0, horizon - (s0 - now)) : s1 - s0;
      const auto ap = closest_approach(p->m, q->m, s0, h, within);
      // Within D only at the instant one of them gives way to its next report: not a conflict
      // of these two pieces (that instant is the next report's).
      if (ap && !(open && ap->t_enter >= s1)) out.push_back({{p->id, q->id, *ap}, p->m, q->m});
      return true;
    });
  std::sort(out.begin(), out.end(), [](const FoundConflict& x, const FoundConflict& y) {
    if (x.c.a != y.c.a) return x.c.a < y.c.a;
    if (x.c.b != y.c.b) return x.c.b < y.c.b;
    return x.c.approach.tcpa < y.c.approach.tcpa;
  });
  std::size_t n = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (n > 0 && out[n - 1].c.a == out[i].c.a && out[n - 1].c.b == out[i].c.b) {
      FoundConflict& kept = out[n - 1];
      const double enter = std::min(kept.c.approach.t_enter, out[i].c.approach.t_enter),
                   exit = std::max(kept.c.approach.t_exit, out[i].c.approach.t_exit);
      if (out[i].c.approach.dcpa < kept.c.approach.dcpa) kept = out[i];
      kept.c.approach.t_enter = enter;
      kept.c.approach.t_exit = exit;
    } else {
      out[n++] = out[i];
    }
  }
  out.resize(n);
  return out;
}

struct Hit {
  Id id;
  double t;  // when it is in the window (the first time, for an interval)
  Point2 p;  // where, in the frame
  double distance = 0;
  std::optional<Point2> lonlat;  // AIS: where, as reported, when it has not moved from it
};

// An AIS object's report's own lon/lat when at time t it is where that report put it (at the
// report's time, or at rest): a window's edge through it then holds it exactly, and it is
// shown as reported. nullopt otherwise, and for planar input.
std::optional<Point2> reported_lonlat(const Loaded& l, Id id, const Motion2& m, double t) {
  if (!l.ais() || (t != m.t && (m.v[0] != 0 || m.v[1] != 0))) return std::nullopt;
  const std::vector<FleetReport>& r = l.data.reports;
  const auto it = std::lower_bound(r.begin(), r.end(), std::pair{id, m.t},
                                   [](const FleetReport& a, const std::pair<Id, double>& k) {
                                     return a.id != k.first ? a.id < k.first : a.m.t < k.second;
                                   });
  if (it == r.end() || it->id != id || it->m.t != m.t) return std::nullopt;
  return l.data.lonlat[std::size_t(it - r.begin())];
}

// Whether the lon/lat box holds the point, where longitudes -180 and 180 are one meridian.
bool holds_lonlat(const Box2& box, const Point2& p) {
  if (intersects(box, Box2::of_point(p))) return true;
  const bool on_antimeridian = std::abs(p[0]) == 180;
  return on_antimeridian && intersects(box, Box2::of_point(Point2{-p[0], p[1]}));
}

std::vector<Hit> window_hits(const Loaded& l, const FleetQueryOptions& o) {
  // AIS windows are lon/lat boxes; objects move in the local frame. A position is in the
  // window when its lon/lat is. Over an interval the window is the polygon of its edges in the
  // frame; a window holding the antipode of the frame's centre holds the frame's edge, where
  // the azimuthal projection is singular: there the polygon's edges bound what lies outside
  // the window (`inverted`), and every object is a candidate.
  std::optional<FlatGeometry> poly;
  bool inverted = false;
  Box2 box = o.box;
  if (l.ais()) {
    if (!l.data.frame) return {};
    const LocalFrame& frame = *l.data.frame;
    poly = lonlat_window(frame, o.box);
    const Point2 antipode{frame.lon0() > 0 ? frame.lon0() - 180 : frame.lon0() + 180,
                          -frame.lat0()};
    inverted = holds_lonlat(o.box, antipode);
    if (inverted) {
      box = {{-kMaxCoordinate, -kMaxCoordinate}, {kMaxCoordinate, kMaxCoordinate}};
    } else {
      // The edges are chords of the window's curved edges, which bulge out of them by far less
      // than this margin: the candidates hold every position the lon/lat test may take.
      box = poly->envelope();
      const double pad = 1000 + 1e-3 * std::max(box.extent(0), box.extent(1));
      box = {{box.min[0] - pad, box.min[1] - pad}, {box.max[0] + pad, box.max[1] + pad}};
    }
  }
  auto in_window = [&](const Point2& p) {
    if (!poly) return true;  // planar: the index query was exact
    try {
      return holds_lonlat(o.box, l.data.frame->to_lonlat(p));
    } catch (const Error&) {
      return false;  // beyond the frame's edge: no lon/lat
    }
  };
  std::vector<Hit> hits;
  if (!o.during) {
    const auto now = in_force(l.data.reports, l.now);
    const FleetIndex ix = index_of(now);
    ix.query(MovingWindow<2>::at(box, l.now), [&](Id id, const Motion2& m) {
      const Point2 p = position(m, l.now);
      const auto ll = reported_lonlat(l, id, m, l.now);
      if (ll ? holds_lonlat(o.box, *ll) : in_window(p)) hits.push_back({id, l.now, p, 0, ll});
      return true;
    });
  } else {
    const auto [t1, t2] = *o.during;
    std::optional<IndexedWindow> indexed;
    if (poly) indexed.emplace(*poly);
    const std::vector<Piece> pieces = pieces_during(l.data.reports, t1, t2);
    FleetIndex ix;
    for (std::size_t i = 0; i < pieces.size(); ++i)
      ix.insert(i, pieces[i].m);
    // The index asked with a window a few ulps wider (a superset: the ends of each piece are
    // decided below by their positions, which its roots may miss by as much).
    const Box2 wider = outset(box, 1e-13 * magnitude(box) + 1e-300);
    ix.query(MovingWindow<2>::during(wider, t1, t2), [&](Id i, const Motion2& m) {
      const Piece& pc = pieces[i];
      const LinearSpan s = meets(m, MovingWindow<2>::during(box, pc.lo, pc.hi));
      double t = s.lo;
      if (poly) {
        if (s.empty()) return true;
      } else {
        // The piece's ends as --at tests a time, by the rounded position there (the roots of
        // the linear constraints may fall a few ulps either side of an end: `--during T,T`
        // and `--at T` disagreed on windows through a computed position).
        const auto in_box = [&](double at) {
          return intersects(box, Box2::of_point(position(m, at)));
        };
        if (in_box(pc.lo))
          t = pc.lo;
        else if (pc.lo == pc.hi)
          return true;
        else if (s.empty() && !pc.open && in_box(pc.hi))
          t = pc.hi;
        else if (s.empty())
          return true;
      }
      if (const auto ll = reported_lonlat(l, pc.id, m, pc.lo)) {
        // At the piece's start where its report put it (at the report's time, or at rest all
        // along): in the window by its reported lon/lat, as --at tests it (a window's edge
        // through it holds it); at rest and outside, never in. Moving and outside, the path is
        // tested against the window's chords below, which a position a hair outside a curved
        // edge may meet at the start too.
        if (holds_lonlat(o.box, *ll)) {
          hits.push_back({pc.id, pc.lo, position(m, pc.lo), 0, ll});
          return true;
        }
        if (m.v == Point2{}) return true;
      }
      if (poly && !inverted) {
        const Segment2 path{position(m, pc.lo), position(m, pc.hi)};
        if (!indexed->meets(path)) return true;
        t = indexed->first_time_in(m, pc.lo, pc.hi);
      } else if (poly) {
        // In the window unless strictly inside the polygon of what lies outside it.
        const Segment2 path{position(m, pc.lo), position(m, pc.hi)};
        if (in_window(path.a)) {
          t = pc.lo;
        } else if (const auto at = indexed->first_meet_of_edges(path)) {
          t = pc.lo + (pc.hi - pc.lo) * *at;
        } else {
          return true;
        }
      }
      // Only at the instant its next report takes over: the object is where that one puts it.
      if (pc.open && t >= pc.hi) return true;
      hits.push_back({pc.id, t, position(m, t), 0, reported_lonlat(l, pc.id, m, t)});
      return true;
    });
  }
  // One row per id, its earliest time in the window.
  std::sort(hits.begin(), hits.end(),
            [](const Hit& a, const Hit& b) { return a.id != b.id ? a.id < b.id : a.t < b.t; });
  hits.erase(std::unique(hits.begin(), hits.end(),
                         [](const Hit& a, const Hit& b) { return a.id == b.id; }),
             hits.end());
  return hits;
}

std::vector<Hit> nearest_hits(const Loaded& l, const FleetQueryOptions& o) {
  // Report times lie within 1e150, so only --at can be beyond (the distances would not fit).
  if (!(std::abs(l.now) <= kMaxCoordinate))
    throw InvalidArgument("--at: nearest-n is answered at times within 1e150");
  Point2 q = o.point;
  if (l.ais()) {
    check_lonlat(q, "the point");
    if (!l.data.frame) return {};
    q = l.data.frame->to_local(q[0], q[1]);
  }
  const FleetIndex ix = index_of(in_force(l.data.reports, l.now));
  std::vector<Hit> hits;
  ix.nearest(q, l.now, o.k, [&](Id id, const Motion2& m, double d) {
    hits.push_back({id, l.now, position(m, l.now), d, reported_lonlat(l, id, m, l.now)});
    return true;
  });
  return hits;
}

// "lon,lat" (AIS) or "x,y" of a frame position, for CSV and GeoJSON.
Point2 shown(const Loaded& l, const Point2& p) {
  return l.ais() ? l.data.frame->to_lonlat(p) : p;
}

// The positions hits are shown at, each converted before anything is written: a position
// with no lon/lat (beyond the far side of the earth from the frame's centre) is an error
// before the first row, not after a block of them has reached stdout.
std::vector<Point2> shown_positions(const Loaded& l, const std::vector<Hit>& hits, Format format) {
  std::vector<Point2> shown_at;
  if (format == Format::ids) return shown_at;
  shown_at.reserve(hits.size());
  for (const Hit& h : hits)
    shown_at.push_back(h.lonlat ? *h.lonlat : shown(l, h.p));
  return shown_at;
}

void write_hits(const Loaded& l, const std::vector<Hit>& hits, const std::vector<Point2>& shown_at,
                bool nearest, Format format, std::FILE* out) {
  const bool ais = l.ais();
  detail::BlockWriter w(out);
  std::string& row = w.buf();
  if (format == Format::ids) {
    for (const Hit& h : hits) {
      detail::append_int(row, h.id);
      row += '\n';
      w.row_done();
    }
    w.flush();
    return;
  }
  if (format == Format::csv) {
    row += nearest ? "id,distance" : "id";
    if (nearest && ais) row += ",distance_nm";
    row += ais ? ",t,time_utc,lon,lat\n" : ",t,x,y\n";
    for (const Hit& h : hits) {
      detail::append_int(row, h.id);
      if (nearest) {
        row += ',';
        detail::append_num(row, h.distance);
      }
      if (nearest && ais) row += "," + fixed(h.distance / kNauticalMile, 4);
      row += ',';
      detail::append_num(row, h.t);
      if (ais) row += "," + format_utc(h.t);
      const Point2 p = shown_at[std::size_t(&h - hits.data())];
      row += ',';
      detail::append_nums(row, {p[0], p[1]});
      row += '\n';
      w.row_done();
    }
    w.flush();
    return;
  }
  row += "{\"type\":\"FeatureCollection\",\"features\":[";
  for (std::size_t i = 0; i < hits.size(); ++i) {
    const Hit& h = hits[i];
    const Point2 p = shown_at[i];
    row += i ? ",\n{\"type\":\"Feature\",\"properties\":{\"id\":"
             : "\n{\"type\":\"Feature\",\"properties\":{\"id\":";
    detail::append_int(row, h.id);
    row += ",\"t\":";
    detail::append_num(row, h.t);
    if (ais) row += ",\"time_utc\":\"" + format_utc(h.t) + "\"";
    if (nearest) {
      row += ",\"distance\":";
      detail::append_num(row, h.distance);
    }
    row += "},\"geometry\":{\"type\":\"Point\",\"coordinates\":[";
    detail::append_nums(row, {p[0], p[1]});
    row += "]}}";
    w.row_done();
  }
  row += "\n]}\n";
  w.flush();
}

}  // namespace

FleetRun fleet_query(const FleetQueryOptions& o, std::FILE* fallback) {
  if (o.kind == FleetQueryOptions::Kind::nearest && o.during)
    throw InvalidArgument("--nearest answers at one time (--at), not --during");
  if (o.during && !(o.during->first <= o.during->second))
    throw InvalidArgument("--during T1,T2 needs T1 <= T2");
  refuse_overwriting(o.out_path, o.path, "input fleet");
  const Loaded l = load(o.path, o.at);
  std::vector<Hit> hits;
  if (o.kind == FleetQueryOptions::Kind::nearest)
    hits = nearest_hits(l, o);
  else
    hits = window_hits(l, o);
  const std::vector<Point2> shown_at = shown_positions(l, hits, o.format);
  OutputFile out(o.out_path, fallback);
  write_hits(l, hits, shown_at, o.kind == FleetQueryOptions::Kind::nearest, o.format, out.stream());
  out.commit();
  FleetRun r = run_of(l);
  r.answers = hits.size();
  return r;
}

FleetRun fleet_conflicts(const FleetConflictOptions& o, std::FILE* fallback) {
  check_conflict_query(o.within, o.at.value_or(0), o.horizon);
  if (o.format == Format::ids)
    throw InvalidArgument("conflicts are written as csv or geojson, not ids");
  refuse_overwriting(o.out_path, o.path, "input fleet");
  const Loaded l = load(o.path, o.at);
  const std::vector<FoundConflict> found = conflicts_of(l, o.within, o.horizon);
  const bool ais = l.ais();
  // The two positions of each pair, converted before anything is written (as for queries).
  std::vector<std::pair<Point2, Point2>> at_tcpa;
  at_tcpa.reserve(found.size());
  auto at = [&](Id id, const Motion2& m, double t) {
    const std::optional<Point2> reported = reported_lonlat(l, id, m, t);
    return reported ? *reported : shown(l, position(m, t));
  };
  for (const FoundConflict& fc : found)
    at_tcpa.emplace_back(at(fc.c.a, fc.ma, fc.c.approach.tcpa),
                         at(fc.c.b, fc.mb, fc.c.approach.tcpa));
  OutputFile out(o.out_path, fallback);
  std::FILE* f = out.stream();
  const bool csv = o.format == Format::csv;
  detail::BlockWriter w(f);
  std::string& row = w.buf();
  if (csv)
    row += ais ? "id_a,id_b,tcpa,dcpa,t_enter,t_exit,dcpa_nm,tcpa_utc,tcpa_min,t_enter_utc,"
                 "t_exit_utc,lon_a,lat_a,lon_b,lat_b\n"
               : "id_a,id_b,tcpa,dcpa,t_enter,t_exit,x_a,y_a,x_b,y_b\n";
  else
    row += "{\"type\":\"FeatureCollection\",\"features\":[";
  for (std::size_t i = 0; i < found.size(); ++i) {
    const Conflict& c = found[i].c;
    const Approach& ap = c.approach;
    const auto& [a, b] = at_tcpa[i];
    if (!csv)
      row += i ? ",\n{\"type\":\"Feature\",\"properties\":{"
               : "\n{\"type\":\"Feature\",\"properties\":{";
    row += csv ? "" : "\"id_a\":";
    detail::append_int(row, c.a);
    row += csv ? "," : ",\"id_b\":";
    detail::append_int(row, c.b);
    const char* const names[] = {",\"tcpa\":", ",\"dcpa\":", ",\"t_enter\":", ",\"t_exit\":"};
    const double values[] = {ap.tcpa, ap.dcpa, ap.t_enter, ap.t_exit};
    for (int k = 0; k < 4; ++k) {
      row += csv ? "," : names[k];
      detail::append_num(row, values[k]);
    }
    if (csv) {
      if (ais)
        row += "," + fixed(ap.dcpa / kNauticalMile, 4) + "," + format_utc(ap.tcpa) + "," +
               fixed((ap.tcpa - l.now) / 60, 2) + "," + format_utc(ap.t_enter) + "," +
               format_utc(ap.t_exit);
      row += ',';
      detail::append_nums(row, {a[0], a[1], b[0], b[1]});
      row += '\n';
    } else {
      if (ais)
        row += ",\"dcpa_nm\":" + fixed(ap.dcpa / kNauticalMile, 4) + ",\"tcpa_utc\":\"" +
               format_utc(ap.tcpa) + "\",\"tcpa_min\":" + fixed((ap.tcpa - l.now) / 60, 2);
      row += "},\"geometry\":{\"type\":\"LineString\",\"coordinates\":[[";
      detail::append_nums(row, {a[0], a[1]});
      row += "],[";
      detail::append_nums(row, {b[0], b[1]});
      row += "]]}}";
    }
    w.row_done();
  }
  if (!csv) row += "\n]}\n";
  w.flush();
  out.commit();
  FleetRun r = run_of(l);
  r.answers = found.size();
  return r;
}

// ---- generate ----

FleetGenerateOptions::Distribution parse_distribution(const std::string& name) {
  if (name == "uniform") return FleetGenerateOptions::Distribution::uniform;
  if (name == "clustered") return FleetGenerateOptions::Distribution::clustered;
  if (name == "lanes") return FleetGenerateOptions::Distribution::lanes;
  throw InvalidArgument("unknown distribution '" + name.substr(0, 40) +
                        "' (choose uniform, clustered or lanes)");
}

FleetFormat parse_fleet_format(const std::string& name) {
  if (name == "csv") return FleetFormat::planar;
  if (name == "ais") return FleetFormat::ais;
  throw InvalidArgument("unknown fleet format '" + name.substr(0, 40) + "' (choose csv or ais)");
}

std::pair<double, double> parse_range(const std::string& text, const char* what) {
  const std::size_t comma = text.find(',');
  auto bad = [&] {
    return InvalidArgument(std::string("bad ") + what + " '" + text.substr(0, 40) +
                           "': expected A,B with A <= B");
  };
  if (comma == std::string::npos) throw bad();
  double a = 0, b = 0;
  try {
    a = parse_time(text.substr(0, comma));
    b = parse_time(text.substr(comma + 1));
  } catch (const Error&) {
    throw bad();
  }
  if (!(a <= b)) throw bad();
  return {a, b};
}

namespace {

// A place and a direction for a generated object, in the generation frame.
struct Start {
  Point2 p;
  double heading;  // radians, counterclockwise from +x
};

// Segments of a line layer (lon/lat for AIS: then in the frame), with their lengths, and the
// polygons of the layer so that lane positions can stay off them.
struct Lanes {
  std::vector<Segment2> segments;
  std::vector<double> cumulative;  // running length
  std::vector<FlatGeometry> areas;

  Lanes(const std::string& path, const LocalFrame* frame) {
    auto ol = detail::open_layer(path, "");
    if (frame) detail::check_lonlat_system(path, detail::system_of(*ol.layer));
    auto map = [&](const Point2& p) { return frame ? frame->to_local(p[0], p[1]) : p; };
    for (auto& f : *ol.layer) {
      const OGRGeometry* g = f->GetGeometryRef();
      if (!g) continue;
      detail::for_each_curve(g, [&](const OGRSimpleCurve& c, bool, std::uint32_t) {
        for (int i = 0; i + 1 < c.getNumPoints(); ++i) {
          const Segment2 s{map({c.getX(i), c.getY(i)}), map({c.getX(i + 1), c.getY(i + 1)})};
          const double len = std::hypot(s.b[0] - s.a[0], s.b[1] - s.a[1]);
          if (!(len > 0)) continue;
          segments.push_back(s);
          cumulative.push_back((cumulative.empty() ? 0 : cumulative.back()) + len);
        }
      });
      if (OGR_GT_Flatten(g->getGeometryType()) == wkbPolygon ||
          OGR_GT_Flatten(g->getGeometryType()) == wkbMultiPolygon) {
        FlatGeometry fg = detail::flatten(g, path);
        for (Point2& p : fg.points)
          p = map(p);
        areas.push_back(std::move(fg));
      }
    }
    if (segments.empty()) throw Error(path + ": has no linework to lay lanes along");
  }

  bool on_land(const Point2& p) const {
    for (const FlatGeometry& a : areas)
      if (meets(a, Box2::of_point(p))) return true;
    return false;
  }
};

}  // namespace

std::size_t fleet_generate(const FleetGenerateOptions& o, std::FILE* fallback) {
  using Dist = FleetGenerateOptions::Distribution;
  const bool ais = o.format == FleetFormat::ais;
  if (o.count == 0) throw InvalidArgument("--count must be >= 1");
  if (o.reports == 0) throw InvalidArgument("reports per object must be >= 1");
  if (!(o.interval > 0) || !std::isfinite(o.interval))
    throw InvalidArgument("the interval between reports must be > 0");
  if (ais && o.interval < 1)  // dates are written to the second
    throw InvalidArgument("AIS dates are whole seconds: the interval between reports must be >= 1");
  if (o.distribution == Dist::lanes && o.along.empty())
    throw InvalidArgument("--distribution lanes needs --along LAYER");
  refuse_overwriting(o.out_path, o.along);
  Box2 bbox = o.bbox.value_or(ais ? Box2{{8, 54.5}, {13, 58}} : Box2{{0, 0}, {1e4, 1e4}});
  if (!ais && !o.bbox && o.distribution == Dist::lanes) {
    // Planar lanes along a layer: by default, the layer's extent and a margin for the offsets.
    auto ol = detail::open_layer(o.along, "");
    OGREnvelope e;
    if (ol.layer->GetExtent(&e, TRUE) != OGRERR_NONE)
      throw Error(o.along + ": has no extent to lay lanes in");
    const double margin = 0.05 * std::max(e.MaxX - e.MinX, e.MaxY - e.MinY);
    bbox = {{e.MinX - margin, e.MinY - margin}, {e.MaxX + margin, e.MaxY + margin}};
  }
  if (ais) {
    check_lonlat(bbox.min, "--bbox");
    check_lonlat(bbox.max, "--bbox");
  }
  const auto [vmin, vmax] = o.speed.value_or(ais ? std::pair{5.0, 20.0} : std::pair{1.0, 10.0});
  if (!(vmin >= 0) || (ais && vmax > 102.2))
    throw InvalidArgument(ais ? "--speed must be in [0, 102.2] knots" : "--speed must be >= 0");
  const double t_last = o.time.value_or(ais ? 1672531200.0 : 0.0);

  // Generation happens in a planar frame: the input's own for CSV, a local frame for AIS.
  std::optional<LocalFrame> frame;
  Box2 area = bbox;
  if (ais) {
    frame.emplace(0.5 * (bbox.min[0] + bbox.max[0]), 0.5 * (bbox.min[1] + bbox.max[1]));
    area = Box2::of_point(frame->to_local(bbox.min[0], bbox.min[1]));
    for (const Point2& c :
         {Point2{bbox.max[0], bbox.min[1]}, bbox.max, Point2{bbox.min[0], bbox.max[1]},
          Point2{0.5 * (bbox.min[0] + bbox.max[0]), bbox.min[1]},
          Point2{0.5 * (bbox.min[0] + bbox.max[0]), bbox.max[1]}})
      area.expand(frame->to_local(c[0], c[1]));
  }
  auto inside = [&](const Point2& p) {
    if (!ais) return contains(bbox, Box2::of_point(p));
    const Point2 ll = frame->to_lonlat(p);
    return contains(bbox, Box2::of_point(ll));
  };
  const double size = std::max(area.max[0] - area.min[0], area.max[1] - area.min[1]);

  std::mt19937_64 rng(o.seed);
  std::uniform_real_distribution<double> unit(0, 1);
  auto uniform_in = [&](const Box2& b) {
    return Point2{b.min[0] + (b.max[0] - b.min[0]) * unit(rng),
                  b.min[1] + (b.max[1] - b.min[1]) * unit(rng)};
  };
  // Uniform over the area: for AIS over the box's surface on the sphere (longitude uniform,
  // the sine of latitude uniform), not over the local frame's image of it, which a box wide in
  // longitude distorts (and one spanning all longitudes collapses onto a meridian).
  auto uniform_point = [&]() {
    if (!ais) return uniform_in(area);
    constexpr double kDeg = std::numbers::pi / 180;
    const double lon = bbox.min[0] + (bbox.max[0] - bbox.min[0]) * unit(rng);
    const double s0 = std::sin(bbox.min[1] * kDeg), s1 = std::sin(bbox.max[1] * kDeg);
    const double lat = std::asin(std::clamp(s0 + (s1 - s0) * unit(rng), -1.0, 1.0)) / kDeg;
    return frame->to_local(lon, lat);
  };
  std::optional<Lanes> lanes;
  if (o.distribution == Dist::lanes) lanes.emplace(o.along, ais ? &*frame : nullptr);
  std::vector<Point2> centres;
  for (int i = 0; i < 8; ++i)
    centres.push_back(uniform_point());
  std::normal_distribution<double> spread(0, size / 40);

  auto place = [&]() -> std::optional<Start> {
    for (int attempt = 0; attempt < 1000; ++attempt) {
      Start s{};
      s.heading = 2 * std::numbers::pi * unit(rng);
      if (o.distribution == Dist::uniform) {
        s.p = uniform_point();
      } else if (o.distribution == Dist::clustered) {
        const Point2 c = centres[std::size_t(unit(rng) * double(centres.size())) % centres.size()];
        s.p = {c[0] + spread(rng), c[1] + spread(rng)};
      } else {
        const double at = unit(rng) * lanes->cumulative.back();
        const std::size_t i =
            std::size_t(std::lower_bound(lanes->cumulative.begin(), lanes->cumulative.end(), at) -
                        lanes->cumulative.begin());
        const Segment2& seg = lanes->segments[std::min(i, lanes->segments.size() - 1)];
        const double dx = seg.b[0] - seg.a[0], dy = seg.b[1] - seg.a[1];
        const double len = std::hypot(dx, dy), f = unit(rng);
        // Off the line by 1% to 4% of the area's size (2 to 8 km off a coast for AIS), on
        // the side away from the layer's polygons; the lane runs either way along the line.
        const double off = (ais ? 2000 + 6000 * unit(rng) : size * (0.01 + 0.03 * unit(rng)));
        const double side = unit(rng) < 0.5 ? 1 : -1;
        s.p = {seg.a[0] + dx * f - side * dy / len * off,
               seg.a[1] + dy * f + side * dx / len * off};
        if (lanes->on_land(s.p)) {
          s.p = {seg.a[0] + dx * f + side * dy / len * off,
                 seg.a[1] + dy * f - side * dx / len * off};
          if (lanes->on_land(s.p)) continue;
        }
        s.heading =
            std::atan2(dy, dx) + (unit(rng) < 0.5 ? 0 : std::numbers::pi) + 0.1 * (unit(rng) - 0.5);
      }
      if (inside(s.p)) return s;
    }
    return std::nullopt;
  };

  struct Out {
    double t;
    Id id;
    Point2 p, v;
  };
  std::vector<Out> rows;
  // Every report must read back as written: distinct times for one object, times within
  // +-1e150 (AIS: dates of four-digit years), positions and velocities within +-1e150.
  constexpr double kYear0 = -62167219200, kYear10000 = 253402300800;  // 0000-01-01, 10000-01-01
  auto check_generated = [&](double t, const Point2& p, const Point2& v) {
    if (!(std::abs(t) <= kMaxCoordinate) || (ais && !(t + 0.5 >= kYear0 && t + 0.5 < kYear10000)))
      throw InvalidArgument(ais ? "--time and --interval give report dates outside years 0 to 9999"
                                : "--time and --interval give report times beyond 1e150");
    if (!(t - o.interval < t))
      throw InvalidArgument(
          "--interval is too small for --time: an object's reports would share a time");
    if (!within_coordinate_range(p) || !within_coordinate_range(v))
      throw InvalidArgument(
          "reports would lie beyond 1e150: lower --speed, --interval or --reports");
  };
  // Placing an object and writing its reports count alike.
  ProgressTicker ticker(o.progress, double(o.count) * double(1 + o.reports));
  // In lanes, an object's course stays off the layer's polygons: at its reports, along each
  // report's leg to the next (four points a leg) and from its last report on to t_last; else
  // it is placed again. (A track runs from the last report back.)
  auto off_land = [&](const std::vector<Out>& track) {
    if (!lanes) return true;
    for (std::size_t r = 0; r < track.size(); ++r) {
      const Motion2 m{track[r].t, track[r].p, track[r].v};
      const double until = r == 0 ? t_last : track[r - 1].t;
      for (int k = 0; k <= (r == 0 ? 4 : 3); ++k)
        if (lanes->on_land(position(m, m.t + (until - m.t) * k / 4))) return false;
    }
    return true;
  };
  std::vector<Out> track;
  for (std::size_t n = 0; n < o.count; ++n) {
    ticker.tick(double(n + 1));
    const double speed = (vmin + (vmax - vmin) * unit(rng)) * (ais ? kKnot : 1.0);
    const Id id = ais ? Id(219000000 + n) : Id(n + 1);
    for (int attempt = 0;; ++attempt) {
      const auto s = attempt < 1000 ? place() : std::nullopt;
      if (!s)
        throw Error("cannot place object " + std::to_string(n + 1) +
                    (lanes ? " inside --bbox with its course off the --along layer's polygons"
                           : " inside --bbox (the clusters may lie outside it)"));
      // The last report is at (about) t_last at the placed position; earlier ones trace back
      // along the course, turning a little between reports.
      double heading = s->heading;
      Point2 p = s->p;
      double t = t_last - std::floor(o.interval * unit(rng) * 0.5);
      track.clear();
      for (std::size_t r = 0; r < o.reports; ++r) {
        const Point2 v{speed * std::cos(heading), speed * std::sin(heading)};
        check_generated(t, p, v);
        track.push_back({t, id, p, v});
        heading += 0.05 * (unit(rng) - 0.5);
        const Point2 back{speed * std::cos(heading), speed * std::sin(heading)};
        p = {p[0] - back[0] * o.interval, p[1] - back[1] * o.interval};
        t -= o.interval;
      }
      if (off_land(track)) break;
    }
    rows.insert(rows.end(), track.begin(), track.end());
  }
  std::sort(rows.begin(), rows.end(),
            [](const Out& a, const Out& b) { return a.t != b.t ? a.t < b.t : a.id < b.id; });

  // Each report's lon/lat and course, before anything is written: one beyond the far side of
  // the earth from the frame's centre (fast courses over long intervals) is an error before
  // the first row reaches stdout.
  struct Shown {
    Point2 ll;
    double speed, cog;
  };
  std::vector<Shown> shown_as;
  if (ais) {
    shown_as.reserve(rows.size());
    try {
      for (const Out& r : rows) {
        const auto [speed, cog] = frame->course(r.p, r.v);
        shown_as.push_back({frame->to_lonlat(r.p), speed, cog});
      }
    } catch (const Error&) {
      throw InvalidArgument(
          "a generated course reaches beyond the far side of the earth from the box's centre, "
          "where it has no longitude and latitude: ask for a lower --speed, fewer --reports or "
          "a shorter --interval");
    }
  }
  OutputFile out(o.out_path, fallback);
  std::FILE* f = out.stream();
  std::size_t written = 0;
  if (ais) {
    std::fprintf(f,
                 "MMSI,BaseDateTime,LAT,LON,SOG,COG,Heading,VesselName,IMO,CallSign,VesselType,"
                 "Status,Length,Width,Draft,Cargo,TransceiverClass\n");
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const Out& r = rows[k];
      ticker.tick(double(o.count + ++written));
      const Point2 ll = shown_as[k].ll;
      const double speed = shown_as[k].speed;
      double cog = std::round(shown_as[k].cog * 10) / 10;
      if (cog >= 360) cog -= 360;
      std::fprintf(f, "%llu,%s,%.5f,%.5f,%.1f,%.1f,%d,SYNTHETIC %llu,,,70,0,120,20,7.5,70,A\n",
                   static_cast<unsigned long long>(r.id), format_utc(r.t).substr(0, 19).c_str(),
                   ll[1], ll[0], speed / kKnot, cog, int(std::lround(cog)) % 360,
                   static_cast<unsigned long long>(r.id - 219000000));
    }
  } else {
    std::fprintf(f, "id,t,x,y,vx,vy\n");
    for (const Out& r : rows) {
      ticker.tick(double(o.count + ++written));
      std::fprintf(f, "%llu,%s,%s,%s,%s,%s\n", static_cast<unsigned long long>(r.id),
                   detail::shortest(r.t).c_str(), detail::shortest(r.p[0]).c_str(),
                   detail::shortest(r.p[1]).c_str(), detail::shortest(r.v[0]).c_str(),
                   detail::shortest(r.v[1]).c_str());
    }
  }
  out.commit();
  return rows.size();
}

// ---- simulate ----

FleetSimulateReport fleet_simulate(const FleetSimulateOptions& o, std::FILE* fallback) {
  check_conflict_query(o.within, 0, o.horizon);
  if (!(o.update_fraction >= 0 && o.update_fraction <= 1))
    throw InvalidArgument("--update-fraction must be in [0, 1]");
  if (!(o.tick > 0) || !std::isfinite(o.tick)) throw InvalidArgument("--tick must be > 0");
  const double slack = o.slack.value_or(o.horizon / 4);
  if (!(slack >= 0) || !std::isfinite(slack)) throw InvalidArgument("--slack must be >= 0");
  refuse_overwriting(o.out_path, o.path, "input fleet");
  const Loaded l = load(o.path, std::nullopt);
  const auto start = in_force(l.data.reports, l.now);
  std::vector<Id> ids;
  std::vector<Motion2> motions;
  ConflictMonitor<2> monitor(o.within, o.horizon, slack);
  for (const FleetReport& r : start) {
    ids.push_back(r.id);
    motions.push_back(r.m);
    if (!o.from_scratch) monitor.report(r.id, r.m);
  }
  // The simulated reports turn but keep their speed: every object must stay within +-1e150
  // until the last tick's horizon whichever way it turns.
  const double span = o.tick * double(o.ticks) + o.horizon;
  if (!(std::abs(l.now + span) <= kMaxCoordinate))
    throw InvalidArgument("--ticks x --tick + --horizon carry the simulation's clock beyond 1e150");
  // Each tick must move the clock: a tick within rounding of the clock's times would run every
  // tick at one time (two units in the last place of the latest time, so that no two ticks
  // round together).
  const double latest = std::max(std::abs(l.now), std::abs(l.now + o.tick * double(o.ticks)));
  if (o.ticks > 0 &&
      !(o.tick >= 2 * (std::nextafter(latest, std::numeric_limits<double>::infinity()) - latest)))
    throw InvalidArgument("--tick " + detail::shortest(o.tick) + " is too small for the clock at " +
                          detail::shortest(l.now) + ": the ticks would not advance it");
  for (std::size_t i = 0; i < motions.size(); ++i) {
    const Motion2& m = motions[i];
    const Point2 p = position(m, l.now);
    const double reach = std::hypot(m.v[0], m.v[1]) * span;
    if (!(std::max(std::abs(p[0]), std::abs(p[1])) + reach <= kMaxCoordinate))
      throw InvalidArgument("id " + std::to_string(ids[i]) +
                            " would move beyond 1e150 during the simulation (--ticks x --tick "
                            "+ --horizon = " +
                            detail::shortest(span) + ")");
  }
  FleetIndex ix = index_of(start);
  FleetSimulateReport rep;
  rep.run = run_of(l);
  rep.objects = ids.size();
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> turn(0, 0.05);
  const std::size_t per_tick =
      ids.empty() || o.update_fraction == 0
          ? 0
          : std::max<std::size_t>(
                1, std::size_t(std::llround(o.update_fraction * double(ids.size()))));
  OutputFile out(o.out_path, fallback);
  std::FILE* f = out.stream();
  std::fprintf(f, "tick,t,updates,update_ms,conflict_ms,pairs,full\n");
  ProgressTicker ticker(o.progress, double(o.ticks));
  std::size_t next = 0;  // round robin: each tick the next per_tick objects report
  double total_update = 0, total_conflict = 0, total_pairs = 0;
  for (std::size_t tick = 1; tick <= o.ticks; ++tick) {
    const double t = l.now + o.tick * double(tick);
    const auto t0 = std::chrono::steady_clock::now();
    for (std::size_t u = 0; u < per_tick; ++u, ++next) {
      const std::size_t i = next % ids.size();
      Motion2 m = motions[i];
      const Point2 p = position(m, t);
      const double a = turn(rng), c = std::cos(a), s = std::sin(a);
      m = {t, p, {m.v[0] * c - m.v[1] * s, m.v[0] * s + m.v[1] * c}};
      motions[i] = m;
      ix.update(ids[i], m);
      if (!o.from_scratch) monitor.report(ids[i], m);
    }
    const double update_ms = 1e3 * seconds_since(t0);
    const auto t1 = std::chrono::steady_clock::now();
    std::size_t pairs = 0;
    bool full = true;
    if (o.from_scratch) {
      // Counted as the monitor's pairs are below: listed, not collected and sorted.
      find_conflicts<2>(
          std::span<const Motion2>(motions), o.within, t, o.horizon,
          [&](std::uint32_t, std::uint32_t, const Approach&) { return ++pairs, true; });
    } else {
      const std::size_t before = monitor.full_computations();
      monitor.refresh(t);
      monitor.conflicts([&](Id, Id, const Approach&) { return ++pairs, true; });
      full = monitor.full_computations() != before;
    }
    const double conflict_ms = 1e3 * seconds_since(t1);
    std::fprintf(f, "%zu,%s,%zu,%.3f,%.3f,%zu,%d\n", tick, detail::shortest(t).c_str(), per_tick,
                 update_ms, conflict_ms, pairs, int(full));
    total_update += update_ms;
    total_conflict += conflict_ms;
    total_pairs += double(pairs);
    ticker.tick(double(tick));
  }
  out.commit();
  if (o.ticks) {
    rep.mean_update_ms = total_update / double(o.ticks);
    rep.mean_conflict_ms = total_conflict / double(o.ticks);
    rep.mean_pairs = total_pairs / double(o.ticks);
  }
  return rep;
}

FleetDrawReport fleet_draw(const FleetDrawOptions& o, std::FILE* fallback) {
  if (o.within.has_value() != o.horizon.has_value())
    throw InvalidArgument("conflicts are drawn with both --within and --horizon, or neither");
  if (o.within) check_conflict_query(*o.within, 0, *o.horizon);
  if (o.arrows && !(std::isfinite(*o.arrows) && *o.arrows >= 0))
    throw InvalidArgument("the arrows' time must be a finite number >= 0");
  if (!o.over.empty()) refuse_overwriting(o.out_path, o.over);
  refuse_overwriting(o.out_path, o.path, "input fleet");
  const Loaded l = load(o.path, o.at);
  const auto now = in_force(l.data.reports, l.now);
  if (now.empty()) throw Error(o.path + ": no object has reported by then; nothing to draw");
  const double ahead = o.arrows.value_or(o.horizon.value_or(60));
  std::vector<Id> ids;
  std::vector<Motion2> motions;
  for (const FleetReport& r : now) {
    ids.push_back(r.id);
    motions.push_back(r.m);
  }
  std::vector<FoundConflict> found;
  if (o.within) found = conflicts_of(l, *o.within, *o.horizon);
  std::vector<Point2> at(motions.size()), to(motions.size());
  Box2 world = Box2::empty();
  for (std::size_t i = 0; i < motions.size(); ++i) {
    at[i] = shown(l, position(motions[i], l.now));
    to[i] = shown(l, position(motions[i], l.now + ahead));
    world.expand(at[i]);
    world.expand(to[i]);
  }
  // The pairs' positions at their closest approach are drawn too (they may lie beyond the
  // arrows: a turn reported later, a closest approach beyond the arrows' time).
  std::vector<std::pair<Point2, Point2>> closest(found.size());
  for (std::size_t i = 0; i < found.size(); ++i) {
    const FoundConflict& fc = found[i];
    closest[i] = {shown(l, position(fc.ma, fc.c.approach.tcpa)),
                  shown(l, position(fc.mb, fc.c.approach.tcpa))};
    world.expand(closest[i].first);
    world.expand(closest[i].second);
  }
  const detail::Frame f = detail::frame_of(detail::drawn_world(world), o.width);
  std::vector<bool> conflicting(ids.size(), false);
  auto index_of = [&](Id id) {
    return std::size_t(std::lower_bound(ids.begin(), ids.end(), id) - ids.begin());
  };
  // An object that first reports after now is in no dot (it is not there yet).
  const auto mark = [&](Id id) {
    const std::size_t i = index_of(id);
    if (i < ids.size() && ids[i] == id) conflicting[i] = true;
  };
  for (const FoundConflict& fc : found)
    mark(fc.c.a), mark(fc.c.b);

  // The layer under the fleet is read (and refused, when it is) before anything is written.
  std::string linework;
  if (!o.over.empty()) {
    char* text = nullptr;
    std::size_t size = 0;
    std::FILE* mem = ::open_memstream(&text, &size);
    if (!mem) throw std::bad_alloc();
    try {
      detail::write_linework(mem, f, o.over, o.over_layer, l.ais());
    } catch (...) {
      std::fclose(mem);
      std::free(text);
      throw;
    }
    const bool written = std::fclose(mem) == 0;
    if (written) linework.assign(text, size);
    std::free(text);
    if (!written) throw std::bad_alloc();
  }
  OutputFile out(o.out_path, fallback);
  std::FILE* svg = out.stream();
  detail::write_svg_head(svg, f);
  std::fwrite(linework.data(), 1, linework.size(), svg);
  std::fprintf(svg, "<g stroke=\"#2b6cb0\" stroke-width=\"0.8\" fill=\"none\">\n");
  for (std::size_t i = 0; i < at.size(); ++i)
    std::fprintf(svg, "<path d=\"M%.1f %.1fL%.1f %.1f\"/>\n", f.x(at[i][0]), f.y(at[i][1]),
                 f.x(to[i][0]), f.y(to[i][1]));
  std::fprintf(svg, "</g>\n");
  for (const bool red : {false, true}) {
    std::fprintf(svg, "<g fill=\"%s\">\n", red ? "#d62728" : "#1a365d");
    for (std::size_t i = 0; i < at.size(); ++i)
      if (conflicting[i] == red)
        std::fprintf(
            svg, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"%.1f\"><title>%llu</title></circle>\n",
            f.x(at[i][0]), f.y(at[i][1]), red ? 2.5 : 1.8, static_cast<unsigned long long>(ids[i]));
    std::fprintf(svg, "</g>\n");
  }
  std::fprintf(svg, "<g stroke=\"#d62728\" stroke-width=\"1.2\" stroke-linecap=\"round\">\n");
  for (std::size_t i = 0; i < found.size(); ++i) {
    const Conflict& c = found[i].c;
    const auto& [a, b] = closest[i];
    const double x1 = f.x(a[0]), y1 = f.y(a[1]), x2 = f.x(b[0]), y2 = f.y(b[1]);
    const std::string title = std::to_string(c.a) + " " + std::to_string(c.b) + ": dcpa " +
                              detail::shortest(c.approach.dcpa) + " at " +
                              detail::shortest(c.approach.tcpa);
    // Closer than a pixel: a dot (a line that short, drawn round-capped and wide).
    std::fprintf(svg,
                 "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\"%s><title>%s</title>"
                 "</line>\n",
                 x1, y1, x2, y2, std::hypot(x2 - x1, y2 - y1) < 1 ? " stroke-width=\"5\"" : "",
                 title.c_str());
  }
  std::fprintf(svg, "</g>\n</svg>\n");
  out.commit();
  FleetDrawReport r;
  r.run = run_of(l);
  r.objects = at.size();
  r.pairs = found.size();
  r.run.answers = found.size();
  return r;
}

}  // namespace loci::io
