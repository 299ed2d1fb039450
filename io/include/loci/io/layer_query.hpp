// Queries on a layer: an index over the layer's features or segments (from a sidecar or built
// in memory) gives candidates, and exact tests on the geometry decide (DESIGN.md section 4).
//
// LayerIndex holds one of the structures loci has (packed R-tree with Hilbert or STR packing,
// which is what a sidecar maps; R*-tree or Guttman's quadratic R-tree, built in memory) and an
// ItemRecord per entry. LayerQuery runs the five questions the command line asks:
//
//   bbox W        features whose geometry meets the closed window W
//   point P       features whose geometry contains or touches P
//   segment S     features whose geometry meets the closed segment S
//   within P, D   features at distance <= D from P, with the distance
//   nearest P, k  the k features nearest to P, nearest first, with the distance
//
// Refinement per feature fetches the candidate's geometry from GDAL by FID (cached for the
// life of the LayerQuery, which is what makes a batch of queries cheap) and applies the exact
// tests of exact.hpp. Per segment, the entries are the linework itself (a segment is its box
// plus one bit saying which diagonal it is), so the exact tests run on the index alone and
// the layer is never opened for `-f ids`; a polygon that contains the query without its rings
// meeting it is found by crossing parity along a horizontal ray (itself an index query),
// polygon by polygon: each ring segment carries its polygon's number.
//
// Nearest-n browses entry boxes by increasing distance (the trees' browse()) and refines with
// exact distances: a feature is final once its exact distance is no larger than the box
// distance of the next entry, since every entry not yet seen is at least that far, and the
// walk stops there. Per segment on a packed tree, it goes over one hierarchy of boxes per
// feature instead (Features), in two passes. First the candidates: the features come out of a
// tree of their hierarchies' roots nearest box first, each with an upper bound on its distance
// from one dive down its hierarchy (nearest child at every level, one leaf measured), until a
// root is no nearer than the k-th smallest upper bound; a feature whose convex hull (stored
// with the hierarchies) is certainly nearest to the query at one of its vertices is at that
// vertex's distance, found from the hull alone (for a far query point, most features are
// measured so, without reading their segments). Then each other candidate, nearest bound
// first, is measured exactly by a depth-first descent of its own hierarchy, nearest child
// first, that drops every node no nearer than the feature's bound or the k-th distance found
// so far. A feature's many segments never come out one by one. --candidates answers from
// boxes alone, with the polygons holding the query (which none of their segments' boxes may
// meet) added, so that it holds the exact answer. Thread-safety: a LayerIndex is immutable; a
// LayerQuery caches geometry and belongs to one thread.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <unordered_map>
#include <variant>
#include <vector>

#include "loci/index/detail/large_alloc.hpp"
#include "loci/index/packed_rtree.hpp"
#include "loci/index/rstar_tree.hpp"
#include "loci/index/rtree.hpp"
#include "loci/io/exact.hpp"
#include "loci/io/layer_reader.hpp"
#include "loci/io/sidecar.hpp"

namespace loci::io {

enum class Structure : std::uint8_t { packed_hilbert, packed_str, rstar, rtree };

// Accepts "packed-hilbert" (alias "hilbert"), "packed-str" ("str"), "rstar", "rtree".
// Throws InvalidArgument listing the choices.
Structure parse_structure(const std::string& name);
const char* to_string(Structure s);
// Accepts "feature" and "segment"; throws InvalidArgument listing the choices.
Per parse_per(const std::string& name);
const char* to_string(Per p);

class LayerIndex {
 public:
  // Builds `structure` over the items in memory.
  static LayerIndex build(LayerItems&& items, Structure structure);
  // Queries the mapped sidecar in place.
  static LayerIndex adopt(Sidecar&& sidecar);

  Per per() const { return per_; }
  Structure structure() const { return structure_; }
  bool has_polygons() const { return has_polygons_; }
  std::size_t size() const { return records_.size(); }
  Box2 bounds() const { return bounds_; }
  const std::string& layer_name() const { return layer_name_; }
  // The layer's fingerprint when the sidecar was written (SidecarInfo::source); null for an
  // index built in memory.
  const Fingerprint* source() const { return source_ ? &*source_ : nullptr; }
  // Every record (from a sidecar: verified first, once).
  std::span<const ItemRecord> records() const {
    if (check_) check_->touch(records_.data(), records_.size_bytes());
    return records_;
  }
  const PackedRTree2* packed() const { return std::get_if<PackedRTree2>(&tree_); }

  // visit(record, box) for every entry whose box meets w; returning false stops.
  template <class Visit>
  void window(const Box2& w, Visit&& visit) const {
    std::visit(
        [&]<BoxIndex Tree>(const Tree& t) {
          t.query(w, [&](Id id, const Box2& b) {
            return id < records_.size() ? visit(record(Id(id)), b) : true;
          });
        },
        tree_);
  }
  // visit(record, box, box_distance) for entries nearest first, found one at a time (distance
  // browsing: the work done is what the answers the caller takes need); returning false stops.
  template <class Visit>
  void browse(const Point2& p, Visit&& visit) const {
    std::visit(
        [&]<NearestIndex Tree>(const Tree& t) {
          t.browse(p, [&](Id id, const Box2& b, double d) {
            return id < records_.size() ? visit(record(Id(id)), b, d) : true;
          });
        },
        tree_);
  }
  // visit(record, box, key) for entries in increasing key(box) (>= 0; infinity leaves a box
  // out, and key must not decrease from a node to what it holds) until visit returns false.
  // Packed trees walk nearest key first; the others collect the entries meeting `search`
  // (which must hold every box of finite key) and sort them.
  template <class Key, class Visit>
  void ordered(const Box2& search, Key&& key, Visit&& visit) const {
    if (const PackedRTree2* t = packed()) {
      t->ordered(key, [&](Id id, const Box2& b, double k) {
        return id < records_.size() ? visit(record(Id(id)), b, k) : true;
      });
      return;
    }
    struct Hit {
      double key;
      const ItemRecord* record;
      Box2 box;
    };
    std::vector<Hit> hits;
    window(search, [&](const ItemRecord& r, const Box2& b) {
      const double k = key(b);
      if (k < std::numeric_limits<double>::infinity()) hits.push_back({k, &r, b});
      return true;
    });
    std::sort(hits.begin(), hits.end(), [](const Hit& a, const Hit& b) { return a.key < b.key; });
    for (const Hit& h : hits)
      if (!visit(*h.record, h.box, h.key)) return;
  }
  // The features of the index numbered densely (0, 1, ... in order of first appearance), so
  // that per-query state is a flat array: the FID of every feature and, except for a packed
  // tree per segment, the feature of every item (of_item). For a packed tree per segment,
  // instead one hierarchy of boxes per feature over its entries: a level-0 node is the part of
  // one leaf of the tree that belongs to one feature (bounded by the leaf's box; an entry of
  // the leaf is the feature's when its record has the feature's FID), a level-l node groups up
  // to 16 level-(l - 1) nodes of one feature, and `roots` names each feature's top node.
  // Nearest-n walks these: no node mixes features, so a feature is measured without reading
  // any other's segments. A sidecar stores them (sidecar.hpp), and they are read in place as
  // the tree is, each node checked as it is read (so that a forged file cannot lead a walk
  // outside the mapping); otherwise they are built on first use, once for all threads.
  struct Features {
    static constexpr std::uint32_t none = 0xffffffffu;
    using Node = HierarchyNode;
    bool hierarchical = false;  // a packed tree per segment: levels and roots, no of_item
    // Every record: verified whole, or with stored hierarchies as mapped (read through
    // record()).
    std::span<const ItemRecord> records;
    // Hierarchical: the tree's item indices (PackedRTree2::item_indices()), read through
    // leaf_items().
    std::span<const std::uint32_t> items;
    loci::detail::LargeVector<std::uint32_t> of_item;
    std::span<const std::int64_t> fid;                       // read through fid_of()
    std::unordered_map<std::int64_t, std::uint32_t> number;  // fid -> feature; not hierarchical
    std::vector<std::span<const Node>> levels;               // read through node()
    std::span<const HierarchyRoot> roots;                    // read through root()
    // A packed tree over the roots' boxes (entry r: roots[r]), so that a query meets only
    // the features near it, however many the layer has.
    PackedRTree2 root_tree;
    // Hierarchical: the convex hull of every feature's segment ends, read through hull().
    std::span<const std::uint32_t> hull_first;  // features + 1 starts in hull_points
    std::span<const Point2> hull_points;

    // Node i of `level`, checked: its feature, and its leaf or the range of its children
    // (at most 16), lie within the arrays. Throws loci::Error for a corrupt file.
    // `touched`: the node was read already (as one of children()).
    [[gnu::always_inline]] const Node& node(std::uint32_t level, std::uint32_t i,
                                            bool touched = false) const {
      if (level >= levels.size() || i >= levels[level].size()) corrupt();
      const Node& n = levels[level][i];
      if (check && !touched) check->touch(&n, sizeof n);
      const bool fits = n.feature < fid.size() &&
                        (level == 0 ? n.first == n.last && n.first < leaves
                                    : n.first < n.last && n.last <= levels[level - 1].size() &&
                                          n.last - n.first <= PackedRTree2::node_size);
      if (!fits) corrupt();
      return n;
    }
    // The children of n, a node of level > 0 given by node() (their boxes may be read; the
    // nodes themselves are checked when node() gives them).
    [[gnu::always_inline]] std::span<const Node> children(const Node& n,
                                                          std::uint32_t level) const {
      const std::span<const Node> c = levels[level - 1].subspan(n.first, n.last - n.first);
      if (check) check->touch(c.data(), c.size_bytes());
      return c;
    }
    HierarchyRoot root(Id r) const {
      if (r >= roots.size()) corrupt();
      if (check) check->touch(&roots[r], sizeof(HierarchyRoot));
      return roots[r];
    }
    // The hull of feature f < fid.size() (geom/convex_hull.hpp), checked to lie within the
    // array and to hold a vertex (every feature has a segment); empty when the hulls are not
    // there.
    std::span<const Point2> hull(std::uint32_t f) const {
      if (hull_first.size() <= f + 1) return {};
      if (check) check->touch(&hull_first[f], 2 * sizeof(std::uint32_t));
      const std::uint32_t first = hull_first[f], last = hull_first[f + 1];
      if (first >= last || last > hull_points.size()) corrupt();
      const std::span<const Point2> h = hull_points.subspan(first, last - first);
      if (check) check->touch(h.data(), h.size_bytes());
      return h;
    }
    std::int64_t fid_of(std::uint32_t f) const {
      if (check) check->touch(&fid[f], sizeof(std::int64_t));
      return fid[f];
    }
    // The item indices of leaf b < leaves, the 16 slots of its packed positions.
    [[gnu::always_inline]] const std::uint32_t* leaf_items(std::size_t b) const {
      const std::uint32_t* at = items.data() + b * PackedRTree2::node_size;
      if (check) check->touch(at, PackedRTree2::node_size * sizeof(std::uint32_t));
      return at;
    }
    // The record of item `id`, or null for an id out of range (a corrupt index).
    [[gnu::always_inline]] const ItemRecord* record(Id id) const {
      if (id >= records.size()) return nullptr;
      if (check) check->touch(&records[id], sizeof(ItemRecord));
      return &records[id];
    }
    // The arrays as write_sidecar stores them.
    Hierarchies stored() const { return {fid, levels, roots, &root_tree, hull_first, hull_points}; }

    const loci::detail::LazyCheck* check = nullptr;  // stored: what is read is touched first
    std::size_t leaves = 0;                          // hierarchical: the tree's leaves
    // Hierarchical: the nodes of every level. In a valid file a node belongs to one feature
    // and one parent, so a query's walks visit at most twice as many (its dives, then its
    // descents); a forged file whose nodes share children (a walk of 16^levels paths) is
    // refused when its walks go past that.
    std::size_t node_count = 0;
    std::string path;  // stored: the sidecar, for messages
    // What fid, levels and roots view when they are built here.
    std::vector<std::int64_t> own_fid;
    std::vector<loci::detail::LargeVector<Node>> own_levels;
    std::vector<HierarchyRoot> own_roots;
    std::vector<std::uint32_t> own_hull_first;
    std::vector<Point2> own_hull_points;

    // Throws loci::Error: the stored hierarchies are inconsistent.
    [[noreturn]] void corrupt() const;
  };
  // The hierarchies of a packed tree per segment over `records` (hierarchical is false
  // otherwise), built; `tree` must outlive them.
  static Features build_features(const PackedRTree2* tree, Per per,
                                 std::span<const ItemRecord> records);
  const Features& features() const;

 private:
  std::variant<PackedRTree2, RStarTree2, RTree2> tree_;
  Per per_ = Per::feature;
  Structure structure_ = Structure::packed_hilbert;
  bool has_polygons_ = false;
  Box2 bounds_ = Box2::empty();
  std::string layer_name_;
  std::optional<Fingerprint> source_;
  std::vector<ItemRecord> own_records_;
  std::span<const ItemRecord> records_;
  std::shared_ptr<const void> keep_alive_;
  const loci::detail::LazyCheck* check_ = nullptr;  // a sidecar's, owned by keep_alive_
  const ItemRecord& record(Id id) const {
    if (check_) check_->touch(&records_[id], sizeof(ItemRecord));
    return records_[id];
  }
  struct LazyFeatures;
  std::shared_ptr<LazyFeatures> features_;
  std::shared_ptr<const MappedHierarchies> stored_;  // a sidecar's hierarchies
  std::span<const std::uint32_t> mapped_items_;      // and its tree's item indices
};

// Features of a per-segment index one of whose polygons contains p (the crossing parity of
// that polygon's rings, as exact.hpp counts it); empty for a per-feature index or a layer
// without polygons. A point on a ring
// may or may not count: callers test the rings themselves first.
std::vector<std::int64_t> containing_polygons(const LayerIndex& index, const Point2& p);
// The same answer, with the features' hierarchies at hand (LayerIndex::features() of a packed
// per-segment index): only the features whose box holds p are counted, along whichever axis
// direction leaves their boxes soonest.
std::vector<std::int64_t> containing_polygons(const LayerIndex& index, const Point2& p,
                                              const LayerIndex::Features& features);

struct Query {
  enum class Kind : std::uint8_t { bbox, point, segment, within, nearest };
  Kind kind = Kind::bbox;
  Box2 box{};          // bbox
  Point2 point{};      // point, within, nearest
  Segment2 segment{};  // segment
  double radius = 0;   // within
  std::size_t k = 1;   // nearest
  bool first = false;  // segment: only the feature met first from the segment's start
};

struct Answer {
  std::size_t query;  // 1-based number of the query in its batch
  std::int64_t fid;
  double distance;  // within, nearest, and a segment's first hit (along it); NaN otherwise
  Point2 at{std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
  // segment: the first point of the segment in the feature; NaN otherwise
};

// A layer's geometries read whole, once, for all the LayerQuery objects of a batch that share
// it: for text formats (GeoJSON, CSV, GML, KML...), where GDAL finds a feature by FID by
// parsing the file from its start. Layers read by FID in place (shapefile, GeoPackage,
// FlatGeobuf...) are not read whole. Thread-safe.
class LayerGeometries {
 public:
  LayerGeometries(std::string path, std::string name);
  ~LayerGeometries();
  // The feature's flattened geometry, the layer read whole on the first call; null when the
  // layer is one read by FID in place. Throws loci::Error for a FID not in the layer.
  const FlatGeometry* find(std::int64_t fid);
  // Takes the layer's geometries as already read (by the index build); a no-op after the
  // first find() or adopt().
  void adopt(std::unordered_map<std::int64_t, FlatGeometry>&& all);

 private:
  std::string path_, name_;
  std::once_flag once_;
  bool whole_ = false;
  std::unordered_map<std::int64_t, FlatGeometry> all_;
};

class LayerQuery {
 public:
  // `layer_path`/`layer_name` are opened only when a per-feature refinement needs geometry;
  // `shared` (made here when null) lets the queries of several threads read a text layer once.
  LayerQuery(const LayerIndex& index, std::string layer_path, std::string layer_name,
             std::shared_ptr<LayerGeometries> shared = {});
  ~LayerQuery();
  LayerQuery(const LayerQuery&) = delete;
  LayerQuery& operator=(const LayerQuery&) = delete;

  // Appends the answers of q to out: windows in ascending FID, nearest-n nearest first and, at
  // equal distances, in ascending FID (so that the k nearest are the first k rows of any
  // larger k's answer, per feature and per segment alike).
  // Throws InvalidArgument for k = 0 or a negative radius, InvalidGeometry for a NaN input.
  void run(const Query& q, std::size_t number, bool candidates_only, std::vector<Answer>& out);

 private:
  // Nearest-n per segment on a packed tree, through the features' hierarchies (the two passes
  // described at the top of this file).
  void nearest_through_hierarchies(const Query& q, std::size_t number, bool candidates_only,
                                   const LayerIndex::Features& features, std::vector<Answer>& out);
  struct Geometries;
  const LayerIndex& index_;
  std::unique_ptr<Geometries> geometries_;
  // Nearest-n state per feature of index_.features(), valid where stamp == generation_.
  struct FeatureState {
    std::uint32_t stamp = 0;
    bool done = false;
    double best = 0;
  };
  std::vector<FeatureState> state_;
  std::uint32_t generation_ = 0;
  // A new query's stamp, state_ sized for `features` (every stamp forgotten when it wraps).
  void next_generation(std::size_t features);
  // A feature ranked by nearest-n: by distance (squared through the hierarchies), then FID.
  struct Ranked {
    double d;
    std::int64_t fid;
    std::uint32_t f;
    friend bool operator<(const Ranked& a, const Ranked& b) {
      return a.d < b.d || (a.d == b.d && a.fid < b.fid);
    }
    friend bool operator>(const Ranked& a, const Ranked& b) { return b < a; }
  };
  // Nearest-n's arrays, kept between queries: the k best, the k smallest upper bounds, and
  // the candidate features (squared bounds, root).
  std::vector<Ranked> top_;
  std::vector<double> bounds_;
  struct Candidate {
    double upper, lower;
    std::uint32_t root;
    std::uint32_t leaf;  // the leaf whose segments gave `upper`, not read again
    bool exact;          // `upper` is the feature's distance (from its hull): not descended
  };
  std::vector<Candidate> candidates_;
};

}  // namespace loci::io
