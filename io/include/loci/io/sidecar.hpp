// The sidecar index file (`LAYER.loci`, DESIGN.md section 7): a packed R-tree over a layer's
// features or segments, saved so that later queries map it into memory and search it in place.
//
// Layout (little-endian, every offset a multiple of 64 from the start of the file):
//
//   0    header, 256 bytes (SidecarHeader below): magic "\x89LOCI\r\n\x1a", format version,
//        byte-order mark, structure kind, packing, coordinate type, granularity (per feature or
//        per segment), dimension, node size, item and block counts, the offsets and sizes of
//        the sections, the layer's bounds, the source fingerprint, a checksum of the payload
//        and finally a checksum of the header bytes before it.
//   256  the layer name (UTF-8, not terminated)
//   ...  blocks: the tree's nodes exactly as PackedRTree::blocks() holds them (SoA doubles)
//   ...  item indices: PackedRTree::item_indices(), 32-bit, one per slot of level 0
//   ...  records: one 16-byte ItemRecord per item (fid, part, flags), indexed by item id
//
// The magic's first byte has the high bit set and it holds CR LF and ^Z, so that text-mode
// transfers and truncation to 7 bits are caught at once, as PNG does. The file is opened with
// mmap and handed to PackedRTree::adopt: no parse step, no copy. Before that, every size and
// offset is checked against the real file size and both checksums are verified, so a
// truncated, corrupt or foreign file is refused with a message. Item ids read from the file
// are bounds-checked where they index the records, so even a file forged with a valid
// checksum cannot make a query read outside the mapping.
//
// Fingerprint. The index is only valid for the exact bytes it was built from: the source's
// size, modification time (nanoseconds) and a 64-bit hash of its contents (for a shapefile,
// of its .shp and .shx, which hold every geometry and the record offsets). Any difference
// makes the sidecar stale; a touched but unchanged layer is reported stale too, as make would.
//
// Writing goes through AtomicFile (atomic_file.hpp): a hidden temporary file in the same
// directory, synced, then renamed over the target, so readers see either the old file or the
// whole new one, and a failed or interrupted `loci index` leaves the old sidecar valid.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "loci/geom/segment.hpp"
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

// The segment an entry of a per-segment index stands for, recovered from its box and flags.
inline Segment2 segment_of(const Box2& box, std::uint32_t flags) {
  if (flags & item_antidiagonal) return {{box.min[0], box.max[1]}, {box.max[0], box.min[1]}};
  return {box.min, box.max};
}

// Granularity of an index: one entry per feature, or one per segment of the linework.
enum class Per : std::uint8_t { feature = 0, segment = 1 };

struct Fingerprint {
  std::uint64_t size = 0;     // bytes
  std::int64_t mtime_ns = 0;  // latest modification time of the files hashed
  std::uint64_t hash = 0;
  friend bool operator==(const Fingerprint&, const Fingerprint&) = default;
};

// Throws loci::Error when the layer's file(s) cannot be read. Paths GDAL understands that are
// not plain files (for instance a database connection) get an empty fingerprint.
Fingerprint fingerprint_of(const std::string& layer_path);

// 64-bit hash of a byte range; fast enough to run over a layer on every open (several GB/s).
std::uint64_t hash_bytes(const void* data, std::size_t size, std::uint64_t seed = 0);

// Where `loci index` writes by default: the layer path with ".loci" appended.
std::string default_sidecar_path(const std::string& layer_path);

struct SidecarInfo {
  Per per = Per::feature;
  Packing packing = Packing::hilbert;
  std::string layer_name;
  bool has_polygons = false;
  std::uint64_t items = 0;
  Box2 bounds = Box2::empty();
  Fingerprint source;
  std::uint64_t file_size = 0;
};

// Throws loci::Error when the file cannot be written (the target is left untouched).
void write_sidecar(const std::string& path, const PackedRTree2& tree,
                   std::span<const ItemRecord> records, const SidecarInfo& info);

// A sidecar mapped into memory. Move-only; the tree and records stay valid while any copy of
// keep_alive() does.
class Sidecar {
 public:
  // Throws loci::Error naming the file for a missing, truncated, corrupt or foreign file.
  static Sidecar open(const std::string& path);

  const SidecarInfo& info() const { return info_; }
  const PackedRTree2& tree() const { return tree_; }
  std::span<const ItemRecord> records() const { return records_; }
  PackedRTree2 take_tree() && { return std::move(tree_); }
  std::shared_ptr<const void> keep_alive() const { return mapping_; }

 private:
  SidecarInfo info_;
  PackedRTree2 tree_;
  std::span<const ItemRecord> records_;
  std::shared_ptr<const void> mapping_;
};

}  // namespace loci::io
