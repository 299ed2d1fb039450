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
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <tuple>
#include <vector>

#include "loci/geom/error.hpp"
#include "loci/io/layer_reader.hpp"
#include "loci/io/sidecar.hpp"

namespace {

namespace fs = std::filesystem;
using loci::io::LayerItems;
using loci::io::Per;
using Make = std::function<std::unique_ptr<OGRGeometry>(int, std::mt19937_64&)>;

fs::path dir() {
  static const fs::path d = [] {
    GDALAllRegister();
    const fs::path p = fs::temp_directory_path() / ("loci-shp-boxes-" + std::to_string(::getpid()));
    fs::remove_all(p);
    fs::create_directories(p);
    return p;
  }();
  return d;
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

// One per-segment item, comparable: GDAL may regroup a polygon's rings, so for polygons the
// items are compared as a multiset without their part numbers.
struct SegmentItem {
  std::int64_t fid;
  std::int32_t part;
  std::uint32_t flags;
  std::array<double, 4> box;
  auto key(bool with_part) const { return std::tuple(fid, with_part ? part : 0, flags, box); }
};

std::array<double, 4> corners(const loci::Box2& b) {
  return {b.min[0], b.min[1], b.max[0], b.max[1]};
}

// GDAL's own per-segment reading: the segments of its lines and rings (read_segments), and
// each point of a point or multipoint feature as a zero-length segment.
std::vector<SegmentItem> gdal_segments(const std::string& path, bool polygons) {
  std::vector<SegmentItem> out;
  for (const loci::io::SegmentRecord& r : loci::io::read_segments(path))
    out.push_back({r.fid, r.part, loci::io::segment_flags(r.segment.a, r.segment.b, polygons),
                   corners(r.segment.box())});
  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY));
  for (auto& f : *ds->GetLayer(0)) {
    const OGRGeometry* g = f->GetGeometryRef();
    if (!g) continue;
    const auto add = [&](const OGRPoint* p, int part) {
      const loci::Point2 q{p->getX(), p->getY()};
      out.push_back({f->GetFID(), part, 0u, corners(loci::Box2::of_point(q))});
    };
    if (wkbFlatten(g->getGeometryType()) == wkbPoint) add(g->toPoint(), 0);
    if (wkbFlatten(g->getGeometryType()) == wkbMultiPoint)
      for (int i = 0; i < g->toMultiPoint()->getNumGeometries(); ++i)
        add(g->toMultiPoint()->getGeometryRef(i), i);
  }
  return out;
}

std::vector<SegmentItem> items_of(const LayerItems& items) {
  std::vector<SegmentItem> out;
  for (std::size_t i = 0; i < items.records.size(); ++i)
    out.push_back({items.records[i].fid, items.records[i].part, items.records[i].flags,
                   corners(items.boxes[i])});
  return out;
}

// The direct per-segment read gives GDAL's segments: in GDAL's order with GDAL's parts for
// lines and points, as the same multiset for polygons.
void expect_segments_like_gdal(const std::string& path, const LayerItems& direct) {
  EXPECT_EQ(direct.per, Per::segment);
  const bool polygons = direct.has_polygons;
  const std::vector<SegmentItem> ref = gdal_segments(path, polygons), got = items_of(direct);
  ASSERT_EQ(got.size(), ref.size());
  std::vector<decltype(ref[0].key(true))> a, b;
  for (const SegmentItem& x : ref)
    a.push_back(x.key(!polygons));
  for (const SegmentItem& x : got)
    b.push_back(x.key(!polygons));
  // A shapefile holds one shape type, so the reference lists either segments or points, in
  // file order; polygons' rings are compared as a multiset.
  if (polygons) {
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
  }
  EXPECT_TRUE(a == b);
  // Every part's segments are consecutive, as the GDAL path writes them.
  for (std::size_t i = 1; i < got.size(); ++i)
    if (got[i].fid == got[i - 1].fid) EXPECT_GE(got[i].part, got[i - 1].part);
}

void expect_like_gdal(const std::string& path) {
  SCOPED_TRACE(path);
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
  // read_items takes the same direct path.
  const LayerItems through = loci::io::read_items(path, "", Per::segment);
  EXPECT_EQ(through.boxes, by_segment->boxes);
  EXPECT_EQ(through.records.size(), by_segment->records.size());
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
  const LayerItems items = loci::io::read_items(path, "", Per::feature);
  const Reference ref = gdal_reference(path);
  EXPECT_EQ(items.boxes, ref.boxes);
  ASSERT_EQ(items.records.size(), ref.fids.size());
  for (std::size_t i = 0; i < ref.fids.size(); ++i)
    EXPECT_EQ(items.records[i].fid, ref.fids[i]);

  const std::string bare = lines_layer("no_dbf", 10);
  fs::remove(fs::path(bare).replace_extension(".dbf"));
  EXPECT_FALSE(loci::io::read_shapefile_boxes(bare));
}

TEST(ShapefileBoxes, BadCoordinatesAreRefusedAsGdalRefusesThem) {
  for (const double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(), 1e200}) {
    // GDAL refuses to write a non-finite coordinate: a marker value is written, then
    // replaced in the file's bytes.
    constexpr double marker = 123456.78125;
    const std::string path = write_shapefile(
        "bad", wkbPolygon, 6,
        [&](int i, std::mt19937_64& rng) -> std::unique_ptr<OGRGeometry> {
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
      if (const auto direct = loci::io::read_shapefile_boxes(copy)) {
        ++answered;
        // A flipped coordinate is a different layer, not a wrong answer: compare with GDAL.
        CPLPushErrorHandler(CPLQuietErrorHandler);
        const Reference ref = gdal_reference(copy);
        CPLPopErrorHandler();
        EXPECT_EQ(direct->items.boxes, ref.boxes) << "round " << round;
      }
      if (const auto segments = loci::io::read_shapefile_segments(copy)) {
        CPLPushErrorHandler(CPLQuietErrorHandler);
        expect_segments_like_gdal(copy, *segments);
        CPLPopErrorHandler();
      }
    } catch (const loci::Error&) {
      ++refused;
    }
  }
  EXPECT_GT(answered, 0);
}

}  // namespace
