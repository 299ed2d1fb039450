// `loci intersections` end to end through the real executable: feature pairs against GEOS
// (through OGR) on the bundled Natural Earth sample and on generated random lines and
// polygons, for one layer and for two; every reported point lies on both features' linework;
// hand-made cases for exact points, overlaps, self-crossings and adjacent segments; formats
// and errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

#include "layers/cli_support.hpp"

namespace fs = std::filesystem;
using namespace loci::test;

namespace {

const std::string kSample = std::string(LOCI_DATASETS_DIR) + "/samples/coastline-denmark.geojson";

struct Row {
  long long a, b;
  double x, y;
};

std::vector<Row> parse_rows(const std::string& csv) {
  std::vector<Row> out;
  const auto ls = lines(csv);
  for (std::size_t i = 1; i < ls.size(); ++i) {
    Row r{};
    char c;
    std::istringstream in(ls[i]);
    in >> r.a >> c >> r.b >> c >> r.x >> c >> r.y;
    out.push_back(r);
  }
  return out;
}

// The linework of a geometry: boundaries of polygons, the geometry itself otherwise.
std::unique_ptr<OGRGeometry> linework(const OGRGeometry& g) {
  const auto t = wkbFlatten(g.getGeometryType());
  if (t == wkbPolygon || t == wkbMultiPolygon) return std::unique_ptr<OGRGeometry>(g.Boundary());
  return std::unique_ptr<OGRGeometry>(g.clone());
}

std::set<std::pair<long long, long long>> geos_pairs(const OgrFeatureSet& l,
                                                     const OgrFeatureSet* r) {
  std::set<std::pair<long long, long long>> out;
  const OgrFeatureSet& other = r ? *r : l;
  for (std::size_t i = 0; i < l.fids.size(); ++i) {
    const auto li = linework(*l.geoms[i]);
    for (std::size_t j = r ? 0 : i + 1; j < other.fids.size(); ++j) {
      const auto lj = linework(*other.geoms[j]);
      if (li->Intersects(lj.get()))
        out.insert(
            r ? std::pair{l.fids[i], other.fids[j]}
              : std::pair{std::min(l.fids[i], other.fids[j]), std::max(l.fids[i], other.fids[j])});
    }
  }
  return out;
}

std::set<std::pair<long long, long long>> distinct_pairs(const std::vector<Row>& rows) {
  std::set<std::pair<long long, long long>> out;
  for (const Row& r : rows)
    if (r.a != r.b) out.insert({r.a, r.b});
  return out;
}

// Every point lies on both features' linework (to the rounding of the crossing point).
void expect_points_on_linework(const std::vector<Row>& rows, const OgrFeatureSet& l,
                               const OgrFeatureSet& r) {
  auto find = [](const OgrFeatureSet& s, long long fid) -> const OGRGeometry* {
    for (std::size_t i = 0; i < s.fids.size(); ++i)
      if (s.fids[i] == fid) return s.geoms[i].get();
    return nullptr;
  };
  for (const Row& row : rows) {
    OGRPoint p(row.x, row.y);
    const OGRGeometry* ga = find(l, row.a);
    const OGRGeometry* gb = find(r, row.b);
    ASSERT_TRUE(ga && gb);
    const double tol = 1e-12 * (1 + std::abs(row.x) + std::abs(row.y));
    EXPECT_LE(linework(*ga)->Distance(&p), tol) << row.a << " at " << row.x << "," << row.y;
    EXPECT_LE(linework(*gb)->Distance(&p), tol) << row.b << " at " << row.x << "," << row.y;
  }
}

fs::path temp_dir() {
  const fs::path d = fs::temp_directory_path() / ("loci-isect-" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

// Random lines and polygons in a GeoJSON file.
fs::path random_layer(const fs::path& dir, const char* name, std::uint64_t seed, int lines) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 100), step(-8, 8);
  std::ostringstream js;
  js.precision(17);
  js << "{\"type\":\"FeatureCollection\",\"features\":[";
  for (int f = 0; f < lines; ++f) {
    js << (f ? "," : "") << "{\"type\":\"Feature\",\"properties\":{},\"geometry\":";
    double x = u(rng), y = u(rng);
    if (f % 4 == 3) {  // a triangle
      js << "{\"type\":\"Polygon\",\"coordinates\":[[[" << x << "," << y << "],[" << x + 9 << ","
         << y << "],[" << x << "," << y + 7 << "],[" << x << "," << y << "]]]}}";
      continue;
    }
    js << "{\"type\":\"LineString\",\"coordinates\":[";
    for (int k = 0; k < 6; ++k) {
      js << (k ? "," : "") << "[" << x << "," << y << "]";
      x += step(rng), y += step(rng);
    }
    js << "]}}";
  }
  js << "]}";
  const fs::path p = dir / name;
  std::ofstream(p) << js.str();
  return p;
}

TEST(IntersectionsCli, SamplePairsMatchGeos) {
  const CliRun r = run_loci("intersections " + shell_quote(kSample));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = parse_rows(r.out);
  const OgrFeatureSet s = read_with_ogr(kSample);
  EXPECT_EQ(distinct_pairs(rows), geos_pairs(s, nullptr));
  EXPECT_FALSE(rows.empty());
  expect_points_on_linework(rows, s, s);
}

TEST(IntersectionsCli, RandomLayersOneAndTwo) {
  const fs::path dir = temp_dir();
  const fs::path a = random_layer(dir, "a.geojson", 1, 60),
                 b = random_layer(dir, "b.geojson", 2, 50);
  const OgrFeatureSet sa = read_with_ogr(a.string()), sb = read_with_ogr(b.string());
  const CliRun one = run_loci("intersections " + shell_quote(a.string()));
  ASSERT_EQ(one.status, 0) << one.err;
  const auto rows1 = parse_rows(one.out);
  EXPECT_EQ(distinct_pairs(rows1), geos_pairs(sa, nullptr));
  expect_points_on_linework(rows1, sa, sa);
  for (const Row& row : rows1) {  // a self row only for a line that is not simple
    if (row.a != row.b) continue;
    for (std::size_t i = 0; i < sa.fids.size(); ++i)
      if (sa.fids[i] == row.a) EXPECT_FALSE(sa.geoms[i]->IsSimple()) << "fid " << row.a;
  }
  for (std::size_t i = 0; i < sa.fids.size(); ++i)  // and every such line has one
    if (!sa.geoms[i]->IsSimple()) {
      bool found = false;
      for (const Row& row : rows1)
        found |= row.a == sa.fids[i] && row.b == sa.fids[i];
      EXPECT_TRUE(found) << "fid " << sa.fids[i] << " crosses itself";
    }
  const CliRun two =
      run_loci("intersections " + shell_quote(a.string()) + " " + shell_quote(b.string()));
  ASSERT_EQ(two.status, 0) << two.err;
  const auto rows2 = parse_rows(two.out);
  std::set<std::pair<long long, long long>> pairs2;
  for (const Row& row : rows2)
    pairs2.insert({row.a, row.b});
  EXPECT_EQ(pairs2, geos_pairs(sa, &sb));
  expect_points_on_linework(rows2, sa, sb);
  // The two layers in one GeoPackage: --layer2 without LAYER2 names the second of its own
  // dataset (it was taken for the layer against itself), and an unknown name is refused.
  const fs::path gpkg = dir / "two.gpkg";
  ASSERT_EQ(
      std::system(("ogr2ogr -q " + shell_quote(gpkg.string()) + " " + shell_quote(a.string()) +
                   " -nln roads && ogr2ogr -q -update " + shell_quote(gpkg.string()) + " " +
                   shell_quote(b.string()) + " -nln rivers")
                      .c_str()),
      0);
  const CliRun in_one =
      run_loci("intersections " + shell_quote(gpkg.string()) + " --layer roads --layer2 rivers");
  ASSERT_EQ(in_one.status, 0) << in_one.err;
  std::set<std::pair<long long, long long>> pairs_in_one;
  for (const Row& row : parse_rows(in_one.out))
    pairs_in_one.insert({row.a, row.b});
  // The GeoPackage numbers features from 1 where the GeoJSON layers number them from 0.
  std::set<std::pair<long long, long long>> shifted;
  for (const auto& [x, y] : pairs2)
    shifted.insert({x + 1, y + 1});
  EXPECT_EQ(pairs_in_one, shifted);
  const CliRun unknown = run_loci("intersections " + shell_quote(a.string()) + " --layer2 nope");
  EXPECT_EQ(unknown.status, 1) << unknown.out;
  EXPECT_NE(unknown.err.find("nope"), std::string::npos) << unknown.err;
  fs::remove_all(dir);
}

TEST(IntersectionsCli, HandCasesFormatsAndErrors) {
  const fs::path dir = temp_dir();
  const fs::path p = dir / "hand.geojson";
  std::ofstream(p) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[0,0],[4,0]]}},
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[1,-1],[1,1]]}},
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[3,0],[6,0]]}},
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[10,0],[12,2],[12,0],[10,2]]}},
{"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[[20,0],[22,0],[22,2],[20,0]]]}},
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[30,0],[31,0],[31,0],[31,1]]}},
{"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[[40,0],[42,0],[42,0],[42,2],[40,0],[40,0]]]}},
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[50,0],[50,0]]}},
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[60,0],[62,2],[62,2],[62,0],[60,2]]}}
]})";
  const CliRun r = run_loci("intersections " + shell_quote(p.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  // 0 x 1 cross at (1,0); 0 and 2 overlap on [3,4]; 3 crosses itself at (11,1); the ring of
  // 4 closes on itself but is simple; 5 and 6 repeat a vertex but are simple, 7 is one point
  // repeated; 8 repeats a vertex and crosses itself at (61,1)
  EXPECT_EQ(r.out, "fid_a,fid_b,x,y\n0,1,1,0\n0,2,3,0\n0,2,4,0\n3,3,11,1\n8,8,61,1\n");
  const CliRun pairs = run_loci("intersections " + shell_quote(p.string()) + " --pairs-only");
  EXPECT_EQ(pairs.out, "fid_a,fid_b\n0,1\n0,2\n3,3\n8,8\n");
  // The layer named twice, spelled differently, is the layer against itself: no feature met by
  // itself for sharing its own linework, and the closest pair is two features.
  const std::string again = shell_quote((dir / "." / "hand.geojson").string());
  const CliRun twice = run_loci("intersections " + shell_quote(p.string()) + " " + again);
  ASSERT_EQ(twice.status, 0) << twice.err;
  EXPECT_EQ(twice.out, r.out);
  const CliRun closest = run_loci("join " + shell_quote(p.string()) + " " + again + " --closest");
  ASSERT_EQ(closest.status, 0) << closest.err;
  EXPECT_EQ(closest.out.substr(closest.out.find('\n') + 1, 4), "0,1,");
  // Also when one side names the layer and the other takes the default (the first layer), in
  // any case GDAL matches.
  for (const char* names : {" --layer hand", " --layer2 HAND"}) {
    const CliRun named = run_loci("intersections " + shell_quote(p.string()) + " " + again + names);
    ASSERT_EQ(named.status, 0) << named.err;
    EXPECT_EQ(named.out, r.out) << names;
    const CliRun join =
        run_loci("join " + shell_quote(p.string()) + " " + again + names + " --closest");
    ASSERT_EQ(join.status, 0) << join.err;
    EXPECT_EQ(join.out, closest.out) << names;
  }
  const CliRun gj = run_loci("intersections " + shell_quote(p.string()) + " -f geojson -o " +
                             shell_quote((dir / "x.geojson").string()));
  ASSERT_EQ(gj.status, 0) << gj.err;
  const OgrFeatureSet pts = read_with_ogr((dir / "x.geojson").string());
  EXPECT_EQ(pts.fids.size(), 5u);
  EXPECT_EQ(read_text((dir / "x.geojson").string()).find("\"crs\""), std::string::npos)
      << "a layer in longitudes and latitudes needs no crs member";
  // A layer in another system: the points say which (GDAL's readers take it from "crs").
  const fs::path utm = dir / "utm.geojson";
  std::ofstream(utm) << R"({"type":"FeatureCollection",
"crs":{"type":"name","properties":{"name":"urn:ogc:def:crs:EPSG::32632"}},"features":[
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[500000,0],[500001,1]]}},
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[500000,1],[500001,0]]}}]})";
  const fs::path utm_out = dir / "utm-x.geojson";
  ASSERT_EQ(run_loci("intersections " + shell_quote(utm.string()) + " -f geojson -o " +
                     shell_quote(utm_out.string()))
                .status,
            0);
  {
    GDALDatasetUniquePtr ds(GDALDataset::Open(utm_out.string().c_str(), GDAL_OF_VECTOR));
    ASSERT_TRUE(ds);
    const OGRSpatialReference* srs = ds->GetLayer(0)->GetSpatialRef();
    ASSERT_TRUE(srs);
    EXPECT_STREQ(srs->GetAuthorityCode(nullptr), "32632");
    EXPECT_EQ(ds->GetLayer(0)->GetFeatureCount(), 1);
  }
  // Two layers in different systems are refused (their coordinates cannot be compared); the
  // same system described in two ways (a shapefile's ESRI .prj, GeoJSON's default) is one.
  const std::string hand = shell_quote(p.string()), other = shell_quote(utm.string());
  const fs::path utm_window = dir / "utm-window.geojson";
  std::ofstream(utm_window) << R"({"type":"FeatureCollection",
"crs":{"type":"name","properties":{"name":"urn:ogc:def:crs:EPSG::32632"}},"features":[
{"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[[0,0],[9,0],[9,9],[0,0]]]}}]})";
  for (const std::string& cmd :
       {"intersections " + hand + " " + other, "join " + hand + " " + other + " -p intersects",
        "clip " + hand + " --window-layer " + shell_quote(utm_window.string()) + " -o " +
            shell_quote((dir / "cw.geojson").string())}) {
    const CliRun r = run_loci(cmd);
    EXPECT_EQ(r.status, 1) << cmd;
    EXPECT_EQ(lines(r.err).size(), 1u) << r.err;
    EXPECT_NE(r.err.find("are in different coordinate systems (EPSG:4326, EPSG:32632)"),
              std::string::npos)
        << cmd << ": " << r.err;
  }
  EXPECT_FALSE(fs::exists(dir / "cw.geojson"));
  // Two layers of one GeoPackage: the message names the layers (it named the file twice).
  const std::string both = shell_quote((dir / "both.gpkg").string());
  ASSERT_EQ(std::system(("ogr2ogr -q " + both + " " + hand + " -nln a && ogr2ogr -q -update " +
                         both + " " + other + " -nln b")
                            .c_str()),
            0);
  for (const std::string& cmd :
       {"intersections " + both + " " + both + " --layer a --layer2 b",
        "join " + both + " " + both + " --layer a --layer2 b -p intersects"}) {
    const CliRun r = run_loci(cmd);
    EXPECT_EQ(r.status, 1) << cmd;
    EXPECT_NE(r.err.find("both.gpkg (layer 'a') and "), std::string::npos) << cmd << ": " << r.err;
    EXPECT_NE(r.err.find("both.gpkg (layer 'b') are in different coordinate systems"),
              std::string::npos)
        << cmd << ": " << r.err;
  }
  // A GeoPackage written from a layer without a system says "Undefined geographic SRS": no
  // system, so not refused.
  const fs::path none_csv = dir / "none.csv", none_gpkg = dir / "none.gpkg";
  std::ofstream(none_csv) << "id,WKT\n1,\"LINESTRING (500000 0,500001 1)\"\n";
  ASSERT_EQ(std::system(("ogr2ogr -q " + shell_quote(none_gpkg.string()) + " " +
                         shell_quote(none_csv.string()))
                            .c_str()),
            0);
  const CliRun undefined =
      run_loci("intersections " + other + " " + shell_quote(none_gpkg.string()));
  EXPECT_EQ(undefined.status, 0) << undefined.err;
  const fs::path shp = dir / "hand.shp";
  ASSERT_EQ(std::system(("ogr2ogr -q " + shell_quote(shp.string()) + " " + hand +
                         " -where \"OGR_GEOMETRY = 'LINESTRING'\"")
                            .c_str()),
            0);
  const CliRun same = run_loci("join " + shell_quote(shp.string()) + " " + hand + " -p intersects");
  EXPECT_EQ(same.status, 0) << same.err;
  EXPECT_NE(same.out.find("\n0,0\n"), std::string::npos) << same.out;
  const CliRun ids = run_loci("intersections " + shell_quote(p.string()) + " -f ids");
  EXPECT_EQ(ids.status, 1);
  EXPECT_NE(ids.err.find("loci: error:"), std::string::npos);
  // A layer of points has no linework: refused (not "no intersections"), alone or as either
  // layer; a layer without features answers nothing.
  const fs::path points = dir / "points.geojson", empty = dir / "empty.geojson";
  std::ofstream(points) << R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":{"type":"Point","coordinates":[1,0]}},
{"type":"Feature","properties":{},"geometry":{"type":"MultiPoint","coordinates":[[3,0],[4,0]]}}]})";
  std::ofstream(empty) << R"({"type":"FeatureCollection","features":[]})";
  const std::string point_layer = shell_quote(points.string());
  for (const std::string& cmd :
       {"intersections " + point_layer, "intersections " + hand + " " + point_layer,
        "intersections " + point_layer + " " + hand}) {
    const CliRun r = run_loci(cmd);
    EXPECT_EQ(r.status, 1) << cmd;
    EXPECT_EQ(lines(r.err).size(), 1u) << r.err;
    EXPECT_NE(r.err.find(points.string() +
                         ": no lines or polygon rings to intersect (its 2 features are points)"),
              std::string::npos)
        << cmd << ": " << r.err;
    EXPECT_EQ(r.out, "") << cmd;
  }
  const CliRun nothing = run_loci("intersections " + shell_quote(empty.string()));
  EXPECT_EQ(nothing.status, 0) << nothing.err;
  EXPECT_EQ(nothing.out, "fid_a,fid_b,x,y\n");
  const CliRun none = run_loci("intersections");
  EXPECT_EQ(none.status, 1);
  const CliRun missing = run_loci("intersections " + shell_quote((dir / "nope.shp").string()));
  EXPECT_EQ(missing.status, 1);
  EXPECT_EQ(lines(missing.err).size(), 1u) << missing.err;
  fs::remove_all(dir);
}

}  // namespace
