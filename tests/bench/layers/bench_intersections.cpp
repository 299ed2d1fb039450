// All intersecting segment pairs of a layer's linework (`loci intersections LAYER`): loci's
// pipeline (tiled sort-and-sweep of the segment boxes, exact segment test, rows sorted and
// unique; on one thread and on every core)
// beside CGAL's box_self_intersection_d on the same boxes and GEOS's STRtree of the segments
// queried once per segment, each followed by the same exact test and the same rows. The
// segments are read once through GDAL before any clock starts; every method must give the
// same rows.
//
// Layer: countries-coastline-1m when it has been fetched (datasets/fetch.sh), else the bundled
// sample. Usage: bench_intersections [--layer PATH] [--no-geos | --loci-only]
#include <CGAL/Bbox_2.h>
#include <CGAL/box_intersection_d.h>
#include <geos_c.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "loci/index/segment_intersections.hpp"
#include "loci/io/intersections.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using loci::io::IntersectionRow;
using loci::io::Linework;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

void geos_message(const char*, void*) {}

// The exact test and row making every peer shares with loci's pipeline.
struct Rows {
  const Linework& lw;
  std::vector<IntersectionRow> rows;
  void test(std::size_t i, std::size_t j) {
    if (i > j) std::swap(i, j);
    const loci::SegmentIntersection x = loci::intersection(lw.segs[i], lw.segs[j]);
    if (x.kind == loci::SegmentMeet::none) return;
    if (lw.adjacent(i, j) && loci::detail::only_at_shared_vertex(lw.segs[i], lw.segs[j], x)) return;
    const auto a = std::min(lw.fid[i], lw.fid[j]), b = std::max(lw.fid[i], lw.fid[j]);
    rows.push_back({a, b, x.a});
    if (x.kind == loci::SegmentMeet::overlap) rows.push_back({a, b, x.b});
  }
  std::vector<IntersectionRow> finish() {
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    return std::move(rows);
  }
};

}  // namespace

int main(int argc, char** argv) {
  std::string layer = std::string(LOCI_DATASETS_DIR) + "/cache/countries-coastline-1m/map.geo.json";
  if (!std::filesystem::exists(layer))
    layer = std::string(LOCI_DATASETS_DIR) + "/samples/coastline-denmark.geojson";
  bool with_geos = true, with_cgal = true;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--layer" && i + 1 < argc)
      layer = argv[++i];
    else if (a == "--no-geos")
      with_geos = false;
    else if (a == "--loci-only")
      with_geos = with_cgal = false;
    else if (a == "--loci-only")
      with_geos = with_cgal = false;
  }
  auto t0 = Clock::now();
  const Linework lw(loci::io::read_segments(layer));
  const std::size_t n = lw.segs.size();
  std::printf("layer %s: %zu segments (read in %.1f s)\n", layer.c_str(), n, seconds_since(t0));
  std::printf("%-44s %10s %10s %12s\n", "method", "seconds", "x loci", "rows");

  // loci on one thread, then on every core (what `loci intersections` does by default).
  t0 = Clock::now();
  const std::vector<IntersectionRow> one = loci::io::intersection_rows(lw, nullptr, false, 1);
  const double one_s = seconds_since(t0);
  t0 = Clock::now();
  const std::vector<IntersectionRow> mine = loci::io::intersection_rows(lw, nullptr, false, 0);
  const double loci_s = seconds_since(t0);
  std::printf("%-44s %10.3f %10.2f %12zu %s\n", "loci (tiled sweep + exact), 1 thread", one_s,
              one_s / loci_s, one.size(), one == mine ? "identical" : "DIFFERENT");
  std::printf("%-44s %10.3f %10.2f %12zu\n", "loci, one thread per core", loci_s, 1.0, mine.size());
  int status = one == mine ? 0 : 1;
  auto report = [&](const char* name, double secs, const std::vector<IntersectionRow>& rows) {
    const bool same = rows == mine;
    std::printf("%-44s %10.3f %10.2f %12zu %s\n", name, secs, secs / loci_s, rows.size(),
                same ? "identical" : "DIFFERENT");
    if (!same) status = 1;
  };

  if (with_cgal) {
    // CGAL: boxes carrying their segment index, closed (touching boxes meet, as loci's do),
    // sequential as loci's pipeline is.
    using CBox = CGAL::Box_intersection_d::Box_with_info_d<double, 2, std::uint32_t,
                                                           CGAL::Box_intersection_d::ID_EXPLICIT>;
    t0 = Clock::now();
    std::vector<CBox> boxes;
    boxes.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      const loci::Box2 b = lw.segs[i].box();
      boxes.emplace_back(CGAL::Bbox_2(b.min[0], b.min[1], b.max[0], b.max[1]), std::uint32_t(i));
    }
    Rows rows{lw, {}};
    CGAL::box_self_intersection_d<CGAL::Sequential_tag>(
        boxes.begin(), boxes.end(),
        [&](const CBox& a, const CBox& b) { rows.test(a.info(), b.info()); }, std::ptrdiff_t(10),
        CGAL::Box_intersection_d::CLOSED);
    const std::vector<IntersectionRow> got = rows.finish();
    report("CGAL box_self_intersection_d + exact", seconds_since(t0), got);
  }

  if (with_geos) {
    // GEOS: an STRtree of the segments as two-point line strings, queried with each segment.
    GEOSContextHandle_t geos = GEOS_init_r();
    GEOSContext_setNoticeMessageHandler_r(geos, geos_message, nullptr);
    GEOSContext_setErrorMessageHandler_r(geos, geos_message, nullptr);
    t0 = Clock::now();
    std::vector<GEOSGeometry*> lines(n);
    GEOSSTRtree* tree = GEOSSTRtree_create_r(geos, 10);
    for (std::size_t i = 0; i < n; ++i) {
      const loci::Segment2& s = lw.segs[i];
      GEOSCoordSequence* cs = GEOSCoordSeq_create_r(geos, 2, 2);
      GEOSCoordSeq_setXY_r(geos, cs, 0, s.a[0], s.a[1]);
      GEOSCoordSeq_setXY_r(geos, cs, 1, s.b[0], s.b[1]);
      lines[i] = GEOSGeom_createLineString_r(geos, cs);
      GEOSSTRtree_insert_r(geos, tree, lines[i], reinterpret_cast<void*>(i));
    }
    struct Ctx {
      Rows* rows;
      std::size_t i;
    };
    Rows rows{lw, {}};
    for (std::size_t i = 0; i < n; ++i) {
      Ctx ctx{&rows, i};
      GEOSSTRtree_query_r(
          geos, tree, lines[i],
          [](void* item, void* user) {
            auto* c = static_cast<Ctx*>(user);
            const auto j = reinterpret_cast<std::size_t>(item);
            if (j > c->i) c->rows->test(c->i, j);
          },
          &ctx);
    }
    const std::vector<IntersectionRow> got = rows.finish();
    report("GEOS STRtree per segment + exact", seconds_since(t0), got);
    GEOSSTRtree_destroy_r(geos, tree);
    for (auto* g : lines)
      GEOSGeom_destroy_r(geos, g);
    GEOS_finish_r(geos);
  }
  return status;
}
