// Many threads query the same built indexes at once, every answer checked against brute force.
// Built indexes are immutable and const queries of dynamic ones may run concurrently (each
// header's thread-safety contract); this suite is what the ThreadSanitizer build of CI runs, so
// a data race in a query path (a shared scratch buffer, a lazily built member) fails it.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <random>
#include <thread>
#include <vector>

#include "loci/index/interval_tree.hpp"
#include "loci/index/kd_tree.hpp"
#include "loci/index/moving/conflicts.hpp"
#include "loci/index/moving/moving_grid.hpp"
#include "loci/index/packed_rtree.hpp"
#include "loci/index/pr_quadtree.hpp"
#include "loci/index/rstar_tree.hpp"
#include "loci/index/segment_tree.hpp"
#include "loci/index/segment_window_tree.hpp"
#include "support/fleet_data.hpp"
#include "support/random_data.hpp"

#ifdef LOCI_HAVE_IO
#include <unistd.h>

#include <filesystem>

#include "loci/io/commands.hpp"
#include "loci/io/sidecar.hpp"
#include "support/scratch.hpp"
#endif

namespace loci::test {
namespace {

constexpr int kThreads = 8;
constexpr int kQueriesPerThread = 300;

// Runs check(thread, rng) kQueriesPerThread times on each of kThreads threads at once and
// returns how many checks failed; a thread's queries come from its own fixed seed.
template <class Check>
std::size_t hammer(Check check) {
  std::atomic<std::size_t> failures{0};
  std::atomic<int> ready{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      std::mt19937_64 rng(1000 + t);
      ++ready;
      while (ready.load() < kThreads) {
      }  // start together, so that queries overlap
      for (int q = 0; q < kQueriesPerThread; ++q)
        if (!check(rng)) ++failures;
    });
  for (auto& th : threads)
    th.join();
  return failures.load();
}

std::vector<Id> sorted_ids(std::vector<Id> v) {
  std::sort(v.begin(), v.end());
  return v;
}

template <int D>
std::vector<Id> brute(const std::vector<Box<D>>& boxes, const Box<D>& w) {
  std::vector<Id> out;
  for (std::size_t i = 0; i < boxes.size(); ++i)
    if (intersects(boxes[i], w)) out.push_back(Id(i));
  return out;
}

template <int D>
double kth_distance(const std::vector<Box<D>>& boxes, const Point<D>& p, std::size_t k) {
  std::vector<double> d;
  for (const auto& b : boxes)
    d.push_back(std::sqrt(squared_distance(p, b)));
  std::nth_element(d.begin(), d.begin() + std::ptrdiff_t(k - 1), d.end());
  return d[k - 1];
}

// Window and nearest-10 answers of a box index against brute force.
template <class Tree>
bool box_query_is_exact(const Tree& tree, const std::vector<Box<2>>& boxes, std::mt19937_64& rng) {
  const Box<2> w = random_window<2>(rng);
  if (sorted_ids(tree.query(w)) != brute(boxes, w)) return false;
  const Point<2> p = random_point<2>(rng);
  const auto near = tree.nearest(p, 10);
  return near.size() == 10 && near.back().distance == kth_distance(boxes, p, 10);
}

TEST(ConcurrentQueries, PackedRTreeAndRStarTree) {
  const auto boxes = make_boxes<2>(Shape::clustered, 8000, 7);
  const auto packed = PackedRTree2::build(boxes);
  RStarTree2 rstar;
  for (std::size_t i = 0; i < boxes.size(); ++i)
    rstar.insert(boxes[i], Id(i));
  EXPECT_EQ(hammer([&](std::mt19937_64& rng) { return box_query_is_exact(packed, boxes, rng); }),
            0u);
  EXPECT_EQ(hammer([&](std::mt19937_64& rng) { return box_query_is_exact(rstar, boxes, rng); }),
            0u);
}

// The moving grid's windows and nearest-n from many threads at once (nearest-n leases its
// scratch per thread).
TEST(ConcurrentQueries, MovingGrid) {
  const auto fleet = make_fleet(Fleet::clustered, 3000, 12);
  MovingGrid<2> grid;
  for (std::size_t i = 0; i < fleet.size(); ++i)
    grid.insert(Id(i), fleet[i]);
  EXPECT_EQ(hammer([&](std::mt19937_64& rng) {
              std::uniform_real_distribution<double> u(0, 1000), ahead(0, 60);
              const double x = u(rng), y = u(rng), t = ahead(rng);
              const auto w = rng() % 2
                                 ? MovingWindow<2>::at({{x, y}, {x + 80, y + 80}}, t)
                                 : MovingWindow<2>::during({{x, y}, {x + 80, y + 80}}, t, t + 5);
              std::vector<Id> want;
              std::vector<double> d;
              const Point2 p{u(rng), u(rng)};
              for (std::size_t i = 0; i < fleet.size(); ++i) {
                if (inside(fleet[i], w)) want.push_back(Id(i));
                d.push_back(std::sqrt(squared_distance(position(fleet[i], t), p)));
              }
              std::nth_element(d.begin(), d.begin() + 4, d.end());
              const auto near = grid.nearest(p, t, 5);
              return sorted_ids(grid.query(w)) == want && near.size() == 5 &&
                     near.back().distance == d[4];
            }),
            0u);
}

// One-off conflict searches on many threads at once, each thread reusing its own leased
// finder over fleets of other sizes: every search visits the pairs a search on the main
// thread visited, in the same order.
TEST(ConcurrentQueries, ConflictSearchesLeasePerThread) {
  struct Case {
    std::vector<Motion2> fleet;
    double within;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> visits;
  };
  auto visits = [](const Case& c) {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
    find_conflicts<2>(c.fleet, c.within, 0, 10,
                      [&](std::uint32_t i, std::uint32_t j, const Approach&) {
                        out.push_back({i, j});
                        return true;
                      });
    return out;
  };
  std::vector<Case> cases;
  const Fleet kinds[] = {Fleet::uniform, Fleet::clustered, Fleet::identical, Fleet::head_on};
  for (std::size_t k = 0; k < 4; ++k) {
    cases.push_back({make_fleet(kinds[k], 300 + 150 * k, 70 + k), k == 2 ? 0.5 : 15.0, {}});
    cases.back().visits = visits(cases.back());
    EXPECT_GT(cases.back().visits.size(), 0u) << name(kinds[k]);
  }
  EXPECT_EQ(hammer([&](std::mt19937_64& rng) {
              const Case& c = cases[rng() % cases.size()];
              return visits(c) == c.visits;
            }),
            0u);
}

TEST(ConcurrentQueries, PointStructures) {
  std::mt19937_64 gen(11);
  std::vector<Point<2>> points(8000);
  std::vector<Box<2>> as_boxes;
  for (auto& p : points) {
    p = random_point<2>(gen);
    as_boxes.push_back(Box<2>::of_point(p));
  }
  const auto kd = KdTree2::build(points);
  const auto quad = PrQuadtree2::build(points, 8);
  EXPECT_EQ(hammer([&](std::mt19937_64& rng) { return box_query_is_exact(kd, as_boxes, rng); }),
            0u);
  EXPECT_EQ(hammer([&](std::mt19937_64& rng) { return box_query_is_exact(quad, as_boxes, rng); }),
            0u);
}

TEST(ConcurrentQueries, IntervalAndSegmentTrees) {
  std::mt19937_64 gen(13);
  std::uniform_real_distribution<double> u(0, 1000), len(0, 20);
  std::vector<Interval> intervals(20000);
  for (auto& iv : intervals) {
    iv.lo = u(gen);
    iv.hi = iv.lo + len(gen);
  }
  const auto itree = IntervalTree::build(intervals);
  const auto stree = SegmentTree::build(intervals);
  auto stab_is_exact = [&](const auto& tree, std::mt19937_64& rng) {
    const double x = std::uniform_real_distribution<double>(-10, 1030)(rng);
    std::vector<Id> ref;
    for (std::size_t i = 0; i < intervals.size(); ++i)
      if (intervals[i].contains(x)) ref.push_back(Id(i));
    return sorted_ids(tree.stab(x)) == ref;
  };
  EXPECT_EQ(hammer([&](std::mt19937_64& rng) { return stab_is_exact(itree, rng); }), 0u);
  EXPECT_EQ(hammer([&](std::mt19937_64& rng) { return stab_is_exact(stree, rng); }), 0u);
}

TEST(ConcurrentQueries, SegmentWindowTree) {
  std::mt19937_64 gen(17);
  std::uniform_real_distribution<double> step(-15, 15);
  std::vector<Segment<2>> segs(20000);
  for (auto& s : segs) {
    s.a = random_point<2>(gen);
    s.b = {s.a[0] + step(gen), s.a[1] + step(gen)};
  }
  const auto tree = SegmentWindowTree::build(segs);
  EXPECT_EQ(hammer([&](std::mt19937_64& rng) {
              const Box<2> w = random_window<2>(rng);
              std::vector<Id> ref;
              for (std::size_t i = 0; i < segs.size(); ++i)
                if (intersects(w, segs[i])) ref.push_back(Id(i));
              return sorted_ids(tree.query(w)) == ref;
            }),
            0u);
}

#ifdef LOCI_HAVE_IO
// One memory-mapped sidecar, its tree and records read by every thread at once.
TEST(ConcurrentQueries, MappedSidecar) {
  const auto boxes = make_boxes<2>(Shape::uniform, 8000, 19);
  const auto tree = PackedRTree2::build(boxes);
  std::vector<io::ItemRecord> records(boxes.size());
  for (std::size_t i = 0; i < records.size(); ++i)
    records[i] = {std::int64_t(1000 + i), 0, 0};
  io::SidecarInfo info;
  info.layer_name = "boxes";
  info.items = boxes.size();
  info.bounds = tree.bounds();
  const std::string path = "/tmp/loci-concurrency-" + std::to_string(::getpid()) + ".loci";
  io::write_sidecar(path, tree, records, info);
  const auto sidecar = io::Sidecar::open(path);
  ::unlink(path.c_str());
  const auto& mapped = sidecar.tree();
  const auto mapped_records = sidecar.records();
  EXPECT_EQ(hammer([&](std::mt19937_64& rng) {
              if (!box_query_is_exact(mapped, boxes, rng)) return false;
              const Box<2> w = random_window<2>(rng);
              bool fids_ok = true;
              mapped.query(w, [&](Id id, const Box<2>&) {
                fids_ok &=
                    id < mapped_records.size() && mapped_records[id].fid == std::int64_t(1000 + id);
                return true;
              });
              return fids_ok;
            }),
            0u);
}

// A batch of layer queries spread over threads (one LayerIndex, a LayerQuery per thread)
// writes what one thread writes: windows, nearest-n and point location on the sample, per
// segment (no GDAL handle is used off the main thread). The sample is copied first, so that a
// sidecar beside it (the quick start writes one) plays no part.
TEST(ConcurrentQueries, LayerBatchOnThreads) {
  const loci::test::Scratch dir("loci-concurrent-layer");
  std::filesystem::create_directories(dir.path());
  const std::string layer = (dir.path() / "coastline-denmark.geojson").string();
  std::filesystem::copy_file(std::string(LOCI_DATASETS_DIR) + "/samples/coastline-denmark.geojson",
                             layer);
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> x(7, 16), y(53.5, 58.5), w(0.01, 0.8);
  for (const auto kind :
       {io::Query::Kind::bbox, io::Query::Kind::nearest, io::Query::Kind::point}) {
    io::QueryOptions o;
    o.load.layer_path = layer;
    o.load.per = io::Per::segment;
    o.numbered = true;
    for (std::size_t n = 1; n <= 600; ++n) {
      io::Query q;
      q.kind = kind;
      q.k = 3;
      q.point = {x(rng), y(rng)};
      q.box = {q.point, {q.point[0] + w(rng), q.point[1] + w(rng)}};
      o.queries.emplace_back(n, q);
    }
    auto run = [&](unsigned jobs) {
      o.jobs = jobs;
      std::FILE* f = std::tmpfile();
      io::query_layer(o, f);
      std::string text;
      std::rewind(f);
      for (int c; (c = std::fgetc(f)) != EOF;)
        text += char(c);
      std::fclose(f);
      return text;
    };
    const std::string one = run(1);
    EXPECT_GT(one.size(), 600u);
    EXPECT_EQ(run(4), one);
  }
}
#endif

}  // namespace
}  // namespace loci::test
