// Per-feature boxes straight from a shapefile's .shx and .shp: see shapefile_boxes.hpp.
#include "loci/io/shapefile_boxes.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <map>
#include <optional>
#include <vector>

#include <cpl_conv.h>

#include "gdal_layer.hpp"
#include "loci/geom/error.hpp"
#include "loci/index/packed_rtree.hpp"
#include "loci/io/exact.hpp"
#include "shapefile_polygons.hpp"

namespace loci::io {

namespace {

std::uint32_t be32(const unsigned char* p) {
  return std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[2]) << 8 | p[3];
}
std::uint32_t le32(const unsigned char* p) {
  return std::uint32_t(p[3]) << 24 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[1]) << 8 | p[0];
}
std::uint32_t le16(const unsigned char* p) {
  return std::uint32_t(p[1]) << 8 | p[0];
}
// The shapefile's doubles are little-endian; the caller checked the host is too.
double le_double(const unsigned char* p) {
  double d;
  std::memcpy(&d, p, sizeof d);
  return d;
}

// A file read forward in large chunks: get(offset, n) gives n bytes that stay valid until the
// next call. Records in file order read each byte once; any order stays correct.
class ChunkReader {
 public:
  // With `hash`, the bytes read are hashed as they pass, as long as each read starts within
  // what was read before (records in file order); hash_rest() then reads and hashes the rest.
  // `chunk`: how much a read that misses fetches (small for reads in random order).
  explicit ChunkReader(const std::string& path, StreamHash* hash = nullptr,
                       std::uint64_t chunk = kChunk)
      : path_(path), hash_(hash), chunk_(chunk) {
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd_ < 0) return;
    struct stat st {};
    if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) {
      ::close(fd_);
      fd_ = -1;
      return;
    }
    size_ = std::uint64_t(st.st_size);
  }
  ~ChunkReader() {
    if (fd_ >= 0) ::close(fd_);
  }
  ChunkReader(const ChunkReader&) = delete;
  ChunkReader& operator=(const ChunkReader&) = delete;

  bool is_open() const { return fd_ >= 0; }
  std::uint64_t size() const { return size_; }

  // Nullptr when [offset, offset + n) runs past the end of the file.
  const unsigned char* get(std::uint64_t offset, std::uint64_t n) {
    if (offset > size_ || n > size_ - offset) return nullptr;
    if (offset >= at_ && offset + n <= at_ + held_) return buffer_.data() + (offset - at_);
    // A read less than a chunk past what was hashed starts there (the .dbf's deletion marks,
    // a byte a record): the hash stays whole and the file is read once.
    const bool fill = hash_ && hashed_ != kBroken && offset > hashed_ && offset - hashed_ < chunk_;
    const std::uint64_t start = fill ? hashed_ : offset, skip = offset - start;
    const std::uint64_t want = std::min(size_ - start, std::max<std::uint64_t>(skip + n, chunk_));
    if (buffer_.size() < want) buffer_.resize(want);
    std::uint64_t done = 0;
    while (done < want) {
      const ssize_t r = ::pread(fd_, buffer_.data() + done, want - done, off_t(start + done));
      if (r < 0 && errno == EINTR) continue;
      if (r < 0) throw Error(path_ + ": cannot read (" + std::strerror(errno) + ")");
      if (r == 0) break;  // shrunk while read: the caller sees too few bytes
      done += std::uint64_t(r);
    }
    at_ = start;
    held_ = done;
    if (hash_ && hashed_ != kBroken) {
      if (start > hashed_) {
        hashed_ = kBroken;  // a gap: the hash needs a pass of its own
      } else if (start + done > hashed_) {
        hash_->update(buffer_.data() + (hashed_ - start), start + done - hashed_);
        hashed_ = start + done;
      }
    }
    return done >= skip + n ? buffer_.data() + skip : nullptr;
  }

  // Reads what no get() reached; false when the bytes did not pass in order.
  bool hash_rest() {
    while (hashed_ != kBroken && hashed_ < size_)
      if (!get(hashed_, std::min(kChunk, size_ - hashed_))) return false;
    return hash_ && hashed_ == size_;
  }

 private:
  static constexpr std::uint64_t kChunk = 256u << 10;
  static constexpr std::uint64_t kBroken = ~std::uint64_t(0);
  std::string path_;
  StreamHash* hash_;
  std::uint64_t chunk_;
  std::uint64_t hashed_ = 0;
  int fd_ = -1;
  std::uint64_t size_ = 0;
  std::vector<unsigned char> buffer_;
  std::uint64_t at_ = 0, held_ = 0;
};

// The sibling of a .shp with another extension, in either case as shapefile writers do.
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

enum class Kind { point, multipoint, polyline_or_polygon, other };

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

// The .shp and .shx headers of one shapefile checked against each other (file codes, version,
// the same shape type, an .shx of whole entries): its shape type and record count, or nullopt.
struct ShapefileHeaders {
  std::uint32_t file_type;
  std::uint64_t count;
};
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

// Where the records of a .dbf lie, from its header, when it holds exactly `count` of them.
struct DbfLayout {
  std::uint64_t header, record;  // header and record lengths
  const unsigned char* deletion_flag(ChunkReader& dbf, std::uint64_t i) const {
    return dbf.get(header + i * record, 1);
  }
};
std::optional<DbfLayout> dbf_layout(ChunkReader& dbf, std::uint64_t count) {
  const unsigned char* h = dbf.get(0, 32);
  if (!h || le32(h + 4) != count) return std::nullopt;
  const DbfLayout layout{le16(h + 8), le16(h + 10)};
  if (layout.record == 0 || layout.header < 32 ||
      dbf.size() < layout.header + count * layout.record)
    return std::nullopt;
  return layout;
}

// Whether the .dbf holds exactly `count` records, none deleted.
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

// A record's contribution: its box and its segments, or nothing for a null shape.
struct RecordRead {
  bool ok = false;    // false: hand the file to GDAL
  bool null = false;  // a null shape: no geometry
  Box2 box = Box2::empty();
  std::uint64_t segments = 0;
  std::uint64_t length = 0;  // of the record's content, in bytes
};

// Shapelib, inside GDAL, takes a record of more points or parts than these for a corrupt one.
constexpr std::uint64_t kMaxPoints = 50'000'000, kMaxParts = 10'000'000;

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

// Whether a record that read_record took (not null) carries M values and one of them is above
// -1e38, below which shapefiles write "no data": what GDAL looks for in a layer's first record
// to give the layer, and so every geometry of it, measures.
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

bool ring_polygons(const unsigned char* c, std::vector<std::uint32_t>& polygon);

// A record's segments, as a per-segment read through GDAL gives them: each line or ring's
// consecutive points (parts numbered in file order), each point of a point or multipoint
// shape, and a part of one point, as a zero-length segment; a ring's segments with the number
// of the polygon it bounds. The record was read and checked by read_record. False, with
// nothing added, for a polygon record whose rings only GDAL sorts (ring_polygons).

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
      }
      break;
    }
    case Kind::other:
      break;
  }
  return true;
}

// The rings of a polygon record (read and checked by read_record): ring k runs over points
// [range(k).first, range(k).second).
struct PolygonRings {
  explicit PolygonRings(const unsigned char* content)
      : c(content), parts(le32(c + 36)), n(le32(c + 40)), xy(c + 44 + 4 * std::uint64_t(parts)) {}
  std::pair<std::uint32_t, std::uint32_t> range(std::uint32_t k) const {
    return {le32(c + 44 + 4 * std::uint64_t(k)),
            k + 1 < parts ? le32(c + 48 + 4 * std::uint64_t(k)) : n};
  }
  double x(std::uint32_t i) const { return le_double(xy + 16 * std::uint64_t(i)); }
  double y(std::uint32_t i) const { return le_double(xy + 16 * std::uint64_t(i) + 8); }
  Point2 point(std::uint32_t i) const { return {x(i), y(i)}; }

  // Ring k's orientation as GDAL decides it: by the turn at its lowest rightmost vertex, or
  // by the sign of GDAL's area sum when that vertex is there twice or has a neighbour within
  // 1e-5.
  // 1 clockwise, 0 counter-clockwise, -1 for a ring GDAL places otherwise: fewer than 4
  // points, unclosed, or of zero area.
  int clockwise(std::uint32_t k) const {
    const auto [begin, end] = range(k);
    if (end - begin < 4 || x(begin) != x(end - 1) || y(begin) != y(end - 1)) return -1;
    // Twice the signed area (shoelace), relative to the ring's first point for precision.
    double area = 0;
    for (std::uint32_t i = begin + 1; i + 1 < end; ++i)
      area += (x(i) - x(begin)) * (y(i + 1) - y(begin)) - (x(i + 1) - x(begin)) * (y(i) - y(begin));
    if (!(area != 0)) return -1;
    std::uint32_t v = begin;
    bool twice = false;
    for (std::uint32_t i = begin + 1; i + 1 < end; ++i) {
      if (y(i) < y(v) || (y(i) == y(v) && x(i) > x(v)))
        v = i, twice = false;
      else if (y(i) == y(v) && x(i) == x(v))
        twice = true;
    }
    const std::uint32_t prev = v == begin ? end - 2 : v - 1, next = v + 2 == end ? begin : v + 1;
    const double turn = (x(v) - x(prev)) * (y(next) - y(v)) - (y(v) - y(prev)) * (x(next) - x(v));
    const auto near = [&](std::uint32_t i) {
      return std::abs(x(i) - x(v)) < 1e-5 && std::abs(y(i) - y(v)) < 1e-5;
    };
    const bool by_area = twice || near(prev) || near(next) || !(turn != 0);
    return (by_area ? green_sum(k) < 0 : turn < 0) ? 1 : 0;
  }

  // Twice ring k's signed area as GDAL sums it (Green's theorem, in GDAL's order): its area
  // ranks rings, its sign decides the orientation when the turn cannot.
  double green_sum(std::uint32_t k) const {
    const auto [begin, end] = range(k);
    double sum = x(begin) * (y(begin + 1) - y(end - 1));
    for (std::uint32_t i = begin + 1; i + 1 < end; ++i)
      sum += x(i) * (y(i + 1) - y(i - 1));
    sum += x(end - 1) * (y(begin) - y(end - 2));
    return sum;
  }

  // Ring k's area as GDAL computes it (Green's theorem, the same sum in the same order), by
  // which it ranks the rings that may hold a hole.
  double gdal_area(std::uint32_t k) const { return 0.5 * std::fabs(green_sum(k)); }

  Box2 envelope(std::uint32_t k) const {
    const auto [begin, end] = range(k);
    Box2 b = Box2::empty();
    for (std::uint32_t i = begin; i < end; ++i)
      b.expand(point(i));
    return b;
  }

  // Ring k alone, for exact point location.
  FlatGeometry ring(std::uint32_t k) const {
    const auto [begin, end] = range(k);
    FlatGeometry g;
    g.points.reserve(end - begin);
    for (std::uint32_t i = begin; i < end; ++i)
      g.points.push_back(point(i));
    g.parts.push_back({0, end - begin, PartKind::ring, 0});
    g.polygons = 1;
    return g;
  }

  const unsigned char* c;
  std::uint32_t parts, n;
  const unsigned char* xy;
};

// A ring prepared for exact point location (the geometry outlives its preparation).
struct PreparedRing {
  explicit PreparedRing(FlatGeometry g) : ring(std::move(g)), prepared(ring) {}
  FlatGeometry ring;
  PreparedGeometry prepared;
};

// GDAL's type for a polygon record of several rings (read and checked by read_record), from
// the orientation of its rings: "Polygon" when exactly one runs clockwise (the outer ring)
// and every other ring's first point lies inside it, "Multi Polygon" when more run clockwise.
// nullptr, for GDAL to answer, whenever a record is unusual: a ring orientation cannot place
// (PolygonRings::clockwise), no clockwise ring, or a hole not plainly inside the outer ring
// (GDAL versions differ there).
// Each ring's PolygonRings::clockwise().
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

// Ring k of r as an OGR ring, made the first time it is asked for.
OGRLinearRing& ogr_ring(const PolygonRings& r, std::vector<std::unique_ptr<OGRLinearRing>>& rings,
                        std::uint32_t k) {
  if (!rings[k]) {
    const auto [begin, end] = r.range(k);
    rings[k] = std::make_unique<OGRLinearRing>();
    rings[k]->setNumPoints(int(end - begin), FALSE);
    for (std::uint32_t i = begin; i < end; ++i)
      rings[k]->setPoint(int(i - begin), r.x(i), r.y(i));
  }
  return *rings[k];
}

// The polygons GDAL's shapefile driver makes of a 2D polygon record of several rings (read
// and checked by read_record), sorted without its all-against-all tests of rings. The
// driver sorts with organizePolygons' ONLY_CCW method: clockwise rings are outer rings, each
// counter-clockwise ring (a hole) goes to the smallest (by GDAL's area) clockwise ring of
// larger area whose envelope holds the hole's and which holds the hole's first point (when
// that lies on the ring, the first of its points, then of its edges' midpoints, off it); the
// polygons keep the order of their outer rings, the holes their order in the record. Here
// the candidates come from a packed R-tree of the outer rings' envelopes and are tested as
// GDAL tests them, so a record of thousands of islands and lakes no longer costs holes times
// rings. Nothing, for GDAL to sort them, whenever the record is
// not plain: a ring orientation cannot place, no outer ring, a tie in area, a hole not
// starting strictly inside the one outer ring (GDAL versions differ there; GDAL needs no
// sorting then). As in GDAL, the largest ring of all, when clockwise, holds every hole inside
// its envelope that no smaller outer ring holds, and a counter-clockwise ring no outer ring
// holds is a polygon of its own.
struct Organized {
  std::vector<std::uint32_t> owner;  // per ring: a hole's outer ring, kNone for others
  std::vector<std::uint32_t> top;    // the rings that start a polygon, in any order
  std::vector<std::unique_ptr<OGRLinearRing>> rings;  // as OGR rings: those made to test
};

// `cw`: the rings' orientations().
std::optional<Organized> organize(const PolygonRings& r, const std::vector<std::int8_t>& cw) {
  std::vector<std::uint32_t> outers;
  for (std::uint32_t k = 0; k < r.parts; ++k) {
    if (cw[k] < 0) return std::nullopt;
    if (cw[k]) outers.push_back(k);
  }
  if (outers.empty() || r.parts < 2) return std::nullopt;
  // The rings as OGR rings, made once: tested below, then handed to the polygons.
  Organized out;
  std::vector<std::unique_ptr<OGRLinearRing>>& rings = out.rings;
  rings.resize(r.parts);
  const auto ring = [&](std::uint32_t k) -> OGRLinearRing& { return ogr_ring(r, rings, k); };
  // Where p lies in an outer ring, decided by GDAL's own predicates on the ring (its boundary
  // test, then its crossing test), so that a point on or within rounding of an edge goes where
  // GDAL puts it; each costs a pass over the ring, as in GDAL, but only the candidates GDAL
  // itself would test are tested.
  const auto at = [&](std::uint32_t outer, const Point2& p) {
    OGRPoint point(p[0], p[1]);
    const OGRLinearRing& o = ring(outer);
    if (o.isPointOnRingBoundary(&point, FALSE)) return Location::boundary;
    return o.isPointInRing(&point, FALSE) ? Location::inside : Location::outside;
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

// The polygon each ring of a polygon record of several rings bounds, as the driver sorts the
// rings and numbers the polygons (in the order of their outer rings): its clockwise rings are
// outer rings, its counterclockwise ones holes of the outer ring holding them, or polygons of
// their own where none does. False, for GDAL to read the record, when organize() leaves the
// sorting to GDAL, unless every ring runs clockwise.
bool ring_polygons(const unsigned char* c, std::vector<std::uint32_t>& polygon) {
  const PolygonRings r(c);
  const std::vector<std::int8_t> cw = orientations(r);
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

// The geometry of organize()'s polygons.
std::unique_ptr<OGRGeometry> build_polygons(const unsigned char* c) {
  const PolygonRings r(c);
  auto organized = organize(r, orientations(r));
  if (!organized) return nullptr;
  const std::vector<std::uint32_t>& owner = organized->owner;
  std::vector<std::uint32_t>& top = organized->top;
  std::vector<std::unique_ptr<OGRLinearRing>>& rings = organized->rings;
  const auto ring = [&](std::uint32_t k) { ogr_ring(r, rings, k); };
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
    ring(outer);
    p->addRingDirectly(rings[outer].release());
    for (std::uint32_t k = head[outer]; k != kNone; k = next[k]) {
      ring(k);
      p->addRingDirectly(rings[k].release());
    }
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
        const OGRFeatureUniquePtr f(gdal.GetFeature(fid));
        if (!f || !f->GetGeometryRef()) return false;
        detail::add_segments(f->GetGeometryRef(), fid, path, items);
        return true;
      });
  if (!read) return std::nullopt;
  return items;
}

namespace detail {

struct ShapefilePolygons::Files {
  Files(const std::string& shp_path, const std::string& shx_path, const std::string& dbf_path)
      : path(shp_path),
        shx(shx_path, nullptr, 4096),
        shp(shp_path, nullptr, 64u << 10),
        dbf(dbf_path, nullptr, 512) {}
  std::string path;
  ChunkReader shx, shp, dbf;
  std::uint64_t count = 0;
  DbfLayout dbf_layout{};
};

ShapefilePolygons::ShapefilePolygons(const std::string& path, OGRLayer& layer) : layer_(&layer) {
  if constexpr (std::endian::native != std::endian::little) return;
  // The rules followed are those of GDAL 3.6 (Debian 12's), checked against it by the tests;
  // other versions, and the options that change how GDAL sorts rings, leave it to GDAL.
  if (std::atoi(GDALVersionInfo("VERSION_NUM")) / 10000 != 306) return;
  if (CPLGetConfigOption("OGR_ORGANIZE_POLYGONS", nullptr) ||
      CPLTestBool(CPLGetConfigOption("OGR_DEBUG_ORGANIZE_POLYGONS", "NO")) || !is_shp_path(path))
    return;
  const std::string shx_path = sibling(path, ".shx", ".SHX");
  const std::string dbf_path = sibling(path, ".dbf", ".DBF");
  if (shx_path.empty() || dbf_path.empty()) return;
  auto f = std::make_unique<Files>(path, shx_path, dbf_path);
  if (!f->shx.is_open() || !f->shp.is_open() || !f->dbf.is_open()) return;
  const auto headers = shapefile_headers(f->shp, f->shx);
  if (!headers || headers->file_type != 5) return;
  f->count = headers->count;
  if (layer.GetFeatureCount(FALSE) != GIntBig(f->count)) return;
  // The .dbf's header only: opening costs the same however big the files (each read checks
  // its record's deletion flag).
  const auto layout = dbf_layout(f->dbf, f->count);
  if (!layout) return;
  f->dbf_layout = *layout;
  srs_ = layer.GetSpatialRef();
  files_ = std::move(f);
}

ShapefilePolygons::~ShapefilePolygons() = default;

std::unique_ptr<OGRGeometry> ShapefilePolygons::read(std::int64_t fid) {
  if (!files_ || fid < 0 || std::uint64_t(fid) >= files_->count) return nullptr;
  const unsigned char* deleted = files_->dbf_layout.deletion_flag(files_->dbf, std::uint64_t(fid));
  if (!deleted || *deleted == '*') return nullptr;  // GDAL has no such feature
  const unsigned char* e = files_->shx.get(100 + 8 * std::uint64_t(fid), 8);
  if (!e) return nullptr;
  const std::uint64_t offset = 2 * std::uint64_t(be32(e)), length = 2 * std::uint64_t(be32(e + 4));
  if (offset < 100 || length < 44) return nullptr;
  // Only the record's header first: most records are not several rings.
  const unsigned char* head = files_->shp.get(offset, 8 + 44);
  if (!head || be32(head + 4) != be32(e + 4) || le32(head + 8) != 5 || le32(head + 8 + 36) < 2)
    return nullptr;
  const unsigned char* record = files_->shp.get(offset, 8 + length);
  if (!record) return nullptr;
  try {
    if (!read_record(record + 8, length, 5, files_->path, fid).ok) return nullptr;
  } catch (const Error&) {
    return nullptr;  // a bad coordinate: GDAL's geometry, as before
  }
  auto g = build_polygons(record + 8);
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
  OGRFeatureUniquePtr f(layer_->GetFeature(fid));
  if (f && g) f->SetGeometryDirectly(g.release());
  return f;
}

}  // namespace detail

}  // namespace loci::io
