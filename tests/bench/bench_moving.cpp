// Moving objects: updates and predictive window queries on loci's TPR*-tree and vectorized
// scan beside libspatialindex's TPR-tree, and conflicts (pairs within D during a horizon)
// beside a vectorized all-pairs closest-approach scan, on the same data in one process.
//
// Workload "objects" (the TPR-tree papers' setting): N points uniform in a 1000 x 1000 space,
// velocities uniform in [-3, 3] per axis and time unit, one tick per time unit; each tick 1/60
// of the objects (chosen at random) report their current position with a new velocity, then
// Q windows of 1% of the area (100 x 100) are asked about at times uniform in
// [now, now + 60] (the horizon). Every structure's answers are checked against the scan (ids
// sorted and compared); libspatialindex's are compared too and its disagreements counted, not
// hidden. libspatialindex needs a time interval (its timeslice is [t, t + 1e-9]), takes
// coordinates at the report time, and deletes by the shape it was given.
//
// Workload "conflicts": vessels one per 0.4 km^2 in a square (100,000 vessels: 200 km),
// speeds 0-12 m/s in any direction, D = 200 m, H = 600 s; loci's find_conflicts beside the
// all-pairs scan (each pair's closest approach, the inner loop written branch-free over
// structure-of-arrays so that the compiler vectorizes it), pair counts compared. The all-pairs
// scan is timed on a sample of rows and scaled by n / rows when N is large (it is quadratic).
//
// Usage: bench_moving [--objects N] [--ticks T] [--queries Q] [--vessels V] [--no-peer]
//        [--all-pairs-rows R]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <spatialindex/SpatialIndex.h>

#include "loci/index/moving/conflicts.hpp"
#include "loci/index/moving/moving_grid.hpp"
#include "loci/index/moving/moving_scan.hpp"
#include "loci/index/moving/star_tree.hpp"
#include "loci/index/moving/tpr_tree.hpp"

namespace {

using loci::Id;
using loci::Motion2;
using loci::MovingWindow;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

struct Options {
  std::size_t objects = 100000;
  int ticks = 10;
  int queries = 200;
  std::size_t vessels = 100000;
  std::size_t all_pairs_rows = 2000;
  bool peer = true;
  std::string only;  // "objects" or "conflicts": that part alone
};

// ---- libspatialindex ---------------------------------------------------------------------

struct IdCollector : SpatialIndex::IVisitor {
  std::vector<Id> ids;
  void visitNode(const SpatialIndex::INode&) override {}
  void visitData(const SpatialIndex::IData& d) override { ids.push_back(Id(d.getIdentifier())); }
  void visitData(std::vector<const SpatialIndex::IData*>& v) override {
    for (auto* d : v)
      ids.push_back(Id(d->getIdentifier()));
  }
};

class SidxTpr {
 public:
  explicit SidxTpr(double horizon)
      : storage_(SpatialIndex::StorageManager::createNewMemoryStorageManager()) {
    SpatialIndex::id_type id;
    tree_.reset(SpatialIndex::TPRTree::createNewTPRTree(
        *storage_, 0.7, 100, 100, 2, SpatialIndex::TPRTree::TPRV_RSTAR, horizon, id));
  }
  void insert(Id id, const Motion2& m) {
    SpatialIndex::MovingPoint p(m.p.c, m.v.c, m.t, INFINITY, 2);
    tree_->insertData(0, nullptr, p, SpatialIndex::id_type(id));
  }
  // Deletes by the shape given at insertion, as its API asks; false when it was not found.
  bool erase(Id id, const Motion2& old, double now) {
    SpatialIndex::MovingPoint p(old.p.c, old.v.c, old.t, now > old.t ? now : old.t + 1e-9, 2);
    try {
      return tree_->deleteData(p, SpatialIndex::id_type(id));
    } catch (...) {
      return false;
    }
  }
  std::vector<Id> query(const loci::Box2& b, double t) {
    const double zero[2] = {0, 0};
    SpatialIndex::MovingRegion r(b.min.c, b.max.c, zero, zero, t, t + 1e-9, 2);
    IdCollector v;
    tree_->intersectsWithQuery(r, v);
    std::sort(v.ids.begin(), v.ids.end());
    return v.ids;
  }

 private:
  std::unique_ptr<SpatialIndex::IStorageManager> storage_;
  std::unique_ptr<SpatialIndex::ISpatialIndex> tree_;
};

// ---- The moving-objects workload ---------------------------------------------------------

struct Report {
  Id id;
  Motion2 m;
};

// Per-tick medians of one contender.
struct Timing {
  std::vector<double> update_s, query_s;
  std::size_t nodes = 0;
};

void run_objects(const Options& o) {
  const double side = 1000, horizon = 60, qside = 100;
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> pos(0, side), vel(-3, 3), ahead(0, horizon),
      corner(0, side - qside);
  std::vector<Motion2> state(o.objects);
  for (auto& m : state)
    m = {0, {pos(rng), pos(rng)}, {vel(rng), vel(rng)}};
  std::vector<Id> ids(o.objects);
  for (std::size_t i = 0; i < ids.size(); ++i)
    ids[i] = i;

  loci::TprParams<2> params;
  params.horizon = horizon;
  params.query_extent = {qside, qside};
  loci::TprParams<2> paper = params;
  paper.in_place_updates = false;
  loci::TprTree<2> tpr(paper), inplace(params), packed(params);
  loci::MovingScan<2> scan;
  loci::StarTree<2> star;
  loci::MovingGridParams<2> grid_params;
  grid_params.horizon = horizon;
  loci::MovingGrid<2> grid(grid_params);
  Timing t_tpr, t_inplace, t_packed, t_scan, t_sidx, t_star, t_grid;
  std::unique_ptr<SidxTpr> sidx;
  std::size_t sidx_wrong = 0, sidx_missing = 0, sidx_extra = 0, sidx_failed_deletes = 0;

  auto timed = [](auto&& f) {
    const auto t0 = Clock::now();
    f();
    return seconds_since(t0);
  };
  const double tpr_build = timed([&] {
    for (std::size_t i = 0; i < state.size(); ++i)
      tpr.insert(i, state[i]);
  });
  timed([&] {
    for (std::size_t i = 0; i < state.size(); ++i)
      inplace.insert(i, state[i]);
  });
  const double star_build = timed([&] {
    for (std::size_t i = 0; i < state.size(); ++i)
      star.insert(i, state[i]);
  });
  const double packed_build = timed([&] { packed.build(ids, state); });
  const double scan_build = timed([&] {
    for (std::size_t i = 0; i < state.size(); ++i)
      scan.insert(i, state[i]);
  });
  const double grid_build = timed([&] {
    for (std::size_t i = 0; i < state.size(); ++i)
      grid.insert(i, state[i]);
  });
  double sidx_build = 0;
  if (o.peer) {
    sidx = std::make_unique<SidxTpr>(horizon);
    sidx_build = timed([&] {
      for (std::size_t i = 0; i < state.size(); ++i)
        sidx->insert(i, state[i]);
    });
  }
  std::printf(
      "objects: %zu points in 1000 x 1000, %d ticks, %zu updates (new velocity) and %d windows "
      "(100 x 100, t in [now, now + 60]) per tick\n",
      o.objects, o.ticks, o.objects / 60, o.queries);
  std::printf(
      "  load: TPR*-tree inserted %.3f s (height %d), STAR-tree %.3f s, packed %.3f s, scan %.3f "
      "s, grid %.3f s",
      tpr_build, tpr.height(), star_build, packed_build, scan_build, grid_build);
  if (o.peer) std::printf(", libspatialindex TPR-tree %.3f s", sidx_build);
  std::printf("\n");

  std::uniform_int_distribution<std::size_t> pick(0, o.objects - 1);
  std::size_t total_hits = 0, total_queries = 0;
  for (int tick = 1; tick <= o.ticks; ++tick) {
    const double now = tick;
    std::vector<Report> batch;
    for (std::size_t u = 0; u < o.objects / 60; ++u) {
      const Id id = pick(rng);
      loci::Point2 p = loci::position(state[id], now);
      for (int a = 0; a < 2; ++a)
        p[a] = std::clamp(p[a], 0.0, side);
      batch.push_back({id, {now, p, {vel(rng), vel(rng)}}});
    }
    t_tpr.update_s.push_back(timed([&] {
      for (const Report& r : batch)
        tpr.update(r.id, r.m);
    }));
    t_inplace.update_s.push_back(timed([&] {
      for (const Report& r : batch)
        inplace.update(r.id, r.m);
    }));
    t_star.update_s.push_back(timed([&] {
      for (const Report& r : batch)
        star.update(r.id, r.m);
    }));
    t_scan.update_s.push_back(timed([&] {
      for (const Report& r : batch)
        scan.update(r.id, r.m);
    }));
    t_grid.update_s.push_back(timed([&] {
      for (const Report& r : batch)
        grid.update(r.id, r.m);
    }));
    if (sidx)
      t_sidx.update_s.push_back(timed([&] {
        for (const Report& r : batch) {
          if (!sidx->erase(r.id, state[r.id], now)) ++sidx_failed_deletes;
          sidx->insert(r.id, r.m);
        }
      }));
    // Rebuild per tick: the reports go into flat arrays, then the tree is packed again.
    t_packed.update_s.push_back(timed([&] {
      for (const Report& r : batch)
        state[r.id] = r.m;
      packed.build(ids, state);
    }));

    std::vector<MovingWindow<2>> windows;
    for (int q = 0; q < o.queries; ++q) {
      const double x = corner(rng), y = corner(rng);
      windows.push_back(MovingWindow<2>::at({{x, y}, {x + qside, y + qside}}, now + ahead(rng)));
    }
    std::vector<std::vector<Id>> truth(windows.size());
    t_scan.query_s.push_back(timed([&] {
      for (std::size_t q = 0; q < windows.size(); ++q)
        truth[q] = scan.query(windows[q]);
    }));
    for (auto& v : truth) {
      std::sort(v.begin(), v.end());
      total_hits += v.size();
    }
    total_queries += windows.size();
    auto check = [&](const char* name, auto& index, Timing& t) {
      std::vector<std::vector<Id>> got(windows.size());
      t.query_s.push_back(timed([&] {
        for (std::size_t q = 0; q < windows.size(); ++q)
          t.nodes += index
                         .query(windows[q],
                                [&](Id id, const Motion2&) {
                                  got[q].push_back(id);
                                  return true;
                                })
                         .nodes_visited;
      }));
      for (std::size_t q = 0; q < windows.size(); ++q) {
        std::sort(got[q].begin(), got[q].end());
        if (got[q] != truth[q]) {
          std::printf("  MISMATCH: %s differs from the scan (tick %d, query %zu)\n", name, tick, q);
          std::exit(1);
        }
      }
    };
    check("TPR*-tree", tpr, t_tpr);
    check("TPR*-tree in place", inplace, t_inplace);
    check("packed", packed, t_packed);
    check("STAR-tree", star, t_star);
    check("grid", grid, t_grid);
    if (sidx) {
      std::vector<std::vector<Id>> answers(windows.size());
      t_sidx.query_s.push_back(timed([&] {
        for (std::size_t q = 0; q < windows.size(); ++q)
          answers[q] = sidx->query(windows[q].from, windows[q].t1);
      }));
      for (std::size_t q = 0; q < windows.size(); ++q) {
        if (answers[q] == truth[q]) continue;
        ++sidx_wrong;
        std::vector<Id> diff;
        std::set_difference(truth[q].begin(), truth[q].end(), answers[q].begin(), answers[q].end(),
                            std::back_inserter(diff));
        sidx_missing += diff.size();
        diff.clear();
        std::set_difference(answers[q].begin(), answers[q].end(), truth[q].begin(), truth[q].end(),
                            std::back_inserter(diff));
        sidx_extra += diff.size();
      }
    }
  }
  tpr.validate();
  grid.validate();
  inplace.validate();
  packed.validate();
  star.validate();
  const double per_tick = double(o.objects / 60);
  const double hits = double(total_hits) / double(total_queries);
  std::printf("  medians per tick; %.1f hits per window on average\n", hits);
  std::printf("  %-40s %12s %10s %8s %8s\n", "", "updates/s", "queries/s", "ns/hit", "nodes/q");
  struct Rates {
    double ups, qps;
  };
  auto row = [&](const char* name, const Timing& t) {
    const Rates r{per_tick / median(t.update_s), o.queries / median(t.query_s)};
    std::printf("  %-40s %12.0f %10.0f %8.1f %8.1f\n", name, r.ups, r.qps,
                1e9 / r.qps / std::max(1.0, hits), double(t.nodes) / double(total_queries));
    return r;
  };
  const Rates tp = row("loci TPR*-tree (erase + insert)", t_tpr);
  const Rates ip = row("loci TPR*-tree (in-place updates)", t_inplace);
  const Rates pk = row("loci packed TPR-tree, rebuilt each tick", t_packed);
  const Rates st = row("loci STAR-tree", t_star);
  const Rates sc = row("loci vectorized scan", t_scan);
  const Rates gr = row("loci velocity-banded grid", t_grid);
  // The grid lays itself out again as the clock passes its reference time: the ticks that do
  // carry that cost, which a median leaves out, so the mean rate is given too.
  double grid_total = 0;
  for (double s : t_grid.update_s)
    grid_total += s;
  std::printf(
      "  grid: %zu layouts; updates %.0f/s over all ticks (layouts included), queries %.2fx the "
      "scan\n",
      grid.layouts(), per_tick * double(t_grid.update_s.size()) / grid_total, gr.qps / sc.qps);
  std::printf(
      "  TPR*-tree: Choose_Path explored at most %zu nodes; rebuild of %zu objects: %.1f ms\n",
      tpr.max_choose_path_nodes(), o.objects, median(t_packed.update_s) * 1e3);
  std::printf(
      "  queries vs the scan: TPR*-tree %.2fx, in place %.2fx, packed %.2fx, STAR-tree %.2fx "
      "(%zu regroupings)\n",
      tp.qps / sc.qps, ip.qps / sc.qps, pk.qps / sc.qps, st.qps / sc.qps, star.regroups());
  if (sidx) {
    const Rates sx = row("libspatialindex TPR-tree", t_sidx);
    std::printf(
        "  vs libspatialindex: updates %.0fx (TPR*), %.0fx (in place), %.0fx (packed), %.0fx "
        "(STAR), %.0fx (scan), %.0fx (grid); queries %.1fx (TPR*), %.1fx (in place), %.1fx "
        "(packed), %.1fx (STAR), %.1fx (scan), %.1fx (grid)\n",
        tp.ups / sx.ups, ip.ups / sx.ups, pk.ups / sx.ups, st.ups / sx.ups, sc.ups / sx.ups,
        gr.ups / sx.ups, tp.qps / sx.qps, ip.qps / sx.qps, pk.qps / sx.qps, st.qps / sx.qps,
        sc.qps / sx.qps, gr.qps / sx.qps);
    std::printf(
        "  libspatialindex: %zu of %zu windows answered differently from brute force (%zu ids "
        "missing, %zu extra); %zu of %zu deletes failed\n",
        sidx_wrong, total_queries, sidx_missing, sidx_extra, sidx_failed_deletes,
        std::size_t(per_tick) * o.ticks);
  }
}

// ---- Conflicts ---------------------------------------------------------------------------

// Every pair's closest approach over [0, H], branch-free over structure-of-arrays: the count
// of pairs within D, for rows [0, rows) against all later objects.
std::size_t all_pairs(const std::vector<double>& x, const std::vector<double>& y,
                      const std::vector<double>& vx, const std::vector<double>& vy, double within,
                      double horizon, std::size_t rows) {
  const std::size_t n = x.size();
  const double d2max = within * within;
  const double* __restrict px = x.data();
  const double* __restrict py = y.data();
  const double* __restrict pvx = vx.data();
  const double* __restrict pvy = vy.data();
  std::size_t count = 0;
  for (std::size_t i = 0; i < rows; ++i) {
    const double xi = px[i], yi = py[i], vxi = pvx[i], vyi = pvy[i];
    double c = 0;  // a double, so that the loop stays in vector registers
    for (std::size_t j = i + 1; j < n; ++j) {
      const double dx = px[j] - xi, dy = py[j] - yi, wx = pvx[j] - vxi, wy = pvy[j] - vyi;
      const double ww = wx * wx + wy * wy, dw = dx * wx + dy * wy;
      // ww == 0 means dw == 0: u = 0, the distance never changes.
      const double u = std::min(std::max(-dw / std::max(ww, 1e-300), 0.0), horizon);
      const double cx = dx + wx * u, cy = dy + wy * u;
      c += (cx * cx + cy * cy <= d2max) ? 1.0 : 0.0;
    }
    count += std::size_t(c);
  }
  return count;
}

void run_conflicts(const Options& o) {
  const std::size_t n = o.vessels;
  const double side = std::sqrt(double(n) * 0.4e6), within = 200, horizon = 600;
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> pos(0, side), speed(0, 12), angle(0, 2 * M_PI);
  std::vector<Motion2> fleet(n);
  std::vector<double> x(n), y(n), vx(n), vy(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double s = speed(rng), a = angle(rng);
    fleet[i] = {0, {pos(rng), pos(rng)}, {s * std::sin(a), s * std::cos(a)}};
    x[i] = fleet[i].p[0], y[i] = fleet[i].p[1], vx[i] = fleet[i].v[0], vy[i] = fleet[i].v[1];
  }
  std::printf("conflicts: %zu vessels in %.0f km x %.0f km, D = %.0f m, H = %.0f s\n", n,
              side / 1000, side / 1000, within, horizon);
  std::vector<double> times;
  std::size_t pairs = 0;
  for (int rep = 0; rep < 5; ++rep) {
    const auto t0 = Clock::now();
    pairs = 0;
    loci::find_conflicts<2>(fleet, within, 0, horizon,
                            [&](std::uint32_t, std::uint32_t, const loci::Approach&) {
                              ++pairs;
                              return true;
                            });
    times.push_back(seconds_since(t0));
  }
  const double loci_s = median(times);
  const std::size_t rows = std::min(n, o.all_pairs_rows);
  auto t0 = Clock::now();
  const std::size_t sampled = all_pairs(x, y, vx, vy, within, horizon, rows);
  const double sample_s = seconds_since(t0);
  // Rows i cost n - i - 1 pair tests each: scale by the total over the sampled share.
  const double total_tests = double(n) * double(n - 1) / 2;
  const double sample_tests = double(rows) * double(n) - double(rows) * double(rows + 1) / 2;
  const double all_s = sample_s * total_tests / sample_tests;
  std::printf("  loci find_conflicts: %zu pairs in %.1f ms (median of 5, %zu slices)\n", pairs,
              loci_s * 1e3, loci::detail::auto_slices<2>(fleet, within, horizon));
  // The first call faults in its buffers; the later ones lease them from the thread.
  std::printf("  first call in the process (fresh memory): %.1f ms\n", times.front() * 1e3);
  std::printf("  all-pairs scan: %.2f s%s (%.2f ns a pair)\n", all_s,
              rows < n ? " (extrapolated from a sample of rows)" : "", all_s / total_tests * 1e9);
  std::printf("  find_conflicts vs all-pairs: %.0fx\n", all_s / loci_s);
  if (rows == n && sampled != pairs) {
    std::printf("  MISMATCH: all-pairs found %zu pairs\n", sampled);
    std::exit(1);
  }
  if (rows < n) {
    // The pairs of the sampled rows must agree too.
    std::size_t in_rows = 0;
    loci::find_conflicts<2>(fleet, within, 0, horizon,
                            [&](std::uint32_t i, std::uint32_t, const loci::Approach&) {
                              in_rows += i < rows;
                              return true;
                            });
    if (in_rows != sampled) {
      std::printf("  MISMATCH: %zu pairs in the sampled rows, all-pairs found %zu\n", in_rows,
                  sampled);
      std::exit(1);
    }
    std::printf("  pairs of the %zu sampled rows identical (%zu)\n", rows, sampled);
  }

  // Incremental mode: ticks of 10 s, 1/60 of the fleet reporting each tick (position on its
  // course, heading turned by up to 10 degrees); the monitor computes 60 s ahead.
  loci::ConflictMonitor<2> monitor(within, horizon, 60);
  std::vector<Id> ids(n);
  for (std::size_t i = 0; i < n; ++i) {
    ids[i] = i;
    monitor.report(i, fleet[i]);
  }
  std::uniform_real_distribution<double> turn(-10 * M_PI / 180, 10 * M_PI / 180);
  std::uniform_int_distribution<std::size_t> pick(0, n - 1);
  std::vector<double> inc_s, full_s, refresh_s, once_s;
  std::size_t answer = 0;
  // A stream keeps its output buffer from tick to tick, as it keeps the monitor.
  std::vector<loci::Conflict> inc, full;
  loci::ConflictFinder<2> scratch;  // kept between ticks too, as a stream would keep it
  for (int tick = 0; tick <= 12; ++tick) {
    const double now = 10.0 * tick;
    std::vector<std::pair<std::size_t, Motion2>> batch;
    if (tick > 0)
      for (std::size_t u = 0; u < n / 60; ++u) {
        const std::size_t i = pick(rng);
        const double a = turn(rng), c = std::cos(a), sn = std::sin(a);
        const loci::Point2 v = fleet[i].v;
        batch.push_back(
            {i,
             {now, loci::position(fleet[i], now), {v[0] * c - v[1] * sn, v[0] * sn + v[1] * c}}});
      }
    inc.clear();
    const std::size_t full_before = monitor.full_computations();
    double tr = 0;
    const double ti = [&] {
      const auto t0 = Clock::now();
      for (const auto& [i, m] : batch)
        monitor.report(i, m);
      monitor.refresh(now);
      tr = seconds_since(t0);
      inc.reserve(answer + answer / 8);
      monitor.conflicts([&](Id a, Id b, const loci::Approach& ap) {
        inc.push_back({a, b, ap});
        return true;
      });
      return seconds_since(t0);
    }();
    for (const auto& [i, m] : batch)
      fleet[i] = m;
    // From scratch, listed the same way (by ids, unsorted, into a kept buffer).
    const auto t0 = Clock::now();
    full.clear();
    scratch.find(std::span<const Motion2>(fleet), within, now, horizon,
                 [&](std::uint32_t i, std::uint32_t j, const loci::Approach& ap) {
                   full.push_back({std::min(ids[i], ids[j]), std::max(ids[i], ids[j]), ap});
                   return true;
                 });
    const double tf = seconds_since(t0);
    // And as a one-off call makes it: a new vector, the answer sorted (the finder's buffers
    // leased from the thread).
    const auto t2 = Clock::now();
    const std::size_t once = loci::find_conflicts<2>(ids, fleet, within, now, horizon).size();
    once_s.push_back(seconds_since(t2));
    if (once != full.size()) {
      std::printf("  MISMATCH: find_conflicts found %zu pairs, the kept finder %zu\n", once,
                  full.size());
      std::exit(1);
    }
    loci::sort_conflicts(inc);
    loci::sort_conflicts(full);
    // The same pairs; times and distances equal to rounding.
    const auto close = [](double x, double y) {
      return std::abs(x - y) <= 1e-9 * (1 + std::abs(y));
    };
    bool same = inc.size() == full.size();
    for (std::size_t k = 0; same && k < inc.size(); ++k)
      same = inc[k].a == full[k].a && inc[k].b == full[k].b &&
             close(inc[k].approach.tcpa, full[k].approach.tcpa) &&
             close(inc[k].approach.dcpa, full[k].approach.dcpa) &&
             close(inc[k].approach.t_enter, full[k].approach.t_enter) &&
             close(inc[k].approach.t_exit, full[k].approach.t_exit);
    if (!same) {
      std::printf("  MISMATCH: incremental answer differs at tick %d\n", tick);
      std::exit(1);
    }
    answer = full.size();
    // The ticks that refresh incrementally (not the first, nor those past the slack).
    if (monitor.full_computations() == full_before) inc_s.push_back(ti), refresh_s.push_back(tr);
    full_s.push_back(tf);
  }
  std::printf(
      "  incremental (1/60 reporting per 10 s tick, computed 60 s ahead): %.2f ms a tick vs "
      "%.1f ms from scratch: %.1fx; the same pairs (%zu), approaches equal to rounding; %zu "
      "full computations in "
      "13 ticks (refresh alone %.2f ms: %.1fx)\n",
      median(inc_s) * 1e3, median(full_s) * 1e3, median(full_s) / median(inc_s), answer,
      monitor.full_computations(), median(refresh_s) * 1e3, median(full_s) / median(refresh_s));
  std::printf(
      "  against find_conflicts(ids, ...) called afresh each tick (new vector, sorted answer): "
      "%.1f ms, %.1fx\n",
      median(once_s) * 1e3, median(once_s) / median(inc_s));
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "bench_moving: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--objects")
      o.objects = std::stoul(next());
    else if (a == "--ticks")
      o.ticks = std::stoi(next());
    else if (a == "--queries")
      o.queries = std::stoi(next());
    else if (a == "--vessels")
      o.vessels = std::stoul(next());
    else if (a == "--all-pairs-rows")
      o.all_pairs_rows = std::stoul(next());
    else if (a == "--no-peer")
      o.peer = false;
    else if (a == "--only")
      o.only = next();
    else {
      std::fprintf(stderr, "bench_moving: unknown argument %s\n", a.c_str());
      return 2;
    }
  }
  if (o.only != "conflicts") run_objects(o);
  if (o.only != "objects") run_conflicts(o);
}
