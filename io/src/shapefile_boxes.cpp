// Per-feature boxes straight from a shapefile's .shx and .shp: see shapefile_boxes.hpp.
#include "loci/io/shapefile_boxes.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <cstring>
#include <map>
#include <optional>
#include <vector>

#include <cpl_conv.h>

#include "gdal_layer.hpp"
#include "loci/geom/error.hpp"
#include "loci/io/exact.hpp"
#include "shapefile_polygons.hpp"
#include "shapefile_records.hpp"

namespace loci::io {

namespace {

using namespace detail::shp;

// Checks that the shapefile at `path` is one this reader takes and calls `begin(file_type,
// records, shp_bytes)`, then reads and checks each record in file order (read_record) and
// hands each shape to `add(read, fid, content, file_type, layer)` (the layer as GDAL opened
// it; false from `add` gives the file to GDAL), counting it in `items`; `items`
// gets the layer's name, whether it holds polygons and the fingerprint's hash from the bytes
// read. False: GDAL must read the file.
template <class Begin, class Add>
bool scan_shapefile(const std::string& path, const std::string& layer, const Progress& progress,
                    LayerItems& items, Begin&& begin, Add&& add) {
  if constexpr (std::endian::native != std::endian::little) return false;
  if (!is_shp_path(path)) return false;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return false;
  const std::string shx_path = sibling(path, ".shx", ".SHX");
  const std::string dbf_path = sibling(path, ".dbf", ".DBF");
  if (shx_path.empty() || dbf_path.empty()) return false;

  // GDAL opens it: the same errors for a file it refuses, the layer's name, its count.
  auto ol = detail::open_layer(path, layer);
  const GDALDriver* driver = ol.dataset->GetDriver();
  if (!driver || std::strcmp(driver->GetDescription(), "ESRI Shapefile") != 0) return false;

  StreamHash shp_hash;
  ChunkReader shx(shx_path), shp(path, &shp_hash);
  if (!shx.is_open() || !shp.is_open()) return false;
  const auto headers = shapefile_headers(shp, shx);
  if (!headers || kind_of(headers->file_type) == Kind::other) return false;
  const auto [file_type, count] = *headers;
  if (ol.layer->GetFeatureCount(FALSE) != GIntBig(count)) return false;
  begin(file_type, count, shp.size());

  ProgressTicker ticker(progress, double(count));
  // The index entries are read in chunks too: their 8 bytes each run ahead of the records.
  for (std::uint64_t i = 0; i < count; ++i) {
    ticker.tick(double(i + 1));
    const unsigned char* e = shx.get(100 + 8 * i, 8);
    if (!e) return false;
    const std::uint64_t offset = 2 * std::uint64_t(be32(e)),
                        length = 2 * std::uint64_t(be32(e + 4));
    if (offset < 100) return false;
    const unsigned char* record = shp.get(offset, 8 + length);
    if (!record || be32(record + 4) != be32(e + 4)) return false;
    const auto fid = std::int64_t(i);
    const RecordRead r = read_record(record + 8, length, file_type, path, fid);
    if (!r.ok) return false;
    if (r.null) {
      ++items.without_geometry;
      continue;
    }
    ++items.features;
    if (!add(r, fid, record + 8, file_type, *ol.layer)) return false;  // false: GDAL reads it
  }
  items.layer_name = ol.layer->GetName();
  items.has_polygons = is_polygon_type(file_type) && items.features > 0;
  // The fingerprint's hash from the same bytes: the .shp as read, then the other files of
  // layer_files() (.shx, .dbf), in the order and with the seeds of fingerprint_of(). The
  // .dbf must hold exactly `count` records, none deleted (else GDAL reads the layer): its
  // marks are checked as it is hashed, so that it is read once. (Checked last, a layer with
  // a deleted record is scanned for nothing; such layers are rare, and GDAL's read of them
  // costs more than the scan.)
  bool dbf_checked = false;
  if (shp.hash_rest()) {
    std::uint64_t hash = shp_hash.digest();
    const std::vector<std::string> files = layer_files(path);
    bool whole = !files.empty() && files[0] == path;
    for (std::size_t i = 1; whole && i < files.size(); ++i) {
      StreamHash next(hash);
      ChunkReader rest(files[i], &next);
      if (files[i] == dbf_path) {
        if (!plain_attributes(rest, count)) return false;
        dbf_checked = true;
      }
      whole = rest.hash_rest();
      hash = next.digest();
    }
    if (whole) items.content_hash = hash;
  }
  if (!dbf_checked) {
    ChunkReader dbf(dbf_path);
    if (!plain_attributes(dbf, count)) return false;
  }
  return true;
}

// Ring k of r as an OGR ring.
std::unique_ptr<OGRLinearRing> ogr_ring(const PolygonRings& r, std::uint32_t k) {
  const auto [begin, end] = r.range(k);
  auto ring = std::make_unique<OGRLinearRing>();
  ring->setNumPoints(int(end - begin), FALSE);
  for (std::uint32_t i = begin; i < end; ++i)
    ring->setPoint(int(i - begin), r.x(i), r.y(i));
  return ring;
}

// The geometry of organize()'s polygons.
std::unique_ptr<OGRGeometry> build_polygons(const unsigned char* c) {
  const PolygonRings r(c);
  auto organized = organize(r, orientations(r));
  if (!organized) return nullptr;
  const std::vector<std::uint32_t>& owner = organized->owner;
  std::vector<std::uint32_t>& top = organized->top;
  // Each outer ring's holes, in the record's order: a list threaded through `next`.
  std::vector<std::uint32_t> head(r.parts, kNone), tail(r.parts, kNone), next(r.parts, kNone);
  for (std::uint32_t k = 0; k < r.parts; ++k) {
    const std::uint32_t o = owner[k];
    if (o == kNone) continue;
    (head[o] == kNone ? head[o] : next[tail[o]]) = k;
    tail[o] = k;
  }
  const auto polygon = [&](std::uint32_t outer) {
    auto p = std::make_unique<OGRPolygon>();
    p->addRingDirectly(ogr_ring(r, outer).release());
    for (std::uint32_t k = head[outer]; k != kNone; k = next[k])
      p->addRingDirectly(ogr_ring(r, k).release());
    return p;
  };
  if (top.size() == 1) return polygon(top[0]);
  std::sort(top.begin(), top.end());  // the polygons in the order of their outer rings
  auto m = std::make_unique<OGRMultiPolygon>();
  for (const std::uint32_t k : top)
    m->addGeometryDirectly(polygon(k).release());
  return m;
}

}  // namespace

std::optional<ShapefileSummary> read_shapefile_summary(const std::string& path,
                                                       const std::string& layer,
                                                       const Progress& progress) {
  // A user's OGR_ORGANIZE_POLYGONS changes how GDAL sorts rings: then GDAL answers.
  if (CPLGetConfigOption("OGR_ORGANIZE_POLYGONS", nullptr)) return std::nullopt;
  ShapefileSummary out;
  LayerItems items;
  std::map<std::string, std::int64_t> types;
  bool measured = false, z = false;
  const bool read = scan_shapefile(
      path, layer, progress, items,
      [&](std::uint32_t, std::uint64_t records, std::uint64_t) {
        out.records = std::int64_t(records);
      },
      [&](const RecordRead& r, std::int64_t fid, const unsigned char* c, std::uint32_t file_type,
          OGRLayer&) {
        out.extent.expand(r.box);
        if (fid == 0) measured = uses_measures(c, r.length, file_type);
        z = has_z(file_type);
        const char* type = "Point";
        if (kind_of(file_type) == Kind::multipoint) {
          type = "Multi Point";
        } else if (kind_of(file_type) == Kind::polyline_or_polygon) {
          const bool single = le32(c + 36) == 1;
          if (!is_polygon_type(file_type)) {
            type = single ? "Line String" : "Multi Line String";
          } else if (single) {
            type = "Polygon";
          } else {
            type = polygon_type(c);
            if (!type) return false;  // a record GDAL places otherwise
          }
        }
        ++types[type];
        return true;
      });
  if (!read) return std::nullopt;
  // Named as GDAL names them: every geometry of a Z type is 3D, and measured when the first
  // record (not a null one) uses measures.
  const std::string prefix = std::string(z ? "3D " : "") + (measured ? "Measured " : "");
  std::map<std::string, std::int64_t> named;
  for (const auto& [type, count] : types)
    named[prefix + type] = count;
  if (const std::int64_t none = out.records - std::int64_t(items.features); none > 0)
    named["(none)"] = none;
  out.geometry_types.assign(named.begin(), named.end());
  return out;
}

std::optional<ShapefileBoxes> read_shapefile_boxes(const std::string& path,
                                                   const std::string& layer,
                                                   const Progress& progress) {
  ShapefileBoxes out;
  LayerItems& items = out.items;
  items.per = Per::feature;
  const bool read = scan_shapefile(
      path, layer, progress, items,
      [&](std::uint32_t, std::uint64_t records, std::uint64_t) {
        items.boxes.reserve(records);
        items.records.reserve(records);
      },
      [&](const RecordRead& r, std::int64_t fid, const unsigned char*, std::uint32_t, OGRLayer&) {
        items.boxes.push_back(r.box);
        items.records.push_back({fid, 0, 0u});
        out.segments += r.segments;
        return true;
      });
  if (!read) return std::nullopt;
  return out;
}

std::optional<LayerItems> read_shapefile_segments(const std::string& path, const std::string& layer,
                                                  const Progress& progress) {
  // A user's OGR_ORGANIZE_POLYGONS changes how GDAL sorts rings: then GDAL answers.
  if (CPLGetConfigOption("OGR_ORGANIZE_POLYGONS", nullptr)) return std::nullopt;
  LayerItems items;
  items.per = Per::segment;
  const bool read = scan_shapefile(
      path, layer, progress, items,
      [&](std::uint32_t file_type, std::uint64_t, std::uint64_t shp_bytes) {
        // Each point takes 16 bytes in the .shp (24 or more with M or Z values), so the size
        // bounds the segments: the arrays never move while they fill.
        const std::uint64_t point_bytes = file_type < 10 ? 16 : 24;
        const auto bound = std::size_t(shp_bytes / point_bytes);
        items.boxes.reserve(bound);
        items.records.reserve(bound);
      },
      [&](const RecordRead&, std::int64_t fid, const unsigned char* c, std::uint32_t file_type,
          OGRLayer& gdal) {
        if (add_record_segments(c, file_type, fid, items)) return true;
        // Rings only GDAL sorts: that record's segments from GDAL's geometry.
        const OGRFeatureUniquePtr f = detail::read_feature(gdal, fid, path);
        if (!f || !f->GetGeometryRef()) return false;
        detail::add_segments(f->GetGeometryRef(), fid, path, items);
        return true;
      });
  if (!read) return std::nullopt;
  return items;
}

namespace detail {

using namespace shp;

ShapefilePolygons::ShapefilePolygons(const std::string& path, OGRLayer& layer)
    : path_(path), layer_(&layer) {
  // The rules followed are those of GDAL 3.6 (Debian 12's), checked against it by the tests;
  // other versions, and the options that change how GDAL sorts rings, leave it to GDAL.
  if (std::atoi(GDALVersionInfo("VERSION_NUM")) / 10000 != 306) return;
  if (CPLGetConfigOption("OGR_ORGANIZE_POLYGONS", nullptr) ||
      CPLTestBool(CPLGetConfigOption("OGR_DEBUG_ORGANIZE_POLYGONS", "NO")))
    return;
  auto f = RecordFiles::open(path);
  if (!f || f->file_type() != 5 || layer.GetFeatureCount(FALSE) != GIntBig(f->count())) return;
  srs_ = layer.GetSpatialRef();
  files_ = std::move(f);
}

ShapefilePolygons::~ShapefilePolygons() = default;

std::unique_ptr<OGRGeometry> ShapefilePolygons::read(std::int64_t fid) {
  if (!files_) return nullptr;
  const auto e = files_->entry(fid);  // none for a deleted record: GDAL has no such feature
  if (!e || e->length < 44) return nullptr;
  // Only the record's header first: most records are not several rings.
  const unsigned char* head = files_->content(*e, 44);
  if (!head || le32(head) != 5 || le32(head + 36) < 2) return nullptr;
  const unsigned char* c = files_->content(*e, e->length);
  if (!c) return nullptr;
  try {
    if (!read_record(c, e->length, 5, files_->path(), fid).ok) return nullptr;
  } catch (const Error&) {
    return nullptr;  // a bad coordinate: GDAL's geometry, as before
  }
  auto g = build_polygons(c);
  if (g && srs_) g->assignSpatialReference(srs_);
  return g;
}

OGRFeatureUniquePtr ShapefilePolygons::fetch(std::int64_t fid) {
  std::unique_ptr<OGRGeometry> g = read(fid);
  if (bool(g) != geometry_ignored_) {
    const char* no_geometry[] = {"OGR_GEOMETRY", nullptr};
    if (layer_->SetIgnoredFields(g ? no_geometry : nullptr) != OGRERR_NONE) g.reset();
    geometry_ignored_ = bool(g);
  }
  OGRFeatureUniquePtr f = read_feature(*layer_, fid, path_);
  if (f && g) f->SetGeometryDirectly(g.release());
  return f;
}

}  // namespace detail

}  // namespace loci::io