// The sidecar index file (`LAYER.loci`, DESIGN.md section 7): a packed R-tree over a layer's
// features or segments, saved so that later queries map it into memory and search it in place.
//
// Layout (little-endian, every offset a multiple of 64 from the start of the file), format 7:
//
//   0    header, 256 bytes (SidecarHeader in sidecar.cpp): magic "\x89LOCI\r\n\x1a", format
//        version, byte-order mark, structure kind, packing, coordinate type, granularity (per
//        feature or per segment), dimension, node size, item and block counts, the offsets and
//        sizes of the sections, the layer's bounds, the source fingerprint, the chunk size and
//        count, a checksum of the name and checksum table, the offset and counts (features,
//        levels, nodes) of the hierarchies, and last a checksum of the header bytes before it
//   256  the layer name (UTF-8, not terminated)
//   ...  the checksum table: XXH3-64 (seed 0) of each chunk of the data below, the last chunk
//        shorter; a chunk is 2^s bytes, s the header's chunk shift, and chunk c is
//        [data + c * 2^s, min(data + (c + 1) * 2^s, file end)). loci writes s = 12 (4 KiB, a
//        page, so that a query hashes little more than it reads), or the least s that keeps
//        the table within 131,072 sums for data over 512 MiB, and reads s from 12 to 30
//        (files written with 64 KiB chunks before stay valid)
//   data blocks: the tree's nodes exactly as PackedRTree::blocks() holds them (SoA doubles)
//   ...  item indices: PackedRTree::item_indices(), 32-bit, one per slot of level 0
//   ...  records: one 16-byte ItemRecord per item (fid, part, flags), indexed by item id
//   ...  per segment only, the features' hierarchies that nearest-n walks (layer_query.hpp,
//        LayerIndex::Features), each array from a 64-byte boundary: the FID of every feature
//        (int64), the node count of every level (uint64), the roots (HierarchyRoot: level and
//        node, one per feature), the nodes of every level, level 0 first (HierarchyNode, 48
//        bytes: box, feature, first, last, slots), a packed tree over the roots' boxes
//        (blocks, then item indices, as above; its entry r is root r), and the convex hull
//        of every feature's segment ends (geom/convex_hull.hpp): where each feature's
//        vertices start (uint32, one per feature and the end), then the vertices (two
//        doubles each, counterclockwise, feature by feature); the header's hull count is
//        the number of vertices
//
// The hierarchies are what `loci index` builds from the tree and the records; storing them
// lets nearest-n start at once instead of reading every record to build them, for about a
// tenth more file on a coastline layer (the README has figures). The hulls let nearest-n
// measure a far feature from a few dozen vertices instead of its segments (a coastline's
// 250 countries have 7,004 hull vertices for 4.8 M segments). Like the rest of the data they are
// read in place and verified chunk by chunk; every node is checked as it is read (its feature, and
// its leaf or its children, at most 16, within the arrays), so a file forged with valid checksums
// is refused rather than followed outside the mapping, and `loci check` compares them with the ones
// the tree and records give.
//
// Every checksum is XXH3-64 with seed 0 (libxxhash), so that others can check a file. The
// magic's first byte has the high bit set and it holds CR LF and ^Z, so that text-mode
// transfers and truncation to 7 bits are caught at once, as PNG does.
//
// Opening costs the same whatever the file's size: the file is mapped, the header, name and
// checksum table are checked (every size and offset against the real file size, each
// section where the writer puts it), and the tree
// adopts the mapping in place. The data is verified one chunk at a time, the first time a query
// reads from that chunk (detail::LazyCheck), so a flipped bit is refused with a message when its
// chunk is read and never answers; `loci check` verifies every chunk and the tree's invariants.
// Item ids read from the file are bounds-checked where they index the records, so even a file
// forged with valid checksums cannot make a query read outside the mapping. Format 1 (one
// checksum over the whole payload, hashed on every open), format 2 (no hierarchies: every
// nearest-n run read all the records to build them), format 3 (level-0 nodes without their
// slots: nearest-n read an item index and a record for every box it measured), format 4
// (ring segments without their polygon: the rings of a feature were counted together by the
// even-odd rule, so that where two polygons overlapped the overlap was outside) and format 5
// (ring segments with a direction bit, where format 6 numbers their polygon) and format 6
// (no hulls) are refused with the usual message.
//
// Fingerprint. The index is valid for the exact bytes it was built from: at index time the
// source's size, modification time (nanoseconds), inode and a 64-bit XXH3 hash of its contents
// (for a shapefile, of its .shp, .shx and .dbf, which hold every geometry, the record offsets
// and the deletion marks; for a directory, of every file in it; the companions of a CSV, a
// MapInfo table or a GeoPackage in WAL mode too: layer_files()).
// At query time size, modification time and inode are compared, nothing read; only when they
// differ (a touched, copied or rewritten layer) is the content hashed again, and the index is
// fresh if size and hash still agree. Sizes, times and inodes are taken before the layer is
// read and compared after; a shapefile read directly (shapefile_boxes.hpp) has its hash taken
// from the bytes as they are read, in one pass.
//
// Writing goes through AtomicFile (atomic_file.hpp): a hidden temporary file in the same
// directory, synced, then renamed over the target, so readers see either the old file or the
// whole new one, and a failed or interrupted `loci index` leaves the old sidecar valid.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "loci/geom/segment.hpp"
#include "loci/index/detail/lazy_check.hpp"
#include "loci/index/packed_rtree.hpp"

namespace loci::io {

// The records section: what one index entry stands for. 16 bytes, trivially copyable: stored as is
// in sidecars.
struct ItemRecord {
  std::int64_t fid;     // the feature id GDAL reports
  std::int32_t part;    // per segment: the line or ring within the feature; per feature: 0
  std::uint32_t flags;  // ItemFlags
};
static_assert(sizeof(ItemRecord) == 16);

enum ItemFlags : std::uint32_t {
  item_ring = 1u,          // the segment lies on a polygon ring
  item_antidiagonal = 2u,  // the segment runs from (min x, max y) to (max x, min y) of its box
};
// On a ring, the bits above those two number the polygon of the feature the ring bounds.
constexpr int kItemPolygonShift = 2;

// The segment an entry of a per-segment index stands for, recovered from its box and flags.
inline Segment2 segment_of(const Box2& box, std::uint32_t flags) {
  if (flags & item_antidiagonal) return {{box.min[0], box.max[1]}, {box.max[0], box.min[1]}};
  return {box.min, box.max};
}

// The polygon of its feature that a ring segment's ring bounds.
inline std::uint32_t polygon_of(std::uint32_t flags) {
  return flags >> kItemPolygonShift;
}

// The flags under which segment_of() gives back the segment from a to b (as a point set), on
// a ring of the feature's polygon `polygon` (below 2^30) when `ring`.
inline std::uint32_t segment_flags(const Point2& a, const Point2& b, bool ring,
                                   std::uint32_t polygon = 0) {
  const bool anti = (a[0] < b[0]) != (a[1] < b[1]) && a[0] != b[0] && a[1] != b[1];
  return (ring ? item_ring | polygon << kItemPolygonShift : 0u) | (anti ? item_antidiagonal : 0u);
}

// Granularity of an index: one entry per feature, or one per segment of the linework.
enum class Per : std::uint8_t { feature = 0, segment = 1 };

// The hierarchies of boxes of a per-segment index, one per feature, that nearest-n walks
// (layer_query.hpp, LayerIndex::Features, says what they are). Nodes and roots are stored as is.
struct HierarchyNode {
  Box2 box;
  std::uint32_t feature;      // the feature's number, an index into the FIDs
  std::uint32_t first, last;  // level 0: the leaf of the tree (first == last); above: the
                              // nodes [first, last) of the level below
  // Level 0: bit e (e < 16) is set when slot e of the leaf holds one of the feature's
  // segments, and bit 16 + e when that segment runs antidiagonally (item_antidiagonal), so
  // that nearest-n measures the feature's segments from the leaf's boxes alone, without
  // reading item indices or records. Above level 0: 0.
  std::uint32_t slots = 0;
};
static_assert(sizeof(HierarchyNode) == 48);

struct HierarchyRoot {
  std::uint32_t level, node;
};
static_assert(sizeof(HierarchyRoot) == 8);

// The hierarchies as arrays (what write_sidecar stores and Sidecar::hierarchies maps): the FID
// of every feature, the nodes level by level, and the roots, one per feature, with a packed
// tree over the roots' boxes whose entry r is roots[r].
struct Hierarchies {
  std::span<const std::int64_t> fids;
  std::vector<std::span<const HierarchyNode>> levels;
  std::span<const HierarchyRoot> roots;
  const PackedRTree2* root_tree = nullptr;
  // The convex hull of every feature's segment ends (geom/convex_hull.hpp): feature f's
  // vertices are hull_points[hull_first[f], hull_first[f + 1]).
  std::span<const std::uint32_t> hull_first;  // one per feature, and the end
  std::span<const Point2> hull_points;
};

struct Fingerprint {
  std::uint64_t size = 0;     // bytes
  std::int64_t mtime_ns = 0;  // latest modification time of the files hashed
  std::uint64_t inode = 0;    // the files' inodes, combined
  std::uint64_t hash = 0;
  friend bool operator==(const Fingerprint&, const Fingerprint&) = default;
};

// The files a layer's fingerprint covers, in the order they are hashed: the path itself; for
// a shapefile also its .shx and .dbf, for a CSV its .csvt, for a MapInfo .tab its .map, .id
// and .dat, and for any file a non-empty FILE-wal (an SQLite database's, a GeoPackage's,
// uncheckpointed changes); for a directory (a dataset of several files) every regular file in
// it, in name order.
std::vector<std::string> layer_files(const std::string& layer_path);

// The full fingerprint, contents hashed (index time). Throws loci::Error when the layer's
// file(s) cannot be read. Paths GDAL understands that are not plain files (for instance a
// database connection) get an empty fingerprint.
Fingerprint fingerprint_of(const std::string& layer_path);

// Size, modification time and inode only, nothing read (hash 0). Taken before a layer is
// read and compared after, it catches a layer that changed while it was being indexed.
Fingerprint fingerprint_stat(const std::string& layer_path);

// XXH3-64 over bytes given in pieces, as fingerprint_of() hashes each file (seeded with the
// previous file's hash): a reader that streams a layer's files anyway gives the fingerprint's
// hash without a second pass over them.
class StreamHash {
 public:
  explicit StreamHash(std::uint64_t seed = 0);
  ~StreamHash();
  StreamHash(const StreamHash&) = delete;
  StreamHash& operator=(const StreamHash&) = delete;
  void update(const void* data, std::size_t size);
  std::uint64_t digest() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// Whether `layer_path` names what only GDAL opens (a virtual file system path such as
// /vsizip/ or /vsistdin/, a connection string) and no file or directory on disk: nothing
// there for a fingerprint, so loci index refuses it.
bool only_gdal_opens(const std::string& layer_path);

// Whether `path` is an OGR VRT: a file describing layers whose features live in other files
// or databases, which a fingerprint of the file does not see change; loci index refuses it.
bool is_vrt(const std::string& path);

// Whether the layer still holds what `was` was taken of: size, modification time and inode
// equal (nothing is read), or else the same size and content hash. `now` receives what was
// measured (for messages). Never for a path only GDAL opens, nor for a VRT.
bool still_fresh(const std::string& layer_path, const Fingerprint& was, Fingerprint* now = nullptr);

// What changed between `was` and `now` (still_fresh's measure), as messages say it: "size A ->
// B bytes", "contents changed" or "modified after the index was written".
std::string stale_reason(const Fingerprint& was, const Fingerprint& now);

// XXH3-64 of a byte range.
std::uint64_t hash_bytes(const void* data, std::size_t size, std::uint64_t seed = 0);

// Where `loci index` writes by default: the layer path with ".loci" appended.
std::string default_sidecar_path(const std::string& layer_path);
// Whether the file at path begins as a loci index file does (its magic), so that a command
// given a sidecar where it takes a layer can say so.
bool starts_as_sidecar(const std::string& path);

struct SidecarInfo {
  Per per = Per::feature;
  Packing packing = Packing::hilbert;
  std::string layer_name;
  bool has_polygons = false;
  bool per_chosen = false;     // `per` was chosen by loci index from the layer's shape
  std::uint64_t features = 0;  // features with a geometry (0: not recorded)
  std::uint64_t items = 0;
  Box2 bounds = Box2::empty();
  Fingerprint source;
  std::uint64_t file_size = 0;
  // The data is checksummed in chunks of 2^chunk_shift bytes, 12 to 30 (4 KiB to 1 GiB): a
  // query verifies the chunks it reads, whole. write_sidecar takes this as the least, and
  // writes sidecar_chunk_shift() of it.
  unsigned chunk_shift = 12;
};

// The chunk size write_sidecar uses for `data_bytes` of data: 2^least (clamped to 12..30)
// bytes, doubled while the checksum table, which opening reads and hashes whole, would hold
// more than 131,072 sums (1 MiB): 4 KiB chunks up to 512 MiB of data, then larger, so that
// opening costs at most that whatever the file's size.
unsigned sidecar_chunk_shift(std::uint64_t data_bytes, unsigned least = 12);

// Throws loci::Error when the file cannot be written (the target is left untouched).
// `hierarchies` (a per-segment index's, or null) are stored with the tree.
void write_sidecar(const std::string& path, const PackedRTree2& tree,
                   std::span<const ItemRecord> records, const SidecarInfo& info,
                   const Hierarchies* hierarchies = nullptr);

// The stored hierarchies of a sidecar, as mapped: nothing is read until it is used. The
// arrays' sizes are checked against the file; their contents are not (the level sizes, the
// nodes' indices): a reader checks what it reads, after check().touch() of it.
struct MappedHierarchies {
  std::size_t features = 0, levels = 0, nodes = 0;
  const std::int64_t* fids = nullptr;
  const std::uint64_t* level_sizes = nullptr;
  const HierarchyRoot* roots = nullptr;
  const HierarchyNode* nodes_at = nullptr;  // every level's nodes, level 0 first
  // A packed tree over the roots (PackedRTree2::adopt() them).
  std::span<const PackedRTree2::Block> root_blocks;
  std::span<const std::uint32_t> root_items;
  const std::uint32_t* hull_first = nullptr;  // features + 1 of them
  const Point2* hull_points = nullptr;
  std::size_t hull_count = 0;
  std::string path;  // the sidecar's, for messages
};

// A sidecar mapped into memory. Move-only; the tree and records stay valid while any copy of
// keep_alive() does.
class Sidecar {
 public:
  // Throws loci::Error naming the file for a missing, truncated, corrupt or foreign file.
  static Sidecar open(const std::string& path);

  const SidecarInfo& info() const { return info_; }
  // The tree verifies what it reads as it reads it.
  const PackedRTree2& tree() const { return tree_; }
  // Every record, verified first (throws loci::Error naming the file when corrupt).
  std::span<const ItemRecord> records() const;
  // The records as mapped, unverified: read record i only after check().touch() of it.
  std::span<const ItemRecord> mapped_records() const { return records_; }
  // The item indices as mapped, unverified, likewise.
  std::span<const std::uint32_t> mapped_items() const { return items_; }
  // The stored hierarchies (a per-segment index of at least one item), else null.
  std::shared_ptr<const MappedHierarchies> hierarchies() const { return hierarchies_; }
  const loci::detail::LazyCheck& check() const { return *check_; }
  // Verifies every chunk and the tree's invariants; throws loci::Error naming the problem.
  void verify() const;
  PackedRTree2 take_tree() && { return std::move(tree_); }
  // Owns the mapping and the check.
  std::shared_ptr<const void> keep_alive() const { return check_; }

 private:
  SidecarInfo info_;
  PackedRTree2 tree_;
  std::span<const ItemRecord> records_;
  std::span<const std::uint32_t> items_;
  std::shared_ptr<const MappedHierarchies> hierarchies_;
  std::shared_ptr<const loci::detail::LazyCheck> check_;
};

}  // namespace loci::io
