// The `loci` executable end to end on small layers the suite makes itself with GDAL: a
// polygon shapefile (holes, multipolygons), a line shapefile (multilines) and a point
// shapefile, from a fixed seed. Every `-f ids` answer is compared with a brute force over all
// features through OGR's geometry (GEOS), for both granularities, with and without a sidecar;
// then every error the command line promises to report, and the sidecar's defences against
// truncation, corruption and a layer that changed after indexing.
#include <fcntl.h>
#include <gdal_utils.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <tuple>

#include "layers/cli_support.hpp"
#include "loci/geom/segment_intersection.hpp"

namespace fs = std::filesystem;
using namespace loci::test;

namespace {

fs::path g_dir;

OGRLinearRing star(double cx, double cy, double r, std::mt19937_64& rng, bool reverse = false) {
  std::uniform_real_distribution<double> u(0.5, 1.0);
  const int n = 5 + int(rng() % 8);
  OGRLinearRing ring;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * (reverse ? n - i : i) / n;
    const double rr = r * u(rng);
    ring.addPoint(cx + rr * std::cos(a), cy + rr * std::sin(a));
  }
  ring.closeRings();
  return ring;
}

OGRPolygon star_polygon(double cx, double cy, double r, std::mt19937_64& rng, bool hole) {
  OGRPolygon p;
  OGRLinearRing outer = star(cx, cy, r, rng);
  p.addRing(&outer);
  if (hole) {
    // The outer ring's radius is at least r / 2; a square of half-side r / 4 fits inside.
    const double h = r / 4;
    OGRLinearRing inner;
    inner.addPoint(cx - h, cy - h);
    inner.addPoint(cx - h, cy + h);
    inner.addPoint(cx + h, cy + h);
    inner.addPoint(cx + h, cy - h);
    inner.closeRings();
    p.addRing(&inner);
  }
  return p;
}

void write_layer(const fs::path& path, OGRwkbGeometryType type,
                 const std::function<std::unique_ptr<OGRGeometry>(int)>& make, int count) {
  GDALDriver* d = GetGDALDriverManager()->GetDriverByName("ESRI Shapefile");
  GDALDatasetUniquePtr ds(d->Create(path.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
  ASSERT_TRUE(ds);
  OGRLayer* layer = ds->CreateLayer(path.stem().c_str(), nullptr, type, nullptr);
  OGRFieldDefn label("label", OFTString);
  layer->CreateField(&label);
  for (int i = 0; i < count; ++i) {
    OGRFeature f(layer->GetLayerDefn());
    f.SetField(0, ("f," + std::to_string(i)).c_str());
    f.SetGeometryDirectly(make(i).release());
    ASSERT_EQ(layer->CreateFeature(&f), OGRERR_NONE);
  }
}

void make_layers() {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> pos(0, 100), rad(1, 8);
  write_layer(
      g_dir / "polys.shp", wkbMultiPolygon,
      [&](int i) -> std::unique_ptr<OGRGeometry> {
        auto mp = std::make_unique<OGRMultiPolygon>();
        const double cx = pos(rng), cy = pos(rng), r = rad(rng);
        OGRPolygon a = star_polygon(cx, cy, r, rng, i % 3 == 0);
        mp->addGeometry(&a);
        if (i % 4 == 1) {  // a second, disjoint part
          OGRPolygon b = star_polygon(cx + 3 * r + 10, cy, r, rng, false);
          mp->addGeometry(&b);
        }
        return mp;
      },
      60);
  write_layer(
      g_dir / "lines.shp", wkbMultiLineString,
      [&](int i) -> std::unique_ptr<OGRGeometry> {
        auto ml = std::make_unique<OGRMultiLineString>();
        for (int part = 0; part < 1 + (i % 3 == 0); ++part) {
          OGRLineString l;
          double x = pos(rng), y = pos(rng);
          const int n = 2 + int(rng() % 12);
          for (int k = 0; k < n; ++k) {
            l.addPoint(x, y);
            x += rad(rng) - 4.5;
            y += rad(rng) - 4.5;
          }
          ml->addGeometry(&l);
        }
        return ml;
      },
      60);
  write_layer(
      g_dir / "points.shp", wkbPoint,
      [&](int) -> std::unique_ptr<OGRGeometry> {
        return std::make_unique<OGRPoint>(pos(rng), pos(rng));
      },
      50);
  // A layer with no geometry column and a file that is no layer at all.
  std::ofstream(g_dir / "table.csv") << "a,b\n1,2\n3,4\n";
  std::ofstream(g_dir / "garbage.geojson") << "this is not a layer\n";
}

class LayersCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    GDALAllRegister();
    g_dir = fs::temp_directory_path() / ("loci-layers-" + std::to_string(::getpid()));
    fs::remove_all(g_dir);
    fs::create_directories(g_dir);
    make_layers();
  }
  static void TearDownTestSuite() { fs::remove_all(g_dir); }
  static std::string path(const std::string& name) { return (g_dir / name).string(); }
};

struct Window {
  double x0, y0, x1, y1;
};

// Random windows, plus windows that only touch a vertex of some feature and degenerate ones.
std::vector<Window> windows_for(const OgrFeatureSet& s, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> pos(-5, 105), size(0.5, 25);
  std::vector<Window> w;
  for (int i = 0; i < 30; ++i) {
    const double x = pos(rng), y = pos(rng);
    w.push_back({x, y, x + size(rng), y + size(rng)});
  }
  for (int i = 0; i < 10; ++i) {
    const OGRGeometry* g = s.geoms[rng() % s.geoms.size()].get();
    OGREnvelope e;
    g->getEnvelope(&e);
    // The window's top-right corner is the feature's lowest-left envelope corner: it touches
    // the feature only when a vertex sits there, which GEOS and loci must agree on.
    w.push_back({e.MinX - 3, e.MinY - 3, e.MinX, e.MinY});
    w.push_back({e.MaxX, e.MinY, e.MaxX, e.MaxY});  // degenerate: a vertical segment
  }
  return w;
}

void check_windows(const std::string& layer, const std::string& extra, std::uint64_t seed) {
  const OgrFeatureSet s = read_with_ogr(layer);
  ASSERT_FALSE(s.fids.empty());
  const auto windows = windows_for(s, seed);
  const std::string file = layer + ".windows";
  {
    std::ofstream out(file);
    out.precision(17);
    for (const auto& w : windows)
      out << w.x0 << ',' << w.y0 << ',' << w.x1 << ',' << w.y1 << '\n';
  }
  const CliRun r =
      run_loci("query " + shell_quote(layer) + " --bbox-file " + shell_quote(file) + extra);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto got = parse_ids(r.out, windows.size());
  std::size_t hits = 0;
  for (std::size_t i = 0; i < windows.size(); ++i) {
    const auto& w = windows[i];
    const auto expected = brute_intersects(s, *ogr_box(w.x0, w.y0, w.x1, w.y1));
    EXPECT_EQ(got[i + 1], expected) << layer << extra << " window " << i + 1;
    hits += expected.size();
  }
  EXPECT_GT(hits, windows.size() / 2);  // the comparison must have had something to compare
}

void check_nearest(const std::string& layer, const std::string& extra, std::uint64_t seed) {
  const OgrFeatureSet s = read_with_ogr(layer);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> pos(-10, 110);
  const std::string file = layer + ".points";
  std::vector<std::pair<double, double>> points;
  {
    std::ofstream out(file);
    out.precision(17);
    for (int i = 0; i < 12; ++i) {
      points.emplace_back(pos(rng), pos(rng));
      out << points.back().first << ',' << points.back().second << '\n';
    }
  }
  const std::size_t k = 5;
  const CliRun r = run_loci("query " + shell_quote(layer) + " --nearest-file " + shell_quote(file) +
                            " -k 5 -f csv" + extra);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = lines(r.out);
  ASSERT_EQ(rows.size(), 1 + points.size() * k);
  EXPECT_EQ(rows[0], "query,fid,distance,label");
  for (std::size_t q = 0; q < points.size(); ++q) {
    const auto brute = brute_distances(s, points[q].first, points[q].second);
    for (std::size_t i = 0; i < k; ++i) {
      std::istringstream in(rows[1 + q * k + i]);
      std::string number, fid, dist;
      std::getline(in, number, ',');
      std::getline(in, fid, ',');
      std::getline(in, dist, ',');
      ASSERT_EQ(std::stoul(number), q + 1);
      const double d = std::stod(dist);
      const double tol = 1e-9 * (1 + brute[i].first);
      EXPECT_NEAR(d, brute[i].first, tol) << layer << extra << " point " << q + 1 << " rank " << i;
      // The reported distance is the feature's own, not only the rank's.
      auto it = std::find_if(brute.begin(), brute.end(),
                             [&](const auto& b) { return b.second == std::stoll(fid); });
      ASSERT_NE(it, brute.end());
      EXPECT_NEAR(it->first, d, tol);
    }
  }
}

// --point, --segment and --within, a few of each.
void check_singles(const std::string& layer, const std::string& extra, std::uint64_t seed) {
  const OgrFeatureSet s = read_with_ogr(layer);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> pos(0, 100), len(-15, 15);
  char buf[200];
  for (int i = 0; i < 3; ++i) {
    const double x = pos(rng), y = pos(rng), x1 = x + len(rng), y1 = y + len(rng), d = 4 + i;
    std::snprintf(buf, sizeof buf, " --segment %.17g,%.17g,%.17g,%.17g", x, y, x1, y1);
    CliRun r = run_loci("query " + shell_quote(layer) + buf + extra);
    ASSERT_EQ(r.status, 0) << r.err;
    OGRLineString seg;
    seg.addPoint(x, y);
    seg.addPoint(x1, y1);
    EXPECT_EQ(parse_ids(r.out, 1)[1], brute_intersects(s, seg)) << buf;

    std::snprintf(buf, sizeof buf, " --within %.17g,%.17g,%.17g", x, y, d);
    r = run_loci("query " + shell_quote(layer) + buf + extra);
    ASSERT_EQ(r.status, 0) << r.err;
    std::vector<long long> expected;
    for (const auto& [dist, fid] : brute_distances(s, x, y))
      if (dist <= d) expected.push_back(fid);
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(parse_ids(r.out, 1)[1], expected) << buf;

    // A point inside a random feature's envelope, and one of its vertices.
    const std::size_t f = rng() % s.geoms.size();
    const OGREnvelope& e = s.envelopes[f];
    const double px = (e.MinX + e.MaxX) / 2, py = (e.MinY + e.MaxY) / 2;
    std::snprintf(buf, sizeof buf, " --point %.17g,%.17g", px, py);
    r = run_loci("query " + shell_quote(layer) + buf + extra);
    ASSERT_EQ(r.status, 0) << r.err;
    OGRPoint p(px, py);
    EXPECT_EQ(parse_ids(r.out, 1)[1], brute_intersects(s, p)) << buf;
  }
}

}  // namespace

class LayersExact : public LayersCli,
                    public ::testing::WithParamInterface<std::tuple<const char*, const char*>> {};

TEST_P(LayersExact, MatchesOgrBruteForce) {
  const auto [name, per] = GetParam();
  const std::string layer = path(name);
  const std::string extra = std::string(" --per ") + per;
  // In memory first, then through a sidecar of that granularity.
  fs::remove(layer + ".loci");
  check_windows(layer, extra, 1);
  CliRun r = run_loci("index " + shell_quote(layer) + extra + " -q");
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_TRUE(fs::exists(layer + ".loci"));
  check_windows(layer, "", 2);
  check_nearest(layer, "", 3);
  check_singles(layer, "", 4);
  fs::remove(layer + ".loci");
}

INSTANTIATE_TEST_SUITE_P(Layers, LayersExact,
                         ::testing::Combine(::testing::Values("polys.shp", "lines.shp",
                                                              "points.shp"),
                                            ::testing::Values("feature", "segment")),
                         [](const auto& info) {
                           return std::string(std::get<0>(info.param))
                                      .substr(0, std::string(std::get<0>(info.param)).find('.')) +
                                  "_" + std::get<1>(info.param);
                         });

// The first parameter t along s (from s.a) of a point of g, from GEOS's intersection of the
// two; -1 when they do not meet.
double ogr_first_meet(const OGRGeometry& g, double x0, double y0, double x1, double y1) {
  OGRLineString seg;
  seg.addPoint(x0, y0);
  seg.addPoint(x1, y1);
  if (!g.Intersects(&seg)) return -1;
  std::unique_ptr<OGRGeometry> x(g.Intersection(&seg));
  if (!x) return -1;
  const double dx = x1 - x0, dy = y1 - y0, dd = dx * dx + dy * dy;
  double best = 2;
  auto visit = [&](double px, double py) {
    best = std::min(best, dd > 0 ? ((px - x0) * dx + (py - y0) * dy) / dd : 0.0);
  };
  std::vector<const OGRGeometry*> stack{x.get()};
  while (!stack.empty()) {
    const OGRGeometry* h = stack.back();
    stack.pop_back();
    const auto type = wkbFlatten(h->getGeometryType());
    if (type == wkbPoint) {
      visit(h->toPoint()->getX(), h->toPoint()->getY());
    } else if (type == wkbLineString) {
      for (const auto& p : *h->toLineString())
        visit(p.getX(), p.getY());
    } else if (OGR_GT_IsSubClassOf(type, wkbGeometryCollection)) {
      for (const auto* part : *h->toGeometryCollection())
        stack.push_back(part);
    } else if (type == wkbPolygon) {
      for (const auto* ring : *h->toPolygon())
        for (const auto& p : *ring)
          visit(p.getX(), p.getY());
    }
  }
  return std::clamp(best, 0.0, 1.0);
}

// --point-file: point location in batch, every point against GEOS, per feature and per
// segment (crossing parity over the index's ring segments).
// Nearest-n ranks features at equal distances by FID, per feature and per segment alike: on a
// grid of squares sharing their edges (each edge in two features, run opposite ways) and a
// lattice of points, where most ranks are ties, both sidecars print the same rows, -k 2's
// answer is the first rows of -k 5's, and each row's distance is brute force's.
TEST_F(LayersCli, NearestTiesRankByFidInEitherGranularity) {
  std::string text = R"({"type":"FeatureCollection","features":[)";
  int fid = 0;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) {
      // FIDs not in the order of the squares: 7 * n mod 37.
      const int id = (7 * fid++) % 37;
      text += std::string(fid > 1 ? "," : "") + R"({"type":"Feature","id":)" + std::to_string(id) +
              R"(,"properties":{},"geometry":{"type":"Polygon",)" + R"("coordinates":[[)";
      const int x = 2 * i, y = 2 * j;
      text += "[" + std::to_string(x) + "," + std::to_string(y) + "],[" + std::to_string(x + 2) +
              "," + std::to_string(y) + "],[" + std::to_string(x + 2) + "," +
              std::to_string(y + 2) + "],[" + std::to_string(x) + "," + std::to_string(y + 2) +
              "],[" + std::to_string(x) + "," + std::to_string(y) + "]]]}}";
    }
  text += "]}";
  const std::string layer = path("squares.geojson");
  std::ofstream(layer) << text;
  std::string points;
  for (double x = -1.5; x <= 13.5; x += 0.75)
    for (double y = -1.5; y <= 13.5; y += 1.25)
      points += std::to_string(x) + "," + std::to_string(y) + "\n";
  const std::string queries = path("lattice.txt");
  std::ofstream(queries) << points;
  std::string answers[2];
  for (int g = 0; g < 2; ++g) {
    const std::string sidecar = path(g ? "squares.segment.loci" : "squares.feature.loci");
    ASSERT_EQ(
        run_loci("index -q " + layer + " -o " + sidecar + " --per " + (g ? "segment" : "feature"))
            .status,
        0);
    const std::string run =
        "query " + layer + " --index " + sidecar + " --nearest-file " + queries + " -f csv";
    const CliRun five = run_loci(run + " -k 5"), two = run_loci(run + " -k 2");
    ASSERT_EQ(five.status, 0) << five.err;
    ASSERT_EQ(two.status, 0) << two.err;
    answers[g] = five.out;
    // -k 2 is the first two rows of each query's five.
    std::map<std::string, std::vector<std::string>> rows5, rows2;
    for (const auto& l : lines(five.out))
      rows5[l.substr(0, l.find(','))].push_back(l);
    for (const auto& l : lines(two.out))
      rows2[l.substr(0, l.find(','))].push_back(l);
    ASSERT_EQ(rows2.size(), rows5.size());
    for (const auto& [q, rows] : rows2)
      if (q != "query")
        EXPECT_EQ(rows, std::vector<std::string>(rows5[q].begin(), rows5[q].begin() + 2)) << q;
  }
  EXPECT_EQ(answers[0], answers[1]);
  // Against brute force through OGR: the distances in order, the FIDs ascending within ties.
  const OgrFeatureSet squares = read_with_ogr(layer);
  const auto rows = lines(answers[1]);
  std::size_t at = 1, ties = 0;
  std::istringstream in(points);
  for (std::size_t n = 1; std::getline(in, points); ++n) {
    const double x = std::stod(points), y = std::stod(points.substr(points.find(',') + 1));
    OGRPoint p(x, y);
    std::vector<std::pair<double, long long>> want;
    for (std::size_t i = 0; i < squares.geoms.size(); ++i)
      want.emplace_back(squares.geoms[i]->Distance(&p), squares.fids[i]);
    std::sort(want.begin(), want.end());
    for (std::size_t r = 0; r < 5; ++r, ++at) {
      ASSERT_LT(at, rows.size());
      const std::string expected = std::to_string(n) + "," + std::to_string(want[r].second) + ",";
      EXPECT_EQ(rows[at].rfind(expected, 0), 0u) << rows[at] << " rank " << r;
      ties += r > 0 && want[r].first == want[r - 1].first;
    }
  }
  EXPECT_EQ(at, rows.size());
  EXPECT_GT(ties, 100u);
}

// A polygon ring whose last point is not its first (GDAL reads it, with a warning) is read
// closed by every command, with or without an index of either granularity: the answers are
// those of the same layer with the ring closed. Here the closing edge, x = 0, is the only
// one a line from (-1, 2) to (1, 2) crosses.
TEST_F(LayersCli, UnclosedRingsAreReadClosedEverywhere) {
  const std::string head =
      R"({"type":"FeatureCollection","features":[{"type":"Feature","properties":{},)"
      R"("geometry":{"type":"Polygon","coordinates":[[[0,0],[4,0],[4,4],[0,4])";
  const std::string tail =
      R"(]]}},{"type":"Feature","properties":{},"geometry":{"type":"LineString",)"
      R"("coordinates":[[-1,2],[1,2]]}}]})";
  const std::string open = path("unclosed.geojson"), closed = path("closed.geojson");
  std::ofstream(open) << head << tail;
  std::ofstream(closed) << head << ",[0,0]" << tail;
  const std::vector<std::string> commands = {
      "query L --nearest -1,3.5 -k 2 -f csv",  // 0 at 1 (the closing edge), 1 at 1.5
      "query L --point -0.5,3.5 -f ids",       // outside
      "query L --point 2,2 -f ids",            // inside
      "query L --within -1,3.5,1 -f ids",
      "query L --bbox -5,1.5,-4,3 -f ids",
      "query L --segment -1,1,-0.5,1 -f ids",
      "join L L --predicate intersects",
      "join L L --closest",
      "intersections L",
  };
  std::map<std::string, std::string> reference;
  for (const std::string& per : {"", "feature", "segment"}) {
    for (const std::string& layer : {closed, open}) {
      const std::string sidecar = layer + ".loci";
      std::filesystem::remove(sidecar);
      if (!per.empty()) ASSERT_EQ(run_loci("index -q " + layer + " --per " + per).status, 0);
      for (const std::string& c : commands) {
        std::string args = c;
        for (std::size_t at; (at = args.find(" L")) != std::string::npos;)
          args.replace(at, 2, " " + layer);
        const CliRun r = run_loci(args);
        ASSERT_EQ(r.status, 0) << args << ": " << r.err;
        if (layer == closed && per.empty())
          reference[c] = r.out;
        else
          EXPECT_EQ(r.out, reference[c]) << args << " (per " << per << ")";
      }
      std::filesystem::remove(sidecar);
    }
  }
  EXPECT_EQ(reference[commands[0]], "fid,distance\n0,1\n1,1.5\n");
  EXPECT_EQ(reference[commands[1]], "");
  EXPECT_EQ(reference[commands[2]], "0\n");
  EXPECT_NE(reference[commands[6]].find("\n0,1\n"), std::string::npos);
  EXPECT_NE(reference[commands[8]].find("\n0,1,0,2\n"), std::string::npos);
  // clip cuts the ring closed (GEOS would refuse it open).
  std::string cut[2];
  for (int i = 0; i < 2; ++i) {
    const std::string out = path(i ? "unclosed-cut.csv" : "closed-cut.csv");
    const CliRun r = run_loci("clip " + (i ? open : closed) + " --bbox -1,-1,2,2 -o " + out);
    ASSERT_EQ(r.status, 0) << r.err;
    std::ifstream in(out);
    cut[i].assign(std::istreambuf_iterator<char>(in), {});
  }
  EXPECT_EQ(cut[1], cut[0]);
  EXPECT_NE(cut[0].find("POLYGON ((0 0,0 2,2 2,2 0,0 0))"), std::string::npos) << cut[0];
}

// A path only GDAL opens (a virtual file system such as /vsigzip/, a connection) has no
// file on disk to fingerprint: loci index refuses it, an index given for it is refused (it
// could not tell when the layer changes), and queries without an index answer.
TEST_F(LayersCli, PathsOnlyGdalOpensAreNotIndexed) {
  const std::string plain = path("vsi-a.geojson");
  std::ofstream(plain)
      << R"({"type":"FeatureCollection","features":[{"type":"Feature","properties":{},)"
         R"("geometry":{"type":"Point","coordinates":[1,1]}}]})";
  ASSERT_EQ(std::system(("gzip -kf " + shell_quote(plain)).c_str()), 0);
  const std::string vsi = "/vsigzip/" + plain + ".gz";
  const CliRun index = run_loci("index " + vsi);
  EXPECT_EQ(index.status, 1);
  EXPECT_NE(index.err.find("a path only GDAL opens"), std::string::npos) << index.err;
  EXPECT_EQ(lines(index.err).size(), 1u) << index.err;
  const std::string other = path("vsi-other.loci");
  const CliRun written = run_loci("index -q " + vsi + " -o " + other);
  EXPECT_EQ(written.status, 1);
  EXPECT_FALSE(std::filesystem::exists(other));
  const CliRun info = run_loci("info " + vsi);
  EXPECT_EQ(info.status, 0) << info.err;
  EXPECT_NE(info.out.find("a path only GDAL opens is not indexed"), std::string::npos) << info.out;
  const CliRun query = run_loci("query " + vsi + " --bbox 0,0,2,2 -f ids");
  EXPECT_EQ(query.status, 0) << query.err;
  EXPECT_EQ(query.out, "0\n");
  // The index of the plain file, given for the compressed one, is not taken for it.
  const std::string sidecar = path("vsi-plain.loci");
  ASSERT_EQ(run_loci("index -q " + plain + " -o " + sidecar).status, 0);
  const CliRun given = run_loci("query " + vsi + " --bbox 0,0,2,2 -f ids --index " + sidecar);
  EXPECT_EQ(given.status, 1);
  EXPECT_EQ(given.out, "");
  EXPECT_NE(given.err.find("cannot be checked against it"), std::string::npos) << given.err;
}

// GeoJSON written by query -f geojson and by clip holds the same doubles as the layer: 17
// significant figures (GDAL's default, 15 decimals, wrote 1e-20 as 0 and 7.123456789012345e-9
// as 0.000000007123457).
TEST_F(LayersCli, GeoJsonOutputKeepsTheCoordinates) {
  const std::string layer = path("tiny.geojson");
  std::ofstream(layer)
      << R"({"type":"FeatureCollection","features":[)"
         R"({"type":"Feature","properties":{},"geometry":{"type":"Point","coordinates":[1e-20,5e-16]}},)"
         R"({"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":)"
         R"([[1.0000000000000002,7.123456789012345e-9],[0.1,2.5],[123456.789,-1e-300]]}}]})";
  const std::string queried = path("tiny-answers.geojson"), cut = path("tiny-cut.geojson");
  const CliRun q = run_loci("query " + layer + " --bbox -1,-1,200000,3 -f geojson -o " + queried);
  ASSERT_EQ(q.status, 0) << q.err;
  std::filesystem::remove(cut);
  const CliRun c = run_loci("clip " + layer + " --bbox -1,-1,200000,3 -o " + cut);
  ASSERT_EQ(c.status, 0) << c.err;
  const OgrFeatureSet in = read_with_ogr(layer);
  for (const std::string& out : {queried, cut}) {
    const OgrFeatureSet got = read_with_ogr(out);
    ASSERT_EQ(got.geoms.size(), in.geoms.size()) << out;
    for (std::size_t i = 0; i < in.geoms.size(); ++i) {
      const auto* la = dynamic_cast<const OGRSimpleCurve*>(in.geoms[i].get());
      const auto* lb = dynamic_cast<const OGRSimpleCurve*>(got.geoms[i].get());
      if (!la) {
        const auto* xa = in.geoms[i]->toPoint();
        const auto* xb = got.geoms[i]->toPoint();
        EXPECT_EQ(xb->getX(), xa->getX()) << out;
        EXPECT_EQ(xb->getY(), xa->getY()) << out;
        continue;
      }
      ASSERT_TRUE(lb) << out;
      ASSERT_EQ(lb->getNumPoints(), la->getNumPoints()) << out;
      for (int k = 0; k < la->getNumPoints(); ++k) {
        EXPECT_EQ(lb->getX(k), la->getX(k)) << out << " point " << k;
        EXPECT_EQ(lb->getY(k), la->getY(k)) << out << " point " << k;
      }
    }
  }
}

// Invalid polygons are cut as the queries read them, by the even-odd rule over each polygon's
// rings (GEOS's repair of a whole polygon dissolved the edges its rings share first, filling
// a hole that shares an edge with its shell), and every feature the query finds meeting the
// window has a piece: where its area misses the window but its rings meet it (two holes
// sharing an edge, a hole repeating its shell, a polygon without area), the rings' cut.
TEST_F(LayersCli, ClipCutsInvalidPolygonsAsTheQueriesReadThem) {
  const std::string layer = path("invalid-holes.geojson");
  auto feature = [](int i, const std::string& rings) {
    return std::string(i ? "," : "") + R"({"type":"Feature","properties":{"i":)" +
           std::to_string(i) + R"(},"geometry":{"type":"Polygon","coordinates":[)" + rings + "]}}";
  };
  const std::string square = "[[0,0],[8,0],[8,8],[0,8],[0,0]]";
  std::ofstream(layer) << R"({"type":"FeatureCollection","features":[)"
                       // 0: a hole sharing two edges with its shell
                       << feature(0,
                                  "[[3,4],[6,4],[6,6],[3,6],[3,4]],[[3,5],[3,6],[5,6],[5,5],[3,5]]")
                       // 1: a hole repeating its shell: no area
                       << feature(1, square + "," + square)
                       // 2: a band across the whole width; 3: a notch in the bottom edge
                       << feature(2, square + ",[[0,2],[8,2],[8,4],[0,4],[0,2]]")
                       << feature(3, square + ",[[2,0],[4,0],[4,2],[2,2],[2,0]]")
                       // 4: two holes sharing the edge x = 4
                       << feature(4, square +
                                         ",[[1,1],[4,1],[4,7],[1,7],[1,1]],"
                                         "[[4,1],[7,1],[7,7],[4,7],[4,1]]")
                       // 5: no area, its ring along y = 3
                       << feature(5, "[[3,3],[6,3],[3,3],[3,3]]") << "]}";
  // Curve polygons too, read linearised as the queries read them (FIDs 1 and 2 of a CSV).
  const std::string curves = path("invalid-curves.csv");
  std::ofstream(curves)
      << "i,WKT\n1,\"CURVEPOLYGON((0 0,8 0,8 8,0 8,0 0),(0 0,8 0,8 8,0 8,0 0))\"\n"
         "2,\"CURVEPOLYGON((0 0,8 0,8 8,0 8,0 0),(0 2,8 2,8 4,0 4,0 2))\"\n";
  struct Case {
    const std::string& layer;
    const char* bbox;
    std::map<int, double> want;  // by feature: the piece's area, or its length for a line
  };
  const Case cases[] = {
      {layer, "3.5,5.2,5.5,5.8", {{0, 0.3}, {2, 1.2}, {3, 1.2}, {4, 0.6}}},
      {layer, "-1,-1,9,9", {{0, 4}, {1, 32}, {2, 48}, {3, 60}, {4, 28}, {5, 3}}},
      {layer, "3.5,2.5,4.5,3.5", {{3, 1}, {4, 1}, {5, 1}}},
      {layer, "2,2.5,5,5", {{0, 2}, {2, 3}, {3, 7.5}, {4, 2.5}, {5, 2}}},
      {curves, "-1,-1,9,9", {{1, 32}, {2, 48}}},
  };
  for (const Case& c : cases) {
    const std::string out = path("invalid-holes-clip.geojson");
    fs::remove(out);
    const CliRun r = run_loci("clip " + c.layer + " --bbox " + c.bbox + " -q -o " + out);
    ASSERT_EQ(r.status, 0) << c.bbox << r.err;
    GDALDatasetUniquePtr ds(GDALDataset::Open(out.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY));
    ASSERT_TRUE(ds) << c.bbox;
    std::map<int, double> got;
    for (auto& f : *ds->GetLayer(0)) {
      const OGRGeometry* g = f->GetGeometryRef();
      ASSERT_TRUE(g) << c.bbox;
      const int dim = g->getDimension();
      got[f->GetFieldAsInteger("i")] =
          dim == 2   ? OGR_G_Area(OGRGeometry::ToHandle(const_cast<OGRGeometry*>(g)))
          : dim == 1 ? OGR_G_Length(OGRGeometry::ToHandle(const_cast<OGRGeometry*>(g)))
                     : 0.0;
    }
    // The features the query lists, each with the measure worked out by hand.
    std::istringstream ids(run_loci("query " + c.layer + " --bbox " + c.bbox).out);
    std::vector<int> listed;
    for (int id; ids >> id;)
      listed.push_back(id);
    std::vector<int> want_ids, got_ids;
    for (const auto& [i, m] : c.want)
      want_ids.push_back(i);
    for (const auto& [i, m] : got)
      got_ids.push_back(i);
    EXPECT_EQ(listed, want_ids) << c.bbox;
    EXPECT_EQ(got_ids, want_ids) << c.bbox;
    for (const auto& [i, m] : c.want)
      if (got.count(i)) EXPECT_NEAR(got[i], m, 1e-9) << c.bbox << " feature " << i;
  }
}

// A field the output format cannot hold is named with the reason, and nothing is left.
TEST_F(LayersCli, ClipSaysWhyAFieldCannotBeWritten) {
  const std::string layer = path("list-field.geojson"), out = path("list-field.shp");
  std::ofstream(layer) << R"({"type":"FeatureCollection","features":[{"type":"Feature",)"
                          R"("properties":{"lst":[1,2,3]},"geometry":{"type":"Point",)"
                          R"("coordinates":[1,1]}}]})";
  const CliRun r = run_loci("clip " + layer + " --bbox 0,0,2,2 -o " + out);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("field lst ("), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("IntegerList"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

// A field the output format holds only as another type (a shapefile's Date for a DateTime:
// the times of day are lost) is written, with a warning naming it, even with --quiet.
TEST_F(LayersCli, ClipWarnsOfAFieldWrittenAsAnotherType) {
  const std::string layer = path("datetime-field.geojson");
  std::ofstream(layer) << R"({"type":"FeatureCollection","features":[{"type":"Feature",)"
                          R"("properties":{"when":"2024-01-02T03:04:05Z","n":1},)"
                          R"("geometry":{"type":"Point","coordinates":[1,1]}}]})";
  for (const char* quiet : {"", " -q"}) {
    const std::string out = path(std::string("datetime") + (*quiet ? "-q" : "") + ".shp");
    const CliRun r = run_loci("clip " + layer + " --bbox 0,0,2,2 -o " + out + quiet);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("warning: " + out + " has no DateTime fields: field when written as Date"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.err.find("field n"), std::string::npos) << r.err;
    const OgrFeatureSet got = read_with_ogr(out);
    ASSERT_EQ(got.geoms.size(), 1u);
  }
  // A format that holds the type says nothing; one whose driver lists no such type (as
  // ogr2ogr reads the list) is said to convert it.
  const CliRun g = run_loci("clip " + layer + " --bbox 0,0,2,2 -o " + path("datetime.gpkg"));
  ASSERT_EQ(g.status, 0) << g.err;
  EXPECT_EQ(g.err.find("warning"), std::string::npos) << g.err;
  const std::string kml = path("datetime.kml");
  const CliRun k = run_loci("clip " + layer + " --bbox 0,0,2,2 -o " + kml);
  ASSERT_EQ(k.status, 0) << k.err;
  EXPECT_NE(k.err.find("warning: " + kml + " has no DateTime fields: GDAL converts field when"),
            std::string::npos)
      << k.err;
}

// loci bench compares the packed tree with Boost.Geometry's on the layer's entries and names
// them: a point layer's are its points, not segments.
TEST_F(LayersCli, BenchNamesWhatItIndexes) {
  const std::string pts = path("bench-points.csv"), lines = path("bench-lines.csv");
  std::ofstream(pts) << "WKT,n\n\"POINT (1 1)\",1\n\"POINT (2 2)\",2\n\"POINT (3 1)\",3\n";
  std::ofstream(lines) << "WKT,n\n\"LINESTRING (0 0,1 1,2 0)\",1\n\"LINESTRING (5 5,6 6)\",2\n";
  const CliRun p = run_loci("bench " + pts + " --queries 50");
  ASSERT_EQ(p.status, 0) << p.err;
  EXPECT_NE(p.out.find(": 3 boxes (per point), 50 windows"), std::string::npos) << p.out;
  const CliRun l = run_loci("bench " + lines + " --queries 50");
  ASSERT_EQ(l.status, 0) << l.err;
  EXPECT_NE(l.out.find(": 3 boxes (per segment), 50 windows"), std::string::npos) << l.out;
  for (const char* row : {"build (packed)", "window queries", "nearest-n queries"})
    EXPECT_NE(l.out.find(row), std::string::npos) << l.out;
}

TEST_F(LayersCli, PointFileLocatesEveryPoint) {
  const std::string layer = path("polys.shp");
  const OgrFeatureSet s = read_with_ogr(layer);
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> pos(-5, 105);
  const std::string file = path("located.points");
  std::vector<std::pair<double, double>> points;
  {
    std::ofstream out(file);
    out.precision(17);
    for (int i = 0; i < 300; ++i) {
      points.emplace_back(pos(rng), pos(rng));
      out << points.back().first << ',' << points.back().second << '\n';
    }
  }
  for (const char* per : {"feature", "segment"}) {
    const CliRun r = run_loci("query " + shell_quote(layer) + " --point-file " + shell_quote(file) +
                              " --per " + per + " -q");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto got = parse_ids(r.out, points.size());
    std::size_t inside = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      OGRPoint p(points[i].first, points[i].second);
      const auto want = brute_intersects(s, p);
      EXPECT_EQ(got[i + 1], want) << per << " point " << i + 1;
      inside += !want.empty();
    }
    EXPECT_GT(inside, 20u);
  }
}

// --segment --first (line of sight): the feature met first and how far along, against GEOS
// on every feature; and plain --segment's x,y are each feature's first point.
TEST_F(LayersCli, SegmentFirstHitMatchesGeos) {
  for (const char* name : {"polys.shp", "lines.shp"}) {
    const std::string layer = path(name);
    const OgrFeatureSet s = read_with_ogr(layer);
    for (const char* per : {"feature", "segment"}) {
      std::mt19937_64 rng(91);
      std::uniform_real_distribution<double> pos(-5, 105), len(-60, 60);
      int hits = 0;
      for (int q = 0; q < 14; ++q) {
        const double x0 = pos(rng), y0 = pos(rng), x1 = x0 + len(rng), y1 = y0 + len(rng);
        std::vector<double> t(s.geoms.size());
        double best = 2;
        for (std::size_t i = 0; i < s.geoms.size(); ++i) {
          t[i] = ogr_first_meet(*s.geoms[i], x0, y0, x1, y1);
          if (t[i] >= 0) best = std::min(best, t[i]);
        }
        char buf[200];
        std::snprintf(buf, sizeof buf, " --segment %.17g,%.17g,%.17g,%.17g", x0, y0, x1, y1);
        const std::string cmd = "query " + shell_quote(layer) + buf + " --per " + per;
        const CliRun r = run_loci(cmd + " --first -f csv");
        ASSERT_EQ(r.status, 0) << r.err;
        const auto rows = lines(r.out);
        ASSERT_FALSE(rows.empty());
        EXPECT_EQ(rows[0].rfind("fid,distance,x,y,", 0), 0u) << rows[0];
        if (best > 1) {
          EXPECT_EQ(rows.size(), 1u) << cmd;
          continue;
        }
        ++hits;
        ASSERT_EQ(rows.size(), 2u) << cmd;
        std::istringstream in(rows[1]);
        std::string fid, dist;
        std::getline(in, fid, ',');
        std::getline(in, dist, ',');
        const double length = std::hypot(x1 - x0, y1 - y0);
        EXPECT_NEAR(std::stod(dist), best * length, 1e-9 * (1 + length)) << cmd;
        const auto it = std::find(s.fids.begin(), s.fids.end(), std::stoll(fid));
        ASSERT_NE(it, s.fids.end());
        EXPECT_NEAR(t[std::size_t(it - s.fids.begin())], best, 1e-9) << cmd << " fid " << fid;

        // Every feature the segment meets, each with its own first point.
        const CliRun all = run_loci(cmd + " -f csv");
        ASSERT_EQ(all.status, 0) << all.err;
        for (const auto& row : lines(all.out)) {
          if (row.rfind("fid", 0) == 0) continue;
          std::istringstream rin(row);
          std::string f, x, y;
          std::getline(rin, f, ',');
          std::getline(rin, x, ',');
          std::getline(rin, y, ',');
          const auto jt = std::find(s.fids.begin(), s.fids.end(), std::stoll(f));
          ASSERT_NE(jt, s.fids.end());
          const double want = t[std::size_t(jt - s.fids.begin())];
          ASSERT_GE(want, 0) << cmd << " fid " << f;
          EXPECT_NEAR(std::stod(x), x0 + want * (x1 - x0), 1e-9 * (1 + length)) << cmd;
          EXPECT_NEAR(std::stod(y), y0 + want * (y1 - y0), 1e-9 * (1 + length)) << cmd;
        }
      }
      EXPECT_GT(hits, 5) << name << " " << per;
    }
  }
  // A segment that starts on a feature and runs towards smaller x and y met it at 0, not -0.
  const std::string box = path("corner.geojson");
  std::ofstream(box) << R"({"type":"FeatureCollection","features":[{"type":"Feature",)"
                        R"("properties":{},"geometry":{"type":"Polygon","coordinates":)"
                        R"([[[12,2],[14,2],[14,4],[12,4],[12,2]]]}}]})";
  for (const char* per : {"feature", "segment"})
    for (const char* seg : {"14,4,0,0", "13,2,13,-5", "12,3,0,3"}) {
      const CliRun r = run_loci("query " + shell_quote(box) + " --segment " + seg + " --per " +
                                per + " --first -f csv");
      ASSERT_EQ(r.status, 0) << r.err;
      ASSERT_EQ(lines(r.out).size(), 2u) << r.out;
      EXPECT_EQ(lines(r.out)[1].rfind("0,0,", 0), 0u) << seg << " " << per << ": " << r.out;
    }
}

// Where a query segment crosses a line it reports the true crossing rounded to the nearest
// doubles, as loci intersections does (it rounded a point recomputed from the parameter: off
// by an ulp in most crossings).
TEST_F(LayersCli, SegmentPointsAreTheTrueCrossingsRounded) {
  const loci::Segment2 line{{0.0730383438336979, 0.6294549122340242},
                            {0.7785108586766508, 0.2697755868501427}};
  const std::string layer = path("one.geojson");
  {
    std::ofstream o(layer);
    o.precision(17);
    o << R"({"type":"FeatureCollection","features":[{"type":"Feature","properties":{},)"
      << R"("geometry":{"type":"LineString","coordinates":[[)" << line.a[0] << ',' << line.a[1]
      << "],[" << line.b[0] << ',' << line.b[1] << "]]}}]}";
  }
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  int crossings = 0;
  for (int q = 0; q < 12; ++q) {
    const loci::Segment2 s{{u(rng), u(rng)}, {u(rng), u(rng)}};
    const loci::SegmentIntersection want = loci::intersection(line, s);
    if (want.kind != loci::SegmentMeet::point) continue;
    ++crossings;
    char seg[120];
    std::snprintf(seg, sizeof seg, " --segment %.17g,%.17g,%.17g,%.17g", s.a[0], s.a[1], s.b[0],
                  s.b[1]);
    for (const char* per : {"feature", "segment"})
      for (const char* first : {"", " --first"}) {
        const CliRun r =
            run_loci("query " + shell_quote(layer) + seg + " --per " + per + first + " -f csv");
        ASSERT_EQ(r.status, 0) << r.err;
        const auto rows = lines(r.out);
        ASSERT_EQ(rows.size(), 2u) << r.out;
        std::vector<std::string> f;
        std::stringstream in(rows[1]);
        for (std::string x; std::getline(in, x, ',');)
          f.push_back(x);
        const std::size_t at = *first ? 2 : 1;  // after fid (and distance)
        ASSERT_GT(f.size(), at + 1) << rows[1];
        EXPECT_EQ(std::stod(f[at]), want.a[0]) << per << first << ": " << rows[1];
        EXPECT_EQ(std::stod(f[at + 1]), want.a[1]) << per << first << ": " << rows[1];
      }
  }
  EXPECT_GE(crossings, 3);
  fs::remove(layer);
  fs::remove(layer + ".loci");
}

TEST_F(LayersCli, CandidatesAreASupersetOfTheExactAnswer) {
  const std::string layer = path("polys.shp");
  const char* window = " --bbox 20,20,45,40";
  const CliRun exact = run_loci("query " + layer + window);
  const CliRun boxes = run_loci("query " + layer + window + " --candidates");
  ASSERT_EQ(exact.status, 0);
  ASSERT_EQ(boxes.status, 0);
  const auto e = parse_ids(exact.out, 1)[1], c = parse_ids(boxes.out, 1)[1];
  EXPECT_TRUE(std::includes(c.begin(), c.end(), e.begin(), e.end()));
  // Envelopes overlap the window more often than the stars themselves do.
  const OgrFeatureSet s = read_with_ogr(layer);
  std::vector<long long> env;
  for (std::size_t i = 0; i < s.fids.size(); ++i)
    if (s.envelopes[i].MaxX >= 20 && s.envelopes[i].MinX <= 45 && s.envelopes[i].MaxY >= 20 &&
        s.envelopes[i].MinY <= 40)
      env.push_back(s.fids[i]);
  EXPECT_EQ(c, env);
}

TEST_F(LayersCli, CsvAndGeoJsonCarryAttributes) {
  const std::string layer = path("polys.shp");
  CliRun r = run_loci("query " + layer + " --bbox 0,0,100,100 -f csv");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = lines(r.out);
  ASSERT_EQ(rows.size(), 61u);
  EXPECT_EQ(rows[0], "fid,label");
  EXPECT_EQ(rows[1], "0,\"f,0\"");
  const std::string out = path("answer.geojson");
  r = run_loci("query " + layer + " --bbox 0,0,100,100 -f geojson -o " + out);
  ASSERT_EQ(r.status, 0) << r.err;
  const OgrFeatureSet s = read_with_ogr(out);
  EXPECT_EQ(s.fids.size(), 60u);
  fs::remove(out);
}

// A text layer (GeoJSON, where GDAL finds a feature by FID by parsing) gives the same CSV and
// GeoJSON answers as the shapefile it was converted from with all 17 digits, features named
// by many answers included (the answers' features are read in one pass over the layer).
TEST_F(LayersCli, CsvAndGeoJsonFromATextLayerMatchTheShapefile) {
  const std::string shp = path("polys.shp"), text = path("polys-text.geojson");
  {
    GDALDatasetH src = GDALOpenEx(shp.c_str(), GDAL_OF_VECTOR, nullptr, nullptr, nullptr);
    ASSERT_TRUE(src);
    const char* argv[] = {"-f", "GeoJSON", "-lco", "SIGNIFICANT_FIGURES=17", nullptr};
    GDALVectorTranslateOptions* opts =
        GDALVectorTranslateOptionsNew(const_cast<char**>(argv), nullptr);
    fs::remove(text);
    GDALDatasetH out = GDALVectorTranslate(text.c_str(), nullptr, 1, &src, opts, nullptr);
    GDALVectorTranslateOptionsFree(opts);
    GDALClose(src);
    ASSERT_TRUE(out);
    GDALClose(out);
  }
  const std::string points = path("text.points");
  {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> pos(-10, 110);
    std::ofstream p(points);
    p.precision(17);
    for (int i = 0; i < 40; ++i)
      p << pos(rng) << ',' << pos(rng) << '\n';
  }
  // The answers' rows of a GeoJSON output: query, fid and label of each feature, in order,
  // with its geometry's envelope.
  auto rows = [](const std::string& file) {
    std::vector<std::tuple<long long, long long, std::string, double, double, double, double>> r;
    GDALDatasetUniquePtr ds(GDALDataset::Open(file.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY));
    if (!ds) return r;
    for (auto& f : *ds->GetLayer(0)) {
      OGREnvelope e;
      if (f->GetGeometryRef()) f->GetGeometryRef()->getEnvelope(&e);
      r.emplace_back(f->GetFieldAsInteger64("query"), f->GetFieldAsInteger64("fid"),
                     f->GetFieldAsString("label"), e.MinX, e.MinY, e.MaxX, e.MaxY);
    }
    return r;
  };
  for (const char* per : {"feature", "segment"}) {
    const std::string batch =
        " --nearest-file " + shell_quote(points) + " -k 6 --per " + per + " -q";
    const CliRun a = run_loci("query " + shell_quote(shp) + batch + " -f csv");
    const CliRun b = run_loci("query " + shell_quote(text) + batch + " -f csv");
    ASSERT_EQ(a.status, 0) << a.err;
    ASSERT_EQ(b.status, 0) << b.err;
    EXPECT_EQ(lines(a.out).size(), 1u + 40 * 6) << per;
    EXPECT_EQ(a.out, b.out) << per;
    const std::string out_a = path("text-a.geojson"), out_b = path("text-b.geojson");
    ASSERT_EQ(run_loci("query " + shell_quote(shp) + batch + " -f geojson -o " + out_a).status, 0);
    ASSERT_EQ(run_loci("query " + shell_quote(text) + batch + " -f geojson -o " + out_b).status, 0);
    const auto ra = rows(out_a), rb = rows(out_b);
    EXPECT_EQ(ra.size(), 40u * 6) << per;
    EXPECT_EQ(ra, rb) << per;
    fs::remove(out_a);
    fs::remove(out_b);
  }
  fs::remove(text);
  fs::remove(text + ".loci");
}

TEST_F(LayersCli, ClipCutsToTheWindow) {
  const std::string out = path("clipped.shp");
  const CliRun r = run_loci("clip " + path("polys.shp") + " --bbox 20,20,60,60 -q -o " + out);
  ASSERT_EQ(r.status, 0) << r.err;
  const OgrFeatureSet s = read_with_ogr(out);
  ASSERT_FALSE(s.fids.empty());
  for (const auto& e : s.envelopes) {
    EXPECT_GE(e.MinX, 20 - 1e-9);
    EXPECT_LE(e.MaxX, 60 + 1e-9);
  }
  // A CSV output keeps the cut geometries (as WKT, which OGR reads back), the same ones to the
  // 15 digits GDAL writes WKT with.
  const std::string csv = path("clipped.csv");
  const CliRun c = run_loci("clip " + path("polys.shp") + " --bbox 20,20,60,60 -q -o " + csv);
  ASSERT_EQ(c.status, 0) << c.err;
  const OgrFeatureSet t = read_with_ogr(csv);
  ASSERT_EQ(t.geoms.size(), s.geoms.size());
  for (std::size_t i = 0; i < t.geoms.size(); ++i) {
    EXPECT_NEAR(t.envelopes[i].MinX, s.envelopes[i].MinX, 1e-9);
    EXPECT_NEAR(t.envelopes[i].MaxY, s.envelopes[i].MaxY, 1e-9);
    const double area = OGR_G_Area(OGRGeometry::ToHandle(s.geoms[i].get()));
    EXPECT_GT(area, 0);
    EXPECT_NEAR(OGR_G_Area(OGRGeometry::ToHandle(t.geoms[i].get())), area, 1e-9 * (1 + area));
  }
  // Clipping that CSV again: its WKT column is its geometry, not a field to copy beside it.
  const std::string again = path("again.csv");
  const CliRun c2 = run_loci("clip " + csv + " --bbox 30,30,50,50 -q -o " + again);
  ASSERT_EQ(c2.status, 0) << c2.err;
  const std::string header = read_text(again).substr(0, read_text(again).find('\n'));
  EXPECT_EQ(header.find("WKT"), header.rfind("WKT")) << header;
  fs::remove(again);
  fs::remove(csv);
  for (const char* ext : {".shp", ".shx", ".dbf"})
    fs::remove(path(std::string("clipped") + ext));
}

TEST_F(LayersCli, DrawWritesAnSvg) {
  const std::string out = path("index.svg");
  const CliRun r = run_loci("draw " + path("lines.shp") + " -q --levels 2 -o " + out);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string svg = read_text(out);
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("<rect x="), std::string::npos);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_EQ(svg.find("<circle"), std::string::npos) << "a layer of lines has no dots";
  // Without -o, or with -o -, the same drawing goes to stdout.
  for (const char* to : {"", " -o -"}) {
    const CliRun piped = run_loci("draw " + path("lines.shp") + " -q --levels 2" + to);
    ASSERT_EQ(piped.status, 0) << piped.err;
    EXPECT_EQ(piped.out, svg) << to;
  }
  const CliRun told = run_loci("draw " + path("lines.shp") + " --levels 2");
  ASSERT_EQ(told.status, 0) << told.err;
  EXPECT_EQ(told.out, svg);
  EXPECT_NE(told.err.find("nodes drawn\n"), std::string::npos) << told.err;
  // The isolated points of a layer are drawn as dots, one per point, a collection's too.
  const std::string points = path("draw-points.geojson");
  std::ofstream(points) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":{"type":"Point","coordinates":[0,0]}},
{"type":"Feature","properties":{},"geometry":{"type":"MultiPoint","coordinates":[[4,2],[2,4]]}},
{"type":"Feature","properties":{},"geometry":{"type":"GeometryCollection","geometries":[
{"type":"LineString","coordinates":[[0,4],[4,4]]},{"type":"Point","coordinates":[4,0]}]}}]})";
  const std::string dots = path("points.svg");
  const CliRun p = run_loci("draw " + points + " -q -o " + dots);
  ASSERT_EQ(p.status, 0) << p.err;
  const std::string drawn = read_text(dots);
  std::size_t circles = 0;
  for (std::size_t at = drawn.find("<circle"); at != std::string::npos;
       at = drawn.find("<circle", at + 1))
    ++circles;
  EXPECT_EQ(circles, 4u) << drawn;
  // The 4 x 4 extent with a margin of 0.2 on every side, 1200 pixels wide: (0,0) at the
  // bottom left, (4,0) bottom right, the line along the top.
  EXPECT_NE(drawn.find("width=\"1200\" height=\"1200\""), std::string::npos) << drawn;
  EXPECT_NE(drawn.find("<circle cx=\"54.5\" cy=\"1145.5\""), std::string::npos) << drawn;
  EXPECT_NE(drawn.find("<circle cx=\"1145.5\" cy=\"1145.5\""), std::string::npos) << drawn;
  EXPECT_NE(drawn.find("<path d=\"M54.5 54.5L1145.5 54.5\"/>"), std::string::npos) << drawn;
  // A layer of one point is drawn at the middle, one of a horizontal line in a drawing of some
  // height (a tenth of its width, and the margins): not one pixel high.
  std::ofstream(points) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":{"type":"Point","coordinates":[3,4]}}]})";
  ASSERT_EQ(run_loci("draw " + points + " -q -o " + dots).status, 0);
  EXPECT_NE(read_text(dots).find("<circle cx=\"600.0\" cy=\"600.0\""), std::string::npos)
      << read_text(dots);
  std::ofstream(points) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[0,4],[10,4]]}}]})";
  ASSERT_EQ(run_loci("draw " + points + " -q -o " + dots).status, 0);
  // 11 x 2 units at 1200 pixels: 219 high, the line from (0.5, 1) to (10.5, 1) units in.
  EXPECT_NE(read_text(dots).find("width=\"1200\" height=\"219\""), std::string::npos)
      << read_text(dots);
  EXPECT_NE(read_text(dots).find("<path d=\"M54.5 109.1L1145.5 109.1\"/>"), std::string::npos)
      << read_text(dots);
  // A layer of any size fills the drawing alike (below 1e-12 it was drawn in the corner).
  for (const char* size : {"1e-12", "1e-15", "1e-200"}) {
    std::ofstream(points) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[0,0],[)"
                          << size << "," << size << "]]}}]}";
    ASSERT_EQ(run_loci("draw " + points + " -q -o " + dots).status, 0);
    EXPECT_NE(read_text(dots).find("<path d=\"M54.5 1145.5L1145.5 54.5\"/>"), std::string::npos)
        << size << "\n"
        << read_text(dots);
  }
  fs::remove(points);
  fs::remove(dots);
}

TEST_F(LayersCli, InfoSummarisesTheLayerAndItsIndex) {
  const std::string layer = path("lines.shp");
  fs::remove(layer + ".loci");
  CliRun r = run_loci("info " + layer);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("features:  60"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("index:     none"), std::string::npos) << r.out;
  ASSERT_EQ(run_loci("index -q " + layer).status, 0);
  r = run_loci("info " + layer);
  EXPECT_NE(r.out.find("fresh"), std::string::npos) << r.out;
  fs::remove(layer + ".loci");
  // A GeoPackage of two layers indexed for one: the other's info does not call it fresh.
  const std::string two = path("two.gpkg");
  fs::remove(two);
  ASSERT_EQ(std::system(("ogr2ogr -f GPKG " + two + " " + layer +
                         " -nln alpha && ogr2ogr -update " + two + " " + layer + " -nln beta")
                            .c_str()),
            0);
  // Before an index: the command that writes one names the layer when it is not the first.
  r = run_loci("info " + two + " --layer beta");
  EXPECT_NE(r.out.find("none (loci index " + two + " --layer beta writes " + two + ".loci)"),
            std::string::npos)
      << r.out;
  r = run_loci("info " + two);
  EXPECT_NE(r.out.find("none (loci index " + two + " writes " + two + ".loci)"), std::string::npos)
      << r.out;
  ASSERT_EQ(run_loci("index -q " + two + " --layer beta").status, 0);
  r = run_loci("info " + two + " --layer alpha");
  EXPECT_NE(r.out.find("not this layer's (it indexes layer 'beta'"), std::string::npos) << r.out;
  r = run_loci("info " + two + " --layer beta");
  EXPECT_NE(r.out.find(": fresh"), std::string::npos) << r.out;
  // --layer as GDAL finds it: in another case it is the layer indexed (it was refused as
  // another layer's index); a name GDAL does not know is said so (it was "indexes 'beta'").
  const std::string all = " --bbox -1e9,-1e9,1e9,1e9 -f ids";
  r = run_loci("query " + two + " --layer BETA" + all);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(r.out.empty());
  EXPECT_EQ(r.out, run_loci("query " + two + " --layer beta" + all).out);
  r = run_loci("query " + two + " --layer nope" + all);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("two.gpkg: no layer named 'nope'"), std::string::npos) << r.err;
  // Indexing the other layer replaces the file's one index, and says so.
  r = run_loci("index " + two + " --layer alpha");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("two.gpkg.loci held the index of layer 'beta', now replaced"),
            std::string::npos)
      << r.err;
  r = run_loci("index " + two + " --layer alpha");
  EXPECT_EQ(r.err.find("now replaced"), std::string::npos) << r.err;
  fs::remove(two + ".loci");
  // The index of another file's layer beside this one: info says whose, as queries do (it
  // said "stale").
  const std::string stranger = path("stranger.geojson");
  std::ofstream(stranger)
      << R"({"type":"FeatureCollection","features":[{"type":"Feature",)"
         R"("properties":{},"geometry":{"type":"Point","coordinates":[3,4]}}]})";
  const std::string lone = path("lone.geojson");
  std::ofstream(lone) << R"({"type":"FeatureCollection","features":[{"type":"Feature",)"
                         R"("properties":{},"geometry":{"type":"Point","coordinates":[1,2]}}]})";
  ASSERT_EQ(run_loci("index -q " + stranger + " -o " + lone + ".loci").status, 0);
  r = run_loci("info " + lone);
  EXPECT_NE(r.out.find("lone.geojson.loci: not this layer's (it indexes layer 'stranger'"),
            std::string::npos)
      << r.out;
  fs::remove(lone + ".loci");
  // Names that hold spaces (and the like) are quoted in the lists, so that each reads apart.
  ASSERT_EQ(std::system(("ogr2ogr -update " + two + " " + layer + " -nln \"my roads\"").c_str()),
            0);
  const std::string named = path("named.geojson");
  std::ofstream(named) << (R"({"type":"FeatureCollection","features":[{"type":"Feature",)"
                           R"("properties":{"Country Name":"x","it's":1,"plain":2},)"
                           R"("geometry":{"type":"Point","coordinates":[1,2]}}]})");
  r = run_loci("info " + two);
  EXPECT_NE(r.out.find("layers:    alpha beta 'my roads'\n"), std::string::npos) << r.out;
  r = run_loci("info " + named);
  EXPECT_NE(r.out.find("fields:    'Country Name':String 'it''s':Integer plain:Integer\n"),
            std::string::npos)
      << r.out;
}

// A feature without a geometry and one whose geometry has no points are told apart, and
// neither widens the extent.
TEST_F(LayersCli, InfoTellsEmptyGeometriesFromMissingOnes) {
  const std::string csv = path("empties.csv");
  {
    std::ofstream(csv) << "id,wkt\n1,POINT EMPTY\n2,\n3,POINT (1 2)\n4,LINESTRING EMPTY\n"
                          "5,POINT (3 4)\n";
  }
  const CliRun r = run_loci("info " + csv);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("features:  5\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("geometry:  (none) x1 Line String (empty) x1 Point x2 Point (empty) x1\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("extent:    1,2,3,4\n"), std::string::npos) << r.out;
  // A shapefile's null shapes are "(none)" on both of its paths (see test_shapefile_boxes).
}

TEST_F(LayersCli, HelpDocumentsEveryCommand) {
  const CliRun top = run_loci("--help");
  EXPECT_EQ(top.status, 0);
  for (const char* c : {"info", "index", "query", "clip", "draw", "bench"}) {
    EXPECT_NE(top.out.find(std::string("  ") + c), std::string::npos) << c;
    const CliRun h = run_loci(std::string(c) + " --help");
    EXPECT_EQ(h.status, 0);
    EXPECT_NE(h.out.find("examples:"), std::string::npos) << c;
  }
  EXPECT_NE(run_loci("query --help").out.find("--bbox-file"), std::string::npos);
}

// ---- errors: one line, exit 1, no partial output ----

void expect_error(const std::string& args, const std::string& fragment) {
  const CliRun r = run_loci(args);
  EXPECT_EQ(r.status, 1) << args << "\n" << r.err;
  EXPECT_EQ(r.err.rfind("loci: error: ", 0), 0u) << args << "\n" << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << args << "\n" << r.err;
  EXPECT_TRUE(r.out.empty()) << args << "\n" << r.out;
}

namespace {

// The answers of a numbered batch output ("N fid" or "N,fid,..." rows), by query number: each
// query's rows after its number, in their order. The rows must come in query order.
std::map<std::size_t, std::vector<std::string>> by_query(const std::string& out, bool csv) {
  std::map<std::size_t, std::vector<std::string>> rows;
  auto all = lines(out);
  std::size_t last = 0;
  for (std::size_t i = csv ? 1 : 0; i < all.size(); ++i) {
    const std::size_t cut = all[i].find(csv ? ',' : ' ');
    const std::size_t q = std::stoul(all[i].substr(0, cut));
    EXPECT_GE(q, last) << "rows out of query order at " << all[i];
    last = q;
    rows[q].push_back(all[i].substr(cut + 1));
  }
  return rows;
}

}  // namespace

// Batches run on threads (chunks of 64 queries each) answer exactly what one thread does, in
// the same order; the batches here are long enough to be cut. Queries run in an order of
// their own (along a curve through their points) whatever the order of the file: the same
// batch reversed gives each query the same answer under its reversed number.
TEST_F(LayersCli, BatchesOnThreadsMatchOneThread) {
  std::mt19937_64 rng(77);
  std::uniform_real_distribution<double> pos(-5, 105), size(0.5, 20);
  const std::string windows = path("batch.windows"), points = path("batch.points");
  const std::string windows_reversed = path("batch.windows.reversed");
  const std::string points_reversed = path("batch.points.reversed");
  {
    std::vector<std::string> w_rows, p_rows;
    char buf[200];
    for (int i = 0; i < 700; ++i) {
      const double x = pos(rng), y = pos(rng), w = size(rng), h = size(rng);
      std::snprintf(buf, sizeof buf, "%.17g,%.17g,%.17g,%.17g\n", x, y, x + w, y + h);
      w_rows.push_back(buf);
      const double px = pos(rng), py = pos(rng);
      std::snprintf(buf, sizeof buf, "%.17g,%.17g\n", px, py);
      p_rows.push_back(buf);
    }
    std::ofstream w(windows), p(points), wr(windows_reversed), pr(points_reversed);
    for (std::size_t i = 0; i < w_rows.size(); ++i) {
      w << w_rows[i];
      p << p_rows[i];
      wr << w_rows[w_rows.size() - 1 - i];
      pr << p_rows[p_rows.size() - 1 - i];
    }
  }
  for (const char* layer : {"polys.shp", "lines.shp"}) {
    for (const char* per : {"feature", "segment"}) {
      for (const bool nearest : {false, true}) {
        auto batch = [&](const std::string& file) {
          return "query " + shell_quote(path(layer)) +
                 (nearest ? " --nearest-file " + shell_quote(file) + " -k 4 -f csv"
                          : " --bbox-file " + shell_quote(file)) +
                 " --per " + per + " -q";
        };
        const std::string cmd = batch(nearest ? points : windows);
        const CliRun one = run_loci(cmd + " -j 1");
        const CliRun three = run_loci(cmd + " -j 3");
        const CliRun reversed = run_loci(batch(nearest ? points_reversed : windows_reversed));
        ASSERT_EQ(one.status, 0) << one.err;
        ASSERT_EQ(three.status, 0) << three.err;
        ASSERT_EQ(reversed.status, 0) << reversed.err;
        EXPECT_GT(lines(one.out).size(), 700u) << cmd;
        EXPECT_EQ(one.out, three.out) << cmd;
        const auto forward = by_query(one.out, nearest), backward = by_query(reversed.out, nearest);
        EXPECT_EQ(forward.size(), backward.size()) << cmd;
        for (const auto& [q, rows] : forward) {
          const auto it = backward.find(701 - q);
          ASSERT_NE(it, backward.end()) << cmd << " query " << q;
          EXPECT_EQ(rows, it->second) << cmd << " query " << q;
        }
      }
    }
  }
  expect_error(
      "query " + shell_quote(path("polys.shp")) + " --bbox-file " + shell_quote(windows) + " -j 0",
      "--jobs");
}

// loci join: intersects and dwithin:D between two layers (and a layer with itself), every
// pair against GEOS's Intersects and Distance on all pairs of features.
TEST_F(LayersCli, JoinMatchesGeosOnAllPairs) {
  const std::vector<std::pair<const char*, const char*>> pairs{
      {"polys.shp", "lines.shp"}, {"polys.shp", "polys.shp"}, {"polys.shp", "points.shp"}};
  for (const auto& [l, r] : pairs) {
    const OgrFeatureSet left = read_with_ogr(path(l)), right = read_with_ogr(path(r));
    for (const std::string pred : {"intersects", "contains", "within", "dwithin:3.5"}) {
      const bool dwithin = pred == "dwithin:3.5";
      const CliRun run = run_loci("join " + shell_quote(path(l)) + " " + shell_quote(path(r)) +
                                  " --predicate " + pred + " -q");
      ASSERT_EQ(run.status, 0) << run.err;
      const auto rows = lines(run.out);
      ASSERT_FALSE(rows.empty());
      EXPECT_EQ(rows[0], dwithin ? "fid_left,fid_right,distance" : "fid_left,fid_right");
      std::map<std::pair<long long, long long>, double> got;
      for (std::size_t k = 1; k < rows.size(); ++k) {
        std::istringstream in(rows[k]);
        std::string a, b, d;
        std::getline(in, a, ',');
        std::getline(in, b, ',');
        std::getline(in, d, ',');
        got[{std::stoll(a), std::stoll(b)}] = dwithin ? std::stod(d) : 0;
      }
      std::size_t want = 0;
      for (std::size_t i = 0; i < left.geoms.size(); ++i) {
        for (std::size_t j = 0; j < right.geoms.size(); ++j) {
          const auto key = std::pair{left.fids[i], right.fids[j]};
          const double dist = left.geoms[i]->Distance(right.geoms[j].get());
          const bool meets = left.geoms[i]->Intersects(right.geoms[j].get());
          // covers: nothing of the covered geometry left outside the other (GEOS overlay).
          auto covers = [](const OGRGeometry& a, const OGRGeometry& b) {
            if (!a.Intersects(&b)) return false;
            const std::unique_ptr<OGRGeometry> rest(b.Difference(&a));
            return rest && rest->IsEmpty();
          };
          const bool in = dwithin              ? (meets || dist <= 3.5)
                          : pred == "contains" ? covers(*left.geoms[i], *right.geoms[j])
                          : pred == "within"   ? covers(*right.geoms[j], *left.geoms[i])
                                               : meets;
          if (!dwithin || std::fabs(dist - 3.5) > 1e-9)
            EXPECT_EQ(got.count(key), in ? 1u : 0u)
                << l << " " << r << " " << pred << " pair " << key.first << "," << key.second;
          if (in && dwithin && got.count(key))
            EXPECT_NEAR(got[key], meets ? 0 : dist, 1e-9) << key.first << "," << key.second;
          want += in;
        }
      }
      // Polygons hold a few lines whole and no line or point holds a polygon.
      std::size_t at_least = 5;
      if (pred == "within" && std::string(r) != "polys.shp") at_least = 0;
      if (pred == "contains" && std::string(r) == "lines.shp") at_least = 1;
      EXPECT_GE(want, at_least) << l << " " << r << " " << pred;
    }
  }
  // --closest: the pair at the smallest distance, against every pair's GEOS distance (two
  // different features of a layer joined with itself).
  for (const auto& [l, r] :
       std::vector<std::pair<const char*, const char*>>{{"polys.shp", "lines.shp"},
                                                        {"lines.shp", "lines.shp"},
                                                        {"points.shp", "points.shp"},
                                                        {"lines.shp", "points.shp"}}) {
    const OgrFeatureSet left = read_with_ogr(path(l)), right = read_with_ogr(path(r));
    const bool self = std::string(l) == r;
    double want = std::numeric_limits<double>::infinity();
    std::map<std::pair<long long, long long>, double> dist;
    for (std::size_t i = 0; i < left.geoms.size(); ++i)
      for (std::size_t j = 0; j < right.geoms.size(); ++j) {
        if (self && i == j) continue;
        const double d = left.geoms[i]->Distance(right.geoms[j].get());
        dist[{left.fids[i], right.fids[j]}] = d;
        want = std::min(want, d);
      }
    const CliRun run =
        run_loci("join " + shell_quote(path(l)) + " " + shell_quote(path(r)) + " --closest -q");
    ASSERT_EQ(run.status, 0) << run.err;
    const auto rows = lines(run.out);
    ASSERT_EQ(rows.size(), 2u) << run.out;
    EXPECT_EQ(rows[0], "fid_left,fid_right,distance");
    std::istringstream in(rows[1]);
    std::string a, b, d;
    std::getline(in, a, ',');
    std::getline(in, b, ',');
    std::getline(in, d, ',');
    EXPECT_NEAR(std::stod(d), want, 1e-9) << l << " " << r;
    const auto it = dist.find({std::stoll(a), std::stoll(b)});
    ASSERT_NE(it, dist.end()) << l << " " << r << ": " << rows[1];
    EXPECT_NEAR(it->second, want, 1e-9) << l << " " << r;
  }
  // A square with a hole covers a square beside the hole, not one over it, nor one along its
  // outer edge that sticks out; a square covers itself.
  {
    const std::string holed = path("holed.geojson"), squares = path("squares.geojson");
    std::ofstream(holed) << R"({"type":"FeatureCollection","features":[{"type":"Feature",
      "properties":{},"geometry":{"type":"Polygon","coordinates":[[[0,0],[10,0],[10,10],[0,10],
      [0,0]],[[4,4],[6,4],[6,6],[4,6],[4,4]]]}}]})";
    auto square = [](double x0, double y0, double x1, double y1) {
      std::ostringstream o;
      o << R"({"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[[)"
        << x0 << ',' << y0 << "],[" << x1 << ',' << y0 << "],[" << x1 << ',' << y1 << "],[" << x0
        << ',' << y1 << "],[" << x0 << ',' << y0 << "]]]}}";
      return o.str();
    };
    std::ofstream(squares) << R"({"type":"FeatureCollection","features":[)" << square(1, 1, 3, 3)
                           << ',' << square(3, 3, 7, 7) << ',' << square(8, 0, 12, 2) << ','
                           << square(0, 0, 10, 10) << "]}";
    const CliRun run = run_loci("join " + shell_quote(holed) + " " + shell_quote(squares) +
                                " --predicate contains -f ids -q");
    ASSERT_EQ(run.status, 0) << run.err;
    EXPECT_EQ(run.out, "0 0\n");
    // The same square with a hole and a far island, as a shapefile: its polygons are built
    // from the records, not by GDAL, and the hole is kept.
    const fs::path holed_shp = g_dir / "holed_multi.shp";
    write_layer(
        holed_shp, wkbMultiPolygon,
        [](int) {
          OGRGeometry* g = nullptr;
          const char* wkt =
              "MULTIPOLYGON(((0 0,10 0,10 10,0 10,0 0),(4 4,6 4,6 6,4 6,4 4)),"
              "((20 20,21 20,21 21,20 21,20 20)))";
          OGRGeometryFactory::createFromWkt(wkt, nullptr, &g);
          return std::unique_ptr<OGRGeometry>(g);
        },
        1);
    const CliRun shp = run_loci("join " + shell_quote(holed_shp.string()) + " " +
                                shell_quote(squares) + " --predicate contains -f ids -q");
    ASSERT_EQ(shp.status, 0) << shp.err;
    EXPECT_EQ(shp.out, "0 0\n");
    const CliRun self = run_loci("join " + shell_quote(squares) + " " + shell_quote(squares) +
                                 " --predicate within -f ids -q");
    ASSERT_EQ(self.status, 0) << self.err;
    EXPECT_EQ(self.out, "0 0\n0 3\n1 1\n1 3\n2 2\n3 3\n");
  }
  expect_error("join " + shell_quote(path("polys.shp")) + " " + shell_quote(path("lines.shp")) +
                   " --predicate dwithin:-1",
               "dwithin");
  expect_error("join " + shell_quote(path("polys.shp")) + " " + shell_quote(path("lines.shp")),
               "--closest");
  expect_error("join " + shell_quote(path("polys.shp")), "LEFT and RIGHT");
}

// Clipping by a polygonal window (--wkt, --window-layer): the features GEOS says meet the
// window, each cut to it (areas and lengths as GEOS's intersection).
TEST_F(LayersCli, ClipByPolygonWindows) {
  // A non-convex window: a star with a notch, and a two-polygon window layer that overlaps.
  const std::string wkt =
      "POLYGON((20 20,50 25,80 20,60 50,80 80,50 60,20 80,35 50,20 20),(45 40,55 40,50 48,45 40))";
  const std::string windows = path("windows.geojson");
  std::ofstream(windows) << R"({"type":"FeatureCollection","features":[
    {"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":
      [[[10,10],[40,10],[40,40],[10,40],[10,10]]]}},
    {"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":
      [[[30,30],[70,35],[50,70],[30,30]]]}}]})";
  std::unique_ptr<OGRGeometry> star;
  {
    OGRGeometry* g = nullptr;
    ASSERT_EQ(OGRGeometryFactory::createFromWkt(wkt.c_str(), nullptr, &g), OGRERR_NONE);
    star.reset(g);
  }
  std::unique_ptr<OGRGeometry> united;
  {
    const OgrFeatureSet w = read_with_ogr(windows);
    united.reset(w.geoms[0]->Union(w.geoms[1].get()));
  }
  for (const char* name : {"polys.shp", "lines.shp"}) {
    const OgrFeatureSet s = read_with_ogr(path(name));
    for (int which = 0; which < 2; ++which) {
      const OGRGeometry& window = which == 0 ? *star : *united;
      const std::string out = path("clip-" + std::to_string(which) + ".geojson");
      fs::remove(out);
      const std::string arg =
          which == 0 ? " --wkt " + shell_quote(wkt) : " --window-layer " + shell_quote(windows);
      const CliRun r = run_loci("clip " + shell_quote(path(name)) + arg + " -q -o " + out);
      ASSERT_EQ(r.status, 0) << r.err;
      const OgrFeatureSet got = read_with_ogr(out);
      std::map<double, int> want_measures, got_measures;  // area or length, counted
      auto measure = [](const OGRGeometry& g) {
        switch (wkbFlatten(g.getGeometryType())) {
          case wkbPolygon:
            return g.toPolygon()->get_Area();
          case wkbMultiPolygon:
            return g.toMultiPolygon()->get_Area();
          case wkbLineString:
            return g.toLineString()->get_Length();
          case wkbMultiLineString:
            return g.toMultiLineString()->get_Length();
          default:
            return 0.0;
        }
      };
      std::size_t want = 0;
      for (std::size_t i = 0; i < s.geoms.size(); ++i) {
        if (!s.geoms[i]->Intersects(&window)) continue;
        ++want;
        // Clip repairs an invalid polygon (a bowtie) before cutting it, as GEOS needs.
        const std::unique_ptr<OGRGeometry> valid(s.geoms[i]->IsValid() ? s.geoms[i]->clone()
                                                                       : s.geoms[i]->MakeValid());
        const std::unique_ptr<OGRGeometry> piece(valid->Intersection(&window));
        ++want_measures[std::round(std::fabs(measure(*piece)) * 1e6) / 1e6];
      }
      for (const auto& g : got.geoms)
        ++got_measures[std::round(std::fabs(measure(*g)) * 1e6) / 1e6];
      EXPECT_EQ(got.fids.size(), want) << name << " window " << which;
      EXPECT_EQ(got_measures, want_measures) << name << " window " << which;
      EXPECT_GT(want, 3u);
      fs::remove(out);
    }
  }
  expect_error("clip " + shell_quote(path("polys.shp")) + " --wkt " +
                   shell_quote("LINESTRING(0 0,1 1)") + " -o " + path("x.geojson"),
               "POLYGON");
  expect_error("clip " + shell_quote(path("polys.shp")) + " --wkt " + shell_quote(wkt) +
                   " --bbox 0,0,1,1 -o " + path("x.geojson"),
               "exactly one window");
  expect_error("clip " + shell_quote(path("polys.shp")) + " --window-layer " +
                   shell_quote(path("lines.shp")) + " -o " + path("x.geojson"),
               "not a polygon");
  EXPECT_FALSE(fs::exists(path("x.geojson")));
}

TEST_F(LayersCli, ReportsBadInput) {
  const std::string polys = path("polys.shp");
  expect_error("query " + path("missing.shp") + " --bbox 0,0,1,1", "no such file");
  expect_error("index " + path("missing.shp"), "no such file");
  expect_error("query " + path("garbage.geojson") + " --bbox 0,0,1,1", "cannot open");
  expect_error("query " + path("table.csv") + " --bbox 0,0,1,1", "has no geometry");
  expect_error("query " + polys + " --layer nope --bbox 0,0,1,1", "no layer named 'nope'");
  expect_error("query " + polys + " --bbox 0,0,1", "bad bbox '0,0,1'");
  expect_error("query " + polys + " --bbox a,b,c,d", "bad bbox");
  expect_error("query " + polys + " --bbox 5,0,1,1", "XMIN > XMAX");
  expect_error("query " + polys + " --nearest 1,1 -k 0", "-k must be >= 1");
  expect_error("query " + polys + " --nearest 1,1 -k -3", "-k must be >= 1");
  expect_error("query " + polys + " --nearest 1,1 -k x", "bad -k");
  expect_error("query " + polys, "exactly one of");
  expect_error("query " + polys + " --bbox 0,0,1,1 --frobnicate", "unknown option --frobnicate");
  expect_error("query " + polys + " --bbox 0,0,1,1 -f xml",
               "'xml' is not a format this command writes (choose ids, csv or geojson)");
  // A value option given twice is refused rather than the last one taken, under either name.
  expect_error("query " + polys + " --bbox 0,0,1,1 --bbox 2,2,3,3",
               "--bbox is given twice; loci query takes one --bbox");
  expect_error("query " + polys + " --nearest 1,1 -k 2 -k 3", "-k is given twice");
  expect_error("query " + polys + " --bbox 0,0,1,1 -k 3", "-k counts the neighbours of --nearest");
  expect_error("query " + polys + " --bbox 0,0,1,1 --format ids -f csv", "-f is given twice");
  // A value joined to its option (-k3, --bbox=...) is that option's value, and counts once.
  for (const char* joined : {"--nearest=1,1 -k3", "-n1,1 -k 3", "-n 1,1 -k3"}) {
    const CliRun r = run_loci("query " + polys + " " + joined + " -fids");
    EXPECT_EQ(r.status, 0) << joined << r.err;
    EXPECT_EQ(r.out, run_loci("query " + polys + " --nearest 1,1 -k 3 -f ids").out) << joined;
  }
  expect_error("query " + polys + " --nearest 1,1 -k3 -k 2", "-k is given twice");
  expect_error("query " + polys + " --bbox=0,0,1,1 -b 0,0,1,1", "-b is given twice");
  expect_error("query " + polys + " --bbox 0,0,1,1 --quiet=yes", "unknown option --quiet=yes");
  expect_error("query " + polys + " --bbox= ", "--bbox needs a value");
  expect_error("query " + polys + " --bbox 0,0,1,1 -xk3", "unknown option -xk3");
  expect_error("index " + polys + " -o " + path("a.loci") + " --output -",
               "--output is given twice");
  expect_error("index " + polys + " --structure rstar", "built in memory only");
  expect_error("frobnicate", "unknown command");
  expect_error("join " + polys + " " + polys + " --closest --predicate intersects", "not both");
  expect_error("join " + polys + " " + polys, "needs --predicate");
  const std::string windows = path("bad.windows");
  std::ofstream(windows) << "0,0,1,1\n0,0,x,1\n";
  expect_error("query " + polys + " --bbox-file " + windows, "line 2");
}

// clip writes the format its output's extension names, and refuses an extension it does not
// know (rather than writing GeoJSON under it) and a shapefile of mixed kinds of geometry,
// naming two features of different kinds; neither leaves a file.
TEST_F(LayersCli, ClipRefusesUnknownFormatsAndMixedShapefiles) {
  const std::string polys = path("polys.shp");
  expect_error("clip " + polys + " --bbox 0,0,50,50 -o " + path("c.xyz"),
               "cannot tell the output format of " + path("c.xyz") + " from its extension");
  EXPECT_FALSE(fs::exists(path("c.xyz")));
  const CliRun json = run_loci("clip " + polys + " --bbox 0,0,50,50 -q -o " + path("c.json"));
  EXPECT_EQ(json.status, 0) << json.err;
  EXPECT_EQ(read_text(path("c.json")).rfind("{", 0), 0u);
  const std::string mixed = path("mixed.geojson");
  std::ofstream(mixed) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":{"type":"Point","coordinates":[1,1]}},
{"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[[2,2],[4,2],[4,4],[2,2]]]}}]})";
  expect_error("clip " + mixed + " --bbox 0,0,9,9 -o " + path("mixed.shp"),
               "a shapefile holds one kind of geometry, and the window meets feature 0 (Point) "
               "and feature 1 (Polygon)");
  EXPECT_FALSE(fs::exists(path("mixed.shp")));
  const CliRun gpkg = run_loci("clip " + mixed + " --bbox 0,0,9,9 -q -o " + path("mixed.gpkg"));
  EXPECT_EQ(gpkg.status, 0) << gpkg.err;
}

// A cut of several parts plus a touching piece of lower dimension (GEOS gives a collection)
// is written as its parts of the feature's dimension: a U cut off from its bar is two arms, not
// one polygon with the second arm as a hole outside it; a line that also touches the window's
// edge at a vertex is a line (into a shapefile too, which once failed); what is left out is
// counted. An invalid --wkt window is refused.
// A dataset holding other layers is not replaced by a clip, or any output, written over it (the
// layers would be lost with the file); one holding only a layer is replaced, as any output
// file is.
TEST_F(LayersCli, OutputsRefuseToReplaceAFileHoldingOtherLayers) {
  const std::string u = path("sq.geojson");
  std::ofstream(u) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{"n":1},"geometry":{"type":"Polygon","coordinates":
[[[0,0],[6,0],[6,6],[0,6],[0,0]]]}}]})";
  const std::string two = path("keep.gpkg");
  fs::remove(two);
  ASSERT_EQ(std::system(("ogr2ogr -f GPKG " + two + " " + u + " -nln alpha && ogr2ogr -update " +
                         two + " " + u + " -nln beta")
                            .c_str()),
            0);
  const auto size = fs::file_size(two);
  expect_error("clip " + u + " --bbox 1,1,2,2 -q -o " + two,
               "holds 2 layers (alpha, beta), which writing the whole file would lose");
  EXPECT_EQ(fs::file_size(two), size);
  // So does every other command's -o (query, index, draw, join and intersections wrote text,
  // a sidecar or SVG over it).
  for (const std::string& command :
       {"query " + u + " --bbox 1,1,2,2", "index " + u + " -q", "draw " + u + " -q",
        "join " + u + " " + u + " -p intersects -q", "intersections " + u + " -q"}) {
    // (an index is refused sooner, by the name: a .gpkg is no sidecar; named otherwise, as
    // the others)
    if (command.rfind("index", 0) == 0) {
      expect_error(command + " -o " + two, "its name says a .gpkg file");
      const std::string unnamed = path("keep-data");
      fs::copy_file(two, unnamed, fs::copy_options::overwrite_existing);
      expect_error(command + " -o " + unnamed,
                   "holds 2 layers (alpha, beta), which writing the whole file would lose");
      EXPECT_EQ(fs::file_size(unnamed), size) << command;
    } else {
      expect_error(command + " -o " + two,
                   "holds 2 layers (alpha, beta), which writing the whole file would lose");
    }
    EXPECT_EQ(fs::file_size(two), size) << command;
  }
  EXPECT_EQ(read_with_ogr(two).geoms.size(), 1u);  // alpha, untouched
  // A GeoPackage of one layer is replaced by the clip.
  const std::string one = path("one.gpkg");
  fs::remove(one);
  ASSERT_EQ(std::system(("ogr2ogr -f GPKG " + one + " " + u + " -nln alpha").c_str()), 0);
  const CliRun r = run_loci("clip " + u + " --bbox 1,1,2,2 -q -o " + one);
  ASSERT_EQ(r.status, 0) << r.err;
  const OgrFeatureSet got = read_with_ogr(one);
  ASSERT_EQ(got.geoms.size(), 1u);
  EXPECT_EQ(got.envelopes[0].MinX, 1.0);
  EXPECT_EQ(got.envelopes[0].MaxY, 2.0);
  // A text output (an answer, a drawing) does not replace a binary dataset, of one layer
  // either: the GeoPackage, a shapefile's .shp or .dbf (they became text, and the dataset
  // would no longer open). A text dataset is replaced, as a run again replaces its answer.
  const std::string shp = path("other.shp"), dbf = path("other.dbf");
  ASSERT_EQ(std::system(("ogr2ogr " + shp + " " + u).c_str()), 0);
  const auto shp_size = fs::file_size(shp), one_size = fs::file_size(one);
  for (const std::string& target : {one, shp, dbf})
    for (const std::string& command :
         {"query " + u + " --bbox 1,1,2,2", "query " + u + " --bbox 1,1,2,2 -f csv",
          "query " + u + " --bbox 1,1,2,2 -f geojson", "draw " + u + " -q",
          "intersections " + u + " -q", "join " + u + " " + u + " -q"})
      expect_error(command + " -o " + target, "which this text output would replace");
  EXPECT_EQ(fs::file_size(shp), shp_size);
  EXPECT_EQ(fs::file_size(one), one_size);
  EXPECT_EQ(read_with_ogr(shp).geoms.size(), 1u);
  // Under a name that says nothing, what a file holds decides.
  const std::string unnamed = path("one-data");
  fs::copy_file(one, unnamed);
  expect_error("query " + u + " --bbox 1,1,2,2 -o " + unnamed,
               "which this text output would replace");
  EXPECT_EQ(fs::file_size(unnamed), one_size);
  // A new file named as a dataset does not get a text answer either (an answer.dbf of CSV).
  const std::string named = path("answer.dbf");
  expect_error("query " + u + " --bbox 1,1,2,2 -f csv -o " + named,
               "its name says a .dbf file but the output is CSV");
  EXPECT_FALSE(fs::exists(named));
  const std::string text = path("answer.geojson");
  for (int run = 0; run < 2; ++run)
    ASSERT_EQ(run_loci("query " + u + " --bbox 1,1,2,2 -f geojson -o " + text).status, 0);
  EXPECT_EQ(read_with_ogr(text).geoms.size(), 1u);
}

// A sidecar written elsewhere with -o is drawn with --index (draw took the layer from the
// sidecar's name and refused it as missing, with no way to name it).
TEST_F(LayersCli, DrawTakesASidecarNamedByIndex) {
  const std::string sidecar = path("elsewhere.loci"), out = path("elsewhere.svg");
  ASSERT_EQ(run_loci("index -q " + path("lines.shp") + " -o " + sidecar).status, 0);
  expect_error("draw " + sidecar + " -q -o " + out, "loci draw LAYER --index " + sidecar);
  EXPECT_FALSE(fs::exists(out));
  const CliRun r = run_loci("draw " + path("lines.shp") + " --index " + sidecar + " -q -o " + out);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(read_text(out).find("<rect x="), std::string::npos);
  // The sidecar of another layer is refused, as queries refuse it.
  const CliRun other =
      run_loci("draw " + path("polys.shp") + " --index " + sidecar + " -q -o " + out);
  EXPECT_EQ(other.status, 1) << other.err;
}

// A query file may start with a UTF-8 byte order mark (it was refused, quoting a line that
// looked right), and -o onto the query file itself is refused (it was overwritten).
TEST_F(LayersCli, QueryFilesTakeAByteOrderMarkAndAreNeverOverwritten) {
  const std::string q = path("bom.txt");
  std::ofstream(q, std::ios::binary) << "\xEF\xBB\xBF"
                                     << "0,0,100,100\r\n";
  const CliRun plain = run_loci("query " + path("lines.shp") + " --bbox 0,0,100,100 -f ids");
  ASSERT_EQ(plain.status, 0) << plain.err;
  const CliRun r = run_loci("query " + path("lines.shp") + " --bbox-file " + q + " -f ids");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out, "");
  const std::string before = read_text(q);
  expect_error("query " + path("lines.shp") + " --bbox-file " + q + " -f ids -o " + q,
               "it is the query file");
  EXPECT_EQ(read_text(q), before);
}

// `draw` of a sidecar refuses, as its output, the layer the sidecar indexes (it wrote the SVG
// over that layer), and the sidecar itself.
TEST_F(LayersCli, DrawOfASidecarRefusesItsLayerAsTheOutput) {
  const std::string u = path("sq2.geojson");
  std::ofstream(u) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{"n":1},"geometry":{"type":"Polygon","coordinates":
[[[0,0],[6,0],[6,6],[0,6],[0,0]]]}}]})";
  // The layer a sidecar indexes, given as draw's output through the sidecar.
  const std::string layer = path("drawn.gpkg");
  fs::remove(layer);
  ASSERT_EQ(std::system(("ogr2ogr -f GPKG " + layer + " " + u + " -nln drawn").c_str()), 0);
  ASSERT_EQ(run_loci("index -q " + layer).status, 0);
  const auto layer_size = fs::file_size(layer);
  // (A GeoPackage: refused as a dataset a drawing would replace, before the layer is read.)
  expect_error("draw " + layer + ".loci -q -o " + layer, "refusing to write " + layer + ": it is");
  EXPECT_EQ(fs::file_size(layer), layer_size);
  EXPECT_EQ(read_with_ogr(layer).geoms.size(), 1u);
  const auto sidecar_size = fs::file_size(layer + ".loci");
  // A .loci name is refused for a drawing by its name; under a name that says nothing, the
  // sidecar read is refused as such.
  expect_error("draw " + layer + ".loci -q -o " + layer + ".loci", "its name says a sidecar");
  EXPECT_EQ(fs::file_size(layer + ".loci"), sidecar_size);
  const std::string plain = path("drawn-index");
  ASSERT_EQ(run_loci("index -q " + layer + " -o " + plain).status, 0);
  const auto plain_size = fs::file_size(plain);
  expect_error("draw " + plain + " -q -o " + plain, "refusing to write");
  EXPECT_EQ(fs::file_size(plain), plain_size);
  // Drawing the layer reads its default sidecar: that is refused as the output too.
  expect_error("draw " + layer + " -q -o " + layer + ".loci", "its name says a sidecar");
  EXPECT_EQ(fs::file_size(layer + ".loci"), sidecar_size);
  expect_error("draw " + layer + " --index " + plain + " -q -o " + plain, "refusing to write");
  EXPECT_EQ(fs::file_size(plain), plain_size);
}

// A GeoPackage of the WKT geometries of a CSV (column WKT), as ogr2ogr converts it.
bool gpkg_of_wkt_csv(const std::string& csv, const std::string& gpkg, const std::string& layer,
                     const std::string& type) {
  fs::remove(gpkg);
  return std::system(("ogr2ogr -q -f GPKG " + gpkg + " " + csv + " -nln " + layer +
                      " -oo GEOM_POSSIBLE_NAMES=WKT -oo KEEP_GEOM_COLUMNS=NO -nlt " + type +
                      " 2> /dev/null")
                         .c_str()) == 0;
}

// Triangles, TINs and polyhedral surfaces (a MultiPatch shapefile's 3D buildings are TINs to
// GDAL) are surfaces: found by points and windows inside them and by nearest-n at 0, and cut
// by clip. Before, the exact tests took them for empty: only a window holding the whole
// feature found it, and clip failed.
TEST_F(LayersCli, TrianglesTinsAndPolyhedralSurfacesAreSurfaces) {
  const std::string csv = path("tin.csv"), gpkg = path("tin.gpkg");
  std::ofstream(csv) << "id,WKT\n"
                        "1,\"TRIANGLE ((0 0, 10 0, 0 10, 0 0))\"\n"
                        "2,\"TIN (((20 0, 30 0, 20 10, 20 0)),((30 0, 30 10, 20 10, 30 0)))\"\n"
                        "3,\"POLYHEDRALSURFACE Z (((40 0 0, 50 0 0, 40 10 0, 40 0 0)))\"\n";
  ASSERT_TRUE(gpkg_of_wkt_csv(csv, gpkg, "tin", "GEOMETRYZ"));
  for (const auto& [query, want] : std::vector<std::pair<std::string, std::string>>{
           {"--point 1,1", "1\n"},
           {"--point 29,9", "2\n"},
           {"--point 41,1", "3\n"},
           {"--point 9,9", ""},  // beyond the triangle's long side
           {"--bbox 1,1,2,2", "1\n"},
           {"--bbox 24,4,26,6", "2\n"},
           {"--nearest 41,1 -k 1", "3\n"}}) {
    const CliRun r = run_loci("query " + gpkg + " " + query + " -f ids");
    EXPECT_EQ(r.status, 0) << query << r.err;
    EXPECT_EQ(r.out, want) << query;
  }
  const std::string cut = path("tin_cut.geojson");
  fs::remove(cut);
  const CliRun c = run_loci("clip " + gpkg + " --bbox 5,-1,45,5 -q -o " + cut);
  ASSERT_EQ(c.status, 0) << c.err;
  const OgrFeatureSet got = read_with_ogr(cut);
  ASSERT_EQ(got.geoms.size(), 3u);
  double area = 0;
  for (const auto& g : got.geoms)
    area += OGR_G_Area(OGRGeometry::ToHandle(g.get()));
  EXPECT_DOUBLE_EQ(area, 12.5 + 50 + 25);
  // A query's GeoJSON holds them as the polygons of their faces (GDAL wrote a null geometry).
  const std::string answer = path("tin_answer.geojson");
  const CliRun q = run_loci("query " + gpkg + " --bbox 0,0,50,10 -f geojson -o " + answer);
  ASSERT_EQ(q.status, 0) << q.err;
  const OgrFeatureSet found = read_with_ogr(answer);
  ASSERT_EQ(found.geoms.size(), 3u);
  area = 0;
  for (const auto& g : found.geoms) {
    ASSERT_TRUE(g) << read_text(answer);
    EXPECT_EQ(wkbFlatten(g->getGeometryType()), wkbMultiPolygon);
    area += OGR_G_Area(OGRGeometry::ToHandle(g.get()));
  }
  EXPECT_DOUBLE_EQ(area, 50 + 100 + 50);
}

// Polygons of one feature that overlap hold their overlap, whichever way their rings run
// (it counted as outside, by the even-odd rule over all of a feature's rings): a collection
// of two squares, an invalid multi-polygon of a square over a square with a hole, a 3D box's
// floor and roof, a TIN's overlapping faces; and a hole running the same way as its outer
// ring is still a hole. Per feature and per segment, in a GeoPackage and, for the
// multi-polygons, a shapefile (rings read from the file as they run).
TEST_F(LayersCli, OverlappingPolygonsOfOneFeatureHoldTheirOverlap) {
  const std::string csv = path("overlaps.csv"), gpkg = path("overlaps.gpkg");
  std::ofstream(csv)
      << "id,WKT\n"
         "1,\"GEOMETRYCOLLECTION (POLYGON ((0 0, 10 0, 10 10, 0 10, 0 0)), "
         "POLYGON ((5 5, 5 15, 15 15, 15 5, 5 5)))\"\n"
         "2,\"MULTIPOLYGON (((20 0, 30 0, 30 10, 20 10, 20 0)), ((22 2, 22 12, 32 12, 32 2, 22 2), "
         "(24 4, 24 6, 26 6, 26 4, 24 4)))\"\n"
         "3,\"POLYGON ((40 0, 50 0, 50 10, 40 10, 40 0), (42 2, 48 2, 48 8, 42 8, 42 2))\"\n"
         "4,\"POLYHEDRALSURFACE Z (((60 0 0, 60 10 0, 70 10 0, 70 0 0, 60 0 0)), "
         "((60 0 5, 70 0 5, 70 10 5, 60 10 5, 60 0 5)), ((60 0 0, 70 0 0, 70 0 5, 60 0 5, 60 0 "
         "0)))\"\n"
         "5,\"TIN (((80 0, 90 0, 80 10, 80 0)), ((80 0, 90 10, 80 10, 80 0)))\"\n"
         "6,\"MULTIPOLYGON (((100 0, 110 0, 110 10, 100 10, 100 0)), ((120 0, 130 0, 130 10, "
         "120 10, 120 0), (102 2, 102 4, 104 4, 104 2, 102 2)))\"\n";
  ASSERT_TRUE(gpkg_of_wkt_csv(csv, gpkg, "overlaps", "GEOMETRYZ"));
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--point 7,7", "1\n"},  // in both squares
      {"--point 2,2", "1\n"},  // in the first only
      {"--point 12,12", "1\n"},
      {"--bbox 6,6,9,9", "1\n"},
      {"--point 25,5", "2\n"},  // in both, in the second's hole
      {"--point 27,7", "2\n"},
      {"--point 31,11", "2\n"},
      {"--bbox 26.5,7,29,9", "2\n"},
      {"--point 45,5", ""},  // in the hole running as its outer ring does
      {"--point 41,1", "3\n"},
      {"--point 65,5", "4\n"},   // under the roof, over the floor
      {"--point 82,5", "5\n"},   // in both faces
      {"--point 88,9", "5\n"},   // in the second face only
      {"--point 103,3", "6\n"},  // in the first polygon, under the second's stray hole
      {"--point 95,5", ""}};
  for (const char* per : {"feature", "segment"})
    for (const auto& [query, want] : cases) {
      const CliRun r = run_loci("query " + gpkg + " " + query + " --per " + per + " -f ids");
      EXPECT_EQ(r.status, 0) << query << r.err;
      EXPECT_EQ(r.out, want) << per << " " << query;
    }
  // clip cuts such a feature as the union of its polygons (GEOS's repair of the whole took
  // the overlap as outside: the cut was empty, or lost the overlap).
  for (const auto& [window, area] : std::vector<std::pair<std::string, double>>{
           {"6,6,9,9", 9},                      // in the collection's overlap
           {"0,0,15,15", 175},                  // the whole collection
           {"24.5,4.5,25.5,5.5", 1},            // in the second polygon's hole, in the first
           {"19,-1,33,13", 100 + 100 - 64}}) {  // the whole multi-polygon: 8 by 8 shared
    const std::string cut = path("overlaps_cut.geojson");
    fs::remove(cut);
    const CliRun c = run_loci("clip " + gpkg + " --bbox " + window + " -q -o " + cut);
    ASSERT_EQ(c.status, 0) << window << c.err;
    const OgrFeatureSet got = read_with_ogr(cut);
    double sum = 0;
    for (const auto& g : got.geoms)
      sum += OGR_G_Area(OGRGeometry::ToHandle(g.get()));
    EXPECT_DOUBLE_EQ(sum, area) << window;
  }
  // The multi-polygons in a shapefile: the driver makes polygons of clockwise rings.
  const std::string shp = path("overlaps_shp.shp");
  for (const char* ext : {".shp", ".shx", ".dbf", ".prj", ".cpg"})
    fs::remove(path(std::string("overlaps_shp") + ext));
  ASSERT_EQ(std::system(("ogr2ogr -q -f 'ESRI Shapefile' " + shp + " " + gpkg +
                         " -where 'id IN (2, 3)' -nlt MULTIPOLYGON -dim XY 2> /dev/null")
                            .c_str()),
            0);
  for (const char* per : {"feature", "segment"})
    for (const auto& [query, want] : cases) {
      if (want != "2\n" && want != "3\n" && query != "--point 45,5") continue;
      const CliRun r = run_loci("query " + shp + " " + query + " --per " + per + " -f ids");
      EXPECT_EQ(r.status, 0) << query << r.err;
      // The shapefile numbers its records from 0.
      EXPECT_EQ(r.out, want.empty()    ? ""
                       : want == "2\n" ? "0\n"
                                       : "1\n")
          << "shapefile " << per << " " << query;
    }
}

// An edge that two polygons of one feature share, each on its own side (a collection of
// adjacent squares, a TIN's faces, a multi-polygon of squares side by side), lies inside the
// feature: a polygon across it is covered (join contains and within took that edge for the
// feature's boundary). One that sticks out is not, nor one over a notch the polygons leave.
TEST_F(LayersCli, EdgesPolygonsOfOneFeatureShareLieInsideIt) {
  const std::string csv = path("shared.csv"), gpkg = path("shared.gpkg");
  std::ofstream(csv) << "id,WKT\n"
                        "1,\"GEOMETRYCOLLECTION (POLYGON ((0 0, 5 0, 5 10, 0 10, 0 0)), "
                        "POLYGON ((5 0, 10 0, 10 10, 5 10, 5 0)))\"\n"
                        "2,\"TIN (((20 0, 30 0, 30 10, 20 0)), ((20 0, 30 10, 20 10, 20 0)))\"\n"
                        "3,\"MULTIPOLYGON (((40 0, 45 0, 45 10, 40 10, 40 0)), "
                        "((50 10, 45 10, 45 0, 50 0, 50 5, 48 5, 48 6, 50 6, 50 10)))\"\n";
  ASSERT_TRUE(gpkg_of_wkt_csv(csv, gpkg, "shared", "GEOMETRY"));
  const std::string squares = path("across.geojson");
  auto square = [](double x0, double y0, double x1, double y1) {
    std::ostringstream o;
    o << R"({"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[[)" << x0
      << ',' << y0 << "],[" << x1 << ',' << y0 << "],[" << x1 << ',' << y1 << "],[" << x0 << ','
      << y1 << "],[" << x0 << ',' << y0 << "]]]}}";
    return o.str();
  };
  std::ofstream(squares) << R"({"type":"FeatureCollection","features":[)" << square(3, 3, 7, 7)
                         << ',' << square(22, 2, 28, 8) << ',' << square(42, 1, 47, 4) << ','
                         << square(8, 8, 12, 12) << ',' << square(42, 4, 49, 7) << "]}";
  const CliRun contains =
      run_loci("join " + gpkg + " " + shell_quote(squares) + " --predicate contains -f ids -q");
  ASSERT_EQ(contains.status, 0) << contains.err;
  EXPECT_EQ(contains.out, "1 0\n2 1\n3 2\n");
  const CliRun within =
      run_loci("join " + shell_quote(squares) + " " + gpkg + " --predicate within -f ids -q");
  ASSERT_EQ(within.status, 0) << within.err;
  EXPECT_EQ(within.out, "0 1\n1 2\n2 3\n");
}

// A null attribute stays null in a GeoJSON answer (it was left out, as if the layer had no
// such value), and empty in a CSV one.
TEST_F(LayersCli, NullAttributesStayNull) {
  const std::string layer = path("nulls.geojson"), answer = path("nulls_answer.geojson");
  std::ofstream(layer) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{"n":null,"m":"x"},"geometry":{"type":"Point","coordinates":[1,1]}},
{"type":"Feature","properties":{"n":2,"m":null},"geometry":{"type":"Point","coordinates":[2,2]}}]})";
  const CliRun r = run_loci("query " + layer + " --bbox 0,0,5,5 -f geojson -o " + answer);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string text = read_text(answer);
  EXPECT_NE(text.find(R"("n": null, "m": "x")"), std::string::npos) << text;
  EXPECT_NE(text.find(R"("n": 2, "m": null)"), std::string::npos) << text;
  const CliRun c = run_loci("query " + layer + " --bbox 0,0,5,5 -f csv");
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_EQ(c.out, "fid,n,m\n0,,x\n1,2,\n");
  // Collections with empty members are written without them (GDAL wrote a null geometry, or
  // "geometries": null).
  const std::string empties = path("empties.csv"), out = path("empties.geojson");
  std::ofstream(empties) << "id,WKT\n1,\"GEOMETRYCOLLECTION (POINT EMPTY, POINT (1 1))\"\n"
                            "2,\"MULTIPOINT (EMPTY, (2 2))\"\n";
  const CliRun e = run_loci("query " + empties + " --bbox 0,0,5,5 -f geojson -o " + out);
  ASSERT_EQ(e.status, 0) << e.err;
  EXPECT_EQ(read_text(out).find("null"), std::string::npos) << read_text(out);
  EXPECT_EQ(read_with_ogr(out).geoms.size(), 2u) << read_text(out);
}

// A clip keeps Z (interpolated along the cut) and writes no M (GEOS does not carry measures:
// every vertex got M = 0, values no one measured), as ogr2ogr -clipsrc does.
TEST_F(LayersCli, ClipKeepsZAndWritesNoMadeUpMeasures) {
  const std::string csv = path("zm.csv"), gpkg = path("zm.gpkg"), cut = path("zm_cut.gpkg");
  std::ofstream(csv) << "id,WKT\n1,\"LINESTRING ZM (0 1 100 5, 10 1 200 15)\"\n";
  fs::remove(cut);
  ASSERT_TRUE(gpkg_of_wkt_csv(csv, gpkg, "zm", "LINESTRINGZM"));
  const CliRun r = run_loci("clip " + gpkg + " --bbox 2,-1,8,2 -q -o " + cut);
  ASSERT_EQ(r.status, 0) << r.err;
  const OgrFeatureSet got = read_with_ogr(cut);
  ASSERT_EQ(got.geoms.size(), 1u);
  const OGRGeometry& g = *got.geoms[0];
  EXPECT_TRUE(g.Is3D());
  EXPECT_FALSE(g.IsMeasured());
  char* wkt = nullptr;
  g.exportToWkt(&wkt, wkbVariantIso);
  EXPECT_STREQ(wkt, "LINESTRING Z (2 1 120,8 1 180)");
  CPLFree(wkt);
}

// Features sharing a FID (GDAL gives GeoJSON features their "id", repeated or not) are refused:
// loci reads features back by FID, and answered with the other feature's geometry and values.
TEST_F(LayersCli, FeaturesSharingAFidAreRefused) {
  const std::string d = path("dup.geojson");
  std::ofstream(d) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","id":1,"properties":{"n":"a"},"geometry":{"type":"Point","coordinates":[0,0]}},
{"type":"Feature","id":1,"properties":{"n":"b"},"geometry":{"type":"Point","coordinates":[20,20]}}]})";
  for (const std::string& command :
       {"query " + d + " --bbox 19,19,21,21 -f csv", "query " + d + " --nearest 20,20 -k 1",
        "index " + d + " -q -o " + path("dup.loci"),
        "clip " + d + " --bbox 19,19,21,21 -q -o " + path("dup_clip.geojson"),
        "join " + d + " " + d + " -p intersects"})
    expect_error(command, "dup.geojson: two features have FID 1");
  EXPECT_FALSE(fs::exists(path("dup.loci")));
  EXPECT_FALSE(fs::exists(path("dup_clip.geojson")));
  // Distinct ids, or none: read as before.
  const std::string ok = path("nodup.geojson");
  std::ofstream(ok) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","id":7,"properties":{"n":"a"},"geometry":{"type":"Point","coordinates":[0,0]}},
{"type":"Feature","id":3,"properties":{"n":"b"},"geometry":{"type":"Point","coordinates":[20,20]}}]})";
  const CliRun r = run_loci("query " + ok + " --bbox 19,19,21,21 -f ids");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "3\n");
}

TEST_F(LayersCli, ClipWritesCutsOfMixedDimensionAsTheirParts) {
  const std::string u = path("u.geojson"), line = path("touch.geojson");
  std::ofstream(u) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{"n":1},"geometry":{"type":"Polygon","coordinates":
[[[0,0],[6,0],[6,6],[4,6],[4,2],[2,2],[2,6],[0,6],[0,0]]]}}]})";
  std::ofstream(line) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{"n":1},"geometry":{"type":"LineString","coordinates":
[[-5,5],[5,5],[5,15],[8,10],[11,15]]}}]})";
  for (const char* ext : {".geojson", ".gpkg", ".shp"}) {
    const std::string out = path(std::string("u-cut") + ext);
    const CliRun r = run_loci("clip " + u + " --bbox -1,2,7,7 -o " + out);
    ASSERT_EQ(r.status, 0) << ext << r.err;
    EXPECT_NE(r.err.find("1 piece of lower dimension left out"), std::string::npos) << r.err;
    const OgrFeatureSet got = read_with_ogr(out);
    ASSERT_EQ(got.geoms.size(), 1u) << ext;
    const OGRGeometry& g = *got.geoms[0];
    ASSERT_EQ(wkbFlatten(g.getGeometryType()), wkbMultiPolygon) << ext;
    EXPECT_EQ(g.toMultiPolygon()->getNumGeometries(), 2) << ext;
    EXPECT_TRUE(g.IsValid()) << ext;
    EXPECT_DOUBLE_EQ(g.toMultiPolygon()->get_Area(), 16.0) << ext;

    const std::string lout = path(std::string("l-cut") + ext);
    const CliRun l = run_loci("clip " + line + " --bbox 0,0,10,10 -o " + lout);
    ASSERT_EQ(l.status, 0) << ext << l.err;
    EXPECT_NE(l.err.find("1 piece of lower dimension left out"), std::string::npos) << l.err;
    const OgrFeatureSet lines = read_with_ogr(lout);
    ASSERT_EQ(lines.geoms.size(), 1u) << ext;
    const OGRGeometry& lg = *lines.geoms[0];
    const auto type = wkbFlatten(lg.getGeometryType());
    ASSERT_TRUE(type == wkbLineString || type == wkbMultiLineString) << ext << " " << type;
    const double length = type == wkbLineString ? lg.toLineString()->get_Length()
                                                : lg.toMultiLineString()->get_Length();
    EXPECT_DOUBLE_EQ(length, 10.0) << ext;
  }
  // A feature that is itself a collection of polygon, line and point keeps all of them.
  const std::string gc = path("gc.geojson"), gc_out = path("gc-cut.geojson");
  std::ofstream(gc) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":{"type":"GeometryCollection","geometries":[
{"type":"Polygon","coordinates":[[[0,0],[4,0],[4,4],[0,4],[0,0]]]},
{"type":"LineString","coordinates":[[10,0],[10,4]]},{"type":"Point","coordinates":[12,2]}]}}]})";
  const CliRun g = run_loci("clip " + gc + " --bbox -1,-1,20,20 -o " + gc_out);
  ASSERT_EQ(g.status, 0) << g.err;
  EXPECT_EQ(g.err.find("left out"), std::string::npos) << g.err;
  const OgrFeatureSet gcs = read_with_ogr(gc_out);
  ASSERT_EQ(gcs.geoms.size(), 1u);
  EXPECT_EQ(wkbFlatten(gcs.geoms[0]->getGeometryType()), wkbGeometryCollection);
  EXPECT_EQ(gcs.geoms[0]->toGeometryCollection()->getNumGeometries(), 3);
  expect_error("clip " + u + " --wkt " +
                   shell_quote("MULTIPOLYGON(((0 0,4 0,4 4,0 4,0 0)),((2 2,6 2,6 6,2 6,2 2)))") +
                   " -o " + path("w.geojson"),
               "--wkt: the window is not a valid polygon");
  expect_error("clip " + u + " --wkt " + shell_quote("POLYGON((0 0,4 4,4 0,0 4,0 0))") + " -o " +
                   path("w.geojson"),
               "--wkt: the window is not a valid polygon");
  // Rings that are no rings are said as such (not as rings that cross, or holes outside).
  const std::pair<const char*, const char*> malformed[] = {
      {"POLYGON((0 0,4 0,4 4,0 4))", "ring 1 of polygon 1 (its shell) is not closed"},
      {"POLYGON((0 0,4 0,0 0))", "ring 1 of polygon 1 (its shell) has 3 points"},
      {"POLYGON((0 0,4 0,2 0,0 0))", "ring 1 of polygon 1 (its shell) has no area"},
      {"POLYGON((0 0,0 0,1 1,3 3,0 0))", "ring 1 of polygon 1 (its shell) has no area"},
      {"POLYGON((2 2,2 2,2 2,2 2))",
       "ring 1 of polygon 1 (its shell) has no area: all its points are one point"},
      {"POLYGON((0 0,9 0,9 9,0 9,0 0),(1 1,2 1,2 2,1 2))",
       "ring 2 of polygon 1 (a hole) is not closed"},
      {"MULTIPOLYGON(((0 0,1 0,1 1,0 0)),((5 5,6 5,7 5,5 5)))",
       "ring 1 of polygon 2 (its shell) has no area"}};
  for (const auto& [wkt, says] : malformed)
    expect_error("clip " + u + " --wkt " + shell_quote(wkt) + " -o " + path("w.geojson"),
                 std::string("--wkt: ") + says);
  EXPECT_FALSE(fs::exists(path("w.geojson")));
  // A ring whose ends differ only in z is closed in plan.
  const CliRun z =
      run_loci("clip " + u + " --wkt " + shell_quote("POLYGON Z((0 0 0,4 0 0,4 4 0,0 0 5))") +
               " -q -o " + path("z.geojson"));
  EXPECT_EQ(z.status, 0) << z.err;
}

// Attributes reach every output format by position, whatever the driver makes of their names
// (a shapefile cuts them to ten characters, GML replaces spaces, names differing in case are one
// name to most formats); an attribute named WKT survives a CSV output; an upper-case .SHP is
// written under that name.
TEST_F(LayersCli, ClipKeepsEveryAttributeWhateverTheDriverNamesIt) {
  const std::string l = path("fields.geojson");
  std::ofstream(l) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{"population_total":123,"my field":7,"Name":"lower","NAME":"upper","WKT":"keep","s":"中文 é"},
"geometry":{"type":"Point","coordinates":[1,1]}}]})";
  for (const char* ext : {".shp", ".SHP", ".gpkg", ".csv", ".gml", ".geojson", ".fgb"}) {
    const std::string out = path(std::string("fields-out") + ext);
    const CliRun r = run_loci("clip " + l + " --bbox 0,0,5,5 -q -o " + out);
    ASSERT_EQ(r.status, 0) << ext << ": " << r.err;
    ASSERT_TRUE(fs::exists(out)) << ext;
    GDALDatasetUniquePtr ds(GDALDataset::Open(out.c_str(), GDAL_OF_VECTOR));
    ASSERT_TRUE(ds) << ext;
    OGRLayer* layer = ds->GetLayer(0);
    OGRFeatureUniquePtr f(layer->GetNextFeature());
    ASSERT_TRUE(f) << ext;
    // Every value once, in the order of the source's fields (a GML or CSV output may add its
    // own fields first: gml_id, WKT).
    std::vector<std::string> values;
    for (int i = 0; i < f->GetFieldCount(); ++i) {
      const std::string name = f->GetFieldDefnRef(i)->GetNameRef();
      if (name == "gml_id" || (std::string(ext) == ".csv" && name == "WKT")) continue;
      values.push_back(f->IsFieldSetAndNotNull(i) ? f->GetFieldAsString(i) : "(null)");
    }
    EXPECT_EQ(values, (std::vector<std::string>{"123", "7", "lower", "upper", "keep",
                                                "\u4e2d\u6587 \u00e9"}))
        << ext;
    ASSERT_TRUE(f->GetGeometryRef()) << ext;
    if (std::string(ext) != ".shp")
      for (const auto& e : fs::directory_iterator(path("")))
        if (e.path().stem() == "fields-out") fs::remove(e.path());
  }
  // .SHP written over an earlier .shp of the same name replaces it: no old .shp left beside the
  // new .shx and .dbf. (The loop above wrote fields-out.shp, then fields-out.SHP.)
  EXPECT_FALSE(fs::exists(path("fields-out.shp")));
  // KML's own Name field takes the source's Name.
  const std::string kml = path("fields-out.kml");
  ASSERT_EQ(run_loci("clip " + l + " --bbox 0,0,5,5 -q -o " + kml).status, 0);
  EXPECT_NE(read_text(kml).find("<name>lower</name>"), std::string::npos) << read_text(kml);
}

// A real attribute is written with every digit that tells it apart (GDAL's text keeps 15).
TEST_F(LayersCli, CsvOutputKeepsRealAttributesExact) {
  const std::string l = path("reals.geojson");
  std::ofstream(l) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{"r":0.30000000000000004,"t":0.1,"u":1e20,"i":3},"geometry":{"type":"Point","coordinates":[1,1]}}]})";
  fs::remove(l + ".loci");
  const CliRun r = run_loci("query " + l + " --bbox 0,0,5,5 -f csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "fid,r,t,u,i\n0,0.30000000000000004,0.1,1e+20,3\n");
}

// A window of no width or height is the segment or point it is: clip cuts from every feature
// query reports for it (a line crossing a zero-width window leaves a point).
TEST_F(LayersCli, ClipToAWindowOfNoWidthOrHeight) {
  const std::string l = path("flat.geojson");
  std::ofstream(l) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{"k":7},"geometry":{"type":"LineString","coordinates":[[0,5],[10,5]]}},
{"type":"Feature","properties":{"k":8},"geometry":{"type":"Polygon","coordinates":[[[0,0],[10,0],[10,10],[0,10],[0,0]]]}}]})";
  fs::remove(l + ".loci");
  for (const char* box : {"5,0,5,10", "0,5,10,5", "5,5,5,5", "-5,3,20,3"}) {
    const CliRun q = run_loci("query " + l + " --bbox " + box);
    const std::string out = path("flat-out.geojson");
    const CliRun r = run_loci("clip " + l + " --bbox " + box + " -q -o " + out);
    ASSERT_EQ(r.status, 0) << box << ": " << r.err;
    const OgrFeatureSet got = read_with_ogr(out);
    EXPECT_EQ(got.geoms.size(), lines(q.out).size()) << box;
    for (const auto& g : got.geoms) {
      ASSERT_TRUE(g) << box;
      OGRPoint at(5, 5);
      if (std::string(box) != "-5,3,20,3") EXPECT_TRUE(g->Intersects(&at)) << box;
      EXPECT_FALSE(g->IsEmpty()) << box;
    }
    fs::remove(out);
  }
  // The vertical window over the square leaves its whole width: the segment x = 5, y 0..10.
  const std::string out = path("flat-out.geojson");
  ASSERT_EQ(run_loci("clip " + l + " --bbox 5,0,5,10 -q -o " + out).status, 0);
  const OgrFeatureSet got = read_with_ogr(out);
  ASSERT_EQ(got.geoms.size(), 2u);
  double length = 0;
  for (const auto& g : got.geoms)
    if (wkbFlatten(g->getGeometryType()) == wkbLineString)
      length += g->toLineString()->get_Length();
  EXPECT_DOUBLE_EQ(length, 10.0);
}

// A line or ring of one point, or a shapefile part of one point, is that point: the
// per-segment index (read through GDAL, and straight from a shapefile's records) answers for
// it as the feature's own geometry does.
TEST_F(LayersCli, PerSegmentKeepsPartsOfOnePoint) {
  const std::string deg = path("deg.geojson"), multi = path("deg2.geojson");
  std::ofstream(deg) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[1,1]]}},
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[2,2],[2,2]]}},
{"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[[3,3]]]}},
{"type":"Feature","properties":{},"geometry":{"type":"MultiPoint","coordinates":[[5,5],[5,5]]}}
]})";
  std::ofstream(multi) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{"a":1},"geometry":{"type":"MultiLineString","coordinates":[[[1,1]],[[5,0],[6,0]]]}},
{"type":"Feature","properties":{"a":2},"geometry":{"type":"MultiLineString","coordinates":[[[10,0],[11,0]],[[3,3]]]}}
]})";
  const std::string shp = path("deg2.shp");
  ASSERT_EQ(std::system(("ogr2ogr " + shell_quote(shp) + " " + shell_quote(multi)).c_str()), 0);
  struct Case {
    std::string layer;
    std::string point;
    std::string fid;
  };
  const std::vector<Case> cases = {{deg, "1,1", "0"}, {deg, "2,2", "1"}, {deg, "3,3", "2"},
                                   {deg, "5,5", "3"}, {shp, "1,1", "0"}, {shp, "3,3", "1"}};
  for (const std::string& layer : {deg, shp}) {
    const CliRun r = run_loci("index " + layer + " --per segment -q");
    ASSERT_EQ(r.status, 0) << r.err;
  }
  for (const Case& c : cases) {
    for (const std::string how : {" --per segment", " --per feature", ""}) {
      // "" reads the sidecar written above (per segment, from the shapefile's records).
      const CliRun r = run_loci("query " + c.layer + " --point " + c.point + how);
      EXPECT_EQ(r.out, c.fid + "\n") << c.layer << " " << c.point << how << r.err;
      const CliRun n =
          run_loci("query " + c.layer + " --nearest " + c.point + " -k 1 -f csv" + how);
      EXPECT_NE(n.out.find("\n" + c.fid + ",0"), std::string::npos)
          << c.layer << " " << c.point << how << n.out << n.err;
    }
  }
}

// A point lying exactly on a slanted segment (where the floating distance is about 2e-15) is at
// distance 0: --within at 0 finds what --point finds, and --nearest says 0; a distance equal to
// the true one is decided exactly.
TEST_F(LayersCli, DistancesAtRoundingAreExact) {
  const std::string on = path("on.geojson");
  std::ofstream(on) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":
[[39008.1,2.9000000000000004],[39048.06,-39.28]]}},
{"type":"Feature","properties":{},"geometry":{"type":"Point","coordinates":[39021.42,-11.17]}}]})";
  // A point exactly on the second segment of a line whose first segment's rounded distance
  // (8e-27) is smaller than the second's (1e-13): nearest through the per-segment sidecar's
  // hierarchies says 0 too.
  const std::string two = path("two-segments.geojson");
  std::ofstream(two) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":
[[84043.75,3042.875],[85298.125,196.625],[-1169076.8750000002,2846446.625]]}}]})";
  ASSERT_EQ(run_loci("index " + two + " --per segment -q").status, 0);
  const CliRun on_second = run_loci("query " + two + " --nearest 84768.5,1398.375 -k 1 -f csv");
  EXPECT_EQ(on_second.out, "fid,distance\n0,0\n") << on_second.err;
  for (const std::string how : {" --per segment", " --per feature"}) {
    EXPECT_EQ(run_loci("query " + on + " --point 39021.42,-11.16" + how).out, "0\n") << how;
    EXPECT_EQ(run_loci("query " + on + " --within 39021.42,-11.16,0" + how).out, "0\n") << how;
    const CliRun n = run_loci("query " + on + " --nearest 39021.42,-11.16 -k 1 -f csv" + how);
    EXPECT_EQ(n.out, "fid,distance\n0,0\n") << how << n.err;
  }
}

// A layer's own fields named like loci's columns (fid, distance) are written as layer_fid and
// layer_distance, in CSV (which wrote two columns named fid) and in GeoJSON (which left them
// out).
TEST_F(LayersCli, FieldsNamedLikeLociColumnsAreKept) {
  const std::string layer = path("named.geojson");
  std::ofstream(layer) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{"fid":"A","distance":7,"name":"x"},"geometry":{"type":"Point","coordinates":[1,1]}}]})";
  const CliRun csv = run_loci("query " + layer + " --nearest 0,0 -k 1 -f csv");
  EXPECT_EQ(csv.out, "fid,distance,layer_fid,layer_distance,name\n0,1.4142135623730951,A,7,x\n")
      << csv.err;
  const std::string out = path("named-out.geojson");
  const CliRun gj = run_loci("query " + layer + " --nearest 0,0 -k 1 -f geojson -o " + out);
  ASSERT_EQ(gj.status, 0) << gj.err;
  const std::string text = read_text(out);
  EXPECT_NE(text.find("\"layer_fid\": \"A\""), std::string::npos) << text;
  EXPECT_NE(text.find("\"layer_distance\": 7"), std::string::npos) << text;
  // That output queried again: fid, distance, layer_fid and layer_distance all kept, each under
  // a name of its own.
  const CliRun again = run_loci("query " + out + " --nearest 0,0 -k 1 -f csv");
  EXPECT_EQ(again.out,
            "fid,distance,layer_fid_2,layer_distance_2,layer_fid,layer_distance,name\n"
            "0,1.4142135623730951,0,1.4142135623730951,A,7,x\n")
      << again.err;
}

TEST_F(LayersCli, UnwritableOutputLeavesNothing) {
  const std::string polys = path("polys.shp");
  expect_error("query " + polys + " --bbox 0,0,50,50 -o /nonexistent-dir/out.txt", "cannot write");
  expect_error("query " + polys + " --bbox 0,0,50,50 -f geojson -o /nonexistent-dir/o.geojson",
               "cannot write");
  expect_error("index " + polys + " -o /nonexistent-dir/x.loci", "cannot write");
  expect_error("clip " + polys + " --bbox 0,0,50,50 -o /nonexistent-dir/c.shp", "cannot write");
  // A failing query does not leave its output behind either.
  const std::string out = path("never.txt");
  expect_error("query " + polys + " --nearest 1,1 -k 0 -o " + out, "-k must be >= 1");
  EXPECT_FALSE(fs::exists(out));
  for (const auto& e : fs::directory_iterator(g_dir))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

TEST_F(LayersCli, RefusesCorruptAndTruncatedSidecars) {
  const std::string layer = path("lines.shp"), sidecar = layer + ".loci";
  ASSERT_EQ(run_loci("index -q --per segment " + layer).status, 0);
  const std::string good = read_text(sidecar);
  ASSERT_GT(good.size(), 1000u);
  const std::string query = "query " + layer + " --bbox 10,10,60,60";
  std::mt19937_64 rng(5);
  auto put = [&](const std::string& bytes) { std::ofstream(sidecar, std::ios::binary) << bytes; };
  for (std::size_t cut : {std::size_t(0), std::size_t(5), std::size_t(8), std::size_t(100),
                          std::size_t(256), std::size_t(300), good.size() / 2, good.size() - 1}) {
    put(good.substr(0, cut));
    const CliRun r = run_loci(query);
    EXPECT_EQ(r.status, 1) << "cut at " << cut << ": " << r.err;
    EXPECT_EQ(r.err.rfind("loci: error: ", 0), 0u) << r.err;
  }
  put(good);
  const CliRun intact = run_loci(query);
  ASSERT_EQ(intact.status, 0) << intact.err;
  const std::string answer = intact.out;
  ASSERT_FALSE(answer.empty());
  // Nearest-n reads the features' hierarchies the sidecar stores too.
  const std::string nearest = "query " + layer + " --nearest 30,30 -k 3";
  const std::string nearest_answer = run_loci(nearest).out;
  ASSERT_FALSE(nearest_answer.empty());
  // One flipped byte anywhere: header, name, checksum table or data. The query reads the
  // chunks it needs and is refused when one of them is corrupt, or else answers exactly as
  // before; loci check reads everything and refuses every one.
  std::size_t refused = 0;
  for (int i = 0; i < 24; ++i) {
    std::string bad = good;
    const std::size_t at = i < 4 ? std::size_t(8 + 20 * i) : rng() % bad.size();
    bad[at] = char(bad[at] ^ (1 + rng() % 255));
    put(bad);
    const CliRun r = run_loci(query);
    if (r.status == 0) {
      EXPECT_EQ(r.out, answer) << "byte " << at;
    } else {
      ++refused;
      EXPECT_EQ(r.status, 1) << "byte " << at;
      EXPECT_NE(r.err.find(sidecar), std::string::npos) << r.err;
    }
    const CliRun n = run_loci(nearest);
    if (n.status == 0) {
      EXPECT_EQ(n.out, nearest_answer) << "byte " << at;
    } else {
      EXPECT_EQ(n.status, 1) << "byte " << at;
      EXPECT_NE(n.err.find(sidecar), std::string::npos) << n.err;
    }
    const CliRun c = run_loci("check " + sidecar);
    EXPECT_EQ(c.status, 1) << "byte " << at << ": " << c.out;
    EXPECT_NE(c.err.find(sidecar), std::string::npos) << c.err;
  }
  EXPECT_GT(refused, 4u);
  put(good + "extra");
  expect_error(query, "damaged index");
  // Sidecars of earlier formats: 2 (nearest-n built the hierarchies at every run), 3 (their
  // level-0 nodes did not say which of the leaf's slots are the feature's), 4 (ring segments
  // without the number of the polygon their ring bounds), 5 (a direction bit there instead),
  // 6 (no hulls of the features).
  for (const int version : {2, 3, 4, 5, 6}) {
    std::string older = good;
    older[8] = char(version);
    put(older);
    expect_error(query, "index format version " + std::to_string(version) +
                            ", this loci reads 7; run 'loci index' to rebuild it");
  }
  std::string newer = good;
  newer[8] = char(8);
  put(newer);
  expect_error(query,
               "index format version 8, written by a newer loci (this one reads 7); use "
               "that loci, or run 'loci index' to rebuild it");
  put(good);
  EXPECT_EQ(run_loci(query).status, 0);
  const CliRun ok = run_loci("check " + sidecar);
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_NE(ok.out.find(": ok,"), std::string::npos) << ok.out;
  EXPECT_NE(ok.out.find(" chunks of 4 KiB verified, "), std::string::npos) << ok.out;
  fs::remove(sidecar);
}

// loci check of a sidecar beside the layer it is named after checks that the layer has not
// changed since, as every query does (it said "ok" of a sidecar every query refused as stale),
// and takes the layer itself for its sidecar.
TEST_F(LayersCli, CheckSaysWhenTheLayerChangedSinceItWasIndexed) {
  const std::string layer = path("checked.geojson");
  fs::copy_file(std::string(LOCI_DATASETS_DIR) + "/samples/coastline-denmark.geojson", layer,
                fs::copy_options::overwrite_existing);
  const std::string sidecar = layer + ".loci";
  fs::remove(sidecar);
  expect_error("check " + layer, "checked.geojson.loci does not exist; run 'loci index " + layer);
  ASSERT_EQ(run_loci("index -q " + layer).status, 0);
  for (const std::string& arg : {layer, sidecar}) {
    const CliRun r = run_loci("check " + arg);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out.rfind(sidecar + ": ok,", 0), 0u) << r.out;
  }
  fs::last_write_time(layer, fs::last_write_time(layer) + std::chrono::seconds(5));
  EXPECT_EQ(run_loci("check " + layer).status, 0);  // touched, same content
  std::string text = read_text(layer);
  const std::size_t at = text.find("12.");
  ASSERT_NE(at, std::string::npos);
  text[at + 3] = text[at + 3] == '5' ? '6' : '5';  // one digit of one coordinate
  { std::ofstream(layer, std::ios::binary) << text; }
  for (const std::string& arg : {layer, sidecar})
    expect_error("check " + arg, sidecar + ": intact but stale, " + layer +
                                     " changed since it was indexed (contents changed); run "
                                     "'loci index " +
                                     layer + "'");
  // An edit of the same size with the modification time set back, which queries do not see
  // (they trust size, time and inode), is found by check, which reads the contents.
  ASSERT_EQ(run_loci("index -q " + layer).status, 0);
  const auto indexed_at = fs::last_write_time(layer);
  text[at + 3] = text[at + 3] == '5' ? '6' : '5';
  {
    std::fstream same(layer, std::ios::in | std::ios::out | std::ios::binary);
    same.seekp(std::streamoff(at + 3));
    same.put(text[at + 3]);
  }
  fs::last_write_time(layer, indexed_at);
  for (const std::string& arg : {layer, sidecar})
    expect_error("check " + arg, sidecar + ": intact but stale, " + layer +
                                     " changed since it was indexed (contents changed)");
  // A sidecar written elsewhere names no layer: its own checks only.
  const std::string elsewhere = path("checked-copy.idx");
  ASSERT_EQ(run_loci("index -q " + layer + " -o " + elsewhere).status, 0);
  std::ofstream(layer, std::ios::app) << "\n";
  const CliRun r = run_loci("check " + elsewhere);
  EXPECT_EQ(r.status, 0) << r.err;
  fs::remove(elsewhere);
  // One named after a layer that is gone says it was checked alone.
  ASSERT_EQ(run_loci("index -q " + layer).status, 0);
  fs::remove(layer);
  const CliRun alone = run_loci("check " + sidecar);
  EXPECT_EQ(alone.status, 0) << alone.err;
  EXPECT_NE(alone.out.find(", not checked against " + layer + " (not found)\n"), std::string::npos)
      << alone.out;
  fs::remove(sidecar);
}

// Without --per, loci index picks per segment for big features (the bundled sample: a few
// multipolygons of thousands of segments) and per feature for small ones, and loci info says
// which and why; an explicit --per is kept and not explained.
TEST_F(LayersCli, IndexChoosesTheGranularity) {
  const std::string sample = path("sample.geojson");
  fs::copy_file(std::string(LOCI_DATASETS_DIR) + "/samples/coastline-denmark.geojson", sample,
                fs::copy_options::overwrite_existing);
  CliRun r = run_loci("index " + sample);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("indexed 18930 segments of 5 features of layer"), std::string::npos)
      << r.err;
  std::string info = run_loci("info " + sample).out;
  EXPECT_NE(info.find("per segment (chosen by loci index: "), std::string::npos) << info;
  for (const char* ext : {".shp", ".shx", ".dbf"})  // a copy: other tests use polys.shp
    fs::copy_file(path(std::string("polys") + ext), path(std::string("chosen") + ext),
                  fs::copy_options::overwrite_existing);
  const std::string chosen = path("chosen.shp");
  ASSERT_EQ(run_loci("index -q " + chosen).status, 0);
  r = run_loci("query " + chosen + " --bbox 0,0,100,100");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out,
            run_loci("query " + path("polys.shp") + " --structure rstar --bbox 0,0,100,100").out);
  info = run_loci("info " + chosen).out;
  EXPECT_NE(info.find("per feature (chosen by loci index: fewer than"), std::string::npos) << info;
  ASSERT_EQ(run_loci("index -q --per feature " + sample).status, 0);
  info = run_loci("info " + sample).out;
  EXPECT_NE(info.find("per feature, layer"), std::string::npos) << info;
  fs::remove(chosen + ".loci");
  fs::remove(sample + ".loci");
}

// The fingerprint covers a shapefile's .dbf (which marks deleted records) and every file of a
// directory opened as one dataset: an edit to any of them makes the index stale, a touch of
// them does not (the content hashed while indexing is the one checked later).
TEST_F(LayersCli, SeesEditsToAShapefilesAttributesAndToADirectoryOfShapefiles) {
  const std::string dir = path("shpdir");
  fs::create_directories(dir);
  for (const char* ext : {".shp", ".shx", ".dbf"}) {
    fs::copy_file(path(std::string("polys") + ext), path(std::string("dbfedit") + ext),
                  fs::copy_options::overwrite_existing);
    fs::copy_file(path(std::string("polys") + ext), dir + "/polys" + ext,
                  fs::copy_options::overwrite_existing);
  }
  // Byte `at` from the end (negative) or the start of `file`, xored with `bits`.
  auto flip = [](const std::string& file, std::streamoff at, char bits) {
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(0, at < 0 ? std::ios::end : std::ios::beg);
    const std::streamoff where = std::streamoff(f.tellg()) + at;
    char c = 0;
    f.seekg(where);
    f.read(&c, 1);
    f.seekp(where);
    c = char(c ^ bits);
    f.write(&c, 1);
  };
  auto touch = [](const std::string& file) {
    fs::last_write_time(file, fs::last_write_time(file) + std::chrono::seconds(5));
  };
  for (const std::string& layer : {path("dbfedit.shp"), dir}) {
    SCOPED_TRACE(layer);
    ASSERT_EQ(run_loci("index -q " + layer).status, 0);
    const std::string before = run_loci("query " + layer + " --bbox 0,0,9,9").out;
    ASSERT_FALSE(before.empty());
    const std::string dbf = layer == dir ? dir + "/polys.dbf" : path("dbfedit.dbf");
    touch(dbf);
    const CliRun touched = run_loci("query " + layer + " --bbox 0,0,9,9");
    EXPECT_EQ(touched.status, 0) << touched.err;
    EXPECT_EQ(touched.out, before);
    EXPECT_NE(run_loci("info " + layer).out.find("fresh"), std::string::npos);
    // The first record of the .dbf marked deleted ('*' for ' '), sizes unchanged.
    {
      std::ifstream f(dbf, std::ios::binary);
      unsigned char head[12] = {};
      f.read(reinterpret_cast<char*>(head), sizeof head);
      const int header_size = head[8] | head[9] << 8;
      flip(dbf, header_size, char(' ' ^ '*'));
    }
    expect_error("query " + layer + " --bbox 0,0,9,9", "stale index");
    EXPECT_NE(run_loci("info " + layer).out.find("stale"), std::string::npos);
  }
  // In the directory, a coordinate of the .shp changed in place.
  ASSERT_EQ(run_loci("index -q " + dir).status, 0);
  flip(dir + "/polys.shp", -8, 0x10);
  expect_error("query " + dir + " --bbox 0,0,9,9", "stale index");
}

// Files beside the one named that hold part of the layer are fingerprinted too: a CSV's
// .csvt (its CoordX/CoordY types make the geometry), a MapInfo table's .map/.id/.dat, and a
// GeoPackage's uncheckpointed WAL. Before, an index stayed "fresh" through edits to them and
// answered from the old geometry.
TEST_F(LayersCli, SeesEditsToTheFilesBesideALayer) {
  const std::string csv = path("xy.csv"), csvt = path("xy.csvt");
  std::ofstream(csv) << "id,x,y\n1,1,2\n2,5,6\n";
  std::ofstream(csvt) << "Integer,CoordX,CoordY\n";
  ASSERT_EQ(run_loci("index -q " + csv).status, 0);
  const CliRun before = run_loci("query " + csv + " --bbox 0.5,1.5,1.5,2.5 -f ids");
  ASSERT_EQ(before.status, 0) << before.err;
  EXPECT_EQ(before.out, "1\n");
  std::ofstream(csvt) << "Integer,CoordY,CoordX\n";  // x and y swapped, the .csv untouched
  expect_error("query " + csv + " --bbox 0.5,1.5,1.5,2.5 -f ids", "stale index");
  ASSERT_EQ(run_loci("index -q " + csv).status, 0);
  const CliRun after = run_loci("query " + csv + " --bbox 1.5,0.5,2.5,1.5 -f ids");
  ASSERT_EQ(after.status, 0) << after.err;
  EXPECT_EQ(after.out, "1\n");

  // MapInfo: a feature appended changes the .map and .dat, not the .tab.
  const std::string tab = path("mi.tab");
  for (const char* e : {".tab", ".map", ".id", ".dat"})
    fs::remove(path(std::string("mi") + e));
  const std::string pts = path("mi.csv");
  std::ofstream(pts) << "id,WKT\n1,\"POINT (1 1)\"\n";
  ASSERT_EQ(std::system(("ogr2ogr -q -f \"MapInfo File\" " + tab + " " + pts).c_str()), 0);
  ASSERT_EQ(run_loci("index -q " + tab).status, 0);
  std::ofstream(pts) << "id,WKT\n2,\"POINT (7 7)\"\n";
  ASSERT_EQ(std::system(("ogr2ogr -q -update -append " + tab + " " + pts + " -nln mi").c_str()), 0);
  expect_error("query " + tab + " --bbox 6,6,8,8 -f ids", "stale index");

  // A GeoPackage in WAL mode with a writer still open: its committed changes sit in the WAL.
  const std::string gpkg = path("w.gpkg");
  fs::remove(gpkg);
  ASSERT_EQ(std::system(("ogr2ogr -q -f GPKG " + gpkg + " " + pts + " -nln w && sqlite3 " + gpkg +
                         " 'PRAGMA journal_mode=WAL' > /dev/null")
                            .c_str()),
            0);
  ASSERT_EQ(run_loci("index -q " + gpkg).status, 0);
  GDALDatasetH writer =
      GDALOpenEx(gpkg.c_str(), GDAL_OF_VECTOR | GDAL_OF_UPDATE, nullptr, nullptr, nullptr);
  ASSERT_NE(writer, nullptr);
  GDALDatasetReleaseResultSet(
      writer, GDALDatasetExecuteSQL(writer, "CREATE TABLE note(x)", nullptr, nullptr));
  GDALDatasetReleaseResultSet(
      writer, GDALDatasetExecuteSQL(writer, "INSERT INTO note VALUES (1)", nullptr, nullptr));
  GDALFlushCache(writer);
  ASSERT_TRUE(fs::exists(gpkg + "-wal") && fs::file_size(gpkg + "-wal") > 0);
  const CliRun info = run_loci("info " + gpkg);
  GDALClose(writer);
  EXPECT_NE(info.out.find("stale"), std::string::npos) << info.out << info.err;
}

// A VRT's features live in its sources: an index of the VRT would stay "fresh" while they
// change, so loci index refuses it (in one line, nothing written) and queries build their
// index in memory, following the source.
TEST_F(LayersCli, RefusesToIndexAVrtWhoseSourcesItCannotWatch) {
  const std::string src = path("vsrc.csv"), vrt = path("v.vrt");
  std::ofstream(src) << "id,WKT\n1,\"POINT (1 1)\"\n2,\"POINT (5 5)\"\n";
  std::ofstream(vrt) << "<OGRVRTDataSource><OGRVRTLayer name=\"v\"><SrcDataSource "
                        "relativeToVRT=\"1\">vsrc.csv</SrcDataSource><SrcLayer>vsrc</SrcLayer>"
                        "<GeometryType>wkbPoint</GeometryType><GeometryField encoding=\"WKT\" "
                        "field=\"WKT\"/></OGRVRTLayer></OGRVRTDataSource>\n";
  const CliRun r = run_loci("index " + vrt);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("a VRT's features live in its sources"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(vrt + ".loci"));
  // loci info does not suggest the command refused.
  const CliRun info = run_loci("info " + vrt);
  ASSERT_EQ(info.status, 0) << info.err;
  EXPECT_NE(info.out.find("index:     none (a VRT is not indexed"), std::string::npos) << info.out;
  EXPECT_EQ(info.out.find("loci index"), std::string::npos) << info.out;
  EXPECT_EQ(run_loci("query " + vrt + " --bbox 0,0,2,2").out, "1\n");
  std::ofstream(src) << "id,WKT\n1,\"POINT (9 9)\"\n2,\"POINT (1 1)\"\n";
  EXPECT_EQ(run_loci("query " + vrt + " --bbox 0,0,2,2").out, "2\n");
  // A sidecar beside it (an older loci's, or another file's written with -o) is not offered
  // to be rebuilt with the command that refuses VRTs.
  ASSERT_EQ(run_loci("index -q " + src + " -o " + vrt + ".loci").status, 0);
  for (const std::string& cmd : {"query " + vrt + " --bbox 0,0,2,2",
                                 "query " + vrt + " --bbox 0,0,2,2 --index " + vrt + ".loci",
                                 "check " + vrt, "check " + vrt + ".loci"}) {
    const CliRun stale = run_loci(cmd);
    EXPECT_EQ(stale.status, 1) << cmd;
    EXPECT_NE(stale.err.find("not an index of " + vrt + " (a VRT is not indexed"),
              std::string::npos)
        << cmd << ": " << stale.err;
    EXPECT_EQ(stale.err.find("loci index"), std::string::npos) << cmd << ": " << stale.err;
  }
  // Nor one that looks fresh: a file indexed as GeoJSON, then made a VRT in place with its
  // size, inode and time kept (the sources it names then change unseen).
  const std::string odd = path("w.vrt");
  std::string geojson = R"({"type":"FeatureCollection","features":[{"type":"Feature",)"
                        R"("properties":{},"geometry":{"type":"Point","coordinates":[5,5]}}]})";
  geojson.resize(512, ' ');  // room for the VRT's text
  std::ofstream(odd) << geojson;
  ASSERT_EQ(run_loci("index -q " + odd).status, 0);
  ASSERT_EQ(run_loci("query " + odd + " --bbox 4,4,6,6").out, "0\n");
  const auto time = fs::last_write_time(odd);
  std::string vrt_text = read_text(vrt);
  ASSERT_LE(vrt_text.size(), geojson.size());
  vrt_text.resize(geojson.size(), ' ');
  std::ofstream(odd, std::ios::binary | std::ios::in | std::ios::out) << vrt_text;
  fs::last_write_time(odd, time);
  const CliRun fresh = run_loci("query " + odd + " --bbox 0,0,2,2");
  EXPECT_EQ(fresh.status, 1) << fresh.out;
  EXPECT_NE(fresh.err.find("not an index of " + odd + " (a VRT is not indexed"), std::string::npos)
      << fresh.err;
  fs::remove(odd + ".loci");
  EXPECT_EQ(run_loci("query " + odd + " --bbox 0,0,2,2").out, "2\n");
}

TEST_F(LayersCli, RefusesASidecarOlderThanItsLayer) {
  // A copy, so that other tests keep their layer.
  for (const char* ext : {".shp", ".shx", ".dbf"})
    fs::copy_file(path(std::string("polys") + ext), path(std::string("stale") + ext),
                  fs::copy_options::overwrite_existing);
  const std::string layer = path("stale.shp");
  ASSERT_EQ(run_loci("index -q " + layer).status, 0);
  ASSERT_EQ(run_loci("query " + layer + " --bbox 0,0,9,9").status, 0);
  // Touched only: the modification time differs, so the content is hashed again; it is the
  // same, and the index still answers (and says so in loci info).
  const std::string before = run_loci("query " + layer + " --bbox 0,0,9,9").out;
  fs::last_write_time(layer, fs::last_write_time(layer) + std::chrono::seconds(5));
  const CliRun touched = run_loci("query " + layer + " --bbox 0,0,9,9");
  EXPECT_EQ(touched.status, 0) << touched.err;
  EXPECT_EQ(touched.out, before);
  EXPECT_NE(run_loci("info " + layer).out.find("fresh"), std::string::npos);
  // Same size, another byte: a coordinate of the .shp changed in place.
  {
    std::fstream f(layer, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(0, std::ios::end);
    const auto size = f.tellg();
    f.seekg(size - std::streamoff(8));
    char c = 0;
    f.read(&c, 1);
    f.seekp(size - std::streamoff(8));
    c = char(c ^ 0x10);
    f.write(&c, 1);
  }
  expect_error("query " + layer + " --bbox 0,0,9,9", "stale index");
  // Given with --index, the sidecar may as well be another file's: the message says both, and
  // the command it offers rewrites that index (the layer's default sidecar path here).
  expect_error("query " + layer + " --index " + layer + ".loci --bbox 0,0,9,9",
               ".loci: does not match " + layer +
                   " (contents changed): the index of another file, or of this "
                   "one before it changed; run 'loci index " +
                   layer + " -o " + layer + ".loci'");
  // Really changed: a feature added through GDAL.
  ASSERT_EQ(run_loci("index -q " + layer).status, 0);
  {
    GDALDatasetUniquePtr ds(GDALDataset::Open(layer.c_str(), GDAL_OF_VECTOR | GDAL_OF_UPDATE));
    ASSERT_TRUE(ds);
    OGRLayer* l = ds->GetLayer(0);
    OGRFeature f(l->GetLayerDefn());
    std::mt19937_64 rng(9);
    OGRPolygon p = star_polygon(5, 5, 3, rng, false);
    f.SetGeometry(&p);
    ASSERT_EQ(l->CreateFeature(&f), OGRERR_NONE);
  }
  expect_error("query " + layer + " --bbox 0,0,9,9 -o " + path("stale.txt"), "stale index");
  EXPECT_FALSE(fs::exists(path("stale.txt")));
  const CliRun info = run_loci("info " + layer);
  EXPECT_NE(info.out.find("stale"), std::string::npos) << info.out;
}

// `loci` answers a query its sidecar serves (per segment, or --candidates; ids on stdout)
// without GDAL, and hands every other command to loci-full beside it. A copy of `loci` alone
// in a directory shows which is which: it answers the first kind as the whole program does,
// and cannot run the second.
TEST_F(LayersCli, TheFrontAnswersSidecarQueriesWithoutGdalAndHandsTheRestOver) {
  const std::string seg = path("front.geojson"), feat = path("front.shp");
  fs::copy_file(std::string(LOCI_DATASETS_DIR) + "/samples/coastline-denmark.geojson", seg,
                fs::copy_options::overwrite_existing);
  for (const char* ext : {".shp", ".shx", ".dbf"})
    fs::copy_file(path(std::string("polys") + ext), path(std::string("front") + ext),
                  fs::copy_options::overwrite_existing);
  // Lines and points indexed per feature too (polys.shp has holes and polygons of two parts).
  for (const char* name : {"lines", "points"})
    for (const char* ext : {".shp", ".shx", ".dbf"})
      fs::copy_file(path(std::string(name) + ext), path(std::string("front-") + name + ext),
                    fs::copy_options::overwrite_existing);
  const std::string lines_layer = path("front-lines.shp"), points_layer = path("front-points.shp");
  ASSERT_EQ(run_loci("index -q --per segment " + seg).status, 0);
  for (const std::string& layer : {feat, lines_layer, points_layer})
    ASSERT_EQ(run_loci("index -q --per feature " + layer).status, 0);
  const std::string points = path("front-points.txt"), spots = path("front-spots.txt");
  {
    std::ofstream out(spots);
    std::mt19937_64 rng(78);
    std::uniform_real_distribution<double> c(0, 100);
    for (int i = 0; i < 300; ++i)
      out << c(rng) << ',' << c(rng) << '\n';
  }
  {
    std::ofstream out(points);
    std::mt19937_64 rng(77);
    std::uniform_real_distribution<double> x(7.5, 13.0), y(54.4, 57.9);
    for (int i = 0; i < 200; ++i)
      out << x(rng) << ',' << y(rng) << '\n';
  }
  const fs::path alone = g_dir / "front-alone";
  fs::create_directories(alone);
  fs::copy_file(LOCI_EXE, alone / "loci", fs::copy_options::overwrite_existing);
  const std::string front = (alone / "loci").string();
  // The output (stderr joined) and exit status of a command started by popen.
  auto finish = [](std::FILE* p) {
    CliRun r;
    char buf[65536];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;)
      r.out.append(buf, n);
    const int st = ::pclose(p);
    r.status = WIFEXITED(st) ? WEXITSTATUS(st) : 128;
    return r;
  };
  auto run_with = [&](const std::string& exe, const std::string& args) {
    return finish(::popen((exe + " " + args + " 2>&1").c_str(), "r"));
  };
  const std::string answered[] = {
      "query " + seg + " --nearest 10.5,56 -k 7",
      "query " + seg + " --nearest-file " + points + " -k 3 -j 2",
      "query " + seg + " --bbox 9,55,11,57",
      "query " + seg + " --point 9.5,56.2",
      "query " + seg + " --within 10.5,56,0.3",
      "query " + seg + " --segment 8,55,12,57 --first",
      "query " + feat + " --bbox 20,20,60,60 --candidates",
      // Per feature of a shapefile: its records read without GDAL.
      "query " + feat + " --bbox 20,20,60,60",
      "query " + feat + " --nearest 50,50 -k 6",
      "query " + feat + " --nearest-file " + spots + " -k 2 -j 2",
      "query " + feat + " --point-file " + spots,
      "query " + feat + " --within 50,50,12",
      "query " + feat + " --segment 0,0,100,100 --first",
      "query " + lines_layer + " --bbox 20,20,60,60",
      "query " + lines_layer + " --nearest-file " + spots + " -k 2",
      "query " + points_layer + " --within 50,50,20",
      "query " + points_layer + " --nearest 50,50 -k 4",
      "check " + seg,
      "check " + feat + ".loci",
  };
  for (const std::string& args : answered) {
    const CliRun whole = run_with(LOCI_FULL_EXE, args), part = run_with(front, args);
    ASSERT_EQ(whole.status, 0) << args << ": " << whole.out;
    EXPECT_FALSE(whole.out.empty()) << args;
    EXPECT_EQ(part.status, 0) << args << ": " << part.out;
    EXPECT_EQ(part.out, whole.out) << args;
  }
  // Work that needs the layer or GDAL: the copy alone says it cannot run loci-full, and
  // nothing else (it neither answers nor half-answers).
  const std::string handed[] = {
      "query " + feat + " --bbox 20,20,60,60 -f csv",
      "query " + seg + " --nearest 10.5,56 -f csv",
      "query " + seg + " --nearest 10.5,56 -o " + path("front-taken.txt"),
      "query " + seg + " --nearest 10.5,56 --per feature",
      "query " + seg + " --bbox 1,2",
      "query " + seg + " --help",
      "info " + seg,
      "--help",
  };
  std::ofstream(path("front-taken.txt")) << "kept\n";  // there already: may be a dataset
  for (const std::string& args : handed) {
    const CliRun r = run_with(front, args);
    EXPECT_EQ(r.status, 1) << args;
    EXPECT_EQ(lines(r.out).size(), 1u) << args << ": " << r.out;
    EXPECT_NE(r.out.find("loci: error: cannot run "), std::string::npos) << args << ": " << r.out;
    EXPECT_NE(r.out.find("loci is not installed whole"), std::string::npos) << args;
  }
  EXPECT_EQ(read_text(path("front-taken.txt")), "kept\n");
  // An output file not there yet is written by the front, as the whole program writes it.
  {
    const std::string args = "query " + seg + " --nearest-file " + points + " -k 3 -o ";
    const CliRun part = run_with(front, args + path("front-new.txt"));
    EXPECT_EQ(part.status, 0) << part.out;
    ASSERT_EQ(run_with(LOCI_FULL_EXE, args + path("front-whole.txt")).status, 0);
    EXPECT_FALSE(read_text(path("front-whole.txt")).empty());
    EXPECT_EQ(read_text(path("front-new.txt")), read_text(path("front-whole.txt")));
    for (const char* f : {"front-taken.txt", "front-new.txt", "front-whole.txt"})
      fs::remove(path(f));
  }
  // A query file on a pipe is read once, by whichever program answers.
  for (const std::string& layer : {seg, feat}) {
    const std::string args = "query " + layer + " --nearest-file /dev/stdin -k 2";
    const CliRun from_file = run_loci("query " + layer + " --nearest-file " + points + " -k 2");
    const CliRun piped =
        run_with("cat " + shell_quote(points) + " | " + std::string(LOCI_EXE), args);
    ASSERT_EQ(from_file.status, 0) << from_file.err;
    EXPECT_EQ(piped.status, 0) << piped.out;
    EXPECT_EQ(piped.out, from_file.out) << layer;
    // The front alone answers it, per feature too (copying the queries in memory first).
    const CliRun alone_piped = run_with("cat " + shell_quote(points) + " | " + front, args);
    EXPECT_EQ(alone_piped.status, 0) << alone_piped.out;
    EXPECT_EQ(alone_piped.out, from_file.out) << layer;
  }
  // A shapefile record the direct reader leaves to GDAL (a hole starting on its outer ring)
  // hands a query per feature over when the query meets it, before anything is written;
  // loci-full reads the queries again (from a regular file), or has read them all (a pipe,
  // handed over at once). The other records are still answered by the front alone.
  {
    const std::string odd = path("front-odd.shp");
    write_layer(
        odd, wkbPolygon,
        [](int i) -> std::unique_ptr<OGRGeometry> {
          auto p = std::make_unique<OGRPolygon>();
          const double x = i == 0 ? 200 : 0;
          OGRLinearRing outer;
          for (const auto& [px, py] :
               {std::pair{x, 0.0}, {x, 10.0}, {x + 10, 10.0}, {x + 10, 0.0}, {x, 0.0}})
            outer.addPoint(px, py);
          p->addRing(&outer);
          if (i == 1) {
            OGRLinearRing hole;
            for (const auto& [px, py] : {std::pair{0.0, 5.0}, {5.0, 2.0}, {5.0, 8.0}, {0.0, 5.0}})
              hole.addPoint(px, py);
            p->addRing(&hole);
          }
          return p;
        },
        2);
    ASSERT_EQ(run_loci("index -q --per feature " + odd).status, 0);
    const std::string far = "query " + odd + " --bbox 199,-1,201,1";
    const CliRun whole_far = run_with(LOCI_FULL_EXE, far);
    EXPECT_EQ(whole_far.out, "0\n");
    EXPECT_EQ(run_with(front, far).out, whole_far.out);
    const CliRun met = run_with(front, "query " + odd + " --bbox 1,4,2,6");
    EXPECT_EQ(met.status, 1);
    EXPECT_EQ(lines(met.out).size(), 1u) << met.out;
    EXPECT_NE(met.out.find("loci is not installed whole"), std::string::npos) << met.out;
    const std::string windows_file = path("front-odd-windows.txt");
    std::ofstream(windows_file) << "199,-1,201,1\n1,4,2,6\n3,4,4,6\n";
    const std::string batch_args = "query " + odd + " --bbox-file ";
    const CliRun expected = run_with(LOCI_FULL_EXE, batch_args + windows_file);
    ASSERT_EQ(expected.status, 0) << expected.out;
    EXPECT_EQ(expected.out, "1 0\n2 1\n");  // the window inside the hole meets nothing
    EXPECT_EQ(run_with(LOCI_EXE, batch_args + windows_file + " -o " + path("front-odd.txt")).status,
              0);
    EXPECT_EQ(read_text(path("front-odd.txt")), expected.out);
    for (const char* stdin_name : {"/dev/stdin", "-"})  // `-` is stdin too
      EXPECT_EQ(run_with("cat " + shell_quote(windows_file) + " | " + std::string(LOCI_EXE),
                         batch_args + stdin_name)
                    .out,
                expected.out)
          << stdin_name;
    // Queries read once (a pipe, a file named as a descriptor) are copied in memory first: the
    // front alone answers those that meet no such record, and hands over those that do (the
    // whole program answered them above, from the copy).
    const std::string far_file = path("front-odd-far.txt");
    std::ofstream(far_file) << "199,-1,201,1\n";
    EXPECT_EQ(run_with(LOCI_EXE, batch_args + far_file).out, "1 0\n");
    for (const std::string& from :
         {"/dev/stdin < " + shell_quote(far_file),
          "--bbox-file=/dev/stdin < " + shell_quote(far_file), "- < " + shell_quote(far_file),
          "--bbox-file=- < " + shell_quote(far_file)}) {
      const std::string args =
          from.rfind("--", 0) == 0 ? "query " + odd + " " + from : batch_args + from;
      const CliRun named = run_with(front, args);
      EXPECT_EQ(named.status, 0) << from << ": " << named.out;
      EXPECT_EQ(named.out, "1 0\n") << from;
    }
    const CliRun piped_far =
        run_with("cat " + shell_quote(far_file) + " | " + front, batch_args + "/dev/stdin");
    EXPECT_EQ(piped_far.status, 0) << piped_far.out;
    EXPECT_EQ(piped_far.out, "1 0\n");
    const CliRun piped_met =
        run_with("cat " + shell_quote(windows_file) + " | " + front, batch_args + "/dev/stdin");
    EXPECT_EQ(piped_met.status, 1);
    EXPECT_EQ(lines(piped_met.out).size(), 1u) << piped_met.out;
    EXPECT_NE(piped_met.out.find("loci is not installed whole"), std::string::npos)
        << piped_met.out;
    // A bad line is named in the file as given, not in its copy.
    const CliRun bad =
        run_with("printf '199,-1,201,1\\nnot a window\\n' | " + front, batch_args + "/dev/stdin");
    EXPECT_EQ(bad.status, 1);
    EXPECT_EQ(lines(bad.out).size(), 1u) << bad.out;
    EXPECT_NE(bad.out.find("loci: error: /dev/stdin: line 2: "), std::string::npos) << bad.out;
    // Nor is what cannot be read copied: loci-full says what it is.
    const CliRun dir = run_with(front, batch_args + "/dev/");
    EXPECT_EQ(dir.status, 1);
    EXPECT_NE(dir.out.find("loci is not installed whole"), std::string::npos) << dir.out;
    for (const char* ext :
         {".shp", ".shx", ".dbf", ".shp.loci", "-windows.txt", ".txt", "-far.txt"})
      fs::remove(path(std::string("front-odd") + ext));
  }
  // A loci-full that cannot run is named as the file that failed.
  {
    std::ofstream(alone / "loci-full") << "#!/bin/sh\n";
    fs::permissions(alone / "loci-full", fs::perms::owner_read | fs::perms::owner_write);
    const CliRun r = run_with(front, "info " + seg);
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.out.find("cannot run " + (alone / "loci-full").string() + " ("), std::string::npos)
        << r.out;
    fs::remove(alone / "loci-full");
  }
  // Runs the front alone (`front`: it cannot hand over) on ARGS whose query file is the FIFO
  // `fifo`: once it has opened it (having chosen its sidecar), `meanwhile` runs, then
  // `queries` are written.
  const std::string fifo = path("front.fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto queries_late = [&](const std::string& args, const std::string& queries,
                          const std::function<void()>& meanwhile) {
    std::FILE* p = ::popen((front + " " + args + " 2>&1").c_str(), "r");
    int fd = -1;
    for (int tries = 0; fd < 0 && tries < 3000; ++tries)  // 30 s at most
      if ((fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK)) < 0) ::usleep(10000);
    EXPECT_GE(fd, 0) << "loci did not open its query file";
    if (fd >= 0) {
      meanwhile();
      const auto pipe_handler = std::signal(SIGPIPE, SIG_IGN);  // a reader gone: a failure
      EXPECT_EQ(::write(fd, queries.data(), queries.size()), ssize_t(queries.size()));
      std::signal(SIGPIPE, pipe_handler);
      ::close(fd);
    } else {
      // A reader blocked in open() goes on (to end of file); a later one finds no FIFO.
      ::close(::open(fifo.c_str(), O_RDWR));
      ::unlink(fifo.c_str());
    }
    return finish(p);
  };
  const std::string windows = "9,55,11,57\n8,56,8.5,56.5\n";
  std::ofstream(path("front-windows.txt")) << windows;
  const std::string batch = "query " + seg + " --bbox-file ";
  // The sidecar chosen is the one answering: replaced by one per feature (which the front
  // would hand over) while the front waits for its queries, they are still answered, exactly.
  {
    const CliRun r = queries_late(batch + fifo, windows, [&] {
      ASSERT_EQ(run_loci("index -q --per feature " + seg).status, 0);
    });
    const CliRun expected = run_with(LOCI_FULL_EXE, batch + path("front-windows.txt"));
    ASSERT_EQ(expected.status, 0) << expected.out;
    EXPECT_EQ(r.status, 0) << r.out;
    EXPECT_EQ(r.out, expected.out);
  }
  // A layer changed and indexed again while the front waits: answered from the new sidecar,
  // as loci-full, which reads its queries first, answers.
  {
    ASSERT_EQ(run_loci("index -q --per segment " + seg).status, 0);
    const CliRun r = queries_late(batch + fifo, windows, [&] {
      std::ofstream(seg, std::ios::app) << "\n";
      ASSERT_EQ(run_loci("index -q --per segment " + seg).status, 0);
    });
    const CliRun expected = run_with(LOCI_FULL_EXE, batch + path("front-windows.txt"));
    ASSERT_EQ(expected.status, 0) << expected.out;
    EXPECT_EQ(r.status, 0) << r.out;
    EXPECT_EQ(r.out, expected.out);
  }
  // A layer changed while the front waits is stale, as loci-full finds it when it reads its
  // queries first.
  {
    const CliRun r =
        queries_late(batch + fifo, windows, [&] { std::ofstream(seg, std::ios::app) << "\n"; });
    const CliRun expected = run_with(LOCI_FULL_EXE, batch + path("front-windows.txt"));
    EXPECT_EQ(r.status, 1) << r.out;
    EXPECT_NE(r.out.find("stale index"), std::string::npos) << r.out;
    EXPECT_EQ(r.out, expected.out);
  }
  for (const char* f : {"front.fifo", "front-windows.txt"})
    fs::remove(path(f));
  // A stale sidecar is the whole program's to report.
  const CliRun stale = run_with(front, "query " + seg + " --nearest 10.5,56");
  EXPECT_NE(stale.out.find("loci is not installed whole"), std::string::npos) << stale.out;
  const CliRun said = run_loci("query " + seg + " --nearest 10.5,56");
  EXPECT_EQ(said.status, 1);
  EXPECT_NE(said.err.find("stale index"), std::string::npos) << said.err;
  // The front does not load GDAL's libraries at all.
  const CliRun libs = run_with("ldd", LOCI_EXE);
  ASSERT_EQ(libs.status, 0) << libs.out;
  EXPECT_EQ(libs.out.find("libgdal"), std::string::npos) << libs.out;
  fs::remove_all(alone);
  for (const char* name : {"front", "front-lines", "front-points"})
    for (const char* ext : {".shp", ".shx", ".dbf", ".shp.loci"})
      fs::remove(path(std::string(name) + ext));
  fs::remove(seg + ".loci");
  fs::remove(seg);
  fs::remove(points);
  fs::remove(spots);
}
