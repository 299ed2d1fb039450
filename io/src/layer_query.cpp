// Exact queries on a layer through its index: see layer_query.hpp.
#include "loci/io/layer_query.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <mutex>
#include <optional>
#include <queue>
#include <unordered_map>
#include <unordered_set>

#include "gdal_seam.hpp"
#include "loci/geom/convex_hull.hpp"
#include "loci/geom/error.hpp"
#include "loci/io/exact.hpp"

namespace loci::io {

Structure parse_structure(const std::string& name) {
  if (name == "packed-hilbert" || name == "hilbert") return Structure::packed_hilbert;
  if (name == "packed-str" || name == "str") return Structure::packed_str;
  if (name == "rstar") return Structure::rstar;
  if (name == "rtree") return Structure::rtree;
  throw InvalidArgument("unknown structure '" + name +
                        "' (choose packed-hilbert, packed-str, rstar or rtree)");
}

const char* to_string(Structure s) {
  switch (s) {
    case Structure::packed_str:
      return "packed-str";
    case Structure::rstar:
      return "rstar";
    case Structure::rtree:
      return "rtree";
    default:
      return "packed-hilbert";
  }
}

Per parse_per(const std::string& name) {
  if (name == "feature") return Per::feature;
  if (name == "segment") return Per::segment;
  throw InvalidArgument("unknown granularity '" + name + "' (choose feature or segment)");
}

const char* to_string(Per p) {
  return p == Per::segment ? "segment" : "feature";
}

LayerIndex LayerIndex::build(LayerItems&& items, Structure structure) {
  LayerIndex x;
  x.per_ = items.per;
  x.structure_ = structure;
  x.has_polygons_ = items.has_polygons;
  x.layer_name_ = items.layer_name;
  for (const auto& b : items.boxes)
    x.bounds_.expand(b);
  switch (structure) {
    case Structure::packed_hilbert:
    case Structure::packed_str:
      x.tree_ = PackedRTree2::build(
          items.boxes, structure == Structure::packed_str ? Packing::str : Packing::hilbert);
      break;
    case Structure::rstar: {
      RStarTree2 t;
      for (std::size_t i = 0; i < items.boxes.size(); ++i)
        t.insert(items.boxes[i], i);
      x.tree_ = std::move(t);
      break;
    }
    case Structure::rtree: {
      RTree2 t;
      for (std::size_t i = 0; i < items.boxes.size(); ++i)
        t.insert(items.boxes[i], i);
      x.tree_ = std::move(t);
      break;
    }
  }
  x.own_records_ = std::move(items.records);
  x.records_ = x.own_records_;
  x.features_ = std::make_shared<LazyFeatures>();
  return x;
}

LayerIndex LayerIndex::adopt(Sidecar&& sidecar) {
  LayerIndex x;
  const SidecarInfo& info = sidecar.info();
  x.per_ = info.per;
  x.structure_ = info.packing == Packing::str ? Structure::packed_str : Structure::packed_hilbert;
  x.has_polygons_ = info.has_polygons;
  x.layer_name_ = info.layer_name;
  x.source_ = info.source;
  x.records_ = sidecar.mapped_records();
  x.keep_alive_ = sidecar.keep_alive();
  x.check_ = &sidecar.check();
  x.stored_ = sidecar.hierarchies();
  x.mapped_items_ = sidecar.mapped_items();
  x.tree_ = std::move(sidecar).take_tree();
  // The root's box, as the tree holds it (verified when read), not the header's copy of it.
  x.bounds_ = x.packed()->bounds();
  x.features_ = std::make_shared<LazyFeatures>();
  return x;
}

LayerGeometries::LayerGeometries(std::string path, std::string name)
    : path_(std::move(path)), name_(std::move(name)) {}

LayerGeometries::~LayerGeometries() = default;

void LayerGeometries::adopt(std::unordered_map<std::int64_t, FlatGeometry>&& all) {
  std::call_once(once_, [&] {
    all_ = std::move(all);
    whole_ = true;
  });
}

const FlatGeometry* LayerGeometries::find(std::int64_t fid) {
  // Text formats find a feature by FID by parsing the file from its start: one pass that keeps
  // every geometry costs what the first lookup would.
  std::call_once(once_, [&] { whole_ = detail::read_whole_layer(path_, name_, all_); });
  if (!whole_) return nullptr;
  const auto it = all_.find(fid);
  if (it == all_.end())
    throw Error(path_ + ": feature " + std::to_string(fid) +
                " is not in the layer: the index does not match it");
  return &it->second;
}

struct LayerQuery::Geometries {
  std::string path;
  std::string name;
  std::shared_ptr<LayerGeometries> shared;
  std::unique_ptr<detail::FeatureReader> reader;  // opened on the first feature read by FID
  std::unordered_map<std::int64_t, FlatGeometry> cache;

  const FlatGeometry& get(std::int64_t fid) {
    if (const FlatGeometry* g = shared->find(fid)) return *g;
    if (auto it = cache.find(fid); it != cache.end()) return it->second;
    if (!reader) reader = detail::open_feature_reader(path, name);
    return cache.emplace(fid, reader->read(fid)).first->second;
  }

  // The feature prepared for point tests (its edges bucketed by y), made on first use.
  std::unordered_map<std::int64_t, PreparedGeometry> prepared_cache;
  const PreparedGeometry& prepared(std::int64_t fid) {
    if (auto it = prepared_cache.find(fid); it != prepared_cache.end()) return it->second;
    return prepared_cache.emplace(fid, PreparedGeometry(get(fid))).first->second;
  }
};

LayerQuery::LayerQuery(const LayerIndex& index, std::string layer_path, std::string layer_name,
                       std::shared_ptr<LayerGeometries> shared)
    : index_(index) {
  if (!shared) shared = std::make_shared<LayerGeometries>(layer_path, layer_name);
  geometries_.reset(
      new Geometries{std::move(layer_path), std::move(layer_name), std::move(shared), {}, {}, {}});
}

LayerQuery::~LayerQuery() = default;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// What one window-like question needs: where to search, which entry boxes and segments
// qualify, how a whole feature qualifies, and the point whose polygon containment counts.
struct Region {
  Box2 search;
  Point2 probe;
  bool with_distance = false;
  std::function<bool(const Box2&)> box_ok;
  std::function<std::optional<double>(const Segment2&)> segment_ok;  // distance when it qualifies
  std::function<std::optional<double>(const FlatGeometry&, const Box2&)> feature_ok;
};

Box2 around(const Point2& p, double r) {
  const double inf = std::numeric_limits<double>::infinity();
  // Rounded outwards, so that a feature at distance exactly r is not lost to the search box.
  return {{std::nextafter(p[0] - r, -inf), std::nextafter(p[1] - r, -inf)},
          {std::nextafter(p[0] + r, inf), std::nextafter(p[1] + r, inf)}};
}

Region region_of(const Query& q) {
  Region r;
  switch (q.kind) {
    case Query::Kind::bbox:
    case Query::Kind::point: {
      const Box2 w = q.kind == Query::Kind::bbox ? q.box : Box2::of_point(q.point);
      r.search = w;
      r.probe = w.min;
      r.box_ok = [](const Box2&) { return true; };
      r.segment_ok = [w](const Segment2& s) -> std::optional<double> {
        if (intersects(w, s)) return kNaN;
        return std::nullopt;
      };
      r.feature_ok = [w](const FlatGeometry& g, const Box2& env) -> std::optional<double> {
        if (intersects(env, w) && meets(g, w)) return kNaN;
        return std::nullopt;
      };
      break;
    }
    case Query::Kind::segment: {
      const Segment2 s = q.segment;
      r.search = s.box();
      r.probe = s.a;
      r.box_ok = [s](const Box2& b) { return intersects(b, s); };
      // Segments and features qualify by first_meeting, which gives the first point of s in
      // them as well (the answers carry it).
      break;
    }
    default: {
      const Point2 p = q.point;
      const double rad = q.radius;
      r.search = around(p, rad);
      r.probe = p;
      r.with_distance = true;
      // Boxes pass with the slack of rounding (a superset); segments and features are
      // decided exactly.
      r.box_ok = [p, rad](const Box2& b) {
        const double slack =
            1e-14 * (std::fabs(p[0]) + std::fabs(p[1]) + std::fabs(b.min[0]) + std::fabs(b.min[1]) +
                     std::fabs(b.max[0]) + std::fabs(b.max[1])) +
            4e-16 * rad + 1e-150;
        return std::sqrt(squared_distance(p, b)) <= rad + slack;
      };
      r.segment_ok = [p, rad](const Segment2& e) -> std::optional<double> {
        if (compare_distance(p, e, rad) <= 0) return std::sqrt(accurate_squared_distance(p, e));
        return std::nullopt;
      };
      r.feature_ok = [p, rad](const FlatGeometry& g, const Box2&) -> std::optional<double> {
        if (within_distance(g, p, rad)) return distance(g, p);
        return std::nullopt;
      };
      break;
    }
  }
  return r;
}

// The parameter at which segment s enters the closed box b (0 when it starts in it), less a
// little slack so that it bounds the exact meeting parameters from below; infinity when s
// misses b (by more than the slack).
double entry_parameter(const Segment2& s, const Box2& b) {
  constexpr double kSlack = 1e-9;
  double t0 = 0, t1 = 1;
  for (int k = 0; k < 2; ++k) {
    const double d = s.b[k] - s.a[k];
    if (d == 0) {
      if (s.a[k] < b.min[k] || s.a[k] > b.max[k]) return std::numeric_limits<double>::infinity();
      continue;
    }
    double u = (b.min[k] - s.a[k]) / d, v = (b.max[k] - s.a[k]) / d;
    if (u > v) std::swap(u, v);
    t0 = std::max(t0, u);
    t1 = std::min(t1, v);
  }
  if (t0 > t1 + kSlack) return std::numeric_limits<double>::infinity();
  return std::max(0.0, t0 - kSlack);
}

void check_query(const Query& q) {
  switch (q.kind) {
    case Query::Kind::bbox:
      check_box(q.box, "bbox");
      break;
    case Query::Kind::segment:
      check_segment(q.segment, "segment");
      break;
    case Query::Kind::within:
      check_point(q.point, "point");
      if (!(q.radius >= 0) || !std::isfinite(q.radius))
        throw InvalidArgument("distance must be a finite number >= 0");
      break;
    case Query::Kind::nearest:
      check_point(q.point, "point");
      if (q.k == 0) throw InvalidArgument("k must be >= 1");
      break;
    default:
      check_point(q.point, "point");
  }
}

}  // namespace

struct LayerIndex::LazyFeatures {
  std::once_flag once;
  Features value;
};

void LayerIndex::Features::corrupt() const {
  throw Error((path.empty() ? std::string("index") : path) +
              ": corrupt index file (feature hierarchies); run 'loci index' to rebuild it");
}

const LayerIndex::Features& LayerIndex::features() const {
  std::call_once(features_->once, [&] {
    Features& f = features_->value;
    const PackedRTree2* t = packed();
    if (!stored_) {
      f = build_features(t, per_, records());
      return;
    }
    // Stored: the arrays are viewed in place; the level sizes are read (and checked) now,
    // everything else as a walk reads it.
    const MappedHierarchies& m = *stored_;
    f.hierarchical = true;
    f.records = records_;
    f.items = mapped_items_;
    f.check = check_;
    f.path = m.path;
    f.leaves = (t->size() + PackedRTree2::node_size - 1) / PackedRTree2::node_size;
    f.fid = {m.fids, m.features};
    f.roots = {m.roots, m.features};
    f.hull_first = {m.hull_first, m.features + 1};
    f.hull_points = {m.hull_points, m.hull_count};
    check_->touch(m.level_sizes, 8 * m.levels);
    std::vector<std::span<const Features::Node>> levels;  // kept only when all are sound
    std::size_t at = 0;
    for (std::size_t l = 0; l < m.levels; ++l) {
      const std::uint64_t size = m.level_sizes[l];
      if (size == 0 || size > m.nodes - at) f.corrupt();
      levels.push_back({m.nodes_at + at, std::size_t(size)});
      at += std::size_t(size);
    }
    if (at != m.nodes) f.corrupt();
    f.levels = std::move(levels);
    f.node_count = m.nodes;
    f.root_tree = PackedRTree2::adopt(m.features, Packing::hilbert, m.root_blocks, m.root_items,
                                      keep_alive_, check_);
  });
  return features_->value;
}

LayerIndex::Features LayerIndex::build_features(const PackedRTree2* t, Per per,
                                                std::span<const ItemRecord> records) {
  Features f;
  f.records = records;
  // Only a packed tree per segment is walked through hierarchies; the other walks look the
  // feature of each item up in of_item.
  const bool hierarchies = f.hierarchical = t && t->size() > 0 && per == Per::segment;
  if (!hierarchies) f.of_item.resize(records.size());
  auto& number = f.number;
  auto& fids = f.own_fid;
  std::int64_t last_fid = 0;
  std::uint32_t last = Features::none;
  for (std::size_t id = 0; id < records.size(); ++id) {
    const std::int64_t fid = records[id].fid;
    if (last == Features::none || fid != last_fid) {
      const auto [it, fresh] = number.try_emplace(fid, std::uint32_t(fids.size()));
      if (fresh) fids.push_back(fid);
      last = it->second;
      last_fid = fid;
    }
    if (!hierarchies) f.of_item[id] = last;
  }
  f.fid = fids;
  if (!hierarchies) return f;
  const std::size_t n = t->size(), features = fids.size();
  f.leaves = (n + PackedRTree2::node_size - 1) / PackedRTree2::node_size;
  f.items = t->item_indices();
  const std::span<const std::uint32_t> items = f.items.first(n);
  // The feature of the item at packed position pos (none for an item of no record, in a
  // corrupt index), asked once per run of one FID: of a table when the FIDs are dense (as
  // GDAL numbers most formats' features), of the map otherwise.
  std::int64_t low = 0;
  std::vector<std::uint32_t> dense;
  if (features > 0) {
    const auto [min, max] = std::minmax_element(fids.begin(), fids.end());
    low = *min;
    if (std::uint64_t(*max) - std::uint64_t(low) < 4 * std::uint64_t(features) + 1024) {
      dense.assign(std::size_t(std::uint64_t(*max) - std::uint64_t(low)) + 1, Features::none);
      for (std::size_t g = 0; g < features; ++g)
        dense[std::size_t(std::uint64_t(fids[g]) - std::uint64_t(low))] = std::uint32_t(g);
    }
  }
  last = Features::none;
  auto feature_at = [&](std::size_t pos) {
    const std::uint32_t id = items[pos];
    if (id >= records.size()) return Features::none;
    if (last == Features::none || records[id].fid != last_fid) {
      last_fid = records[id].fid;
      last = dense.empty() ? number.find(last_fid)->second
                           : dense[std::size_t(std::uint64_t(last_fid) - std::uint64_t(low))];
    }
    return last;
  };
  // Level 0: per leaf of the tree, one node per feature it holds, grouped by feature (a
  // counting sort that keeps packed order, so that a feature's neighbouring leaves stay
  // together). The features of each leaf are listed first, compactly.
  constexpr std::uint32_t kFanout = 16;
  static_assert(kFanout == PackedRTree2::node_size);
  struct Part {
    std::uint32_t feature, leaf;
  };
  loci::detail::LargeVector<Part> parts;
  parts.reserve(n / kFanout + n / kFanout / 8 + 1);
  std::vector<std::uint32_t> start(features + 1, 0);
  for (std::size_t b = 0, first = 0; first < n; ++b, first += kFanout) {
    const std::size_t last_pos = std::min<std::size_t>(first + kFanout, n);
    std::uint32_t seen[kFanout];
    int distinct = 0;
    for (std::size_t pos = first; pos < last_pos; ++pos) {
      const std::uint32_t g = feature_at(pos);
      if (g == Features::none || (distinct > 0 && seen[distinct - 1] == g)) continue;
      if (std::find(seen, seen + distinct, g) == seen + distinct) seen[distinct++] = g;
    }
    for (int i = 0; i < distinct; ++i) {
      parts.push_back({seen[i], std::uint32_t(b)});
      ++start[seen[i] + 1];
    }
  }
  for (std::size_t i = 0; i < features; ++i)
    start[i + 1] += start[i];
  // The box the tree stores for the leaf bounds each of its features' parts: looser for a
  // leaf shared by several features, but no leaf is read until a query reaches it.
  Box2 only_leaf = Box2::empty();
  if (t->levels() == 1)
    for (std::size_t pos = 0; pos < n; ++pos)
      only_leaf.expand(t->box_at(pos));
  // Each part's slots: which of the leaf's entries are the feature's, and which of those run
  // antidiagonally.
  auto slots_of = [&](const Part& part) {
    std::uint32_t slots = 0;
    const std::size_t first = std::size_t(part.leaf) * kFanout;
    const std::size_t end = std::min<std::size_t>(first + kFanout, n);
    for (std::size_t pos = first; pos < end; ++pos) {
      if (feature_at(pos) != part.feature) continue;
      const std::uint32_t e = std::uint32_t(pos - first);
      slots |= 1u << e;
      if (records[items[pos]].flags & item_antidiagonal) slots |= 1u << (kFanout + e);
    }
    return slots;
  };
  loci::detail::LargeVector<Features::Node> level(parts.size());
  for (const Part& part : parts)
    level[start[part.feature]++] = {t->levels() > 1 ? t->entry_box(1, part.leaf) : only_leaf,
                                    part.feature, part.leaf, part.leaf, slots_of(part)};
  parts = {};
  // The hull of every feature's segment ends, from its level-0 nodes (in feature order),
  // leaving out first those strictly inside the polygon of their extremes (whole leaves at a
  // time where the leaf's box is).
  f.own_hull_first.assign(features + 1, 0);
  {
    std::vector<Point2> ends, kept;
    std::vector<std::size_t> ends_at;  // where each of the feature's nodes' ends start
    std::size_t i = 0;
    for (std::uint32_t g = 0; g < features; ++g) {
      ends.clear();
      ends_at.clear();
      const std::size_t from = i;
      for (; i < level.size() && level[i].feature == g; ++i) {
        ends_at.push_back(ends.size());
        const std::size_t first = std::size_t(level[i].first) * kFanout;
        for (std::uint32_t mine = level[i].slots & 0xffffu; mine != 0; mine &= mine - 1) {
          const int e = std::countr_zero(mine);
          const bool anti = (level[i].slots >> (kFanout + e)) & 1;
          const Segment2 s = segment_of(t->box_at(first + e), anti ? item_antidiagonal : 0u);
          // Along a line or ring, a segment's start is often the end of the one before.
          if (ends.size() == ends_at.back() || !(ends.back() == s.a)) ends.push_back(s.a);
          ends.push_back(s.b);
        }
      }
      ends_at.push_back(ends.size());
      const ExtremesPolygon inner(ends);
      kept.clear();
      for (std::size_t k = from; k < i; ++k) {
        if (inner.strictly_inside(level[k].box)) continue;
        for (std::size_t e = ends_at[k - from]; e < ends_at[k - from + 1]; ++e)
          if (!inner.strictly_inside(ends[e])) kept.push_back(ends[e]);
      }
      convex_hull(kept, f.own_hull_points);
      f.own_hull_first[g + 1] = std::uint32_t(f.own_hull_points.size());
    }
  }
  f.hull_first = f.own_hull_first;
  f.hull_points = f.own_hull_points;
  // Then up to 16 nodes of one feature per node, until each feature has one node, its root.
  while (!level.empty()) {
    loci::detail::LargeVector<Features::Node> up;
    const auto l = std::uint32_t(f.own_levels.size());
    for (std::uint32_t i = 0; i < level.size();) {
      std::uint32_t j = i + 1;
      while (j < level.size() && level[j].feature == level[i].feature)
        ++j;
      if (j - i == 1) {
        f.own_roots.push_back({l, i});
      } else {
        for (std::uint32_t c = i; c < j; c += kFanout) {
          Features::Node node{Box2::empty(), level[i].feature, c, std::min(c + kFanout, j), 0};
          for (std::uint32_t k = node.first; k < node.last; ++k)
            node.box.expand(level[k].box);
          up.push_back(node);
        }
      }
      i = j;
    }
    f.own_levels.push_back(std::move(level));
    level = std::move(up);
  }
  for (const auto& l : f.own_levels) {
    f.levels.emplace_back(l.data(), l.size());
    f.node_count += l.size();
  }
  f.roots = f.own_roots;
  std::vector<Box2> boxes;
  boxes.reserve(f.roots.size());
  for (const HierarchyRoot& r : f.roots)
    boxes.push_back(f.levels[r.level][r.node].box);
  f.root_tree = PackedRTree2::build(boxes);
  return f;
}

// The ring segments crossing the ray from p towards +x, counted per polygon of each feature.
std::vector<std::int64_t> containing_polygons(const LayerIndex& index, const Point2& p) {
  std::vector<std::int64_t> out;
  if (!index.has_polygons() || index.size() == 0 || p[0] > index.bounds().max[0]) return out;
  const Box2 ray{p, {index.bounds().max[0], p[1]}};
  std::unordered_map<std::int64_t, OddPolygons> odd;
  index.window(ray, [&](const ItemRecord& r, const Box2& b) {
    if (r.flags & item_ring) {
      const Segment2 s = segment_of(b, r.flags);
      if (ray_crosses(s.a, s.b, p)) odd[r.fid].toggle(polygon_of(r.flags));
    }
    return true;
  });
  for (auto& [fid, o] : odd)
    if (o.any()) out.push_back(fid);
  return out;
}

namespace {

// The features (by number) whose polygons contain p, through their hierarchies: only a
// feature whose box holds p can contain it. Its rings are counted along the axis direction
// that leaves its box soonest, through its own hierarchy: no other feature's segments are
// read. Each direction is a map that turns it into +x (reflections and swaps of coordinates
// are exact), and ray_crosses decides on the mapped points as it does for +x.
std::vector<std::uint32_t> containing_features(const LayerIndex& index, const Point2& p,
                                               const LayerIndex::Features& features) {
  std::vector<std::uint32_t> out;
  const PackedRTree2* tree = index.packed();
  if (!index.has_polygons() || !tree || tree->size() == 0) return out;
  std::vector<HierarchyRoot> stack;
  std::size_t visits = 0;  // at most every node once (Features::node_count)
  features.root_tree.query(Box2::of_point(p), [&](Id r, const Box2&) {
    const HierarchyRoot root = features.root(r);
    const LayerIndex::Features::Node& top = features.node(root.level, root.node);
    // Outside the feature's hull, p is outside every polygon of it (without hulls: counted).
    const std::span<const Point2> hull = features.hull(top.feature);
    if (!hull.empty() && strictly_outside(hull, p)) return true;
    const Box2& reach = top.box;
    const double length[4] = {reach.max[0] - p[0], p[0] - reach.min[0], reach.max[1] - p[1],
                              p[1] - reach.min[1]};
    const int dir = int(std::min_element(length, length + 4) - length);
    auto map = [dir](const Point2& q) -> Point2 {
      switch (dir) {
        case 0:
          return q;
        case 1:
          return {-q[0], q[1]};
        case 2:
          return {q[1], q[0]};
        default:
          return {-q[1], q[0]};
      }
    };
    const Box2 ray = dir == 0   ? Box2{p, {reach.max[0], p[1]}}
                     : dir == 1 ? Box2{{reach.min[0], p[1]}, p}
                     : dir == 2 ? Box2{p, {p[0], reach.max[1]}}
                                : Box2{{p[0], reach.min[1]}, p};
    const Point2 mp = map(p);
    const std::int64_t fid = features.fid_of(top.feature);
    OddPolygons odd;
    stack.assign(1, root);
    while (!stack.empty()) {
      const auto [level, i] = stack.back();
      stack.pop_back();
      if (++visits > features.node_count) features.corrupt();
      const LayerIndex::Features::Node& node = features.node(level, i);
      if (level > 0) {
        const auto below = features.children(node, level);
        for (std::uint32_t c = 0; c < below.size(); ++c)
          if (intersects(below[c].box, ray)) stack.push_back({level - 1, node.first + c});
        continue;
      }
      const std::size_t first = std::size_t(node.first) * PackedRTree2::node_size;
      const std::size_t last = std::min(first + PackedRTree2::node_size, tree->size());
      for (std::size_t pos = first; pos < last; ++pos) {
        const Box2 b = tree->box_at(pos);
        if (!intersects(b, ray)) continue;
        const ItemRecord* r = features.record(features.leaf_items(node.first)[pos - first]);
        if (!r || r->fid != fid || !(r->flags & item_ring)) continue;
        const Segment2 s = segment_of(b, r->flags);
        if (ray_crosses(map(s.a), map(s.b), mp)) odd.toggle(polygon_of(r->flags));
      }
    }
    if (odd.any()) out.push_back(top.feature);
    return true;
  });
  return out;
}

}  // namespace

std::vector<std::int64_t> containing_polygons(const LayerIndex& index, const Point2& p,
                                              const LayerIndex::Features& features) {
  std::vector<std::int64_t> out;
  for (const std::uint32_t f : containing_features(index, p, features))
    out.push_back(features.fid_of(f));
  return out;
}

namespace {

// The squared distance from p to the segments (or, for candidates, the boxes) of the feature
// of node (level, i) below that node, taken into `best` when nearer: children nearest first,
// each dropped unread once it is no nearer than best.
struct FeatureDescent {
  const LayerIndex::Features& features;
  const PackedRTree2& tree;
  Point2 p;
  bool boxes_only;
  // Squared distances at most this are within rounding of 0 for segments of the tree's extent
  // (accurate_squared_distance's zone for the largest coordinates there).
  double near2 = near_zone_squared(p, tree.bounds());
  mutable std::size_t visits = 0;  // nodes read by this query's walks (Features::node_count)

  // `skip` is a leaf (level 0 node) already measured into best (by dive), not read again.
  void operator()(std::uint32_t level, std::uint32_t i, double& best, bool touched,
                  std::uint32_t skip = kNoLeaf) const {
    if (++visits > 2 * features.node_count) features.corrupt();
    const LayerIndex::Features::Node& node = features.node(level, i, touched);
    if (level == 0) {
      const std::size_t first = std::size_t(node.first) * PackedRTree2::node_size;
      const std::size_t used = std::min<std::size_t>(PackedRTree2::node_size, tree.size() - first);
      const PackedRTree2::Block& leaf = tree.leaf(node.first);
      double box2[PackedRTree2::Block::kSlots];
      leaf.squared_distances(p, box2);
      // The feature's slots among those the leaf uses (the node says which they are).
      constexpr unsigned kAnti = PackedRTree2::node_size;
      for (std::uint32_t mine = node.slots & ((1u << used) - 1); mine != 0; mine &= mine - 1) {
        const int e = std::countr_zero(mine);
        if (!(box2[e] < best)) continue;
        if (boxes_only) {
          best = box2[e];
          continue;
        }
        // A segment is no nearer than its box, so only those whose box is nearer are measured.
        const Segment2 s =
            segment_of(leaf.box(e), (node.slots >> (kAnti + e)) & 1 ? item_antidiagonal : 0u);
        const double d2 = squared_distance(p, s);
        // Measured exactly where rounding could be much of it (a point on the segment: 0),
        // also when the rounded value does not beat the best (which may be rounded too).
        if (d2 < best || d2 <= near2) best = std::min(best, accurate_squared_distance(p, s));
      }
      return;
    }
    const auto below = features.children(node, level);
    struct Child {
      double d2;
      std::uint32_t node;
    };
    Child order[PackedRTree2::node_size];
    int n = 0;
    for (std::uint32_t c = 0; c < below.size(); ++c) {
      const double c2 = squared_distance(p, below[c].box);
      if (!(c2 < best) || (level == 1 && node.first + c == skip)) continue;
      if (level == 1 && below[c].first < features.leaves) {
        // The leaf will likely be read: its loads overlap the work before it.
        tree.prefetch_leaf(below[c].first);
      }
      int j = n++;
      for (; j > 0 && order[j - 1].d2 > c2; --j)
        order[j] = order[j - 1];
      order[j] = {c2, node.first + c};
    }
    for (int j = 0; j < n && order[j].d2 < best; ++j)
      (*this)(level - 1, order[j].node, best, true, skip);
  }

  static constexpr std::uint32_t kNoLeaf = std::numeric_limits<std::uint32_t>::max();

  // An upper bound on the squared distance of the feature of node (level, i): the nearest
  // child at every level down to one leaf, measured there (infinity when that leaf holds none
  // of its segments, in a corrupt index, or when every child's squared distance overflows).
  // `leaf` is set to the leaf measured (kNoLeaf when none was): the bound is the least
  // distance of the feature's segments there, so a descent need not read it again.
  double dive(std::uint32_t level, std::uint32_t i, std::uint32_t& leaf) const {
    leaf = kNoLeaf;
    bool touched = false;  // node (level, i) was read as a child
    for (; level > 0; --level, touched = true) {
      if (++visits > 2 * features.node_count) features.corrupt();
      const LayerIndex::Features::Node& node = features.node(level, i, touched);
      const auto below = features.children(node, level);
      double nearest = std::numeric_limits<double>::infinity();
      for (std::uint32_t c = 0; c < below.size(); ++c) {
        const double c2 = squared_distance(p, below[c].box);
        if (c2 < nearest) nearest = c2, i = node.first + c;
      }
      if (!(nearest < std::numeric_limits<double>::infinity())) return nearest;
    }
    double best = std::numeric_limits<double>::infinity();
    (*this)(0, i, best, touched);
    leaf = i;
    return best;
  }
};

}  // namespace

void LayerQuery::next_generation(std::size_t features) {
  if (state_.size() != features) {
    state_.assign(features, FeatureState{});
    generation_ = 0;
  }
  if (++generation_ == 0) {  // wrapped: forget every stamp
    std::fill(state_.begin(), state_.end(), FeatureState{});
    generation_ = 1;
  }
}

void LayerQuery::nearest_through_hierarchies(const Query& q, std::size_t number,
                                             bool candidates_only,
                                             const LayerIndex::Features& features,
                                             std::vector<Answer>& out) {
  const Point2 p = q.point;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  // The k best (distance, FID) as a max-heap: its top is the k-th. Features rank by the
  // distance reported, the square root of the squared distances compared here, and at equal
  // distances by FID: a squared distance a little above another can give the same distance,
  // so the walk follows bounds up to `reach` of a distance (squared), beyond every square
  // whose root is that distance.
  auto reach = [](double d) {
    const double above = std::nextafter(std::nextafter(d, kInf), kInf);
    return std::max(above * above, std::nextafter(d * d, kInf));  // (0 squares to 0)
  };
  auto& top = top_;
  top.clear();
  double kth_reach = kInf;  // reach of the k-th distance once there are k, kept as top changes
  auto kth = [&] { return kth_reach; };
  auto keep = [&](double d2, std::uint32_t f) {
    const Ranked r{std::sqrt(d2), features.fid_of(f), f};
    if (top.size() == q.k) {
      if (!(r < top.front())) return;
      std::pop_heap(top.begin(), top.end());
      top.pop_back();
    }
    top.push_back(r);
    std::push_heap(top.begin(), top.end());
    if (top.size() == q.k) kth_reach = reach(top.front().d);
  };
  // Every feature has one root; one met twice is a forged file, refused (its hull would
  // otherwise answer for roots that are not its own).
  next_generation(features.fid.size());
  // A polygon holding p is at 0, for candidates too (its boxes need not reach p).
  std::vector<std::uint32_t> inside;
  for (const std::uint32_t f : containing_features(index_, p, features)) {
    inside.push_back(f);
    keep(0.0, f);
  }
  // First the candidates: the features in increasing distance of their roots' boxes, each
  // with an upper bound on its distance from one dive down its hierarchy, until a root is
  // no nearer than the k-th smallest upper bound (no feature from there on can rank).
  auto& bounds = bounds_;  // the k smallest upper bounds, as a max-heap
  bounds.assign(top.size(), 0.0);
  double bound_reach = bounds.size() < q.k ? kInf : reach(0.0);  // kept as bounds changes
  auto bound = [&] { return bound_reach; };
  const FeatureDescent descend{features, *index_.packed(), p, candidates_only};
  auto& candidates = candidates_;
  candidates.clear();
  features.root_tree.browse(p, [&](Id r, const Box2& b, double) {
    const double lower = squared_distance(p, b);
    if (!(lower < bound())) return false;
    const auto [level, i] = features.root(r);
    const std::uint32_t f = features.node(level, i).feature;
    if (state_[f].stamp == generation_) features.corrupt();
    state_[f].stamp = generation_;
    if (std::find(inside.begin(), inside.end(), f) != inside.end()) return true;
    std::uint32_t leaf = FeatureDescent::kNoLeaf;
    // The feature's distance itself when a vertex of its hull is certainly nearest (no
    // segment read); else an upper bound from one dive down its hierarchy, or that vertex's
    // distance when nearer.
    const NearestVertex v = candidates_only ? NearestVertex{} : nearest_vertex(features.hull(f), p);
    const double upper = v.certified ? v.d2 : std::min(v.d2, descend.dive(level, i, leaf));
    candidates.push_back({upper, lower, std::uint32_t(r), leaf, v.certified});
    if (bounds.size() == q.k) {
      if (!(upper < bounds.front())) return true;
      std::pop_heap(bounds.begin(), bounds.end());
      bounds.pop_back();
    }
    bounds.push_back(upper);
    std::push_heap(bounds.begin(), bounds.end());
    if (bounds.size() == q.k) bound_reach = reach(std::sqrt(bounds.front()));
    return true;
  });
  // Then each candidate measured exactly, nearest upper bound first (so that the k-th
  // distance is soon the final one), its descent bounded by the nearer of its own upper
  // bound (a distance it has) and the k-th distance so far; a candidate whose root is no
  // nearer than the k-th distance is dropped unread.
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.upper < b.upper || (a.upper == b.upper && a.lower < b.lower);
  });
  for (const Candidate& c : candidates) {
    const double limit = kth();
    if (!(c.lower < limit)) continue;
    const auto [level, i] = features.root(c.root);
    const std::uint32_t f = features.node(level, i).feature;
    // Not descended when its hull is farther than the k-th distance (a bound that is not
    // finite, from a forged hull of coordinates that are not, rules nothing out).
    if (!c.exact && !candidates_only) {
      const double hull_lower = hull_lower_bound(features.hull(f), p);
      if (!(hull_lower < limit) && hull_lower < kInf) continue;
    }
    // The descent takes what is nearer than `best`: below the reach of the k-th distance.
    double best = std::min(c.upper, limit);
    if (!c.exact && (level > 0 || i != c.leaf)) descend(level, i, best, false, c.leaf);
    if (best < limit) keep(best, f);
  }
  std::sort_heap(top.begin(), top.end());
  for (const Ranked& r : top)
    out.push_back({number, r.fid, r.d});
}

void LayerQuery::run(const Query& q, std::size_t number, bool candidates_only,
                     std::vector<Answer>& out) {
  check_query(q);
  const bool per_segment = index_.per() == Per::segment;

  if (q.kind == Query::Kind::nearest) {
    const Point2 p = q.point;
    const LayerIndex::Features& features = index_.features();
    if (features.hierarchical) {
      nearest_through_hierarchies(q, number, candidates_only, features, out);
      return;
    }
    next_generation(features.fid.size());
    constexpr double kInf = std::numeric_limits<double>::infinity();
    // The state of feature f in this query (fresh: not seen, best infinite).
    auto state = [&](std::uint32_t f) -> FeatureState& {
      FeatureState& s = state_[f];
      if (s.stamp != generation_) s = {generation_, false, kInf};
      return s;
    };
    std::priority_queue<Ranked, std::vector<Ranked>, std::greater<>> pending;
    std::size_t found = 0;
    auto offer = [&](std::uint32_t f, double d) {
      FeatureState& s = state(f);
      if (d >= s.best) return;
      s.best = d;
      pending.push({d, features.fid[f], f});
    };
    // Everything pending nearer than `limit` is final: every entry not yet browsed is at
    // least `limit` away, to the rounding of box distances (a few units in the last place:
    // one a hair nearer may tie, and rank first by its FID).
    auto settle = [&](double limit) {
      const double below = limit * (1 - 0x1p-48);
      while (!pending.empty() && found < q.k && (pending.top().d < below || limit == kInf)) {
        const Ranked r = pending.top();
        pending.pop();
        FeatureState& s = state(r.f);
        if (s.done || s.best != r.d) continue;
        s.done = true;
        out.push_back({number, r.fid, r.d});
        ++found;
      }
    };
    const ItemRecord* records = features.records.data();
    if (per_segment) {
      for (const auto fid : containing_polygons(index_, p))
        offer(features.number.at(fid), 0.0);
    }
    auto visit = [&](const ItemRecord& r, const Box2& b, double box_distance) {
      settle(box_distance);
      if (found >= q.k) return false;
      const std::uint32_t f = features.of_item[std::size_t(&r - records)];
      if (state(f).done) return true;
      if (candidates_only)
        offer(f, box_distance);
      else if (per_segment)
        offer(f, std::sqrt(accurate_squared_distance(p, segment_of(b, r.flags))));
      else
        offer(f, distance(geometries_->get(r.fid), p));
      return true;
    };
    index_.browse(p, visit);
    settle(std::numeric_limits<double>::infinity());
    return;
  }

  if (q.kind == Query::Kind::segment && q.first) {
    // Best first along the segment: entries in increasing entry parameter of their boxes,
    // until the next box is entered after the best hit so far.
    const Segment2 s = q.segment;
    double best_t = std::numeric_limits<double>::infinity();
    std::int64_t best_fid = -1;
    Point2 best_at{kNaN, kNaN};
    auto offer = [&](std::int64_t fid, const Meet& m) {
      if (m.t < best_t || (m.t == best_t && fid < best_fid))
        best_t = m.t, best_fid = fid, best_at = m.at;
    };
    if (per_segment)
      for (const auto fid : containing_polygons(index_, s.a))
        offer(fid, {0.0, s.a});
    index_.ordered(
        s.box(), [&](const Box2& b) { return entry_parameter(s, b); },
        [&](const ItemRecord& r, const Box2& b, double key) {
          if (key > best_t) return false;
          if (candidates_only) {
            offer(r.fid, {key, {kNaN, kNaN}});
          } else if (per_segment) {
            if (auto m = first_meeting(segment_of(b, r.flags), s)) offer(r.fid, *m);
          } else if (auto m = first_meeting(geometries_->get(r.fid), s)) {
            offer(r.fid, *m);
          }
          return true;
        });
    if (best_fid >= 0) {
      const double length = std::hypot(s.b[0] - s.a[0], s.b[1] - s.a[1]);
      // + 0.0: a segment starting on the feature has met it at 0, never at -0 (a parameter
      // rounded from a negative direction).
      out.push_back({number, best_fid, best_t * length + 0.0, best_at});
    }
    return;
  }

  if (q.kind == Query::Kind::point && !per_segment && !candidates_only) {
    // Point location per feature: the features whose envelope holds the point, each tested
    // on its edges near the point's y (one entry per feature: no duplicates to merge).
    const std::size_t first = out.size();
    index_.window(Box2::of_point(q.point), [&](const ItemRecord& r, const Box2&) {
      if (geometries_->prepared(r.fid).meets(q.point)) out.push_back({number, r.fid, kNaN});
      return true;
    });
    std::sort(out.begin() + std::ptrdiff_t(first), out.end(),
              [](const Answer& a, const Answer& b) { return a.fid < b.fid; });
    return;
  }

  const Region region = region_of(q);
  std::unordered_map<std::int64_t, double> hits;
  // A segment query's first point in each feature, by fid (see first_meeting).
  const bool meeting = q.kind == Query::Kind::segment && !candidates_only;
  std::unordered_map<std::int64_t, Point2> first_at;
  auto hit = [&](std::int64_t fid, double d) {
    auto [it, fresh] = hits.try_emplace(fid, d);
    if (!fresh && d < it->second) it->second = d;
  };
  auto met = [&](std::int64_t fid, const Meet& m) {
    auto [it, fresh] = hits.try_emplace(fid, m.t);
    if (fresh || m.t < it->second) it->second = m.t, first_at[fid] = m.at;
  };
  if (per_segment) {
    index_.window(region.search, [&](const ItemRecord& r, const Box2& b) {
      if (candidates_only) {
        if (region.box_ok(b))
          hit(r.fid, region.with_distance ? std::sqrt(squared_distance(q.point, b)) : kNaN);
      } else if (meeting) {
        if (auto m = first_meeting(segment_of(b, r.flags), q.segment)) met(r.fid, *m);
      } else if (auto d = region.segment_ok(segment_of(b, r.flags))) {
        hit(r.fid, *d);
      }
      return true;
    });
    // Polygons holding the query (whose segments' boxes it may not meet), for candidates too:
    // they are part of the exact answer.
    for (const auto fid : containing_polygons(index_, region.probe)) {
      if (meeting)
        met(fid, {0.0, q.segment.a});
      else
        hit(fid, region.with_distance ? 0.0 : kNaN);
    }
  } else {
    std::vector<std::pair<std::int64_t, Box2>> candidates;
    index_.window(region.search, [&](const ItemRecord& r, const Box2& b) {
      if (region.box_ok(b)) candidates.emplace_back(r.fid, b);
      return true;
    });
    for (const auto& [fid, b] : candidates) {
      // A feature whose envelope lies inside the window meets it: no geometry needed.
      if (q.kind == Query::Kind::bbox && !candidates_only && within(b, q.box)) {
        hit(fid, kNaN);
        continue;
      }
      if (candidates_only) {
        hit(fid, region.with_distance ? std::sqrt(squared_distance(q.point, b)) : kNaN);
      } else if (meeting) {
        if (auto m = first_meeting(geometries_->get(fid), q.segment)) met(fid, *m);
      } else if (auto d = region.feature_ok(geometries_->get(fid), b)) {
        hit(fid, *d);
      }
    }
  }
  const std::size_t first = out.size();
  for (const auto& [fid, d] : hits) {
    if (meeting)
      out.push_back({number, fid, kNaN, first_at.at(fid)});
    else
      out.push_back({number, fid, d});
  }
  std::sort(out.begin() + std::ptrdiff_t(first), out.end(),
            [](const Answer& a, const Answer& b) { return a.fid < b.fid; });
}

}  // namespace loci::io
