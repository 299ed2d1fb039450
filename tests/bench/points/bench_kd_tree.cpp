// bench_kd_tree [N]: loci KdTree against nanoflann on N points (default 1,000,000): real
// coastline vertices and uniform points. Build time and nearest-10 queries per second, the
// ratios loci / nanoflann for both (queries: > 1 means loci is faster; build: < 1 means loci
// is faster). Both trees must return the same 10 distances for every query, or the run
// fails. Both use leaf buckets of about a dozen points (nanoflann's default is 10).
#include <nanoflann.hpp>

#include <cmath>
#include <cstdio>
#include <random>

#include "bench_common.hpp"
#include "loci/index/kd_tree.hpp"

namespace {

using namespace loci;

struct Cloud {
  const std::vector<Point<2>>* pts;
  std::size_t kdtree_get_point_count() const { return pts->size(); }
  double kdtree_get_pt(std::size_t i, std::size_t d) const { return (*pts)[i][int(d)]; }
  template <class B>
  bool kdtree_get_bbox(B&) const {
    return false;
  }
};
using Nano = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>, Cloud,
                                                 2, std::uint32_t>;

std::vector<Point<2>> queries_near(const std::vector<Point<2>>& pts, std::size_t q) {
  std::mt19937_64 rng(99);
  Box2 b = Box2::empty();
  for (const auto& p : pts)
    b.expand(p);
  std::normal_distribution<double> jitter(0, 1e-3 * b.extent(0));
  std::vector<Point<2>> out(q);
  for (auto& p : out) {
    p = pts[rng() % pts.size()];
    p[0] += jitter(rng);
    p[1] += jitter(rng);
  }
  return out;
}

void run(const char* label, const std::vector<Point<2>>& pts) {
  constexpr std::size_t kQueries = 100000, kK = 10;
  const auto qs = queries_near(pts, kQueries);
  const Cloud cloud{&pts};

  KdTree2 loci_tree;
  const double loci_build = bench::median_seconds(3, [&] { loci_tree = KdTree2::build(pts); });
  double nano_build = bench::median_seconds(3, [&] {
    Nano t(2, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    t.buildIndex();
  });
  Nano nano(2, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  nano.buildIndex();

  std::vector<double> loci_d(kQueries * kK), nano_d(kQueries * kK);
  const double loci_q = bench::median_seconds(3, [&] {
    for (std::size_t i = 0; i < kQueries; ++i) {
      std::size_t r = 0;
      loci_tree.nearest(qs[i], kK, [&](Id, const Box2&, double d) {
        loci_d[i * kK + r++] = d;
        return true;
      });
    }
  });
  const double nano_q = bench::median_seconds(3, [&] {
    std::uint32_t idx[kK];
    double d2[kK];
    for (std::size_t i = 0; i < kQueries; ++i) {
      nano.knnSearch(qs[i].c, kK, idx, d2);
      for (std::size_t r = 0; r < kK; ++r)
        nano_d[i * kK + r] = d2[r];
    }
  });
  for (std::size_t i = 0; i < loci_d.size(); ++i)
    if (std::fabs(loci_d[i] * loci_d[i] - nano_d[i]) > 1e-9 * (1 + nano_d[i])) {
      std::printf("MISMATCH at query %zu rank %zu: loci %.17g nanoflann %.17g\n", i / kK, i % kK,
                  loci_d[i] * loci_d[i], nano_d[i]);
      std::exit(1);
    }
  std::printf("%-10s n=%zu  build: loci %.3f s, nanoflann %.3f s (loci/nanoflann time %.2fx)\n",
              label, pts.size(), loci_build, nano_build, loci_build / nano_build);
  std::printf(
      "%-10s nearest-10: loci %.0f q/s, nanoflann %.0f q/s (loci/nanoflann speed "
      "%.2fx)\n",
      label, kQueries / loci_q, kQueries / nano_q, nano_q / loci_q);
}

}  // namespace

int main(int argc, char** argv) {
  const std::size_t n = bench::size_argument(argc, argv, 1000000);
  const auto segs = bench::coastline_segments();
  if (!segs.empty()) run("coastline", bench::coastline_vertices(segs, n));
  run("uniform", bench::uniform_points(n, 1));
  return 0;
}
