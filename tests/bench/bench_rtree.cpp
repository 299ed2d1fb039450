// bench_rtree: the R-tree family against its peers on the same data, in one process.
//
// Workload A: boxes of real coastline segments (Natural Earth countries-coastline-1m, one box
// per segment, shuffled with a fixed seed, the first N kept); workload B: N uniform boxes.
// On each: build time, window queries centred on data and sized for about 100 hits, and
// nearest-10 queries, for
//   loci PackedRTree (Hilbert, STR), loci RStarTree / RTree (inserted one by one),
//   Boost.Geometry rtree (packing constructor with rstar<16>; insertion with rstar<16> and
//   quadratic<16>), GEOS STRtree (C API, node capacity 10), libspatialindex (STR bulk load
//   and R* insertion, memory storage, capacity 16).
// Every structure must return the same number of window hits and the same nearest
// distances, or the benchmark fails. Times are medians of --reps repetitions; the ratios
// at the end are the figures the README quotes. For instruction counts, run it under
// `valgrind --tool=callgrind` (tests/bench/callgrind.sh): each timed phase is its own
// function, so callgrind_annotate shows each phase's inclusive count.
#include <geos_c.h>
#include <spatialindex/SpatialIndex.h>

#include <algorithm>
#include <boost/geometry.hpp>
#include <boost/geometry/index/rtree.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "loci/index/packed_rtree.hpp"
#include "loci/index/rstar_tree.hpp"
#include "loci/index/rtree.hpp"
#include "loci/io/layer_reader.hpp"

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;

namespace {

#define PHASE __attribute__((noinline))

using BPoint = bg::model::point<double, 2, bg::cs::cartesian>;
using BBox = bg::model::box<BPoint>;
using BValue = std::pair<BBox, std::uint32_t>;

// Counts the bytes Boost's rtree holds, for the bytes-per-box comparison.
inline std::size_t g_boost_bytes = 0;
template <class T>
struct CountingAllocator {
  using value_type = T;
  CountingAllocator() = default;
  template <class U>
  CountingAllocator(const CountingAllocator<U>&) {}
  T* allocate(std::size_t n) {
    g_boost_bytes += n * sizeof(T);
    return std::allocator<T>().allocate(n);
  }
  void deallocate(T* p, std::size_t n) {
    g_boost_bytes -= n * sizeof(T);
    std::allocator<T>().deallocate(p, n);
  }
  friend bool operator==(const CountingAllocator&, const CountingAllocator&) { return true; }
};
template <class Params>
using BoostTree = bgi::rtree<BValue, Params, bgi::indexable<BValue>, bgi::equal_to<BValue>,
                             CountingAllocator<BValue>>;

struct Options {
  std::size_t n = 1000000;
  std::size_t queries = 10000;
  int reps = 5;
  std::string workload = "both";
  bool slow_peers = true;  // libspatialindex R* insertion takes minutes at 1M
  std::string only;        // run only the rows whose name contains this
};

struct Workload {
  std::string name;
  std::vector<loci::Box2> boxes;
  std::vector<loci::Box2> windows;
  std::vector<loci::Point2> points;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double time_ms(const std::function<void()>& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

double median_ms(int reps, const std::function<void()>& f) {
  std::vector<double> t;
  for (int r = 0; r < reps; ++r)
    t.push_back(time_ms(f));
  return median(t);
}

// Windows centred on random data boxes; one square side for all, chosen so that the mean hit
// count over the set is about `target`.
std::vector<loci::Box2> make_windows(const std::vector<loci::Box2>& boxes, std::size_t count,
                                     double target, std::mt19937_64& rng) {
  std::vector<loci::Point2> centres(count);
  for (auto& c : centres)
    c = boxes[rng() % boxes.size()].center();
  const auto tree = loci::PackedRTree2::build(boxes);
  auto windows_of = [&](double side) {
    std::vector<loci::Box2> w(count);
    for (std::size_t i = 0; i < count; ++i)
      w[i] = {{centres[i][0] - side / 2, centres[i][1] - side / 2},
              {centres[i][0] + side / 2, centres[i][1] + side / 2}};
    return w;
  };
  auto mean_hits = [&](double side) {
    const auto w = windows_of(side);
    std::size_t hits = 0;
    for (std::size_t i = 0; i < std::min<std::size_t>(count, 500); ++i)
      hits += tree.query(w[i]).size();
    return double(hits) / double(std::min<std::size_t>(count, 500));
  };
  double lo = 0, hi = std::max(tree.bounds().extent(0), tree.bounds().extent(1));
  for (int it = 0; it < 50; ++it) {
    const double mid = (lo + hi) / 2;
    (mean_hits(mid) < target ? lo : hi) = mid;
  }
  return windows_of(hi);
}

Workload coastline(const Options& o) {
  Workload w{"A: coastline segments", {}, {}, {}};
  const std::string path =
      std::string(LOCI_DATASETS_DIR) + "/cache/countries-coastline-1m/map.geo.json";
  if (!std::filesystem::exists(path)) {
    std::printf("workload A skipped: %s is missing (run datasets/fetch.sh)\n", path.c_str());
    return w;
  }
  for (const auto& s : loci::io::read_segments(path))
    w.boxes.push_back(s.segment.box());
  std::mt19937_64 rng(42);
  std::shuffle(w.boxes.begin(), w.boxes.end(), rng);
  if (w.boxes.size() > o.n) w.boxes.resize(o.n);
  return w;
}

Workload uniform(const Options& o) {
  Workload w{"B: uniform boxes", {}, {}, {}};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> pos(0, 1000), side(0, 1.0);
  for (std::size_t i = 0; i < o.n; ++i) {
    const double x = pos(rng), y = pos(rng);
    w.boxes.push_back({{x, y}, {x + side(rng), y + side(rng)}});
  }
  return w;
}

BBox to_boost(const loci::Box2& b) {
  return {{b.min[0], b.min[1]}, {b.max[0], b.max[1]}};
}

struct Result {
  double build_ms = 0;
  double window_ms = 0;
  double nearest_ms = 0;
  double bytes_per_box = 0;
  std::size_t window_hits = 0;
  double nearest_sum = 0;
  bool has_window = false, has_nearest = false;
};

// ---- loci ----------------------------------------------------------------------------------

template <class Tree>
PHASE std::size_t loci_windows(const Tree& t, const std::vector<loci::Box2>& ws) {
  std::size_t hits = 0;
  for (const auto& w : ws)
    t.query(w, [&](loci::Id, const loci::Box2&) { return ++hits, true; });
  return hits;
}

template <class Tree>
PHASE double loci_nearest(const Tree& t, const std::vector<loci::Point2>& ps) {
  double sum = 0;
  for (const auto& p : ps)
    t.nearest(p, 10, [&](loci::Id, const loci::Box2&, double d) { return sum += d, true; });
  return sum;
}

PHASE loci::PackedRTree2 loci_pack(const std::vector<loci::Box2>& boxes, loci::Packing p) {
  return loci::PackedRTree2::build(boxes, p);
}

template <class Tree>
PHASE void loci_insert_all(Tree& t, const std::vector<loci::Box2>& boxes) {
  for (std::size_t i = 0; i < boxes.size(); ++i)
    t.insert(boxes[i], i);
}

template <class Tree>
void query_loci(const Tree& t, const Workload& w, const Options& o, Result& r) {
  r.window_ms = median_ms(o.reps, [&] { r.window_hits = loci_windows(t, w.windows); });
  r.nearest_ms = median_ms(o.reps, [&] { r.nearest_sum = loci_nearest(t, w.points); });
  r.has_window = r.has_nearest = true;
}

Result run_loci_packed(const Workload& w, const Options& o, loci::Packing p) {
  Result r;
  loci::PackedRTree2 t;
  r.build_ms = median_ms(o.reps, [&] { t = loci_pack(w.boxes, p); });
  r.bytes_per_box = double(t.memory_bytes()) / double(w.boxes.size());
  query_loci(t, w, o, r);
  return r;
}

template <class Tree>
Result run_loci_inserted(const Workload& w, const Options& o) {
  Result r;
  std::vector<double> times;
  Tree kept;
  for (int rep = 0; rep < std::max(1, o.reps / 2); ++rep) {
    Tree t;
    times.push_back(time_ms([&] { loci_insert_all(t, w.boxes); }));
    if (rep == 0) kept = std::move(t);
  }
  r.build_ms = median(times);
  r.bytes_per_box = double(kept.memory_bytes()) / double(w.boxes.size());
  query_loci(kept, w, o, r);
  return r;
}

// ---- Boost.Geometry ------------------------------------------------------------------------

template <class Tree>
PHASE std::size_t boost_windows(const Tree& t, const std::vector<BBox>& ws) {
  std::size_t hits = 0;
  for (const auto& w : ws) {
    // a counting output iterator: nothing is stored, as for the loci visitor
    struct Count {
      std::size_t* n;
      Count& operator*() { return *this; }
      Count& operator=(const BValue&) { return ++*n, *this; }
      Count& operator++() { return *this; }
      Count operator++(int) { return *this; }
    };
    t.query(bgi::intersects(w), Count{&hits});
  }
  return hits;
}

template <class Tree>
PHASE double boost_nearest(const Tree& t, const std::vector<BPoint>& ps) {
  double sum = 0;
  std::vector<BValue> out;
  for (const auto& p : ps) {
    out.clear();
    t.query(bgi::nearest(p, 10), std::back_inserter(out));
    for (const auto& v : out)
      sum += bg::distance(p, v.first);
  }
  return sum;
}

template <class Params>
PHASE void boost_pack(std::unique_ptr<BoostTree<Params>>& t, const std::vector<BValue>& values) {
  t = std::make_unique<BoostTree<Params>>(values.begin(), values.end());
}

template <class Params>
PHASE void boost_insert_all(BoostTree<Params>& t, const std::vector<BValue>& values) {
  for (const auto& v : values)
    t.insert(v);
}

template <class Params>
Result run_boost(const Workload& w, const Options& o, bool packed) {
  std::vector<BValue> values;
  for (std::size_t i = 0; i < w.boxes.size(); ++i)
    values.push_back({to_boost(w.boxes[i]), std::uint32_t(i)});
  std::vector<BBox> ws;
  for (const auto& b : w.windows)
    ws.push_back(to_boost(b));
  std::vector<BPoint> ps;
  for (const auto& p : w.points)
    ps.push_back({p[0], p[1]});
  Result r;
  std::unique_ptr<BoostTree<Params>> t;
  std::vector<double> times;
  for (int rep = 0; rep < (packed ? o.reps : std::max(1, o.reps / 2)); ++rep) {
    t.reset();
    const std::size_t before = g_boost_bytes;
    if (packed) {
      times.push_back(time_ms([&] { boost_pack<Params>(t, values); }));
    } else {
      t = std::make_unique<BoostTree<Params>>();
      times.push_back(time_ms([&] { boost_insert_all<Params>(*t, values); }));
    }
    r.bytes_per_box = double(g_boost_bytes - before) / double(values.size());
  }
  r.build_ms = median(times);
  r.window_ms = median_ms(o.reps, [&] { r.window_hits = boost_windows(*t, ws); });
  r.nearest_ms = median_ms(o.reps, [&] { r.nearest_sum = boost_nearest(*t, ps); });
  r.has_window = r.has_nearest = true;
  return r;
}

// ---- GEOS STRtree (C API) ------------------------------------------------------------------

PHASE GEOSSTRtree* geos_build(GEOSContextHandle_t ctx, const std::vector<GEOSGeometry*>& geoms,
                              std::vector<std::uint32_t>& items) {
  GEOSSTRtree* t = GEOSSTRtree_create_r(ctx, 10);
  for (std::size_t i = 0; i < geoms.size(); ++i)
    GEOSSTRtree_insert_r(ctx, t, geoms[i], &items[i]);
  // GEOS 3.11 builds lazily on the first query: make that happen inside the build time.
  GEOSGeometry* nothing = GEOSGeom_createRectangle_r(ctx, 1e300, 1e300, 1e300, 1e300);
  GEOSSTRtree_query_r(
      ctx, t, nothing, [](void*, void*) {}, nullptr);
  GEOSGeom_destroy_r(ctx, nothing);
  return t;
}

PHASE std::size_t geos_windows(GEOSContextHandle_t ctx, GEOSSTRtree* t,
                               const std::vector<GEOSGeometry*>& ws) {
  std::size_t hits = 0;
  for (auto* w : ws)
    GEOSSTRtree_query_r(
        ctx, t, w, [](void*, void* n) { ++*static_cast<std::size_t*>(n); }, &hits);
  return hits;
}

Result run_geos(const Workload& w, const Options& o) {
  GEOSContextHandle_t ctx = GEOS_init_r();
  std::vector<GEOSGeometry*> geoms, ws;
  for (const auto& b : w.boxes)
    geoms.push_back(GEOSGeom_createRectangle_r(ctx, b.min[0], b.min[1], b.max[0], b.max[1]));
  for (const auto& b : w.windows)
    ws.push_back(GEOSGeom_createRectangle_r(ctx, b.min[0], b.min[1], b.max[0], b.max[1]));
  std::vector<std::uint32_t> items(w.boxes.size());
  Result r;
  GEOSSTRtree* t = nullptr;
  std::vector<double> times;
  for (int rep = 0; rep < o.reps; ++rep) {
    if (t) GEOSSTRtree_destroy_r(ctx, t);
    times.push_back(time_ms([&] { t = geos_build(ctx, geoms, items); }));
  }
  r.build_ms = median(times);
  r.window_ms = median_ms(o.reps, [&] { r.window_hits = geos_windows(ctx, t, ws); });
  r.has_window = true;
  GEOSSTRtree_destroy_r(ctx, t);
  for (auto* g : geoms)
    GEOSGeom_destroy_r(ctx, g);
  for (auto* g : ws)
    GEOSGeom_destroy_r(ctx, g);
  GEOS_finish_r(ctx);
  return r;
}

// ---- libspatialindex -----------------------------------------------------------------------

class BoxStream : public SpatialIndex::IDataStream {
 public:
  explicit BoxStream(const std::vector<loci::Box2>& b) : boxes_(b) {}
  SpatialIndex::IData* getNext() override {
    const auto& b = boxes_[i_];
    SpatialIndex::Region r(b.min.c, b.max.c, 2);
    return new SpatialIndex::RTree::Data(0, nullptr, r, SpatialIndex::id_type(i_++));
  }
  bool hasNext() override { return i_ < boxes_.size(); }
  uint32_t size() override { return uint32_t(boxes_.size()); }
  void rewind() override { i_ = 0; }

 private:
  const std::vector<loci::Box2>& boxes_;
  std::size_t i_ = 0;
};

struct CountVisitor : SpatialIndex::IVisitor {
  std::size_t hits = 0;
  double sum = 0;
  const double* p = nullptr;
  void visitNode(const SpatialIndex::INode&) override {}
  void visitData(const SpatialIndex::IData& d) override {
    // nearestNeighborQuery reports every entry tied with the k-th: count the first k only
    if (p && hits == 10) return;
    ++hits;
    if (p) {
      SpatialIndex::IShape* s;
      d.getShape(&s);
      sum += s->getMinimumDistance(SpatialIndex::Point(p, 2));
      delete s;
    }
  }
  void visitData(std::vector<const SpatialIndex::IData*>& v) override { hits += v.size(); }
};

PHASE std::size_t sidx_windows(SpatialIndex::ISpatialIndex& t, const std::vector<loci::Box2>& ws) {
  CountVisitor v;
  for (const auto& w : ws)
    t.intersectsWithQuery(SpatialIndex::Region(w.min.c, w.max.c, 2), v);
  return v.hits;
}

PHASE double sidx_nearest(SpatialIndex::ISpatialIndex& t, const std::vector<loci::Point2>& ps) {
  double sum = 0;
  for (const auto& p : ps) {
    CountVisitor v;
    v.p = p.c;
    t.nearestNeighborQuery(10, SpatialIndex::Point(p.c, 2), v);
    sum += v.sum;
  }
  return sum;
}

PHASE SpatialIndex::ISpatialIndex* sidx_build(SpatialIndex::IStorageManager& sm,
                                              const std::vector<loci::Box2>& boxes, bool bulk) {
  SpatialIndex::id_type index_id;
  if (bulk) {
    BoxStream stream(boxes);
    return SpatialIndex::RTree::createAndBulkLoadNewRTree(SpatialIndex::RTree::BLM_STR, stream, sm,
                                                          0.7, 16, 16, 2,
                                                          SpatialIndex::RTree::RV_RSTAR, index_id);
  }
  auto* t = SpatialIndex::RTree::createNewRTree(sm, 0.7, 16, 16, 2, SpatialIndex::RTree::RV_RSTAR,
                                                index_id);
  for (std::size_t i = 0; i < boxes.size(); ++i)
    t->insertData(0, nullptr, SpatialIndex::Region(boxes[i].min.c, boxes[i].max.c, 2),
                  SpatialIndex::id_type(i));
  return t;
}

Result run_sidx(const Workload& w, const Options& o, bool bulk) {
  Result r;
  std::unique_ptr<SpatialIndex::IStorageManager> sm(
      SpatialIndex::StorageManager::createNewMemoryStorageManager());
  std::unique_ptr<SpatialIndex::ISpatialIndex> t;
  r.build_ms = time_ms([&] { t.reset(sidx_build(*sm, w.boxes, bulk)); });
  const int reps = std::max(1, o.reps / 2);
  r.window_ms = median_ms(reps, [&] { r.window_hits = sidx_windows(*t, w.windows); });
  r.nearest_ms = median_ms(reps, [&] { r.nearest_sum = sidx_nearest(*t, w.points); });
  r.has_window = r.has_nearest = true;
  return r;
}

// ---- report --------------------------------------------------------------------------------

bool run_workload(Workload w, const Options& o) {
  if (w.boxes.empty()) return true;
  std::mt19937_64 rng(99);
  w.windows = make_windows(w.boxes, o.queries, 100.0, rng);
  for (std::size_t i = 0; i < o.queries; ++i)
    w.points.push_back(w.boxes[rng() % w.boxes.size()].center());
  std::printf(
      "\n== workload %s: %zu boxes, %zu windows (side %.4g), %zu nearest-10 queries, median of "
      "%d\n",
      w.name.c_str(), w.boxes.size(), w.windows.size(), w.windows[0].extent(0), w.points.size(),
      o.reps);

  std::vector<std::pair<std::string, Result>> rows;
  auto add = [&](const std::string& name, auto&& run) {
    if (!o.only.empty() && name.find(o.only) == std::string::npos) return;
    const Result r = run();
    rows.push_back({name, r});
    std::printf("%-34s build %9.1f ms", name.c_str(), r.build_ms);
    if (r.has_window) std::printf("  windows %10.0f q/s", 1000.0 * o.queries / r.window_ms);
    if (r.has_nearest) std::printf("  nearest-10 %9.0f q/s", 1000.0 * o.queries / r.nearest_ms);
    if (r.bytes_per_box > 0) std::printf("  %6.1f B/box", r.bytes_per_box);
    std::printf("\n");
    std::fflush(stdout);
  };
  add("loci PackedRTree (Hilbert)", [&] { return run_loci_packed(w, o, loci::Packing::hilbert); });
  add("loci PackedRTree (STR)", [&] { return run_loci_packed(w, o, loci::Packing::str); });
  add("Boost rtree pack rstar<16>", [&] { return run_boost<bgi::rstar<16>>(w, o, true); });
  add("GEOS STRtree (cap 10)", [&] { return run_geos(w, o); });
  add("libspatialindex STR (cap 16)", [&] { return run_sidx(w, o, true); });
  add("loci RStarTree<16> insert", [&] { return run_loci_inserted<loci::RStarTree2>(w, o); });
  add("loci RTree quadratic<16> insert",
      [&] { return run_loci_inserted<loci::RTree<2, loci::QuadraticSplit>>(w, o); });
  add("loci RTree linear<16> insert",
      [&] { return run_loci_inserted<loci::RTree<2, loci::LinearSplit>>(w, o); });
  add("Boost rtree insert rstar<16>", [&] { return run_boost<bgi::rstar<16>>(w, o, false); });
  add("Boost rtree insert quadratic<16>",
      [&] { return run_boost<bgi::quadratic<16>>(w, o, false); });
  if (o.slow_peers)
    add("libspatialindex R* insert (cap 16)", [&] { return run_sidx(w, o, false); });

  if (rows.empty()) return true;
  // Every structure must agree, or the figures mean nothing.
  bool ok = true;
  const Result& ref = rows.front().second;
  for (const auto& [name, r] : rows) {
    if (r.has_window && r.window_hits != ref.window_hits) {
      std::printf("MISMATCH: %s found %zu window hits, loci %zu\n", name.c_str(), r.window_hits,
                  ref.window_hits);
      ok = false;
    }
    if (r.has_nearest &&
        std::fabs(r.nearest_sum - ref.nearest_sum) > 1e-6 * (1 + ref.nearest_sum)) {
      std::printf("MISMATCH: %s nearest distances sum %.9g, loci %.9g\n", name.c_str(),
                  r.nearest_sum, ref.nearest_sum);
      ok = false;
    }
  }
  std::printf("answers agree: %s (%zu window hits, %.1f per window)\n", ok ? "yes" : "NO",
              ref.window_hits, double(ref.window_hits) / double(o.queries));

  auto find = [&](const std::string& n) -> const Result* {
    for (const auto& [name, r] : rows)
      if (name == n) return &r;
    return nullptr;
  };
  std::printf("ratios (target in brackets):\n");
  using Figure = double (*)(const Result& ours, const Result& peer);
  const Figure windows_faster = [](const Result& a, const Result& b) {
    return b.window_ms / a.window_ms;
  };
  const Figure nearest_faster = [](const Result& a, const Result& b) {
    return b.nearest_ms / a.nearest_ms;
  };
  const Figure build_share = [](const Result& a, const Result& b) {
    return a.build_ms / b.build_ms;
  };
  const Figure bytes_share = [](const Result& a, const Result& b) {
    return a.bytes_per_box / b.bytes_per_box;
  };
  auto ratio = [&](const char* ours, const char* what, const char* peer, Figure f,
                   const char* target) {
    const Result* a = find(ours);
    const Result* b = find(peer);
    if (a && b)
      std::printf("  %-28s %-28s %-28s %6.2f  [%s]\n", ours + 5, what, peer, f(*a, *b), target);
  };
  for (const char* packed : {"loci PackedRTree (Hilbert)", "loci PackedRTree (STR)"}) {
    ratio(packed, "windows/s over", "Boost rtree pack rstar<16>", windows_faster, ">= 2.0");
    ratio(packed, "windows/s over", "GEOS STRtree (cap 10)", windows_faster, ">= 1.5");
    ratio(packed, "nearest-10/s over", "Boost rtree pack rstar<16>", nearest_faster, ">= 2.0");
    ratio(packed, "build time / that of", "Boost rtree pack rstar<16>", build_share, "<= 0.5");
    ratio(packed, "bytes per box / that of", "Boost rtree pack rstar<16>", bytes_share, "<= 1.0");
  }
  ratio("loci RStarTree<16> insert", "build time / that of", "Boost rtree insert rstar<16>",
        build_share, "<= 0.5");
  ratio("loci RStarTree<16> insert", "windows/s over", "Boost rtree insert rstar<16>",
        windows_faster, ">= 1.0");
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "bench_rtree: %s needs a value\n", a.c_str());
        std::exit(1);
      }
      return argv[++i];
    };
    if (a == "--n")
      o.n = std::stoul(next());
    else if (a == "--queries")
      o.queries = std::stoul(next());
    else if (a == "--reps")
      o.reps = std::max(1, std::stoi(next()));
    else if (a == "--workload")
      o.workload = next();
    else if (a == "--no-slow-peers")
      o.slow_peers = false;
    else if (a == "--only")
      o.only = next();
    else {
      std::fprintf(stderr,
                   "usage: bench_rtree [--n N] [--queries Q] [--reps R] "
                   "[--workload coastline|uniform|both] [--no-slow-peers] [--only NAME]\n");
      return 1;
    }
  }
  bool ok = true;
  if (o.workload != "uniform") ok &= run_workload(coastline(o), o);
  if (o.workload != "coastline") ok &= run_workload(uniform(o), o);
  return ok ? 0 : 1;
}
