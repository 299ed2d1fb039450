// Per-feature boxes and per-segment items read straight from shapefiles
// (read_shapefile_boxes, read_shapefile_segments) against GDAL read feature by feature: every
// shape family, Z variants, null and empty shapes, random and degenerate coordinates; the
// granularity chosen; the files handed back to GDAL (deleted records, a missing .dbf, corrupt
// bytes) and bad coordinates refused with GDAL's message.
#include "loci/io/shapefile_boxes.hpp"

#include <gdal_priv.h>
#include <gtest/gtest.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "gdal_layer.hpp"
#include "loci/geom/error.hpp"
#include "loci/io/layer_reader.hpp"
#include "loci/io/sidecar.hpp"
#include "shapefile_polygons.hpp"
#include "shapefile_records.hpp"
#include "support/scratch.hpp"

namespace {

namespace fs = std::filesystem;
using loci::io::LayerItems;
using loci::io::Per;
using Make = std::function<std::unique_ptr<OGRGeometry>(int, std::mt19937_64&)>;

fs::path dir() {
  static const loci::test::Scratch d = [] {
    GDALAllRegister();
    loci::test::Scratch s("loci-shp-boxes");
    fs::create_directories(s.path());
    return s;
  }();
  return d.path();
}

// Writes a shapefile of `count` features made by `make` (nullptr: no geometry).
std::string write_shapefile(const std::string& name, OGRwkbGeometryType type, int count,
                            const Make& make, std::uint64_t seed) {
  const std::string path = (dir() / (name + ".shp")).string();
  GDALDriver* d = GetGDALDriverManager()->GetDriverByName("ESRI Shapefile");
  GDALDatasetUniquePtr ds(d->Create(path.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
  EXPECT_TRUE(ds);
  OGRLayer* layer = ds->CreateLayer(name.c_str(), nullptr, type, nullptr);
  OGRFieldDefn field("n", OFTInteger);
  layer->CreateField(&field);
  std::mt19937_64 rng(seed);
  for (int i = 0; i < count; ++i) {
    OGRFeature f(layer->GetLayerDefn());
    f.SetField(0, i);
    if (auto g = make(i, rng)) f.SetGeometryDirectly(g.release());
    EXPECT_EQ(layer->CreateFeature(&f), OGRERR_NONE);
  }
  return path;
}

struct Reference {
  std::vector<loci::Box2> boxes;
  std::vector<std::int64_t> fids;
};

// GDAL's own reading, feature by feature: what the direct reader must give.
Reference gdal_reference(const std::string& path) {
  Reference r;
  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY));
  for (auto& f : *ds->GetLayer(0)) {
    const OGRGeometry* g = f->GetGeometryRef();
    if (!g || g->IsEmpty()) continue;
    OGREnvelope e;
    g->getEnvelope(&e);
    r.boxes.push_back({{e.MinX, e.MinY}, {e.MaxX, e.MaxY}});
    r.fids.push_back(f->GetFID());
  }
  return r;
}

std::array<double, 4> corners(const loci::Box2& b) {
  return {b.min[0], b.min[1], b.max[0], b.max[1]};
}

// The copy of a shapefile without its .dbf, in dir()/no_dbf: the direct reader hands it to
// GDAL, so what loci reads of it is GDAL's answer.
std::string without_dbf(const std::string& path) {
  const fs::path sub = dir() / "no_dbf";
  fs::create_directories(sub);
  const fs::path stem = fs::path(path).replace_extension();
  const std::string name = stem.filename().string();
  fs::remove(sub / (name + ".dbf"));
  for (const char* ext : {".shp", ".shx"})
    fs::copy_file(stem.string() + ext, sub / (name + ext), fs::copy_options::overwrite_existing);
  return (sub / (name + ".shp")).string();
}

// GDAL's own per-segment reading, through read_items: the same .shp and .shx without their
// .dbf, which the direct reader hands to GDAL.
LayerItems through_gdal(const std::string& path) {
  const std::string copy = without_dbf(path);
  EXPECT_FALSE(loci::io::read_shapefile_segments(copy)) << "no .dbf: GDAL reads it";
  return loci::io::read_items(copy, "", Per::segment);
}

// Each feature's parts as lists of (box, flags), in any order and each sorted: GDAL may
// regroup a polygon's rings (and so number them differently).
using Segment = std::pair<std::array<double, 4>, std::uint32_t>;
using Parts = std::map<std::int64_t, std::vector<std::vector<Segment>>>;
Parts parts_of(const LayerItems& items) {
  std::map<std::int64_t, std::map<std::int32_t, std::vector<Segment>>> by;
  for (std::size_t i = 0; i < items.records.size(); ++i)
    by[items.records[i].fid][items.records[i].part].emplace_back(corners(items.boxes[i]),
                                                                 items.records[i].flags);
  Parts out;
  for (auto& [fid, parts] : by)
    for (auto& [part, segments] : parts) {
      std::sort(segments.begin(), segments.end());
      out[fid].push_back(std::move(segments));
    }
  for (auto& [fid, parts] : out)
    std::sort(parts.begin(), parts.end());
  return out;
}

// The direct per-segment read gives GDAL's items: the same items in the same order with the
// same parts for lines and points; the same rings, each with its segments, for polygons.
void expect_segments_like_gdal(const std::string& path, const LayerItems& direct) {
  const LayerItems gdal = through_gdal(path);
  EXPECT_EQ(direct.per, Per::segment);
  EXPECT_EQ(direct.features, gdal.features);
  EXPECT_EQ(direct.has_polygons, gdal.has_polygons);
  ASSERT_EQ(direct.records.size(), gdal.records.size());
  {
    const Parts d = parts_of(direct), g = parts_of(gdal);
    EXPECT_EQ(d.size(), g.size());
    for (const auto& [fid, parts] : d) {
      const auto it = g.find(fid);
      EXPECT_TRUE(it != g.end() && it->second == parts) << "feature " << fid << " of " << path;
    }
  }
  if (!gdal.has_polygons) {
    EXPECT_EQ(direct.boxes, gdal.boxes);
    for (std::size_t i = 0; i < gdal.records.size(); ++i) {
      EXPECT_EQ(direct.records[i].fid, gdal.records[i].fid) << "item " << i;
      EXPECT_EQ(direct.records[i].part, gdal.records[i].part) << "item " << i;
      EXPECT_EQ(direct.records[i].flags, gdal.records[i].flags) << "item " << i;
    }
  }
  // Every part's segments are consecutive, as the GDAL path writes them.
  for (std::size_t i = 1; i < direct.records.size(); ++i)
    if (direct.records[i].fid == direct.records[i - 1].fid)
      EXPECT_GE(direct.records[i].part, direct.records[i - 1].part);
}

// What `loci info` reads of the file directly is what GDAL's geometries say: per record a
// type name ("(none)" without geometry) and the extent. `direct_read`: whether the file is
// one the direct summary takes (else GDAL answers for it).
void expect_summary_like_gdal(const std::string& path, bool direct_read = true) {
  const auto direct = loci::io::read_shapefile_summary(path);
  ASSERT_EQ(bool(direct), direct_read) << "summary read directly";
  const std::string copy = without_dbf(path);
  ASSERT_FALSE(loci::io::read_shapefile_summary(copy)) << "no .dbf: GDAL reads it";
  const loci::io::LayerSummary gdal = loci::io::summarize_layer(copy, "", {});
  if (direct) {
    EXPECT_EQ(direct->records, gdal.feature_count);
    EXPECT_EQ(direct->geometry_types, gdal.geometry_types);
    EXPECT_EQ(direct->extent, gdal.extent);
  }
  const loci::io::LayerSummary summary = loci::io::summarize_layer(path, "", {});
  EXPECT_EQ(summary.feature_count, gdal.feature_count);
  EXPECT_EQ(summary.geometry_types, gdal.geometry_types);
  EXPECT_EQ(summary.extent, gdal.extent);
}

OGRLinearRing ring_of(std::initializer_list<std::pair<double, double>> points) {
  OGRLinearRing r;
  for (const auto& [x, y] : points)
    r.addPoint(x, y);
  r.closeRings();
  return r;
}

void add_ring(OGRPolygon& p, OGRLinearRing r) {
  p.addRing(&r);
}

// Reverses, in the .shp's bytes, the points of parts `parts` of record `fid` (first point
// kept): GDAL's writer orients rings by how they nest, this makes rings it never writes.
void reverse_parts(const std::string& shp, int fid, std::initializer_list<int> parts) {
  const auto be32 = [](const char* p) {
    return std::uint32_t(std::uint8_t(p[0])) << 24 | std::uint32_t(std::uint8_t(p[1])) << 16 |
           std::uint32_t(std::uint8_t(p[2])) << 8 | std::uint32_t(std::uint8_t(p[3]));
  };
  std::vector<char> shx(fs::file_size(fs::path(shp).replace_extension(".shx")));
  std::ifstream(fs::path(shp).replace_extension(".shx"), std::ios::binary)
      .read(shx.data(), std::streamsize(shx.size()));
  std::vector<char> bytes(fs::file_size(shp));
  std::ifstream(shp, std::ios::binary).read(bytes.data(), std::streamsize(bytes.size()));
  char* c = bytes.data() + 2 * std::size_t(be32(shx.data() + 100 + 8 * fid)) + 8;
  std::int32_t count, n;
  std::memcpy(&count, c + 36, 4);
  std::memcpy(&n, c + 40, 4);
  char* xy = c + 44 + 4 * count;
  for (const int k : parts) {
    std::int32_t begin, end = n;
    std::memcpy(&begin, c + 44 + 4 * k, 4);
    if (k + 1 < count) std::memcpy(&end, c + 48 + 4 * k, 4);
    for (int i = begin + 1, j = end - 2; i < j; ++i, --j)
      std::swap_ranges(xy + 16 * i, xy + 16 * (i + 1), xy + 16 * j);
  }
  std::ofstream(shp, std::ios::binary | std::ios::trunc)
      .write(bytes.data(), std::streamsize(bytes.size()));
}

// The direct reader of features (for the `loci` front, without GDAL) gives, for every record it
// takes, the geometry GDAL gives flattened as the GDAL path flattens it: the same points, in
// the same parts, in the same order, the rings numbered by the same polygons. Returns how many
// records it took (the others it leaves to GDAL).
int expect_features_like_gdal(const std::string& path) {
  SCOPED_TRACE(path);
  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR));
  if (!ds) {
    ADD_FAILURE() << "GDAL cannot open " << path;
    return 0;
  }
  OGRLayer* layer = ds->GetLayer(0);
  loci::io::detail::shp::ShapefileFeatures direct(path);
  if (!direct.active()) return 0;
  int taken = 0;
  const GIntBig count = layer->GetFeatureCount();
  for (GIntBig fid = -1; fid <= count; ++fid) {
    const auto ours = direct.read(fid);
    OGRFeatureUniquePtr f(fid >= 0 && fid < count ? layer->GetFeature(fid) : nullptr);
    if (!f) {  // deleted, or no such FID
      EXPECT_FALSE(ours) << "feature " << fid;
      continue;
    }
    if (!ours) continue;
    ++taken;
    const loci::io::FlatGeometry ref =
        loci::io::detail::flatten(f->GetGeometryRef(), loci::io::detail::where(path, fid));
    EXPECT_EQ(ours->points, ref.points) << "feature " << fid;
    EXPECT_EQ(ours->polygons, ref.polygons) << "feature " << fid;
    EXPECT_EQ(ours->parts.size(), ref.parts.size()) << "feature " << fid;
    for (std::size_t i = 0; i < std::min(ours->parts.size(), ref.parts.size()); ++i) {
      const auto &a = ours->parts[i], &b = ref.parts[i];
      EXPECT_TRUE(a.begin == b.begin && a.end == b.end && a.kind == b.kind &&
                  a.polygon == b.polygon)
          << "feature " << fid << " part " << i;
    }
  }
  return taken;
}

void expect_like_gdal(const std::string& path) {
  SCOPED_TRACE(path);
  expect_summary_like_gdal(path);
  EXPECT_GT(expect_features_like_gdal(path), 0);
  const auto direct = loci::io::read_shapefile_boxes(path);
  ASSERT_TRUE(direct) << "handed back to GDAL";
  const Reference ref = gdal_reference(path);
  const LayerItems& items = direct->items;
  ASSERT_EQ(items.boxes.size(), ref.boxes.size());
  ASSERT_EQ(items.records.size(), ref.fids.size());
  EXPECT_EQ(items.features, ref.fids.size());
  for (std::size_t i = 0; i < ref.boxes.size(); ++i) {
    EXPECT_EQ(items.records[i].fid, ref.fids[i]);
    EXPECT_EQ(items.records[i].part, 0);
    EXPECT_EQ(items.boxes[i], ref.boxes[i]) << "feature " << ref.fids[i];
  }
  // The segment count decides the granularity: it must be what a per-segment read gives.
  const auto by_segment = loci::io::read_shapefile_segments(path);
  ASSERT_TRUE(by_segment) << "segments handed back to GDAL";
  expect_segments_like_gdal(path, *by_segment);
  EXPECT_EQ(direct->segments, by_segment->records.size());
  EXPECT_EQ(by_segment->features, items.features);
  EXPECT_EQ(items.has_polygons, by_segment->has_polygons);
  EXPECT_EQ(items.layer_name, by_segment->layer_name);
  EXPECT_EQ(by_segment->content_hash, items.content_hash);
  // read_items takes the direct path (the one that has the content hash from the bytes read).
  const LayerItems through = loci::io::read_items(path, "", Per::segment);
  EXPECT_TRUE(through.content_hash);
  EXPECT_EQ(through.boxes, by_segment->boxes);
  // The fingerprint's hash, from the bytes read, is the one a pass of its own gives.
  ASSERT_TRUE(items.content_hash);
  EXPECT_EQ(*items.content_hash, loci::io::fingerprint_of(path).hash);
}

double coordinate(std::mt19937_64& rng) {
  return std::uniform_real_distribution<double>(-1000, 1000)(rng);
}

std::unique_ptr<OGRLineString> random_line(std::mt19937_64& rng, int points, bool z) {
  auto l = std::make_unique<OGRLineString>();
  for (int i = 0; i < points; ++i)
    if (z)
      l->addPoint(coordinate(rng), coordinate(rng), coordinate(rng));
    else
      l->addPoint(coordinate(rng), coordinate(rng));
  return l;
}

std::unique_ptr<OGRPolygon> random_polygon(std::mt19937_64& rng, int rings, bool z) {
  auto p = std::make_unique<OGRPolygon>();
  for (int r = 0; r < rings; ++r) {
    const double cx = coordinate(rng), cy = coordinate(rng), radius = 1 + double(rng() % 50);
    OGRLinearRing ring;
    const int n = 3 + int(rng() % 20);
    for (int i = 0; i < n; ++i) {
      const double a = 2 * M_PI * i / n * (r % 2 ? -1 : 1);
      if (z)
        ring.addPoint(cx + radius * std::cos(a), cy + radius * std::sin(a), 7.0);
      else
        ring.addPoint(cx + radius * std::cos(a), cy + radius * std::sin(a));
    }
    ring.closeRings();
    p->addRing(&ring);
  }
  return p;
}

// Every fifth feature has no geometry; the rest vary in size.
std::unique_ptr<OGRGeometry> sometimes_null(int i, std::unique_ptr<OGRGeometry> g) {
  if (i % 5 == 3) return nullptr;
  return g;
}

TEST(ShapefileBoxes, EveryShapeFamilyMatchesGdal) {
  for (const bool z : {false, true}) {
    const std::string s = z ? "_z" : "";
    expect_like_gdal(write_shapefile(
        "points" + s, z ? wkbPoint25D : wkbPoint, 300,
        [&](int i, std::mt19937_64& rng) {
          return sometimes_null(
              i, z ? std::make_unique<OGRPoint>(coordinate(rng), coordinate(rng), 1.0)
                   : std::make_unique<OGRPoint>(coordinate(rng), coordinate(rng)));
        },
        1));
    expect_like_gdal(write_shapefile(
        "multipoints" + s, z ? wkbMultiPoint25D : wkbMultiPoint, 200,
        [&](int i, std::mt19937_64& rng) {
          auto m = std::make_unique<OGRMultiPoint>();
          for (int k = 0, n = 1 + int(rng() % 9); k < n; ++k)
            m->addGeometryDirectly(z ? new OGRPoint(coordinate(rng), coordinate(rng), 2.0)
                                     : new OGRPoint(coordinate(rng), coordinate(rng)));
          return sometimes_null(i, std::move(m));
        },
        2));
    expect_like_gdal(write_shapefile(
        "lines" + s, z ? wkbMultiLineString25D : wkbMultiLineString, 200,
        [&](int i, std::mt19937_64& rng) -> std::unique_ptr<OGRGeometry> {
          if (i % 2) return sometimes_null(i, random_line(rng, 2 + int(rng() % 30), z));
          auto m = std::make_unique<OGRMultiLineString>();
          for (int k = 0, n = 1 + int(rng() % 4); k < n; ++k)
            m->addGeometryDirectly(random_line(rng, 2 + int(rng() % 10), z).release());
          return sometimes_null(i, std::move(m));
        },
        3));
    expect_like_gdal(write_shapefile(
        "polygons" + s, z ? wkbMultiPolygon25D : wkbMultiPolygon, 200,
        [&](int i, std::mt19937_64& rng) -> std::unique_ptr<OGRGeometry> {
          if (i % 2) return sometimes_null(i, random_polygon(rng, 1 + int(rng() % 3), z));
          auto m = std::make_unique<OGRMultiPolygon>();
          for (int k = 0, n = 1 + int(rng() % 3); k < n; ++k)
            m->addGeometryDirectly(random_polygon(rng, 1, z).release());
          return sometimes_null(i, std::move(m));
        },
        4));
  }
}

TEST(ShapefileBoxes, PolygonTypesFollowRingOrientationAsGdalSortsRings) {
  // Rings as GDAL writes them (outer clockwise, holes counter-clockwise), read back: holes
  // inside, a hole outside its outer ring, islands, an island in a lake, a hole sharing
  // vertices with the outer ring, a concave outer ring, one ring only.
  const auto square = [](double x, double y, double s) {
    return ring_of({{x, y}, {x + s, y}, {x + s, y + s}, {x, y + s}});
  };
  const auto make = [&](int i, std::mt19937_64&) -> std::unique_ptr<OGRGeometry> {
    auto p = std::make_unique<OGRPolygon>();
    auto m = std::make_unique<OGRMultiPolygon>();
    switch (i) {
      case 0:  // one ring
        add_ring(*p, square(0, 0, 10));
        return p;
      case 1:  // two holes inside
        add_ring(*p, square(0, 0, 10));
        add_ring(*p, square(1, 1, 2));
        add_ring(*p, square(5, 5, 3));
        return p;
      case 2:  // a "hole" outside the outer ring
        add_ring(*p, square(0, 0, 10));
        add_ring(*p, square(20, 20, 2));
        return p;
      case 3: {  // two islands
        OGRPolygon a, b;
        add_ring(a, square(0, 0, 1));
        add_ring(b, square(5, 5, 1));
        m->addGeometry(&a);
        m->addGeometry(&b);
        return m;
      }
      case 4: {  // an island in a lake of an island
        OGRPolygon a, b;
        add_ring(a, square(0, 0, 10));
        add_ring(a, square(2, 2, 6));
        add_ring(b, square(4, 4, 2));
        m->addGeometry(&a);
        m->addGeometry(&b);
        return m;
      }
      case 5: {  // a hole whose vertices, but not its first, touch the outer ring
        add_ring(*p, square(0, 0, 10));
        add_ring(*p, ring_of({{5, 5}, {10, 4}, {10, 6}}));
        return p;
      }
      default: {  // a concave outer ring with a hole in its notch's shadow
        add_ring(*p,
                 ring_of({{0, 0}, {10, 0}, {10, 10}, {6, 10}, {6, 3}, {4, 3}, {4, 10}, {0, 10}}));
        add_ring(*p, square(1, 5, 1));
        return p;
      }
    }
  };
  const std::string path = write_shapefile("ring_types", wkbPolygon, 7, make, 8);
  expect_summary_like_gdal(path);
  const auto direct = loci::io::read_shapefile_summary(path);
  ASSERT_TRUE(direct);
  // Both answers occur: the test would not pass on a rule that always says one.
  EXPECT_EQ(direct->geometry_types, (std::vector<std::pair<std::string, std::int64_t>>{
                                        {"Multi Polygon", 3}, {"Polygon", 4}}));

  // A counter-clockwise ring outside the clockwise one, which GDAL's writer never makes but
  // other writers may: the first record's hole moved 20 units east in the .shp's bytes.
  const std::string moved = write_shapefile(
      "moved_hole", wkbPolygon, 2,
      [&](int, std::mt19937_64&) -> std::unique_ptr<OGRGeometry> {
        auto p = std::make_unique<OGRPolygon>();
        add_ring(*p, square(0, 0, 10));
        add_ring(*p, square(1, 1, 2));
        return p;
      },
      11);
  {
    std::vector<char> bytes(fs::file_size(moved));
    std::ifstream(moved, std::ios::binary).read(bytes.data(), std::streamsize(bytes.size()));
    // Record 0: 8 bytes of header, 44 of content header, 2 part starts, then x,y pairs; the
    // hole's five points follow the outer ring's five.
    for (int i = 5; i < 10; ++i) {
      double x;
      char* at = bytes.data() + 100 + 8 + 44 + 8 + 16 * i;
      std::memcpy(&x, at, 8);
      x += 20;
      std::memcpy(at, &x, 8);
    }
    std::ofstream(moved, std::ios::binary | std::ios::trunc)
        .write(bytes.data(), std::streamsize(bytes.size()));
  }
  // GDAL 3.6 keeps it as a hole of the one outer ring, later versions make it a polygon of
  // its own: GDAL answers for such a file.
  expect_summary_like_gdal(moved, false);

  // A self-intersecting hole, whose signed area and lowest turn disagree on its orientation:
  // read as GDAL reads it, by the turn.
  expect_summary_like_gdal(
      write_shapefile(
          "bowtie_hole", wkbPolygon, 1,
          [&](int, std::mt19937_64&) -> std::unique_ptr<OGRGeometry> {
            auto p = std::make_unique<OGRPolygon>();
            add_ring(*p, square(-5, -5, 20));
            add_ring(*p, ring_of({{0, 0}, {10, 1}, {0, 2}, {0, 10}, {10, 10}, {10, 2.5}}));
            return p;
          },
          12),
      true);

  // A hole starting on the outer ring, and a hole of zero area: orientation cannot place
  // them plainly, GDAL answers for those files.
  expect_summary_like_gdal(write_shapefile(
                               "ring_on_outer", wkbPolygon, 2,
                               [&](int i, std::mt19937_64&) -> std::unique_ptr<OGRGeometry> {
                                 auto p = std::make_unique<OGRPolygon>();
                                 add_ring(*p, square(0, 0, 10));
                                 if (i == 1) add_ring(*p, ring_of({{10, 5}, {8, 4}, {8, 6}}));
                                 return p;
                               },
                               9),
                           false);
  expect_summary_like_gdal(write_shapefile(
                               "flat_hole", wkbPolygon, 1,
                               [&](int, std::mt19937_64&) -> std::unique_ptr<OGRGeometry> {
                                 auto p = std::make_unique<OGRPolygon>();
                                 add_ring(*p, square(0, 0, 10));
                                 add_ring(*p, ring_of({{2, 2}, {3, 3}, {4, 4}}));
                                 return p;
                               },
                               10),
                           false);
}

// Feature by feature, the polygons built from the records are GDAL's to the byte (polygons,
// rings and points in GDAL's order), and fetch() gives GDAL's features; `built`: how many
// were built rather than left to GDAL.
void expect_polygons_like_gdal(const std::string& path, int* built_out) {
  SCOPED_TRACE(path);
  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR));
  ASSERT_TRUE(ds);
  OGRLayer* layer = ds->GetLayer(0);
  loci::io::detail::ShapefilePolygons polygons(path, *layer);
  GDALDatasetUniquePtr again(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR));
  loci::io::detail::ShapefilePolygons fetching(path, *again->GetLayer(0));
  const auto wkb = [](const OGRGeometry& g) {
    std::vector<unsigned char> b(g.WkbSize());
    g.exportToWkb(wkbNDR, b.data(), wkbVariantIso);
    return b;
  };
  int built = 0;
  for (GIntBig fid = 0; fid < layer->GetFeatureCount(); ++fid) {
    OGRFeatureUniquePtr f(layer->GetFeature(fid));
    const OGRGeometry* ref = f ? f->GetGeometryRef() : nullptr;
    const auto ours = polygons.read(fid);
    if (!f) {  // a deleted record
      EXPECT_FALSE(ours) << "feature " << fid;
      EXPECT_FALSE(fetching.fetch(fid)) << "feature " << fid;
      continue;
    }
    if (ours) {
      ++built;
      EXPECT_TRUE(ref) << "feature " << fid;
      if (!ref) continue;
      EXPECT_EQ(wkb(*ours), wkb(*ref)) << "feature " << fid;
    }
    // fetch() gives the same feature, attributes included, whichever builds the geometry.
    OGRFeatureUniquePtr fetched = fetching.fetch(fid);
    ASSERT_TRUE(fetched && f) << "feature " << fid;
    EXPECT_EQ(fetched->GetFID(), fid);
    EXPECT_EQ(fetched->GetFieldAsInteger(0), f->GetFieldAsInteger(0)) << "feature " << fid;
    const OGRGeometry* g = fetched->GetGeometryRef();
    EXPECT_EQ(bool(g), bool(ref)) << "feature " << fid;
    if (g && ref) EXPECT_EQ(wkb(*g), wkb(*ref)) << "feature " << fid;
  }
  *built_out = built;
  EXPECT_GE(expect_features_like_gdal(path), built);
  // The per-segment read numbers each ring's polygon as GDAL's sorting does (or leaves the
  // record to GDAL).
  if (const auto segments = loci::io::read_shapefile_segments(path))
    expect_segments_like_gdal(path, *segments);
}

TEST(ShapefileBoxes, PolygonsOfManyRingsAreBuiltAsGdalBuildsThem) {
  // Archipelagos: islands with lakes, islands in those lakes with lakes of their own (so a
  // lake has two islands around it and belongs to the smaller), lakes starting on their
  // island's shore, polygons in random order, a few single polygons and lines of one ring.
  const auto square = [](double x, double y, double s) {
    return ring_of({{x, y}, {x + s, y}, {x + s, y + s}, {x, y + s}});
  };
  const auto make = [&](int i, std::mt19937_64& rng) -> std::unique_ptr<OGRGeometry> {
    if (i % 7 == 6) return nullptr;
    std::uniform_real_distribution<double> u(0, 1);
    auto m = std::make_unique<OGRMultiPolygon>();
    std::vector<std::unique_ptr<OGRPolygon>> parts;
    const int systems = 1 + int(rng() % 6);
    for (int k = 0; k < systems; ++k) {
      const double x = 100.0 * k + 3 * u(rng), y = 100.0 * double(i) + 3 * u(rng);
      auto island = std::make_unique<OGRPolygon>();
      add_ring(*island, square(x, y, 90));
      const int depth = int(rng() % 4);  // 0: none, 1: a lake, 2: an island in it, 3: its lake
      const bool pond = rng() % 2 == 0;  // a second, small lake, before or after the first
      if (pond && rng() % 2) add_ring(*island, square(x + 2, y + 2, 5));
      if (depth >= 1) {
        if (rng() % 3 == 0)  // a lake starting on the shore, its other points inside
          add_ring(*island,
                   ring_of({{x, y + 40}, {x + 80, y + 5}, {x + 85, y + 85}, {x + 5, y + 80}}));
        else
          add_ring(*island, square(x + 10, y + 10, 70));
      }
      if (pond && island->getNumInteriorRings() == (depth >= 1 ? 1 : 0))
        add_ring(*island, square(x + 2, y + 2, 5));
      parts.push_back(std::move(island));
      if (depth >= 2) {
        auto inner = std::make_unique<OGRPolygon>();
        add_ring(*inner, square(x + 25, y + 25, 40));
        if (depth >= 3) add_ring(*inner, square(x + 30 + 10 * u(rng), y + 30, 10));
        parts.push_back(std::move(inner));
      }
    }
    std::shuffle(parts.begin(), parts.end(), rng);
    for (auto& p : parts)
      m->addGeometryDirectly(p.release());
    return m;
  };
  const std::string path = write_shapefile("archipelagos", wkbMultiPolygon, 60, make, 21);
  int built = 0;
  expect_polygons_like_gdal(path, &built);
  EXPECT_GT(built, 20);  // most multi-ring records are built here, not left to GDAL
  EXPECT_TRUE(loci::io::read_shapefile_segments(path)) << "segments left to GDAL";

  // The layouts of the type test (a hole outside its one outer ring, holes touching) and
  // random overlapping rings, which GDAL sorts however it sorts them: built alike or left to
  // GDAL, never different.
  const std::string random = write_shapefile(
      "overlapping_rings", wkbMultiPolygon, 40,
      [](int, std::mt19937_64& rng) -> std::unique_ptr<OGRGeometry> {
        auto m = std::make_unique<OGRMultiPolygon>();
        for (int k = 0, n = 2 + int(rng() % 5); k < n; ++k)
          m->addGeometryDirectly(random_polygon(rng, 1 + int(rng() % 3), false).release());
        return m;
      },
      22);
  expect_polygons_like_gdal(random, &built);
  EXPECT_GT(built, 0);

  // Rings a writer oriented against the rule, made by reversing rings in the .shp's bytes: a
  // counter-clockwise island far from the others (a polygon of its own for GDAL) and one in
  // the notch of a concave island, inside that island's envelope but not the island (GDAL
  // makes it a hole of the largest ring, on its envelope alone).
  const std::string reversed = write_shapefile(
      "reversed_rings", wkbMultiPolygon, 1,
      [&](int, std::mt19937_64&) -> std::unique_ptr<OGRGeometry> {
        auto m = std::make_unique<OGRMultiPolygon>();
        OGRPolygon c, notch, far, other;
        add_ring(c,
                 ring_of({{0, 0}, {10, 0}, {10, 10}, {6, 10}, {6, 3}, {4, 3}, {4, 10}, {0, 10}}));
        add_ring(notch, square(4.5, 5, 1));
        add_ring(far, square(20, 20, 1));
        add_ring(other, square(30, 0, 2));
        for (OGRPolygon* p : {&c, &notch, &far, &other})
          m->addGeometry(p);
        return m;
      },
      24);
  {
    std::vector<char> bytes(fs::file_size(reversed));
    std::ifstream(reversed, std::ios::binary).read(bytes.data(), std::streamsize(bytes.size()));
    // Record 0: 8 bytes of header, 44 of content header, 4 part starts, then x,y pairs: the
    // concave ring's 9 points, then the rings of 5 points; rings 1 and 2 are reversed.
    char* xy = bytes.data() + 100 + 8 + 44 + 4 * 4;
    for (const int first : {9, 14})
      for (int i = 0; i < 2; ++i)
        std::swap_ranges(xy + 16 * (first + 1 + i), xy + 16 * (first + 2 + i),
                         xy + 16 * (first + 3 - i));
    std::ofstream(reversed, std::ios::binary | std::ios::trunc)
        .write(bytes.data(), std::streamsize(bytes.size()));
  }
  expect_polygons_like_gdal(reversed, &built);
  EXPECT_EQ(built, 1);
  {
    GDALDatasetUniquePtr ds(GDALDataset::Open(reversed.c_str(), GDAL_OF_VECTOR));
    OGRFeatureUniquePtr f(ds->GetLayer(0)->GetFeature(0));
    const auto* m = f->GetGeometryRef()->toMultiPolygon();
    ASSERT_EQ(m->getNumGeometries(), 3);                        // the notch is a hole
    EXPECT_EQ(m->getGeometryRef(0)->getNumInteriorRings(), 1);  // of the concave ring
  }

  // A deleted record (kept, not repacked) is no feature: nothing is built for it.
  {
    const std::string copy = (dir() / "archipelagos_deleted.shp").string();
    for (const char* ext : {".shp", ".shx", ".dbf"})
      fs::copy_file(fs::path(path).replace_extension(ext), fs::path(copy).replace_extension(ext));
    GIntBig victim = 0;  // a record built when not deleted
    {
      GDALDatasetUniquePtr ds(GDALDataset::Open(copy.c_str(), GDAL_OF_VECTOR));
      loci::io::detail::ShapefilePolygons polygons(copy, *ds->GetLayer(0));
      while (!polygons.read(victim))
        ++victim;
    }
    const char* const options[] = {"AUTO_REPACK=NO", nullptr};
    {
      GDALDatasetUniquePtr ds(
          GDALDataset::Open(copy.c_str(), GDAL_OF_VECTOR | GDAL_OF_UPDATE, nullptr, options));
      ASSERT_EQ(ds->GetLayer(0)->DeleteFeature(victim), OGRERR_NONE);
    }
    GDALDatasetUniquePtr ds(GDALDataset::Open(copy.c_str(), GDAL_OF_VECTOR));
    loci::io::detail::ShapefilePolygons polygons(copy, *ds->GetLayer(0));
    EXPECT_FALSE(polygons.read(victim));
    int built_here = 0;
    CPLPushErrorHandler(CPLQuietErrorHandler);  // GDAL reports reading the deleted record
    expect_polygons_like_gdal(copy, &built_here);
    CPLPopErrorHandler();
    EXPECT_GT(built_here, 20);
  }

  // Decisions GDAL takes in floating point, which the built polygons must take alike: a
  // hole whose first point lies on (or within rounding of) a sloped edge of an outer ring
  // inside another, and sliver rings whose orientation GDAL decides by the sign of its area
  // sum (their vertices within 1e-5 of each other), beside two outer rings.
  const std::string rounding = write_shapefile(
      "rounding", wkbMultiPolygon, 200,
      [&](int i, std::mt19937_64& rng) -> std::unique_ptr<OGRGeometry> {
        std::uniform_real_distribution<double> u(-1, 1);
        auto m = std::make_unique<OGRMultiPolygon>();
        OGRPolygon big, inner;
        if (i % 2 == 0) {
          add_ring(big, square(-1000, -1000, 2000));
          const double ax = u(rng), ay = u(rng), bx = 100 + u(rng), by = 37 + u(rng);
          add_ring(inner, ring_of({{ax, ay}, {bx, ay}, {bx, by}}));
          const double t = 0.3 + 0.4 * (u(rng) + 1) / 2;
          const double px = ax + t * (bx - ax), py = ay + t * (by - ay);
          if (rng() % 2)
            add_ring(inner, ring_of({{px, py}, {px - 2, py + 4}, {px - 4, py + 4}}));
          else
            add_ring(inner, ring_of({{px, py}, {px + 2, py - 0.5}, {px + 2, py - 2}}));
          m->addGeometry(&big);
          m->addGeometry(&inner);
          return m;
        }
        add_ring(big, square(0, 0, 200));
        OGRPolygon far, sliver;
        add_ring(far, square(300, 0, 1));
        const double x = 100 + 70 * (u(rng) + 1) / 2, y = 10 + 50 * (u(rng) + 1) / 2;
        const double dx = u(rng), dy = u(rng);
        const int k = 3 + int(rng() % 4);
        OGRLinearRing r;
        for (int j = 0; j < k; ++j)
          r.addPoint(x + dx * j * 5e-6, y + dy * j * 5e-6 + 1e-13 * u(rng));
        for (int j = k - 2; j > 0; --j)
          r.addPoint(x + dx * j * 5e-6, y + dy * j * 5e-6 + 1e-13 * u(rng));
        r.closeRings();
        sliver.addRing(&r);
        for (OGRPolygon* p : {&big, &far, &sliver})
          m->addGeometry(p);
        return m;
      },
      25);
  // GDAL's writer made the triangle a hole of the square and the hole an island in it: the
  // two are turned back into an outer ring and its hole.
  for (int i = 0; i < 200; i += 2)
    reverse_parts(rounding, i, {1, 2});
  expect_polygons_like_gdal(rounding, &built);
  EXPECT_GT(built, 100);

  // A user's ring sorting method: GDAL builds everything.
  CPLSetConfigOption("OGR_ORGANIZE_POLYGONS", "DEFAULT");
  {
    GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR));
    loci::io::detail::ShapefilePolygons polygons(path, *ds->GetLayer(0));
    for (GIntBig fid = 0; fid < 10; ++fid)
      EXPECT_FALSE(polygons.read(fid));
  }
  CPLSetConfigOption("OGR_ORGANIZE_POLYGONS", nullptr);
  // Not a shapefile of polygons: nothing is built.
  const std::string lines = write_shapefile(
      "some_lines", wkbLineString, 3,
      [](int, std::mt19937_64& rng) -> std::unique_ptr<OGRGeometry> {
        return random_line(rng, 5, false);
      },
      23);
  expect_polygons_like_gdal(lines, &built);
  EXPECT_EQ(built, 0);
}

// The direct readers place a hole in an outer ring as GDAL's ring predicates place it, to the
// rounding: points on vertices, on edges (midpoints, points a few units in the last place off
// them), near and far, against OGRLinearRing's own tests, on rings of random, lattice and
// sliver shapes.
TEST(ShapefileBoxes, RingPredicatesAreGdals) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-1, 1);
  int boundary = 0, inside = 0, outside = 0;
  for (int round = 0; round < 300; ++round) {
    const int n = 3 + int(rng() % 12);
    const double scale = round % 3 == 0 ? 1e-3 : (round % 3 == 1 ? 1 : 1e6);
    std::vector<std::pair<double, double>> pts;
    for (int i = 0; i < n; ++i) {
      const double a = 2 * M_PI * i / n, radius = 0.2 + 0.8 * std::abs(u(rng));
      double x = scale * radius * std::cos(a), y = scale * radius * std::sin(a);
      if (round % 4 == 2)
        x = std::round(x * 4 / scale) * scale / 4, y = std::round(y * 4 / scale) * scale / 4;
      pts.emplace_back(x, y);
    }
    pts.push_back(pts.front());
    // The record content of one polygon of one ring: what PolygonRings reads.
    std::string c(44, '\0');
    const auto put32 = [&](std::size_t at, std::uint32_t v) { std::memcpy(&c[at], &v, 4); };
    put32(0, 5);
    put32(36, 1);
    put32(40, std::uint32_t(pts.size()));
    c.append(4, '\0');
    for (const auto& [x, y] : pts) {
      c.append(reinterpret_cast<const char*>(&x), 8);
      c.append(reinterpret_cast<const char*>(&y), 8);
    }
    const loci::io::detail::shp::PolygonRings rings(
        reinterpret_cast<const unsigned char*>(c.data()));
    OGRLinearRing ring;
    for (const auto& [x, y] : pts)
      ring.addPoint(x, y);
    std::vector<std::pair<double, double>> probes;
    for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
      const auto [ax, ay] = pts[i];
      const auto [bx, by] = pts[i + 1];
      probes.emplace_back(ax, ay);
      for (const double t : {0.5, 0.25, 1.0 / 3}) {
        const double x = ax + t * (bx - ax), y = ay + t * (by - ay);
        probes.emplace_back(x, y);
        for (int k = 1; k <= 3; ++k) {
          probes.emplace_back(std::nextafter(x, x + k), y);
          probes.emplace_back(x, std::nextafter(y, y - k));
        }
      }
      probes.emplace_back(ax, by);
      probes.emplace_back(bx, ay);
    }
    for (int i = 0; i < 20; ++i)
      probes.emplace_back(scale * u(rng), scale * u(rng));
    for (const auto& [x, y] : probes) {
      OGRPoint p(x, y);
      const loci::io::Location gdal =
          ring.isPointOnRingBoundary(&p, FALSE)
              ? loci::io::Location::boundary
              : (ring.isPointInRing(&p, FALSE) ? loci::io::Location::inside
                                               : loci::io::Location::outside);
      const loci::io::Location ours =
          loci::io::detail::shp::gdal_ring_location(rings, 0, loci::Point2{x, y});
      ASSERT_EQ(ours, gdal) << "round " << round << " point (" << x << ", " << y << ")";
      boundary += gdal == loci::io::Location::boundary;
      inside += gdal == loci::io::Location::inside;
      outside += gdal == loci::io::Location::outside;
    }
  }
  // Each answer met many times: the test tells them apart.
  EXPECT_GT(boundary, 1000);
  EXPECT_GT(inside, 1000);
  EXPECT_GT(outside, 1000);
}

TEST(ShapefileBoxes, ARingSortingMethodChosenByTheUserGoesToGdal) {
  const std::string path = write_shapefile(
      "islands", wkbMultiPolygon, 3,
      [](int, std::mt19937_64& rng) -> std::unique_ptr<OGRGeometry> {
        auto m = std::make_unique<OGRMultiPolygon>();
        for (int k = 0; k < 3; ++k)
          m->addGeometryDirectly(random_polygon(rng, 1, false).release());
        return m;
      },
      13);
  expect_summary_like_gdal(path);
  CPLSetConfigOption("OGR_ORGANIZE_POLYGONS", "SKIP");
  CPLPushErrorHandler(CPLQuietErrorHandler);  // GDAL warns of every record it leaves unsorted
  expect_summary_like_gdal(path, false);
  CPLPopErrorHandler();
  CPLSetConfigOption("OGR_ORGANIZE_POLYGONS", nullptr);
}

TEST(ShapefileBoxes, DegenerateShapes) {
  // Zero-length lines, repeated points, huge and tiny coordinates, all features null but one.
  expect_like_gdal(write_shapefile(
      "degenerate", wkbLineString, 50,
      [](int i, std::mt19937_64&) -> std::unique_ptr<OGRGeometry> {
        auto l = std::make_unique<OGRLineString>();
        const double v = i % 3 == 0 ? 1e149 : (i % 3 == 1 ? -1e-300 : 0.0);
        l->addPoint(v, -v);
        l->addPoint(v, -v);
        if (i % 2) l->addPoint(v * 0.5, v);
        return l;
      },
      5));
  expect_like_gdal(write_shapefile(
      "mostly_null", wkbPolygon, 20,
      [](int i, std::mt19937_64& rng) -> std::unique_ptr<OGRGeometry> {
        if (i != 17) return nullptr;
        return random_polygon(rng, 2, false);
      },
      6));
  // An empty layer: no feature, nothing to choose.
  const std::string empty = write_shapefile(
      "empty", wkbPolygon, 0, [](int, std::mt19937_64&) { return nullptr; }, 7);
  const auto direct = loci::io::read_shapefile_boxes(empty);
  ASSERT_TRUE(direct);
  EXPECT_TRUE(direct->items.boxes.empty());
  EXPECT_EQ(loci::io::read_items_choosing(empty, "").per, Per::feature);
}

TEST(ShapefileBoxes, ChoosesSegmentsForBigFeatures) {
  const std::string big = write_shapefile(
      "big_rings", wkbPolygon, 10,
      [](int, std::mt19937_64& rng) -> std::unique_ptr<OGRGeometry> {
        auto p = std::make_unique<OGRPolygon>();
        OGRLinearRing ring;
        for (int i = 0; i < 200; ++i)
          ring.addPoint(std::cos(i / 200.0 * 2 * M_PI) + coordinate(rng) * 1e-6,
                        std::sin(i / 200.0 * 2 * M_PI));
        ring.closeRings();
        p->addRing(&ring);
        return p;
      },
      8);
  const LayerItems chosen = loci::io::read_items_choosing(big, "");
  EXPECT_EQ(chosen.per, Per::segment);
  EXPECT_EQ(chosen.records.size(), 10u * 200u);
  const std::string small = write_shapefile(
      "small_rings", wkbPolygon, 10,
      [](int, std::mt19937_64& rng) -> std::unique_ptr<OGRGeometry> {
        return random_polygon(rng, 1, false);
      },
      9);
  const LayerItems feature = loci::io::read_items_choosing(small, "");
  EXPECT_EQ(feature.per, Per::feature);
  EXPECT_EQ(feature.boxes, gdal_reference(small).boxes);
}

std::string lines_layer(const std::string& name, int count) {
  return write_shapefile(
      name, wkbLineString, count,
      [](int, std::mt19937_64& rng) -> std::unique_ptr<OGRGeometry> {
        return random_line(rng, 2 + int(rng() % 6), false);
      },
      10);
}

// read_items per feature (through GDAL when the direct reader hands the file back) gives
// GDAL's features and boxes.
void expect_read_as_gdal_reads(const std::string& path) {
  const LayerItems items = loci::io::read_items(path, "", Per::feature);
  const Reference ref = gdal_reference(path);
  EXPECT_EQ(items.boxes, ref.boxes);
  ASSERT_EQ(items.records.size(), ref.fids.size());
  for (std::size_t i = 0; i < ref.fids.size(); ++i)
    EXPECT_EQ(items.records[i].fid, ref.fids[i]);
}

TEST(ShapefileBoxes, DeletedRecordsAndMissingAttributesGoToGdal) {
  const std::string path = lines_layer("deleted", 30);
  {
    // Kept as a deleted record: GDAL would otherwise repack the file when closing it.
    const char* const options[] = {"AUTO_REPACK=NO", nullptr};
    GDALDatasetUniquePtr ds(
        GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_UPDATE, nullptr, options));
    ASSERT_EQ(ds->GetLayer(0)->DeleteFeature(4), OGRERR_NONE);
  }
  EXPECT_FALSE(loci::io::read_shapefile_boxes(path));
  EXPECT_EQ(gdal_reference(path).fids.size(), 29u);
  expect_read_as_gdal_reads(path);

  const std::string bare = lines_layer("no_dbf", 10);
  fs::remove(fs::path(bare).replace_extension(".dbf"));
  EXPECT_FALSE(loci::io::read_shapefile_boxes(bare));
}

TEST(ShapefileBoxes, WideAttributesAreCheckedAndHashedInOneRead) {
  // Records of about 770 bytes: the deletion marks lie past the reads' 256 KiB chunks at
  // offsets no chunk ends on, so each read of a mark fills the bytes skipped before it.
  const std::string path = (dir() / "wide.shp").string();
  constexpr int kCount = 1500;
  {
    GDALDriver* d = GetGDALDriverManager()->GetDriverByName("ESRI Shapefile");
    GDALDatasetUniquePtr ds(d->Create(path.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
    ASSERT_TRUE(ds);
    OGRLayer* layer = ds->CreateLayer("wide", nullptr, wkbLineString, nullptr);
    OGRFieldDefn number("n", OFTInteger);
    layer->CreateField(&number);
    for (const char* name : {"a", "b", "c"}) {
      OGRFieldDefn text(name, OFTString);
      text.SetWidth(254);
      layer->CreateField(&text);
    }
    std::mt19937_64 rng(91);
    for (int i = 0; i < kCount; ++i) {
      OGRFeature f(layer->GetLayerDefn());
      f.SetField(0, i);
      for (int k = 1; k <= 3; ++k)
        f.SetField(k, std::string(std::size_t(rng() % 254), char('a' + rng() % 26)).c_str());
      f.SetGeometryDirectly(random_line(rng, 2 + int(rng() % 4), false).release());
      ASSERT_EQ(layer->CreateFeature(&f), OGRERR_NONE);
    }
  }
  ASSERT_GT(fs::file_size(fs::path(path).replace_extension(".dbf")), 4u << 18);
  const auto direct = loci::io::read_shapefile_boxes(path);
  ASSERT_TRUE(direct);
  ASSERT_TRUE(direct->items.content_hash);
  EXPECT_EQ(*direct->items.content_hash, loci::io::fingerprint_of(path).hash);
  EXPECT_EQ(direct->items.boxes, gdal_reference(path).boxes);

  // Deleted: the first record whose mark lies past the first chunk (read by filling), then
  // also one near the end. Each time the direct reader sees it and GDAL reads the layer.
  std::array<unsigned char, 12> header{};
  {
    std::ifstream dbf(fs::path(path).replace_extension(".dbf"), std::ios::binary);
    dbf.read(reinterpret_cast<char*>(header.data()), header.size());
  }
  const std::uint64_t header_bytes = header[8] | std::uint64_t(header[9]) << 8,
                      record_bytes = header[10] | std::uint64_t(header[11]) << 8;
  ASSERT_GT(record_bytes, 3 * 254u);
  const std::uint64_t past_chunk = ((256u << 10) - header_bytes + record_bytes - 1) / record_bytes;
  ASSERT_NE(header_bytes + past_chunk * record_bytes, 256u << 10);
  for (const GIntBig victim : {GIntBig(past_chunk), GIntBig(kCount - 2)}) {
    {
      const char* const options[] = {"AUTO_REPACK=NO", nullptr};
      GDALDatasetUniquePtr ds(
          GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_UPDATE, nullptr, options));
      ASSERT_EQ(ds->GetLayer(0)->DeleteFeature(victim), OGRERR_NONE);
    }
    EXPECT_FALSE(loci::io::read_shapefile_boxes(path)) << "record " << victim << " deleted";
    EXPECT_FALSE(loci::io::read_shapefile_segments(path)) << "record " << victim << " deleted";
    expect_read_as_gdal_reads(path);
    const Reference ref = gdal_reference(path);
    EXPECT_EQ(std::count(ref.fids.begin(), ref.fids.end(), victim), 0);
  }
}

TEST(ShapefileBoxes, MeasuredShapesAndOnePointParts) {
  // M-only shape types (21, 23, 25, 28) and lines with a part of one point (a segment of
  // length zero, with a part number of its own).
  const auto point_m = [](std::mt19937_64& rng) {
    auto p = std::make_unique<OGRPoint>(coordinate(rng), coordinate(rng));
    p->setM(coordinate(rng));
    return p;
  };
  expect_like_gdal(write_shapefile(
      "points_m", wkbPointM, 40,
      [&](int i, std::mt19937_64& rng) { return sometimes_null(i, point_m(rng)); }, 20));
  expect_like_gdal(write_shapefile(
      "multipoints_m", wkbMultiPointM, 40,
      [&](int i, std::mt19937_64& rng) {
        auto m = std::make_unique<OGRMultiPoint>();
        for (int k = 0, n = 1 + int(rng() % 5); k < n; ++k)
          m->addGeometryDirectly(point_m(rng).release());
        return sometimes_null(i, std::move(m));
      },
      21));
  expect_like_gdal(write_shapefile(
      "lines_m", wkbMultiLineStringM, 60,
      [&](int i, std::mt19937_64& rng) {
        auto m = std::make_unique<OGRMultiLineString>();
        for (int k = 0, parts = 1 + int(rng() % 4); k < parts; ++k) {
          auto l = std::make_unique<OGRLineString>();
          for (int j = 0, n = k == 1 ? 1 : 2 + int(rng() % 6); j < n; ++j)
            l->addPointM(coordinate(rng), coordinate(rng), double(j));
          m->addGeometryDirectly(l.release());
        }
        return sometimes_null(i, std::move(m));
      },
      22));
  expect_like_gdal(write_shapefile(
      "polygons_m", wkbMultiPolygonM, 40,
      [&](int i, std::mt19937_64& rng) {
        auto m = std::make_unique<OGRMultiPolygon>();
        for (int k = 0, n = 1 + int(rng() % 3); k < n; ++k) {
          auto p = random_polygon(rng, 1 + int(rng() % 2), false);
          p->setMeasured(TRUE);
          m->addGeometryDirectly(p.release());
        }
        return sometimes_null(i, std::move(m));
      },
      23));
  // The files are what they say: M types, and a line feature with a part of one point (kept
  // as one segment of length zero).
  const auto direct = loci::io::read_shapefile_segments((dir() / "lines_m.shp").string());
  ASSERT_TRUE(direct);
  bool one_point_part = false;
  for (std::size_t i = 1; i + 1 < direct->records.size(); ++i)
    one_point_part |= direct->records[i].fid == direct->records[i - 1].fid &&
                      direct->records[i].part == 1 && direct->records[i - 1].part == 0 &&
                      direct->records[i + 1].part == 2 &&
                      direct->boxes[i].min == direct->boxes[i].max;
  EXPECT_TRUE(one_point_part) << "no part of one point between two others";
  std::ifstream shp(dir() / "lines_m.shp", std::ios::binary);
  unsigned char header[36];
  shp.read(reinterpret_cast<char*>(header), sizeof header);
  EXPECT_EQ(header[32], 23);  // PolyLineM
}

// One shape record's content as the format stores it (little-endian): `points` (x, y) as a
// point, a multipoint or a line of one part, by `type`; Z values when `z`; then M values
// when `m` is not empty (one per point).
std::string shape_record(std::int32_t type, const std::vector<std::pair<double, double>>& points,
                         bool z, const std::vector<double>& m) {
  static_assert(std::endian::native == std::endian::little);
  std::string c;
  const auto i32 = [&](std::int32_t v) { c.append(reinterpret_cast<const char*>(&v), 4); };
  const auto f64 = [&](double v) { c.append(reinterpret_cast<const char*>(&v), 8); };
  const auto n = std::int32_t(points.size());
  i32(type);
  const bool point = type % 10 == 1, multipoint = type % 10 == 8;
  if (!point) {
    for (const double v : {0.0, 0.0, 10.0, 10.0})
      f64(v);
    if (!multipoint) i32(1);
    i32(n);
    if (!multipoint) i32(0);
  }
  for (const auto& [x, y] : points)
    f64(x), f64(y);
  if (z) {
    if (!point) f64(0.5), f64(0.5);  // the range, then the values
    for (std::size_t i = 0; i < points.size(); ++i)
      f64(0.5);
  }
  if (!m.empty()) {
    if (!point) f64(-1), f64(7);
    for (const double v : m)
      f64(v);
  }
  return c;
}

// Replaces a shapefile's .shp and .shx by `records` of shape `type` (the .dbf, which must
// hold as many records, is kept).
void write_shapes(const std::string& shp, std::int32_t type,
                  const std::vector<std::string>& records) {
  const auto be32 = [](std::string& s, std::uint32_t v) {
    for (int k = 3; k >= 0; --k)
      s.push_back(char(v >> (8 * k) & 0xff));
  };
  std::string body, index;
  std::uint32_t offset = 50;  // in 16-bit words, after the header
  for (std::size_t i = 0; i < records.size(); ++i) {
    const auto words = std::uint32_t(records[i].size() / 2);
    be32(body, std::uint32_t(i + 1));
    be32(body, words);
    body += records[i];
    be32(index, offset);
    be32(index, words);
    offset += 4 + words;
  }
  const auto write = [&](const std::string& path, const std::string& content) {
    std::string h;
    be32(h, 9994);
    for (int k = 0; k < 5; ++k)
      be32(h, 0);
    be32(h, std::uint32_t((100 + content.size()) / 2));
    const std::int32_t version = 1000;
    h.append(reinterpret_cast<const char*>(&version), 4);
    h.append(reinterpret_cast<const char*>(&type), 4);
    for (const double v : {0.0, 0.0, 10.0, 10.0, 0.0, 0.0, 0.0, 0.0})
      h.append(reinterpret_cast<const char*>(&v), 8);
    std::ofstream(path, std::ios::binary | std::ios::trunc) << h << content;
  };
  write(shp, body);
  write(fs::path(shp).replace_extension(".shx").string(), index);
}

// A ring whose last point is not its first is closed, by the direct read as through GDAL:
// the closing edge is a segment of the ring like the others (a point inside the triangle it
// closes is inside the polygon).
TEST(ShapefileBoxes, AnUnclosedRingIsReadClosed) {
  const std::vector<std::pair<double, double>> open{{0, 0}, {0, 4}, {4, 4}},
      square{{5, 5}, {5, 6}, {6, 6}, {6, 5}, {5, 5}};
  const std::string path = write_shapefile(
      "unclosed", wkbPoint, 2,
      [](int, std::mt19937_64&) { return std::make_unique<OGRPoint>(0, 0); }, 0);
  write_shapes(path, 5, {shape_record(5, open, false, {}), shape_record(5, square, false, {})});
  const auto direct = loci::io::read_shapefile_segments(path);
  ASSERT_TRUE(direct);
  expect_segments_like_gdal(path, *direct);
  std::vector<loci::Box2> first;
  for (std::size_t i = 0; i < direct->records.size(); ++i)
    if (direct->records[i].fid == 0) first.push_back(direct->boxes[i]);
  ASSERT_EQ(first.size(), 3u);
  EXPECT_EQ(first[2], (loci::Box2{{0, 0}, {4, 4}}));  // (4, 4) back to (0, 0)
}

TEST(ShapefileBoxes, GeometryTypesNameZAndMAsGdalDoes) {
  // GDAL gives a layer measures when its first record (fid 0) carries M values and one of
  // them is above -1e38 (shapefiles' "no data"); then every geometry has them, a record
  // without them reading as M = 0. A Z type is 3D throughout, and a record of a Z type
  // without its Z values is corrupt.
  const std::vector<std::pair<double, double>> line{{1, 2}, {2, 3}, {3, 4}},
      ring{{0, 0}, {0, 1}, {1, 1}, {0, 0}};
  const std::vector<double> m7(4, 7.0), none(4, -1e39), mixed{-1e39, 5, -1e39, -1e39},
      nan(4, std::numeric_limits<double>::quiet_NaN());
  const std::string null_record("\0\0\0\0", 4);
  const auto m_of = [](const std::vector<double>& m, std::size_t n) {
    return std::vector<double>(m.begin(), m.begin() + std::ptrdiff_t(n));
  };
  struct Case {
    const char* name;
    std::int32_t type;
    std::vector<std::string> records;
    std::vector<std::pair<std::string, std::int64_t>> types;
  };
  const std::vector<Case> cases{
      {"m_first",
       23,
       {shape_record(23, line, false, m_of(m7, 3)), shape_record(23, line, false, {})},
       {{"Measured Line String", 2}}},
      {"m_no_data",
       23,
       {shape_record(23, line, false, m_of(none, 3)), shape_record(23, line, false, m_of(m7, 3))},
       {{"Line String", 2}}},
      {"m_mixed",
       23,
       {shape_record(23, line, false, m_of(mixed, 3)), shape_record(23, line, false, {})},
       {{"Measured Line String", 2}}},
      {"m_nan",
       23,
       {shape_record(23, line, false, m_of(nan, 3)), shape_record(23, line, false, m_of(m7, 3))},
       {{"Line String", 2}}},
      {"m_absent_first",
       23,
       {shape_record(23, line, false, {}), shape_record(23, line, false, m_of(m7, 3))},
       {{"Line String", 2}}},
      {"m_null_first",
       23,
       {null_record, shape_record(23, line, false, m_of(m7, 3))},
       {{"(none)", 1}, {"Line String", 1}}},
      {"zm_line",
       13,
       {shape_record(13, line, true, m_of(m7, 3)), shape_record(13, line, true, {})},
       {{"3D Measured Line String", 2}}},
      {"z_line",
       13,
       {shape_record(13, line, true, {}), shape_record(13, line, true, m_of(m7, 3))},
       {{"3D Line String", 2}}},
      {"zm_polygon", 15, {shape_record(15, ring, true, m7)}, {{"3D Measured Polygon", 1}}},
      {"m_polygon", 25, {shape_record(25, ring, false, m_of(none, 4))}, {{"Polygon", 1}}},
      {"zm_multipoint",
       18,
       {shape_record(18, line, true, m_of(m7, 3)), shape_record(18, line, true, {})},
       {{"3D Measured Multi Point", 2}}},
      {"m_multipoint",
       28,
       {shape_record(28, line, false, m_of(m7, 3))},
       {{"Measured Multi Point", 1}}},
      {"z_point",
       11,
       {shape_record(11, {{1, 2}}, true, {}), shape_record(11, {{1, 2}}, true, {7})},
       {{"3D Point", 2}}},
      {"zm_point",
       11,
       {shape_record(11, {{1, 2}}, true, {7}), shape_record(11, {{1, 2}}, true, {})},
       {{"3D Measured Point", 2}}},
      {"m_point",
       21,
       {shape_record(21, {{1, 2}}, false, {7}), shape_record(21, {{1, 2}}, false, {})},
       {{"Measured Point", 2}}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = write_shapefile(
        c.name, wkbPoint, int(c.records.size()),
        [](int, std::mt19937_64&) { return std::make_unique<OGRPoint>(0, 0); }, 0);
    write_shapes(path, c.type, c.records);
    const auto direct = loci::io::read_shapefile_summary(path);
    ASSERT_TRUE(direct);
    EXPECT_EQ(direct->geometry_types, c.types);
    expect_summary_like_gdal(path);
  }
  // A Z record without its Z values: the direct readers hand the file to GDAL, which refuses
  // it as corrupt (as it did before any direct read).
  for (const auto& [type, record] : {std::pair{13, shape_record(13, line, false, {})},
                                     std::pair{18, shape_record(18, line, false, {})},
                                     std::pair{11, shape_record(11, {{1, 2}}, false, {})}}) {
    SCOPED_TRACE(type);
    const std::string path = write_shapefile(
        "z_missing", wkbPoint, 2,
        [](int, std::mt19937_64&) { return std::make_unique<OGRPoint>(0, 0); }, 0);
    write_shapes(
        path, type,
        {shape_record(type, type == 11 ? std::vector<std::pair<double, double>>{{1, 2}} : line,
                      true, {}),
         record});
    EXPECT_FALSE(loci::io::read_shapefile_summary(path));
    EXPECT_FALSE(loci::io::read_shapefile_boxes(path));
    EXPECT_FALSE(loci::io::read_shapefile_segments(path));
    EXPECT_THROW(loci::io::read_items(path, "", Per::feature), loci::Error);
  }
}

TEST(ShapefileBoxes, BadCoordinatesAreRefusedAsGdalRefusesThem) {
  // The bad value as x of the second point (in the checks' four-point blocks), or as y of the
  // fifth of six (in the rest after them).
  for (const bool in_rest : {false, true})
    for (const double bad : {std::numeric_limits<double>::quiet_NaN(),
                             std::numeric_limits<double>::infinity(), 1e200}) {
      SCOPED_TRACE(in_rest ? "y in the rest" : "x in a block");
      // GDAL refuses to write a non-finite coordinate: a marker value is written, then
      // replaced in the file's bytes.
      constexpr double marker = 123456.78125;
      const std::string path = write_shapefile(
          "bad", wkbPolygon, 6,
          [&](int i, std::mt19937_64& rng) -> std::unique_ptr<OGRGeometry> {
            if (i == 4 && in_rest) {
              auto p = std::make_unique<OGRPolygon>();
              OGRLinearRing ring;
              for (const auto& [x, y] : {std::pair{0.0, 0.0},
                                         {1.0, 0.0},
                                         {2.0, 0.0},
                                         {2.0, 2.0},
                                         {0.0, marker},
                                         {0.0, 0.0}})
                ring.addPoint(x, y);
              p->addRing(&ring);
              return p;
            }
            auto p = random_polygon(rng, 1, false);
            if (i == 4) p->getExteriorRing()->setPoint(1, marker, 3.0);
            return p;
          },
          11);
      std::vector<char> bytes(fs::file_size(path));
      std::ifstream(path, std::ios::binary).read(bytes.data(), std::streamsize(bytes.size()));
      int replaced = 0;
      for (std::size_t at = 0; at + 8 <= bytes.size(); ++at)
        if (std::memcmp(bytes.data() + at, &marker, 8) == 0) {
          std::memcpy(bytes.data() + at, &bad, 8);
          ++replaced;
        }
      ASSERT_GE(replaced, 1);  // the point, and the boxes of its record and of the file
      std::ofstream(path, std::ios::binary | std::ios::trunc)
          .write(bytes.data(), std::streamsize(bytes.size()));
      std::string direct, gdal;
      try {
        loci::io::read_shapefile_boxes(path);
      } catch (const loci::InvalidGeometry& e) {
        direct = e.what();
      }
      try {
        loci::io::read_segments(path);
      } catch (const loci::InvalidGeometry& e) {
        gdal = e.what();
      }
      std::string segments;
      try {
        loci::io::read_shapefile_segments(path);
      } catch (const loci::InvalidGeometry& e) {
        segments = e.what();
      }
      EXPECT_NE(direct.find(": feature 4 has"), std::string::npos) << direct;
      EXPECT_EQ(direct, gdal);
      EXPECT_EQ(segments, gdal);
      fs::remove(path);
    }
}

// Flipped and truncated bytes: the direct reader hands the file to GDAL or refuses it with a
// loci::Error, never crashes; when it answers, it answers with GDAL's boxes.
TEST(ShapefileBoxes, CorruptFilesNeverCrash) {
  const std::string path = write_shapefile(
      "corrupt_src", wkbMultiPolygon, 40,
      [](int, std::mt19937_64& rng) -> std::unique_ptr<OGRGeometry> {
        return random_polygon(rng, 1 + int(rng() % 2), false);
      },
      12);
  const fs::path stem = fs::path(path).replace_extension();
  std::mt19937_64 rng(13);
  int answered = 0, refused = 0;
  for (int round = 0; round < 120; ++round) {
    const std::string name = "corrupt";
    for (const char* ext : {".shp", ".shx", ".dbf", ".prj"}) {
      const fs::path from = fs::path(stem.string() + ext), to = dir() / (name + ext);
      if (fs::exists(from)) fs::copy_file(from, to, fs::copy_options::overwrite_existing);
    }
    const fs::path victim = dir() / (name + (round % 3 == 0 ? ".shx" : ".shp"));
    std::vector<char> bytes(fs::file_size(victim));
    std::ifstream(victim, std::ios::binary).read(bytes.data(), std::streamsize(bytes.size()));
    if (round % 4 == 3) {
      bytes.resize(rng() % bytes.size());  // truncated
    } else {
      for (int k = 0, n = 1 + int(rng() % 4); k < n; ++k)
        bytes[rng() % bytes.size()] ^= char(1 << (rng() % 8));
    }
    std::ofstream(victim, std::ios::binary | std::ios::trunc)
        .write(bytes.data(), std::streamsize(bytes.size()));
    const std::string copy = (dir() / (name + ".shp")).string();
    try {
      const auto direct = loci::io::read_shapefile_boxes(copy);
      const auto segments = loci::io::read_shapefile_segments(copy);
      EXPECT_EQ(bool(direct), bool(segments)) << "round " << round;
      if (direct && segments) {
        ++answered;
        // A flipped coordinate is a different layer, not a wrong answer: compare with GDAL,
        // which must read what the direct reader read.
        CPLPushErrorHandler(CPLQuietErrorHandler);
        try {
          const Reference ref = gdal_reference(copy);
          EXPECT_EQ(direct->items.boxes, ref.boxes) << "round " << round;
          expect_segments_like_gdal(copy, *segments);
        } catch (const std::exception& e) {
          ADD_FAILURE() << "round " << round
                        << ": GDAL refused what was read directly: " << e.what();
        }
        CPLPopErrorHandler();
      }
    } catch (const loci::Error&) {
      ++refused;
    }
  }
  EXPECT_GT(answered, 0);
}

}  // namespace
