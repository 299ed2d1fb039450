// What the direct shapefile readers share, GDAL-free: the files read in chunks, the headers
// and records checked as GDAL's shapefile driver would take them, the rings of a polygon
// record sorted into polygons as the driver sorts them, and a feature's geometry flattened
// for the exact tests (ShapefileFeatures). Part of io/'s core, so that the `loci` front reads
// a shapefile's features without loading GDAL; shapefile_boxes.cpp builds the readers that
// need GDAL on it. The format: see loci/io/shapefile_boxes.hpp.
#pragma once

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "loci/geom/error.hpp"
#include "loci/io/exact.hpp"
#include "loci/io/layer_reader.hpp"
#include "loci/io/sidecar.hpp"

namespace loci::io::detail::shp {

inline std::uint32_t be32(const unsigned char* p) {
  return std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[2]) << 8 | p[3];
}
inline std::uint32_t le32(const unsigned char* p) {
  return std::uint32_t(p[3]) << 24 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[1]) << 8 | p[0];
}
inline std::uint32_t le16(const unsigned char* p) {
  return std::uint32_t(p[1]) << 8 | p[0];
}
// The shapefile's doubles are little-endian; the caller checked the host is too.
inline double le_double(const unsigned char* p) {
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

// The sibling of a .shp with another extension, in either case as shapefile writers do ("" when
// there is none).
std::string sibling(const std::string& shp, const char* lower_ext, const char* upper_ext);
bool is_shp_path(const std::string& path);

enum class Kind { point, multipoint, polyline_or_polygon, other };
Kind kind_of(std::uint32_t type);
bool is_polygon_type(std::uint32_t type);
bool has_z(std::uint32_t type);
bool may_have_m(std::uint32_t type);

// The .shp and .shx headers of one shapefile checked against each other (file codes, version,
// the same shape type, an .shx of whole entries): its shape type and record count, or nullopt.
struct ShapefileHeaders {
  std::uint32_t file_type;
  std::uint64_t count;
};
std::optional<ShapefileHeaders> shapefile_headers(ChunkReader& shp, ChunkReader& shx);

// Where the records of a .dbf lie, from its header, when it holds exactly `count` of them.
struct DbfLayout {
  std::uint64_t header, record;  // header and record lengths
  const unsigned char* deletion_flag(ChunkReader& dbf, std::uint64_t i) const {
    return dbf.get(header + i * record, 1);
  }
};
std::optional<DbfLayout> dbf_layout(ChunkReader& dbf, std::uint64_t count);

// Whether the .dbf holds exactly `count` records, none deleted.
bool plain_attributes(ChunkReader& dbf, std::uint64_t count);

// Adds one record's points to `box`, refusing a bad coordinate as the GDAL path does.
void add_points(const unsigned char* xy, std::uint64_t n, Box2& box, const std::string& path,
                std::int64_t fid);

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

// Reads and checks record content `c` of `length` bytes in a file of shape type `file_type`.
RecordRead read_record(const unsigned char* c, std::uint64_t length, std::uint32_t file_type,
                       const std::string& path, std::int64_t fid);

// Whether a record that read_record took (not null) carries M values and one of them is above
// -1e38, below which shapefiles write "no data": what GDAL looks for in a layer's first record
// to give the layer, and so every geometry of it, measures.
bool uses_measures(const unsigned char* c, std::uint64_t length, std::uint32_t type);

// A record's segments, as a per-segment read through GDAL gives them: each line or ring's
// consecutive points (parts numbered in file order), each point of a point or multipoint
// shape, and a part of one point, as a zero-length segment; a ring's segments with the number
// of the polygon it bounds. The record was read and checked by read_record. False, with
// nothing added, for a polygon record whose rings only GDAL sorts (ring_polygons).
bool add_record_segments(const unsigned char* c, std::uint32_t file_type, std::int64_t fid,
                         LayerItems& out);

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

// Each ring's PolygonRings::clockwise().
std::vector<std::int8_t> orientations(const PolygonRings& r);

// GDAL's type for a polygon record of several rings (read and checked by read_record), from
// the orientation of its rings: "Polygon" when exactly one runs clockwise (the outer ring)
// and every other ring's first point lies inside it, "Multi Polygon" when more run clockwise.
// nullptr, for GDAL to answer, whenever a record is unusual: a ring orientation cannot place
// (PolygonRings::clockwise), no clockwise ring, or a hole not plainly inside the outer ring
// (GDAL versions differ there).
const char* polygon_type(const PolygonRings& r, const std::vector<std::int8_t>& cw);
const char* polygon_type(const unsigned char* c);

// The polygons GDAL's shapefile driver makes of a 2D polygon record of several rings (read
// and checked by read_record), sorted without its all-against-all tests of rings. The
// driver sorts with organizePolygons' ONLY_CCW method: clockwise rings are outer rings, each
// counter-clockwise ring (a hole) goes to the smallest (by GDAL's area) clockwise ring of
// larger area whose envelope holds the hole's and which holds the hole's first point (when
// that lies on the ring, the first of its points, then of its edges' midpoints, off it); the
// polygons keep the order of their outer rings, the holes their order in the record. Here
// the candidates come from a packed R-tree of the outer rings' envelopes and are tested as
// GDAL tests them (gdal_ring_location), so a record of thousands of islands and lakes no
// longer costs holes times rings. Nothing, for GDAL to sort them, whenever the record is
// not plain: a ring orientation cannot place, no outer ring, a tie in area, a hole not
// starting strictly inside the one outer ring (GDAL versions differ there; GDAL needs no
// sorting then). As in GDAL, the largest ring of all, when clockwise, holds every hole inside
// its envelope that no smaller outer ring holds, and a counter-clockwise ring no outer ring
// holds is a polygon of its own.
struct Organized {
  std::vector<std::uint32_t> owner;  // per ring: a hole's outer ring, kNone for others
  std::vector<std::uint32_t> top;    // the rings that start a polygon, in any order
};

// Where p lies with respect to ring k of r for GDAL's ring predicates, as organizePolygons
// asks them: on the boundary (OGRLinearRing::isPointOnRingBoundary), else inside or outside
// (isPointInRing's crossing count), both without their envelope test. Computed with the same
// floating-point operations in the same order (this file is built without contraction into
// fused multiply-adds, as GDAL is for x86-64), so that a point on or within rounding of an
// edge goes where GDAL puts it. The ring is closed, of 4 points or more (clockwise() >= 0).
Location gdal_ring_location(const PolygonRings& r, std::uint32_t k, const Point2& p);

// `cw`: the rings' orientations().
std::optional<Organized> organize(const PolygonRings& r, const std::vector<std::int8_t>& cw);

// The polygon each ring of a polygon record of several rings bounds, as the driver sorts the
// rings and numbers the polygons (in the order of their outer rings): its clockwise rings are
// outer rings, its counterclockwise ones holes of the outer ring holding them, or polygons of
// their own where none does. False, for GDAL to read the record, when organize() leaves the
// sorting to GDAL, unless every ring runs clockwise.
bool ring_polygons(const unsigned char* c, std::vector<std::uint32_t>& polygon);
// The same for rings whose orientations() are `cw`.
bool ring_polygons(const PolygonRings& r, const std::vector<std::int8_t>& cw,
                   std::vector<std::uint32_t>& polygon);

// A shapefile's files opened to read its records by FID, in any order: the .shp, .shx and .dbf
// (found beside the .shp in either case) checked against each other when opened, each record
// found through the .shx and checked against its own header when read; a record the .dbf
// marks deleted is none (GDAL gives no feature for it).
class RecordFiles {
 public:
  // Nullptr when `path` is not a .shp of a shape type the readers take, with its .shx and
  // .dbf, all three agreeing on the count of records. Reads the headers only.
  static std::unique_ptr<RecordFiles> open(const std::string& path);

  const std::string& path() const { return path_; }
  std::uint32_t file_type() const { return file_type_; }
  std::uint64_t count() const { return count_; }

  // Where record `fid`'s content lies in the .shp, and its length; nullopt for a FID out of
  // range, a deleted record or an entry out of place.
  struct Entry {
    std::uint64_t offset, length;
  };
  std::optional<Entry> entry(std::int64_t fid);
  // The first `bytes` (at most the length) of the record's content, valid until the next
  // read; nullptr when the .shp does not hold them or the record's header disagrees with
  // the .shx.
  const unsigned char* content(const Entry& e, std::uint64_t bytes);

 private:
  RecordFiles(const std::string& shp, const std::string& shx, const std::string& dbf);
  std::string path_;
  ChunkReader shx_, shp_, dbf_;
  std::uint32_t file_type_ = 0;
  std::uint64_t count_ = 0;
  DbfLayout dbf_layout_{};
};

// A shapefile's features read by FID without GDAL, each flattened as the GDAL path flattens
// the geometry GDAL's shapefile driver (that of GDAL 3.6, which loci-full loads) makes of it:
// a point or multipoint shape its points, a line shape its parts as lines, a polygon shape its
// rings, numbered by the polygon each bounds as the driver sorts them (ring_polygons), in the
// order of its polygons, each outer ring before its holes. What this reader cannot tell as GDAL
// would it leaves to GDAL (nullopt): a file it does not take, a deleted or out-of-range
// record, an unusual or corrupt one, a bad coordinate, a ring of fewer than 4 points, unclosed or
// of zero area, a polygon record whose rings only GDAL sorts, and every record when
// OGR_ORGANIZE_POLYGONS or OGR_DEBUG_ORGANIZE_POLYGONS is set or loci was built with another
// GDAL. Reads the files' headers when made, then each record it is asked for.
class ShapefileFeatures {
 public:
  explicit ShapefileFeatures(const std::string& path);
  ~ShapefileFeatures();
  ShapefileFeatures(const ShapefileFeatures&) = delete;
  ShapefileFeatures& operator=(const ShapefileFeatures&) = delete;

  // Whether the file was taken (else read() always answers nullopt).
  bool active() const { return bool(files_); }
  std::optional<FlatGeometry> read(std::int64_t fid);

 private:
  std::unique_ptr<RecordFiles> files_;
};

}  // namespace loci::io::detail::shp
