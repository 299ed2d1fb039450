// All overlapping pairs of N moving 2D boxes, tick after tick: loci's broad phases beside
// CGAL's box_self_intersection_d and, when present, Bullet's btDbvtBroadphase and
// bt32BitAxisSweep3 and Box2D 2.4's b2DynamicTree, on the same motion in one process.
//
// Workload (issue 9): boxes of half-size 1..3 on each axis, about one per 100 area units,
// moving at constant speed (up to 1.4 per tick, or 0.05 for the coherent workload) and
// bouncing off the world's walls. The large workload moves as the fast one, but a tenth of the
// boxes (drawn at random) have half-sizes 10..30: a grid sized for the small boxes loses there.
// Every structure is told every box's new position each tick and asked for every overlapping pair;
// the time of both is the tick's time. The pair sets are checked identical (count and a hash of the
// sorted pairs) against the first library's.
//
// Peers, as used here: CGAL gets a fresh vector of boxes each tick (it keeps nothing); Bullet's
// broad phases get setAabb() for every proxy, then calculateOverlappingPairs(), and their pair
// caches (which hold pairs of fat or quantised boxes) are filtered with the exact boxes;
// Bullet's SAP runs without its ray-cast accelerator (not needed for pairs). Box2D's tree has
// no pair list of its own, so each tick moves every proxy (MoveProxy, with the displacement)
// and queries the tree with every box, as a broad phase built on it does when all move.
//
// Usage: bench_broadphase [--n N[,N...]] [--ticks T] [--peer-ticks P] [--workload
// fast|coherent|large|all] [--peers no]. Slow peers (Bullet, Box2D) run P ticks (default 10) at N
// >= 50,000 to keep the run short; medians are per tick, so the ratios stay comparable. Fixed
// seeds.
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

#include <CGAL/Bbox_2.h>
#include <CGAL/box_intersection_d.h>

#include "loci/index/broadphase/dynamic_aabb_tree.hpp"
#include "loci/index/broadphase/sweep_prune.hpp"
#include "loci/index/broadphase/uniform_grid.hpp"

#if LOCI_HAVE_BULLET
#include <btBulletCollisionCommon.h>
#endif
#if LOCI_HAVE_BOX2D
#include <box2d/b2_dynamic_tree.h>
#endif

namespace {

using loci::Box2;
using loci::Id;
using Pairs = std::vector<std::uint64_t>;  // (lower index << 32 | higher index)

std::uint64_t pair_key(std::uint32_t a, std::uint32_t b) {
  return a < b ? (std::uint64_t(a) << 32 | b) : (std::uint64_t(b) << 32 | a);
}

// Boxes bouncing in a square world.
struct Motion {
  std::vector<Box2> boxes;
  std::vector<double> vx, vy;
  double side;

  // A fraction `large` of the boxes get half-sizes 10..30 instead of 1..3 (with large = 0 the
  // random sequence, hence the boxes, are those of the other workloads).
  Motion(std::size_t n, double max_speed, double large, std::uint64_t seed)
      : side(std::sqrt(double(n) * 100)) {
    std::mt19937_64 rng(seed);
    auto u = [&](double lo, double hi) {
      return std::uniform_real_distribution<double>(lo, hi)(rng);
    };
    boxes.resize(n);
    vx.resize(n);
    vy.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double scale = large > 0 && u(0, 1) < large ? 10 : 1;
      const double hx = scale * u(1, 3), hy = scale * u(1, 3);
      const double cx = u(hx, side - hx), cy = u(hy, side - hy);
      boxes[i] = {{cx - hx, cy - hy}, {cx + hx, cy + hy}};
      const double speed = u(0, max_speed), angle = u(0, 2 * M_PI);
      vx[i] = speed * std::cos(angle);
      vy[i] = speed * std::sin(angle);
    }
  }

  void step() {
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      Box2& b = boxes[i];
      if (b.min[0] + vx[i] < 0 || b.max[0] + vx[i] > side) vx[i] = -vx[i];
      if (b.min[1] + vy[i] < 0 || b.max[1] + vy[i] > side) vy[i] = -vy[i];
      b.min[0] += vx[i], b.max[0] += vx[i];
      b.min[1] += vy[i], b.max[1] += vy[i];
    }
  }
};

// ---- loci --------------------------------------------------------------------------------

template <class BP>
struct Loci {
  std::string label;
  BP bp;
  explicit Loci(std::string name, BP b = BP()) : label(std::move(name)), bp(std::move(b)) {}
  std::string name() const { return label; }
  void init(const std::vector<Box2>& boxes) {
    for (std::size_t i = 0; i < boxes.size(); ++i)
      bp.add(Id(i), boxes[i]);
  }
  void tick(const std::vector<Box2>& boxes, Pairs& out) {
    for (std::size_t i = 0; i < boxes.size(); ++i)
      bp.move(Id(i), boxes[i]);
    bp.pairs([&](Id a, Id b) { return out.push_back(a << 32 | b), true; });
  }
};

// ---- CGAL --------------------------------------------------------------------------------

struct Cgal {
  using CBox = CGAL::Box_intersection_d::Box_with_info_d<double, 2, std::uint32_t,
                                                         CGAL::Box_intersection_d::ID_EXPLICIT>;
  std::vector<CBox> cboxes;
  std::string name() const { return "CGAL box_self_intersection_d"; }
  void init(const std::vector<Box2>&) {}
  void tick(const std::vector<Box2>& boxes, Pairs& out) {
    cboxes.clear();
    cboxes.reserve(boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      const Box2& b = boxes[i];
      cboxes.emplace_back(CGAL::Bbox_2(b.min[0], b.min[1], b.max[0], b.max[1]), std::uint32_t(i));
    }
    CGAL::box_self_intersection_d(cboxes.begin(), cboxes.end(), [&](const CBox& a, const CBox& b) {
      out.push_back(pair_key(a.info(), b.info()));
    });
  }
};

// ---- Bullet ------------------------------------------------------------------------------

#if LOCI_HAVE_BULLET
struct BulletBase {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  std::unique_ptr<btBroadphaseInterface> bp;
  std::vector<btBroadphaseProxy*> proxies;

  static btVector3 lo(const Box2& b) {
    return btVector3(btScalar(b.min[0]), btScalar(b.min[1]), 0);
  }
  static btVector3 hi(const Box2& b) {
    return btVector3(btScalar(b.max[0]), btScalar(b.max[1]), 1);
  }

  void init(const std::vector<Box2>& boxes) {
    for (std::size_t i = 0; i < boxes.size(); ++i)
      proxies.push_back(bp->createProxy(lo(boxes[i]), hi(boxes[i]), BOX_SHAPE_PROXYTYPE,
                                        reinterpret_cast<void*>(i), -1, -1, &dispatcher));
  }
  void tick(const std::vector<Box2>& boxes, Pairs& out) {
    for (std::size_t i = 0; i < boxes.size(); ++i)
      bp->setAabb(proxies[i], lo(boxes[i]), hi(boxes[i]), &dispatcher);
    bp->calculateOverlappingPairs(&dispatcher);
    btBroadphasePairArray& arr = bp->getOverlappingPairCache()->getOverlappingPairArray();
    for (int k = 0; k < arr.size(); ++k) {
      const auto a =
          std::uint32_t(reinterpret_cast<std::uintptr_t>(arr[k].m_pProxy0->m_clientObject));
      const auto b =
          std::uint32_t(reinterpret_cast<std::uintptr_t>(arr[k].m_pProxy1->m_clientObject));
      if (loci::intersects(boxes[a], boxes[b])) out.push_back(pair_key(a, b));
    }
  }
};

struct BulletDbvt : BulletBase {
  BulletDbvt() { bp = std::make_unique<btDbvtBroadphase>(); }
  std::string name() const { return "Bullet btDbvtBroadphase"; }
};

struct BulletSap : BulletBase {
  explicit BulletSap(double side) {
    bp = std::make_unique<bt32BitAxisSweep3>(btVector3(-10, -10, -1),
                                             btVector3(btScalar(side + 10), btScalar(side + 10), 2),
                                             1500000, nullptr, true);
  }
  std::string name() const { return "Bullet bt32BitAxisSweep3"; }
};
#endif

// ---- Box2D -------------------------------------------------------------------------------

#if LOCI_HAVE_BOX2D
struct Box2dTree {
  b2DynamicTree tree;
  std::vector<int32> proxies;
  std::vector<Box2> before;
  const std::vector<Box2>* boxes = nullptr;
  Pairs* out = nullptr;
  std::uint32_t self = 0;

  static b2AABB aabb(const Box2& b) {
    b2AABB r;
    r.lowerBound.Set(float(b.min[0]), float(b.min[1]));
    r.upperBound.Set(float(b.max[0]), float(b.max[1]));
    return r;
  }
  std::string name() const { return "Box2D 2.4 b2DynamicTree"; }
  void init(const std::vector<Box2>& bs) {
    before = bs;
    for (std::size_t i = 0; i < bs.size(); ++i)
      proxies.push_back(tree.CreateProxy(aabb(bs[i]), reinterpret_cast<void*>(i)));
  }
  bool QueryCallback(int32 id) {
    const auto j = std::uint32_t(reinterpret_cast<std::uintptr_t>(tree.GetUserData(id)));
    if (j > self && loci::intersects((*boxes)[self], (*boxes)[j]))
      out->push_back(pair_key(self, j));
    return true;
  }
  void tick(const std::vector<Box2>& bs, Pairs& o) {
    for (std::size_t i = 0; i < bs.size(); ++i) {
      const b2Vec2 d(float(bs[i].min[0] - before[i].min[0]),
                     float(bs[i].min[1] - before[i].min[1]));
      tree.MoveProxy(proxies[i], aabb(bs[i]), d);
      before[i] = bs[i];
    }
    boxes = &bs;
    out = &o;
    for (self = 0; self < bs.size(); ++self)
      tree.Query(this, aabb(bs[self]));
  }
};
#endif

// ---- Harness -----------------------------------------------------------------------------

struct Result {
  std::string name;
  double median_ms = 0;
  std::vector<std::uint64_t> hashes;  // per tick: count and sorted-pair hash mixed
  std::vector<std::size_t> counts;
};

std::uint64_t hash_pairs(Pairs& p) {
  std::sort(p.begin(), p.end());
  std::uint64_t h = 1469598103934665603ull;
  for (const std::uint64_t k : p)
    h = (h ^ k) * 1099511628211ull;
  return h ^ p.size();
}

// A workload: the speed limit and the fraction of large boxes.
struct Workload {
  const char* name;
  double speed;
  double large;
};

template <class Lib>
Result run(Lib& lib, std::size_t n, const Workload& w, int ticks) {
  Motion m(n, w.speed, w.large, 42);
  lib.init(m.boxes);
  Result r;
  r.name = lib.name();
  std::vector<double> ms;
  Pairs out;
  for (int t = 0; t < ticks; ++t) {
    m.step();
    out.clear();
    const auto t0 = std::chrono::steady_clock::now();
    lib.tick(m.boxes, out);
    const auto t1 = std::chrono::steady_clock::now();
    ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    r.counts.push_back(out.size());
    r.hashes.push_back(hash_pairs(out));
  }
  std::sort(ms.begin(), ms.end());
  r.median_ms = ms.empty() ? 0 : ms[ms.size() / 2];
  return r;
}

void report(const std::vector<Result>& rs, std::size_t n, const char* workload) {
  const Result* cgal = nullptr;
  for (const auto& r : rs)
    if (r.name.rfind("CGAL", 0) == 0) cgal = &r;
  const Result& ref = rs.front();
  double avg = 0;
  for (std::size_t c : ref.counts)
    avg += double(c);
  avg /= double(std::max<std::size_t>(1, ref.counts.size()));
  std::printf("\n%s workload, N = %zu, %.0f pairs per tick on average\n", workload, n, avg);
  std::printf("  %-36s %12s %10s %8s  %s\n", "structure", "ms/tick", "vs CGAL", "ticks", "pairs");
  for (const auto& r : rs) {
    bool same = true;
    for (std::size_t t = 0; t < std::min(r.hashes.size(), ref.hashes.size()); ++t)
      same = same && r.hashes[t] == ref.hashes[t] && r.counts[t] == ref.counts[t];
    std::printf("  %-36s %12.3f %9.2fx %8zu  %s\n", r.name.c_str(), r.median_ms,
                cgal ? cgal->median_ms / r.median_ms : 0.0, r.hashes.size(),
                same ? "identical" : "DIFFERENT");
  }
  auto find = [&](const char* prefix) -> const Result* {
    for (const auto& r : rs)
      if (r.name.rfind(prefix, 0) == 0) return &r;
    return nullptr;
  };
  const Result* best = nullptr;
  for (const auto& r : rs)
    if (r.name.rfind("loci", 0) == 0 && (!best || r.median_ms < best->median_ms)) best = &r;
  const Result* dbvt = find("Bullet btDbvt");
  const Result* b2 = find("Box2D");
  const Result* tree = find("loci DynamicAabbTree");
  if (best && cgal)
    std::printf("  best loci (%s) vs CGAL: %.2fx (target 6x)\n", best->name.c_str(),
                cgal->median_ms / best->median_ms);
  if (best && dbvt)
    std::printf("  best loci vs Bullet DBVT: %.2fx (target 30x)\n",
                dbvt->median_ms / best->median_ms);
  if (tree && b2)
    std::printf("  loci DynamicAabbTree vs Box2D tree: %.2fx (target 3x)\n",
                b2->median_ms / tree->median_ms);
}

void bench(std::size_t n, const Workload& w, int ticks, int peer_ticks, bool peers) {
  const int slow = n >= 50000 ? std::min(ticks, peer_ticks) : ticks;
  std::vector<Result> rs;
  {
    Loci<loci::SweepPrune<2>> l("loci SweepPrune");
    rs.push_back(run(l, n, w, ticks));
  }
  {
    Loci<loci::IncrementalSweepPrune<2>> l("loci IncrementalSweepPrune");
    rs.push_back(run(l, n, w, ticks));
  }
  {
    Loci<loci::UniformGrid<2>> l("loci UniformGrid");
    rs.push_back(run(l, n, w, ticks));
  }
  {
    Loci<loci::DynamicAabbTree<2>> l("loci DynamicAabbTree");
    rs.push_back(run(l, n, w, ticks));
  }
  {
    Cgal c;
    rs.push_back(run(c, n, w, ticks));
  }
#if LOCI_HAVE_BULLET
  if (peers) {
    BulletDbvt b;
    rs.push_back(run(b, n, w, slow));
  }
  if (peers) {
    BulletSap b(std::sqrt(double(n) * 100));
    rs.push_back(run(b, n, w, slow));
  }
#endif
#if LOCI_HAVE_BOX2D
  if (peers) {
    auto b = std::make_unique<Box2dTree>();
    rs.push_back(run(*b, n, w, slow));
  }
#endif
  report(rs, n, w.name);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::size_t> ns{10000, 100000};
  int ticks = 100, peer_ticks = 10;
  std::string workload = "all";
  bool peers = true;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i], value = argv[i + 1];
    if (flag == "--n") {
      ns.clear();
      for (std::size_t p = 0; p < value.size();) {
        const std::size_t q = value.find(',', p);
        ns.push_back(std::stoul(value.substr(p, q - p)));
        p = q == std::string::npos ? value.size() : q + 1;
      }
    } else if (flag == "--ticks") {
      ticks = std::stoi(value);
    } else if (flag == "--peer-ticks") {
      peer_ticks = std::stoi(value);
    } else if (flag == "--peers") {
      peers = value != "no";
    } else if (flag == "--workload") {
      workload = value;
    } else {
      std::fprintf(stderr,
                   "usage: bench_broadphase [--n N,...] [--ticks T] [--peer-ticks P] [--workload "
                   "fast|coherent|large|all] [--peers no]\n");
      return 1;
    }
  }
  std::printf("bench_broadphase: median time per tick (moves + all pairs), fixed seed 42\n");
  for (const std::size_t n : ns) {
    if (workload == "all" || workload == "fast")
      bench(n, {"fast (speed <= 1.4)", 1.4, 0}, ticks, peer_ticks, peers);
    if (workload == "all" || workload == "coherent")
      bench(n, {"coherent (speed <= 0.05)", 0.05, 0}, ticks, peer_ticks, peers);
    if (workload == "all" || workload == "large")
      bench(n, {"large (10% of boxes half-size 10..30, speed <= 1.4)", 1.4, 0.1}, ticks, peer_ticks,
            peers);
  }
  return 0;
}
