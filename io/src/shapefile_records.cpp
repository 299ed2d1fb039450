// The direct shapefile readers' GDAL-free part: see shapefile_records.hpp.
#include "shapefile_records.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <bit>
#include <cctype>
#include <cstdlib>

#include "layer_points.hpp"
#include "loci/index/packed_rtree.hpp"

namespace loci::io::detail::shp {

std::string sibling(const std::string& shp, const char* lower_ext, const char* upper_ext) {
  const std::string stem = shp.substr(0, shp.size() - 4);
  for (const char* ext : {lower_ext, upper_ext}) {
    struct stat st {};
    if (::stat((stem + ext).c_str(), &st) == 0 && S_ISREG(st.st_mode)) return stem + ext;
  }
  return {};
}

bool is_shp_path(const std::string& path) {
  if (path.size() < 5) return false;
  std::string ext = path.substr(path.size() - 4);
  for (char& c : ext)
    c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".shp";
}

Kind kind_of(std::uint32_t type) {
  switch (type) {
    case 1:
    case 11:
    case 21:
      return Kind::point;
    case 8:
    case 18:
    case 28:
      return Kind::multipoint;
    case 3:
    case 5:
    case 13:
    case 15:
    case 23:
    case 25:
      return Kind::polyline_or_polygon;
    default:
      return Kind::other;
  }
}

bool is_polygon_type(std::uint32_t type) {
  return type == 5 || type == 15 || type == 25;
}
bool has_z(std::uint32_t type) {
  return type == 11 || type == 13 || type == 15 || type == 18;
}
bool may_have_m(std::uint32_t type) {
  return has_z(type) || type == 21 || type == 23 || type == 25 || type == 28;
}

std::optional<ShapefileHeaders> shapefile_headers(ChunkReader& shp, ChunkReader& shx) {
  const unsigned char* sh = shx.get(0, 100);
  const unsigned char* ph = shp.get(0, 100);
  if (!sh || !ph || be32(sh) != 9994 || be32(ph) != 9994 || le32(sh + 28) != 1000 ||
      le32(ph + 28) != 1000 || le32(sh + 32) != le32(ph + 32))
    return std::nullopt;
  if (2 * std::uint64_t(be32(sh + 24)) != shx.size() || (shx.size() - 100) % 8 != 0)
    return std::nullopt;
  return ShapefileHeaders{le32(ph + 32), (shx.size() - 100) / 8};
}

std::optional<DbfLayout> dbf_layout(ChunkReader& dbf, std::uint64_t count) {
  const unsigned char* h = dbf.get(0, 32);
  if (!h || le32(h + 4) != count) return std::nullopt;
  const DbfLayout layout{le16(h + 8), le16(h + 10)};
  if (layout.record == 0 || layout.header < 32 ||
      dbf.size() < layout.header + count * layout.record)
    return std::nullopt;
  return layout;
}

bool plain_attributes(ChunkReader& dbf, std::uint64_t count) {
  if (!dbf.is_open()) return false;
  const auto layout = dbf_layout(dbf, count);
  if (!layout) return false;
  for (std::uint64_t i = 0; i < count; ++i) {
    const unsigned char* flag = layout->deletion_flag(dbf, i);
    if (!flag || *flag == '*') return false;
  }
  return true;
}

// Adds one record's points to `box`, refusing a bad coordinate as the GDAL path does. The
// loop keeps no branch per point (a NaN drops out of min and max, so range is tracked apart);
// the first bad point is looked for only when there is one.
void add_points(const unsigned char* xy, std::uint64_t n, Box2& box, const std::string& path,
                std::int64_t fid) {
  double lo[2] = {box.min[0], box.min[1]}, hi[2] = {box.max[0], box.max[1]};
  bool in_range = true;
#if defined(__SSE2__)
  // Each point is one (x, y) vector: min, max and the range test take one instruction each.
  // Four points at a time into four sets of accumulators, so that the minimum and maximum of
  // one point need not wait for those of the previous one.
  constexpr int kWays = 4;
  __m128d vlo[kWays], vhi[kWays], ok[kWays];
  for (int k = 0; k < kWays; ++k) {
    vlo[k] = _mm_loadu_pd(lo);
    vhi[k] = _mm_loadu_pd(hi);
    ok[k] = _mm_castsi128_pd(_mm_set1_epi32(-1));
  }
  const __m128d limit = _mm_set1_pd(kMaxCoordinate), sign = _mm_set1_pd(-0.0);
  const auto add = [&](int k, std::uint64_t i) {
    const __m128d p = _mm_loadu_pd(reinterpret_cast<const double*>(xy + 16 * i));
    ok[k] = _mm_and_pd(ok[k], _mm_cmple_pd(_mm_andnot_pd(sign, p), limit));
    vlo[k] = _mm_min_pd(p, vlo[k]);  // a NaN in p gives the second operand
    vhi[k] = _mm_max_pd(p, vhi[k]);
  };
  std::uint64_t i = 0;
  for (; i + kWays <= n; i += kWays)
    for (int k = 0; k < kWays; ++k)
      add(k, i + std::uint64_t(k));
  for (; i < n; ++i)
    add(0, i);
  for (int k = 1; k < kWays; ++k) {
    vlo[0] = _mm_min_pd(vlo[k], vlo[0]);
    vhi[0] = _mm_max_pd(vhi[k], vhi[0]);
    ok[0] = _mm_and_pd(ok[k], ok[0]);
  }
  _mm_storeu_pd(lo, vlo[0]);
  _mm_storeu_pd(hi, vhi[0]);
  in_range = _mm_movemask_pd(ok[0]) == 3;
#else
  for (std::uint64_t i = 0; i < n; ++i) {
    double p[2];
    std::memcpy(p, xy + 16 * i, sizeof p);
    for (int a = 0; a < 2; ++a) {
      in_range &= p[a] >= -kMaxCoordinate && p[a] <= kMaxCoordinate;
      lo[a] = p[a] < lo[a] ? p[a] : lo[a];
      hi[a] = p[a] > hi[a] ? p[a] : hi[a];
    }
  }
#endif
  if (!in_range) [[unlikely]]
    for (std::uint64_t i = 0; i < n; ++i) {
      const Point2 p{le_double(xy + 16 * i), le_double(xy + 16 * i + 8)};
      if (!within_coordinate_range(p)) detail::check_layer_point(p, detail::where(path, fid));
    }
  box = Box2{{lo[0], lo[1]}, {hi[0], hi[1]}};
}

RecordRead read_record(const unsigned char* c, std::uint64_t length, std::uint32_t file_type,
                       const std::string& path, std::int64_t fid) {
  RecordRead r;
  r.length = length;
  if (length < 4) return r;
  const std::uint32_t type = le32(c);
  if (type == 0) {
    r.ok = r.null = true;
    return r;
  }
  if (type != file_type) return r;
  // A record of a Z type must hold its Z values (GDAL takes one without them for corrupt); its
  // M values are optional, as for the M types.
  const std::uint64_t z_point = has_z(type) ? 8 : 0;
  switch (kind_of(type)) {
    case Kind::point:
      if (length < 20 + z_point) return r;
      add_points(c + 4, 1, r.box, path, fid);
      r.segments = 1;  // an isolated point is one zero-length segment
      break;
    case Kind::multipoint: {
      if (length < 40) return r;
      const std::uint64_t n = le32(c + 36);
      if (n == 0 || n > kMaxPoints || n > (length - 40) / 16 ||
          40 + 16 * n + (z_point ? 16 + 8 * n : 0) > length)
        return r;
      add_points(c + 40, n, r.box, path, fid);
      r.segments = n;
      break;
    }
    case Kind::polyline_or_polygon: {
      if (length < 44) return r;
      const std::uint64_t parts = le32(c + 36), n = le32(c + 40);
      if (parts == 0 || n == 0 || parts > n || n > kMaxPoints || parts > kMaxParts ||
          44 + 4 * parts + 16 * n + (z_point ? 16 + 8 * n : 0) > length)
        return r;
      // Parts start at 0 and each holds at least one point.
      // A part of one point counts as one segment (of length zero), the others one fewer
      // than their points.
      std::uint64_t previous = 0, single = 0;
      for (std::uint64_t i = 0; i < parts; ++i) {
        const std::uint64_t start = le32(c + 44 + 4 * i);
        if ((i == 0 && start != 0) || (i > 0 && start <= previous) || start >= n) return r;
        single += i > 0 && start - previous == 1;
        previous = start;
      }
      single += n - previous == 1;
      add_points(c + 44 + 4 * parts, n, r.box, path, fid);
      r.segments = n - parts + single;
      break;
    }
    case Kind::other:
      return r;
  }
  check_box(r.box, detail::where(path, fid).c_str());
  r.ok = true;
  return r;
}

bool uses_measures(const unsigned char* c, std::uint64_t length, std::uint32_t type) {
  if (!may_have_m(type)) return false;
  const std::uint64_t z_point = has_z(type) ? 8 : 0;
  std::uint64_t n = 1, m_at = 20 + z_point;  // a point: its M right after x, y (and z)
  if (kind_of(type) != Kind::point) {
    n = le32(c + (kind_of(type) == Kind::multipoint ? 36 : 40));
    const std::uint64_t xy = kind_of(type) == Kind::multipoint ? 40 : 44 + 4 * le32(c + 36);
    // after the points (and the Z range and values): the M range, then the values
    m_at = xy + 16 * n + (z_point ? 16 + 8 * n : 0) + 16;
  }
  if (m_at + 8 * n > length) return false;
  for (std::uint64_t i = 0; i < n; ++i)
    if (le_double(c + m_at + 8 * i) > -1e38) return true;
  return false;
}

bool add_record_segments(const unsigned char* c, std::uint32_t file_type, std::int64_t fid,
                         LayerItems& out) {
  const auto point = [](const unsigned char* xy) {
    return Point2{le_double(xy), le_double(xy + 8)};
  };
  const auto add_point = [&](const unsigned char* xy, std::int32_t part) {
    out.boxes.push_back(Box2::of_point(point(xy)));
    out.records.push_back({fid, part, 0u});
  };
  switch (kind_of(file_type)) {
    case Kind::point:
      add_point(c + 4, 0);
      break;
    case Kind::multipoint:
      for (std::uint32_t i = 0, n = le32(c + 36); i < n; ++i)
        add_point(c + 40 + 16 * std::uint64_t(i), std::int32_t(i));
      break;
    case Kind::polyline_or_polygon: {
      const std::uint32_t parts = le32(c + 36), n = le32(c + 40);
      const bool ring = is_polygon_type(file_type);
      // The polygon each ring bounds, as the driver sorts the rings.
      static thread_local std::vector<std::uint32_t> polygon;
      polygon.assign(parts, 0);
      if (ring && parts > 1 && !ring_polygons(c, polygon)) return false;
      const unsigned char* xy = c + 44 + 4 * std::uint64_t(parts);
      for (std::uint32_t k = 0; k < parts; ++k) {
        const std::uint32_t begin = le32(c + 44 + 4 * std::uint64_t(k)),
                            end = k + 1 < parts ? le32(c + 48 + 4 * std::uint64_t(k)) : n;
        Point2 a = point(xy + 16 * std::uint64_t(begin));
        if (end - begin == 1) {  // a part of one point is that point
          out.boxes.push_back(Box2::of_point(a));
          out.records.push_back({fid, std::int32_t(k), segment_flags(a, a, ring, polygon[k])});
        }
        for (std::uint32_t i = begin + 1; i < end; ++i) {
          const Point2 b = point(xy + 16 * std::uint64_t(i));
          out.boxes.push_back(Segment2{a, b}.box());
          out.records.push_back({fid, std::int32_t(k), segment_flags(a, b, ring, polygon[k])});
          a = b;
        }
        // A ring that does not end where it starts is closed, as GDAL builds it.
        const Point2 first = point(xy + 16 * std::uint64_t(begin));
        if (ring && end - begin > 1 && !(a == first)) {
          out.boxes.push_back(Segment2{a, first}.box());
          out.records.push_back({fid, std::int32_t(k), segment_flags(a, first, ring, polygon[k])});
        }
      }
      break;
    }
    case Kind::other:
      break;
  }
  return true;
}

// A ring prepared for exact point location (the geometry outlives its preparation).
struct PreparedRing {
  explicit PreparedRing(FlatGeometry g) : ring(std::move(g)), prepared(ring) {}
  FlatGeometry ring;
  PreparedGeometry prepared;
};

std::vector<std::int8_t> orientations(const PolygonRings& r) {
  std::vector<std::int8_t> cw(r.parts);
  for (std::uint32_t k = 0; k < r.parts; ++k)
    cw[k] = std::int8_t(r.clockwise(k));
  return cw;
}

const char* polygon_type(const PolygonRings& r, const std::vector<std::int8_t>& cw) {
  std::uint32_t outer = 0, outers = 0;
  for (std::uint32_t k = 0; k < r.parts; ++k) {
    if (cw[k] < 0) return nullptr;
    if (cw[k]) outer = k, ++outers;
  }
  if (outers == 0) return nullptr;
  if (outers > 1) return "Multi Polygon";
  // Each hole's first point strictly inside the outer ring, located exactly through the
  // ring prepared once (linear in the points, however many holes).
  const PreparedRing prepared(r.ring(outer));
  for (std::uint32_t k = 0; k < r.parts; ++k)
    if (k != outer && prepared.prepared.locate(r.point(r.range(k).first)) != Location::inside)
      return nullptr;
  return "Polygon";
}

const char* polygon_type(const unsigned char* c) {
  const PolygonRings r(c);
  return polygon_type(r, orientations(r));
}

std::optional<Organized> organize(const PolygonRings& r, const std::vector<std::int8_t>& cw) {
  std::vector<std::uint32_t> outers;
  for (std::uint32_t k = 0; k < r.parts; ++k) {
    if (cw[k] < 0) return std::nullopt;
    if (cw[k]) outers.push_back(k);
  }
  if (outers.empty() || r.parts < 2) return std::nullopt;
  Organized out;
  // Where p lies in an outer ring, as GDAL's own predicates place it; each costs a pass over
  // the ring, as in GDAL, but only the candidates GDAL itself would test are tested.
  const auto at = [&](std::uint32_t outer, const Point2& p) {
    return gdal_ring_location(r, outer, p);
  };
  // Where hole k lies for GDAL: where its first point lies in the outer ring; when that is
  // on the ring, where the first of its next points off the ring lies (repeats skipped), and
  // when all are on it, the first midpoint of its edges off it; outside if none is.
  const auto locate = [&](std::uint32_t outer, std::uint32_t k) {
    const auto [begin, end] = r.range(k);
    const Location first = at(outer, r.point(begin));
    if (first != Location::boundary) return first;
    Point2 previous = r.point(begin);
    for (std::uint32_t i = begin + 1; i < end; ++i) {
      const Point2 p = r.point(i);
      if (p == previous) continue;
      if (const Location l = at(outer, p); l != Location::boundary) return l;
      previous = p;
    }
    previous = r.point(begin);
    for (std::uint32_t i = begin + 1; i < end; ++i) {
      const Point2 p = r.point(i);
      if (p == previous) continue;
      const Point2 middle{(p[0] + previous[0]) / 2, (p[1] + previous[1]) / 2};
      if (const Location l = at(outer, middle); l != Location::boundary) return l;
      previous = p;
    }
    return Location::outside;
  };
  std::vector<std::uint32_t>& owner = out.owner;  // the outer ring of each hole
  std::vector<std::uint32_t>& top = out.top;      // the rings that start a polygon
  owner.assign(r.parts, kNone);
  top = outers;
  if (outers.size() == 1) {
    // GDAL makes every other ring a hole of the one outer ring (later versions test them):
    // taken here when each starts inside it, where all versions agree.
    for (std::uint32_t k = 0; k < r.parts; ++k) {
      if (k == outers[0]) continue;
      if (at(outers[0], r.point(r.range(k).first)) != Location::inside) return std::nullopt;
      owner[k] = outers[0];
    }
  } else {
    std::vector<double> area(r.parts);
    std::vector<Box2> envelope(r.parts);
    std::uint32_t largest = 0;  // GDAL's first ring after sorting by area
    for (std::uint32_t k = 0; k < r.parts; ++k) {
      area[k] = r.gdal_area(k);
      envelope[k] = r.envelope(k);
      if (area[k] > area[largest]) largest = k;
    }
    for (std::uint32_t k = 0; k < r.parts; ++k)
      if (k != largest && area[k] == area[largest]) return std::nullopt;  // GDAL's order unknown
    std::vector<Box2> outer_boxes;
    outer_boxes.reserve(outers.size());
    for (const std::uint32_t k : outers)
      outer_boxes.push_back(envelope[k]);
    const PackedRTree2 tree = PackedRTree2::build(outer_boxes);
    std::vector<std::uint32_t> candidates;
    for (std::uint32_t k = 0; k < r.parts; ++k) {
      if (cw[k]) continue;
      candidates.clear();
      bool tie = false;
      tree.query(
          envelope[k],
          [&](Id i, const Box2&) {
            const std::uint32_t o = outers[i];
            if (area[o] == area[k]) tie = true;
            if (area[o] > area[k]) candidates.push_back(o);
            return true;
          },
          Relation::contains);
      if (tie) return std::nullopt;
      std::sort(candidates.begin(), candidates.end(),
                [&](std::uint32_t a, std::uint32_t b) { return area[a] < area[b]; });
      for (std::size_t j = 0; j < candidates.size() && owner[k] == kNone; ++j) {
        const std::uint32_t o = candidates[j];
        if (j + 1 < candidates.size() && area[candidates[j + 1]] == area[o]) return std::nullopt;
        // GDAL takes the largest ring of all on its envelope alone.
        if (o == largest || locate(o, k) == Location::inside) owner[k] = o;
      }
      // Held by no outer ring: a polygon of its own (outer ring counter-clockwise).
      if (owner[k] == kNone) top.push_back(k);
    }
  }
  return out;
}

bool ring_polygons(const unsigned char* c, std::vector<std::uint32_t>& polygon) {
  const PolygonRings r(c);
  return ring_polygons(r, orientations(r), polygon);
}

bool ring_polygons(const PolygonRings& r, const std::vector<std::int8_t>& cw,
                   std::vector<std::uint32_t>& polygon) {
  polygon.assign(r.parts, 0);
  if (std::all_of(cw.begin(), cw.end(), [](std::int8_t o) { return o == 1; })) {
    for (std::uint32_t k = 0; k < r.parts; ++k)
      polygon[k] = k;
    return true;
  }
  if (const char* type = polygon_type(r, cw); type && std::strcmp(type, "Polygon") == 0)
    return true;  // one outer ring holding all the others
  const auto organized = organize(r, cw);
  if (!organized) return false;
  std::uint32_t next = 0;
  for (std::uint32_t k = 0; k < r.parts; ++k)
    if (organized->owner[k] == kNone) polygon[k] = next++;
  for (std::uint32_t k = 0; k < r.parts; ++k)
    if (organized->owner[k] != kNone) polygon[k] = polygon[organized->owner[k]];
  return true;
}

Location gdal_ring_location(const PolygonRings& r, std::uint32_t k, const Point2& p) {
  const auto [begin, end] = r.range(k);
  // The boundary test: p on the segment from point i - 1 to point i when the cross product of
  // their offsets from p is zero and p projects within the segment.
  double prev_dx = p[0] - r.x(begin), prev_dy = p[1] - r.y(begin);
  for (std::uint32_t i = begin + 1; i < end; ++i) {
    const double dx = p[0] - r.x(i), dy = p[1] - r.y(i);
    if (dx * prev_dy - prev_dx * dy == 0 && !(dx == prev_dx && dy == prev_dy)) {
      const double sx = r.x(i) - r.x(i - 1), sy = r.y(i) - r.y(i - 1);
      const double along = prev_dx * sx + prev_dy * sy;
      if (along >= 0 && along <= sx * sx + sy * sy) return Location::boundary;
    }
    prev_dx = dx;
    prev_dy = dy;
  }
  // The crossing test: a ray from p towards +x, each segment that straddles p's y (one end
  // strictly above, the other not) counted when it crosses the ray beyond p.
  int crossings = 0;
  prev_dx = r.x(begin) - p[0];
  prev_dy = r.y(begin) - p[1];
  for (std::uint32_t i = begin + 1; i < end; ++i) {
    const double dx = r.x(i) - p[0], dy = r.y(i) - p[1];
    if ((dy > 0 && prev_dy <= 0) || (prev_dy > 0 && dy <= 0)) {
      const double at = (dx * prev_dy - prev_dx * dy) / (prev_dy - dy);
      if (0.0 < at) ++crossings;
    }
    prev_dx = dx;
    prev_dy = dy;
  }
  return crossings % 2 ? Location::inside : Location::outside;
}

RecordFiles::RecordFiles(const std::string& shp, const std::string& shx, const std::string& dbf)
    : path_(shp),
      shx_(shx, nullptr, 4096),
      shp_(shp, nullptr, 64u << 10),
      dbf_(dbf, nullptr, 512) {}

std::unique_ptr<RecordFiles> RecordFiles::open(const std::string& path) {
  if constexpr (std::endian::native != std::endian::little) return nullptr;
  if (!is_shp_path(path)) return nullptr;
  const std::string shx = sibling(path, ".shx", ".SHX"), dbf = sibling(path, ".dbf", ".DBF");
  if (shx.empty() || dbf.empty()) return nullptr;
  std::unique_ptr<RecordFiles> f(new RecordFiles(path, shx, dbf));
  if (!f->shx_.is_open() || !f->shp_.is_open() || !f->dbf_.is_open()) return nullptr;
  const auto headers = shapefile_headers(f->shp_, f->shx_);
  if (!headers || kind_of(headers->file_type) == Kind::other) return nullptr;
  f->file_type_ = headers->file_type;
  f->count_ = headers->count;
  // The .dbf's header only: opening costs the same however big the files (each read checks
  // its record's deletion flag).
  const auto layout = dbf_layout(f->dbf_, f->count_);
  if (!layout) return nullptr;
  f->dbf_layout_ = *layout;
  return f;
}

std::optional<RecordFiles::Entry> RecordFiles::entry(std::int64_t fid) {
  if (fid < 0 || std::uint64_t(fid) >= count_) return std::nullopt;
  const unsigned char* deleted = dbf_layout_.deletion_flag(dbf_, std::uint64_t(fid));
  if (!deleted || *deleted == '*') return std::nullopt;
  const unsigned char* e = shx_.get(100 + 8 * std::uint64_t(fid), 8);
  if (!e) return std::nullopt;
  const Entry out{2 * std::uint64_t(be32(e)), 2 * std::uint64_t(be32(e + 4))};
  if (out.offset < 100) return std::nullopt;
  return out;
}

const unsigned char* RecordFiles::content(const Entry& e, std::uint64_t bytes) {
  const unsigned char* record = shp_.get(e.offset, 8 + std::min(bytes, e.length));
  if (!record || 2 * std::uint64_t(be32(record + 4)) != e.length) return nullptr;
  return record + 8;
}

ShapefileFeatures::ShapefileFeatures(const std::string& path) {
#if defined(LOCI_GDAL_SHAPEFILE_RULES)
  // The options that change how GDAL sorts rings, whatever their value: then GDAL reads.
  if (std::getenv("OGR_ORGANIZE_POLYGONS") || std::getenv("OGR_DEBUG_ORGANIZE_POLYGONS")) return;
  files_ = RecordFiles::open(path);
#else
  (void)path;  // built with a GDAL whose rules this reader does not follow
#endif
}

ShapefileFeatures::~ShapefileFeatures() = default;

std::optional<FlatGeometry> ShapefileFeatures::read(std::int64_t fid) {
  if (!files_) return std::nullopt;
  RecordFiles& f = *files_;
  const auto e = f.entry(fid);
  if (!e) return std::nullopt;
  const std::uint64_t length = e->length;
  const unsigned char* c = f.content(*e, length);
  if (!c) return std::nullopt;
  RecordRead read;
  try {
    read = read_record(c, length, f.file_type(), f.path(), fid);
  } catch (const Error&) {
    return std::nullopt;  // a bad coordinate: GDAL's path says so
  }
  FlatGeometry g;
  if (!read.ok) return std::nullopt;
  if (read.null) return g;  // a feature without geometry
  const auto point = [](const unsigned char* xy) {
    return Point2{le_double(xy), le_double(xy + 8)};
  };
  const auto add_part = [&](std::uint32_t begin, std::uint32_t end, PartKind kind,
                            std::uint32_t polygon, const unsigned char* xy) {
    const auto at = std::uint32_t(g.points.size());
    for (std::uint32_t i = begin; i < end; ++i)
      g.points.push_back(point(xy + 16 * std::uint64_t(i)));
    g.parts.push_back({at, std::uint32_t(g.points.size()), kind, polygon});
  };
  switch (kind_of(f.file_type())) {
    case Kind::point:
      add_part(0, 1, PartKind::point, 0, c + 4);
      return g;
    case Kind::multipoint:
      for (std::uint32_t i = 0, n = le32(c + 36); i < n; ++i)
        add_part(i, i + 1, PartKind::point, 0, c + 40);
      return g;
    case Kind::polyline_or_polygon:
      break;
    case Kind::other:
      return std::nullopt;
  }
  const PolygonRings r(c);
  if (!is_polygon_type(f.file_type())) {
    for (std::uint32_t k = 0; k < r.parts; ++k)
      add_part(r.range(k).first, r.range(k).second, PartKind::line, 0, r.xy);
    return g;
  }
  // Rings GDAL builds otherwise (closing them, or sorting them some other way) are left to it.
  const std::vector<std::int8_t> cw = orientations(r);
  if (std::any_of(cw.begin(), cw.end(), [](std::int8_t o) { return o < 0; })) return std::nullopt;
  std::vector<std::uint32_t> polygon(r.parts, 0);
  if (r.parts > 1 && !ring_polygons(r, cw, polygon)) return std::nullopt;
  // GDAL's order: the polygons as numbered, each its outer ring (its clockwise ring, or its
  // only ring) first, then its holes in the record's order.
  g.polygons = r.parts == 0 ? 0 : *std::max_element(polygon.begin(), polygon.end()) + 1;
  std::vector<std::uint32_t> order(r.parts);
  for (std::uint32_t k = 0; k < r.parts; ++k)
    order[k] = k;
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    if (polygon[a] != polygon[b]) return polygon[a] < polygon[b];
    return cw[a] > cw[b];
  });
  for (const std::uint32_t k : order)
    add_part(r.range(k).first, r.range(k).second, PartKind::ring, polygon[k], r.xy);
  return g;
}

}  // namespace loci::io::detail::shp
