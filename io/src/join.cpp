// Spatial joins of two layers; see join.hpp.
#include "loci/io/join.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <span>

#include "block_writer.hpp"
#include "gdal_layer.hpp"
#include "loci/geom/error.hpp"
#include "loci/index/packed_rtree.hpp"
#include "loci/index/sweep_join.hpp"
#include "loci/io/atomic_file.hpp"
#include "loci/io/exact.hpp"
#include "shapefile_polygons.hpp"

namespace loci::io {

JoinLayer::JoinLayer(JoinLayer&&) noexcept = default;
JoinLayer::~JoinLayer() = default;

const PreparedGeometry& JoinLayer::prepared(std::size_t i) const {
  if (prepared_.size() != geoms.size()) prepared_.resize(geoms.size());
  if (!prepared_[i]) prepared_[i] = std::make_unique<PreparedGeometry>(geoms[i]);
  return *prepared_[i];
}

JoinLayer read_join_layer(const std::string& path, const std::string& name) {
  JoinLayer out;
  auto ol = detail::open_layer(path, name);
  out.path = path;
  out.system = detail::system_of(*ol.layer);
  // A shapefile's polygons of many rings are built from its records (GDAL would sort their
  // rings all against all): GDAL then reads the features in order without geometry, and the
  // other geometries by FID through a second handle.
  detail::ShapefilePolygons polygons(path, *ol.layer);
  std::optional<detail::OpenLayer> by_fid;
  if (polygons.active()) {
    by_fid = detail::open_layer(path, name);
    const char* no_geometry[] = {"OGR_GEOMETRY", nullptr};
    if (ol.layer->SetIgnoredFields(no_geometry) != OGRERR_NONE) by_fid.reset();
  }
  const detail::ReadCheck check(path);
  ol.layer->ResetReading();
  for (auto& f : *ol.layer) {
    check.feature(f->GetFID());
    std::unique_ptr<OGRGeometry> built;
    OGRFeatureUniquePtr whole;
    const OGRGeometry* g = f->GetGeometryRef();
    if (by_fid) {
      built = polygons.read(f->GetFID());
      if (!built) whole = detail::read_feature(*by_fid->layer, f->GetFID(), path);
      g = built ? built.get() : whole ? whole->GetGeometryRef() : nullptr;
    }
    FlatGeometry flat = detail::flatten(g, detail::where(path, f->GetFID()));
    if (flat.empty()) continue;
    out.boxes.push_back(flat.envelope());
    out.fids.push_back(f->GetFID());
    out.geoms.push_back(std::move(flat));
  }
  check.finish();
  return out;
}

void parse_join_predicate(const std::string& text, JoinOptions& o) {
  if (text == "intersects" || text == "contains" || text == "within") {
    o.predicate = text == "intersects" ? JoinPredicate::intersects
                  : text == "contains" ? JoinPredicate::contains
                                       : JoinPredicate::within;
    return;
  }
  if (text.rfind("dwithin:", 0) == 0) {
    const std::string d = text.substr(8);
    char* end = nullptr;
    const double v = std::strtod(d.c_str(), &end);
    if (!d.empty() && end == d.c_str() + d.size() && std::isfinite(v) && v >= 0) {
      o.predicate = JoinPredicate::dwithin;
      o.distance = v;
      return;
    }
    throw InvalidArgument("dwithin needs a finite distance >= 0, as in dwithin:2.5");
  }
  throw InvalidArgument("unknown predicate '" + text +
                        "' (choose intersects, contains, within or dwithin:D)");
}

namespace {

// The distance between two closed boxes (0 when they meet).
double box_distance(const Box2& a, const Box2& b) {
  const double dx = std::max({0.0, a.min[0] - b.max[0], b.min[0] - a.max[0]});
  const double dy = std::max({0.0, a.min[1] - b.max[1], b.min[1] - a.max[1]});
  return std::hypot(dx, dy);
}

// The exact distance of two geometries, bounded from above by the distance of their first
// points.
double exact_distance(const PreparedGeometry& a, const PreparedGeometry& b) {
  const Point2& p = a.geometry().points[0];
  const Point2& q = b.geometry().points[0];
  const double bound =
      std::nextafter(std::hypot(p[0] - q[0], p[1] - q[1]), std::numeric_limits<double>::infinity());
  return distance(a, b, bound);
}

std::vector<JoinRow> closest_pair(const JoinLayer& left, const JoinLayer& right, bool self,
                                  const Progress& progress) {
  std::vector<JoinRow> rows;
  if (left.fids.empty() || right.fids.empty() || (self && left.fids.size() < 2)) return rows;
  // An upper bound: each left feature with the right one whose envelope is nearest its centre.
  PackedRTree2::Builder builder(right.boxes.size());
  for (const Box2& b : right.boxes)
    builder.add(b);
  const PackedRTree2 tree = std::move(builder).finish();
  double bound = std::numeric_limits<double>::infinity();
  JoinRow best{-1, -1, bound};
  auto offer = [&](std::size_t i, std::size_t j, double d) {
    const JoinRow r{left.fids[i], right.fids[j], d};
    if (d < best.distance || (d == best.distance && r < best)) best = r;
    bound = std::min(bound, d);
  };
  for (std::size_t i = 0; i < left.boxes.size(); ++i) {
    const Box2& b = left.boxes[i];
    const Point2 c{(b.min[0] + b.max[0]) / 2, (b.min[1] + b.max[1]) / 2};
    tree.browse(c, [&](Id j, const Box2&, double) {
      if (self && j == i) return true;
      offer(i, j, exact_distance(left.prepared(i), right.prepared(j)));
      return false;
    });
  }
  // Every pair whose envelopes lie within the bound, nearest envelopes first.
  std::vector<Box2> grown(left.boxes.size());
  for (std::size_t i = 0; i < grown.size(); ++i)
    grown[i] = outset(left.boxes[i], bound);
  // In order of envelope distance, then of the pair's FIDs: a candidate no nearer than the
  // best so far can only tie it, and a tie goes to the smaller pair, which came first.
  struct Candidate {
    double box_distance;
    JoinRow pair;
    Id i, j;
  };
  std::vector<Candidate> candidates;
  join(std::span<const Box2>(grown), std::span<const Box2>(right.boxes), [&](Id i, Id j) {
    if (!(self && i == j))
      candidates.push_back(
          {box_distance(left.boxes[i], right.boxes[j]), {left.fids[i], right.fids[j], 0}, i, j});
    return true;
  });
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.box_distance != b.box_distance ? a.box_distance < b.box_distance : a.pair < b.pair;
  });
  ProgressTicker ticker(progress, double(candidates.size()));
  std::size_t done = 0;
  for (const Candidate& c : candidates) {
    if (c.box_distance > bound || (c.box_distance == bound && !(c.pair < best))) break;
    if (auto d = distance_within(left.prepared(c.i), right.prepared(c.j), bound))
      offer(c.i, c.j, *d);
    ticker.tick(double(++done));
  }
  rows.push_back(best);
  return rows;
}

}  // namespace

std::vector<JoinRow> join_layers(const JoinOptions& o) {
  // A layer joined with itself (however its path is spelled, and by name or as the default
  // first layer) is read once, and no feature is paired with itself.
  const bool self = detail::same_layer(o.left_path, o.left_name, o.right_path, o.right_name);
  const JoinLayer left = read_join_layer(o.left_path, o.left_name);
  if (self) return join_layers(left, nullptr, o.predicate, o.distance, o.progress);
  const JoinLayer right = read_join_layer(o.right_path, o.right_name);
  detail::check_same_system(detail::layer_label(left.path, o.left_name), left.system,
                            detail::layer_label(right.path, o.right_name), right.system);
  return join_layers(left, &right, o.predicate, o.distance, o.progress);
}

std::vector<JoinRow> join_layers(const JoinLayer& left, const JoinLayer* other,
                                 JoinPredicate predicate, double distance,
                                 const Progress& progress) {
  const bool self = other == nullptr;
  const JoinLayer& right = self ? left : *other;
  if (predicate == JoinPredicate::closest) return closest_pair(left, right, self, progress);
  const bool dwithin = predicate == JoinPredicate::dwithin;
  std::vector<Box2> grown = left.boxes;
  if (dwithin)
    for (Box2& b : grown)
      b = outset(b, distance);
  std::vector<std::pair<Id, Id>> candidates;
  join(std::span<const Box2>(grown), std::span<const Box2>(right.boxes), [&](Id i, Id j) {
    candidates.emplace_back(i, j);
    return true;
  });
  std::vector<JoinRow> rows;
  ProgressTicker ticker(progress, double(candidates.size()));
  std::size_t done = 0;
  for (const auto& [i, j] : candidates) {
    if (dwithin) {
      if (auto d = distance_within(left.prepared(i), right.prepared(j), distance))
        rows.push_back({left.fids[i], right.fids[j], *d});
    } else {
      const PreparedGeometry& a = left.prepared(i);
      const PreparedGeometry& b = right.prepared(j);
      const bool yes = predicate == JoinPredicate::contains ? covers(a, b)
                       : predicate == JoinPredicate::within ? covers(b, a)
                                                            : meets(a, b);
      if (yes) rows.push_back({left.fids[i], right.fids[j], 0});
    }
    ticker.tick(double(++done));
  }
  std::sort(rows.begin(), rows.end());
  return rows;
}

std::size_t write_join(const JoinOptions& o, std::FILE* fallback) {
  if (o.format == Format::geojson)
    throw InvalidArgument("loci join writes csv or ids, not geojson");
  refuse_overwriting(o.out_path, o.left_path);
  refuse_overwriting(o.out_path, o.right_path);
  const std::vector<JoinRow> rows = join_layers(o);
  const bool dwithin =
      o.predicate == JoinPredicate::dwithin || o.predicate == JoinPredicate::closest;
  OutputFile out(o.out_path, fallback);
  std::FILE* f = out.stream();
  if (o.format == Format::csv)
    std::fputs(dwithin ? "fid_left,fid_right,distance\n" : "fid_left,fid_right\n", f);
  for (const JoinRow& r : rows) {
    if (o.format == Format::ids)
      std::fprintf(f, "%lld %lld\n", (long long)r.left, (long long)r.right);
    else if (dwithin)
      std::fprintf(f, "%lld,%lld,%s\n", (long long)r.left, (long long)r.right,
                   detail::shortest(r.distance).c_str());
    else
      std::fprintf(f, "%lld,%lld\n", (long long)r.left, (long long)r.right);
  }
  out.commit();
  return rows.size();
}

}  // namespace loci::io
