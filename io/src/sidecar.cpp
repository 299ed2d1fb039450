// The sidecar index file: see sidecar.hpp for the format and its guarantees.
#include "loci/io/sidecar.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <utility>
#include <vector>

#include "loci/geom/error.hpp"
#include "loci/io/atomic_file.hpp"

#define XXH_INLINE_ALL
#include <xxhash.h>

namespace fs = std::filesystem;

namespace loci::io {

#ifdef LOCI_HASH_AVX2
namespace detail {
// hash_avx2.cpp: XXH3 with AVX2, about twice the bytes per instruction of SSE2 (the chunks a
// query reads are checked on first touch; `loci check` and `loci index` hash whole files).
std::uint64_t hash_bytes_avx2(const void* data, std::size_t size, std::uint64_t seed);
void hash_update_avx2(XXH3_state_t* state, const void* data, std::size_t size);
}  // namespace detail
namespace {
bool has_avx2() {
  static const bool avx2 = (__builtin_cpu_init(), __builtin_cpu_supports("avx2"));
  return avx2;
}
}  // namespace
#endif
namespace {

constexpr char kMagic[8] = {'\x89', 'L', 'O', 'C', 'I', '\r', '\n', '\x1a'};
constexpr std::uint32_t kVersion = 7;
constexpr std::uint32_t kByteOrder = 0x01020304;
constexpr std::uint8_t kStructurePackedRTree = 1;
constexpr std::uint8_t kCoordFloat64 = 1;
constexpr std::uint32_t kFlagPolygons = 1;
constexpr std::uint32_t kFlagPerChosen = 2;  // the granularity was chosen by loci index
constexpr std::size_t kAlign = 64;
// Data is checked a chunk at a time; a chunk is 2^chunk_shift bytes. loci writes pages (4 KiB),
// so that a query verifies little more than what it reads, and larger chunks only where the
// checksum table, which opening reads whole, would pass kMaxChunks sums (data over 512 MiB).
// Files with 64 KiB chunks (what loci wrote before) are read as they are.
constexpr unsigned kMinChunkShift = 12, kMaxChunkShift = 30;
constexpr std::uint64_t kMaxChunks = std::uint64_t(1) << 17;  // a table of at most 1 MiB

struct SidecarHeader {
  char magic[8];
  std::uint32_t version;
  std::uint32_t byte_order;
  std::uint8_t structure;
  std::uint8_t packing;
  std::uint8_t coordinate_type;
  std::uint8_t per;
  std::uint16_t dimension;
  std::uint16_t node_size;
  std::uint32_t flags;
  std::uint32_t reserved0;
  std::uint64_t item_count;
  std::uint64_t block_count;
  std::uint64_t slot_count;  // entries of item_indices
  std::uint64_t name_offset;
  std::uint64_t name_size;
  std::uint64_t blocks_offset;
  std::uint64_t items_offset;
  std::uint64_t records_offset;
  std::uint64_t file_size;
  double bounds[4];  // min x, min y, max x, max y
  std::uint64_t source_size;
  std::int64_t source_mtime_ns;
  std::uint64_t source_hash;
  std::uint64_t source_inode;
  std::uint64_t checks_offset;  // chunk_count XXH3-64 values, one per chunk of the data
  std::uint64_t chunk_count;
  std::uint64_t data_offset;  // = blocks_offset; chunks cover [data_offset, file_size)
  std::uint32_t chunk_shift;  // a chunk is 2^chunk_shift bytes (the last may be shorter)
  std::uint32_t reserved1;
  std::uint64_t front_checksum;      // XXH3-64 of bytes [sizeof(SidecarHeader), data_offset)
  std::uint64_t feature_count;       // features with a geometry (0: not recorded)
  std::uint64_t hierarchy_offset;    // the feature hierarchies (0: none), after the records
  std::uint64_t hierarchy_features;  // their FIDs and roots
  std::uint64_t hierarchy_nodes;     // their nodes, all levels
  std::uint32_t hierarchy_levels;
  std::uint32_t hull_count;       // the vertices of the features' hulls
  std::uint64_t header_checksum;  // XXH3-64 of the bytes before this field
};
static_assert(sizeof(SidecarHeader) == 256);
static_assert(std::endian::native == std::endian::little, "sidecars are little-endian");

std::size_t align_up(std::size_t n) {
  return (n + kAlign - 1) / kAlign * kAlign;
}

// Where the arrays of the hierarchies section lie, from its offset and counts (each array
// from a 64-byte boundary): FIDs, level sizes, roots, nodes, the roots' tree's blocks and item
// indices, the hulls' starts and vertices. Counts too large for the file give an end beyond it
// (no overflow: each count is checked against the file size first).
struct HierarchyLayout {
  std::uint64_t fids, sizes, roots, nodes, root_blocks, root_items, hull_first, hull_points, end;
  std::uint64_t root_block_count, root_slots;
};

HierarchyLayout hierarchy_layout(std::uint64_t offset, std::uint64_t features, std::uint64_t levels,
                                 std::uint64_t nodes, std::uint64_t hull_count) {
  HierarchyLayout l{};
  l.root_block_count = PackedRTree2::block_count(std::size_t(features));
  l.root_slots =
      (features + PackedRTree2::node_size - 1) / PackedRTree2::node_size * PackedRTree2::node_size;
  l.fids = offset;
  l.sizes = align_up(l.fids + 8 * features);
  l.roots = align_up(l.sizes + 8 * levels);
  l.nodes = align_up(l.roots + sizeof(HierarchyRoot) * features);
  l.root_blocks = align_up(l.nodes + sizeof(HierarchyNode) * nodes);
  l.root_items = align_up(l.root_blocks + sizeof(PackedRTree2::Block) * l.root_block_count);
  l.hull_first = align_up(l.root_items + 4 * l.root_slots);
  l.hull_points = align_up(l.hull_first + 4 * (features + 1));
  l.end = l.hull_points + sizeof(Point2) * hull_count;
  return l;
}

struct Mapping {
  const std::byte* data = nullptr;
  std::size_t size = 0;
};

// Maps a whole file read-only; the returned pointer unmaps it. Empty files map to nullptr.
std::shared_ptr<const Mapping> map_file(const std::string& path) {
  // O_NONBLOCK: a FIFO must be refused at once, not wait for a writer
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) throw Error(path + ": cannot open (" + std::strerror(errno) + ")");
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw Error(path + ": not a regular file");
  }
  auto m = std::shared_ptr<Mapping>(new Mapping, [](Mapping* m) {
    if (m->data) ::munmap(const_cast<std::byte*>(m->data), m->size);
    delete m;
  });
  m->size = std::size_t(st.st_size);
  if (m->size > 0) {
    void* p = ::mmap(nullptr, m->size, PROT_READ, MAP_PRIVATE, fd, 0);
    if (p == MAP_FAILED) {
      ::close(fd);
      throw Error(path + ": cannot map (" + std::strerror(errno) + ")");
    }
    m->data = static_cast<const std::byte*>(p);
  }
  ::close(fd);
  return m;
}

// Verifies a mapped sidecar's data chunk by chunk against the file's checksum table.
class ChunkCheck final : public loci::detail::LazyCheck {
 public:
  ChunkCheck(std::shared_ptr<const Mapping> m, std::string path, std::uint64_t data_offset,
             std::uint64_t checks_offset, unsigned chunk_shift)
      : LazyCheck(m->data + data_offset, m->size - data_offset, chunk_shift),
        mapping_(std::move(m)),
        path_(std::move(path)),
        checks_(mapping_->data + checks_offset) {}

 protected:
  void verify(std::size_t c, const std::byte* data, std::size_t bytes) const override {
    std::uint64_t expected;
    std::memcpy(&expected, checks_ + 8 * c, 8);
    if (hash_bytes(data, bytes) != expected)
      throw Error(path_ + ": corrupt index file (checksum mismatch in chunk " + std::to_string(c) +
                  "); run 'loci index' to rebuild it");
  }

 private:
  std::shared_ptr<const Mapping> mapping_;
  std::string path_;
  const std::byte* checks_;
};

bool stat_file(const std::string& path, struct stat& st) {
  return ::stat(path.c_str(), &st) == 0;
}

std::int64_t mtime_ns(const struct stat& st) {
  return std::int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

// Writes all of `data` or throws.
void write_all(int fd, const void* data, std::size_t size, const std::string& path) {
  const auto* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw Error("cannot write " + path + " (" + std::strerror(errno) + ")");
    p += n;
    size -= std::size_t(n);
  }
}

}  // namespace

std::uint64_t hash_bytes(const void* data, std::size_t size, std::uint64_t seed) {
#ifdef LOCI_HASH_AVX2
  if (has_avx2()) return detail::hash_bytes_avx2(data, size, seed);
#endif
  return XXH3_64bits_withSeed(data, size, seed);
}

std::vector<std::string> layer_files(const std::string& layer_path) {
  struct stat st {};
  if (stat_file(layer_path, st) && S_ISDIR(st.st_mode)) {
    // A directory GDAL opens as one dataset (shapefiles, a FileGDB): every file in it, in name
    // order, so that an edit to any of them is seen.
    std::vector<std::string> files;
    std::error_code ec;
    for (fs::directory_iterator it(layer_path, ec), end; !ec && it != end; it.increment(ec))
      if (it->is_regular_file(ec)) files.push_back(it->path().string());
    if (ec) throw Error(layer_path + ": cannot list (" + ec.message() + ")");
    std::sort(files.begin(), files.end());
    return files;
  }
  std::vector<std::string> files{layer_path};
  const std::string ext = layer_path.size() > 4 ? layer_path.substr(layer_path.size() - 4) : "";
  const std::string stem = layer_path.substr(0, layer_path.size() - ext.size());
  // The companions that hold part of the layer, each in lower or upper case when there.
  const auto add = [&](std::initializer_list<std::pair<const char*, const char*>> exts) {
    for (const auto& [lower_ext, upper_ext] : exts)
      for (const char* e : {lower_ext, upper_ext}) {
        struct stat s2 {};
        if (stat_file(stem + e, s2) && S_ISREG(s2.st_mode)) {
          files.push_back(stem + e);
          break;
        }
      }
  };
  if (lower(ext) == ".shp") {
    // Its index (.shx) and its attributes (.dbf, which also marks deleted records).
    add({{".shx", ".SHX"}, {".dbf", ".DBF"}});
  } else if (lower(ext) == ".csv") {
    // The column types, which can make two columns the geometry's x and y.
    add({{".csvt", ".CSVT"}});
  } else if (lower(ext) == ".tab") {
    // A MapInfo table: its geometries (.map, .id) and attributes (.dat).
    add({{".map", ".MAP"}, {".id", ".ID"}, {".dat", ".DAT"}});
  }
  // An SQLite database (a GeoPackage) in WAL mode keeps the changes committed since its last
  // checkpoint in FILE-wal, which readers see: an edit there changes the layer too.
  struct stat wal {};
  if (stat_file(layer_path + "-wal", wal) && S_ISREG(wal.st_mode) && wal.st_size > 0)
    files.push_back(layer_path + "-wal");
  return files;
}

namespace {

// Size, modification time and inode of the layer's files, nothing read; `regular` tells
// whether there is content to hash. Nullopt for a GDAL path that is not a file.
std::optional<Fingerprint> stat_fingerprint(const std::string& layer_path, bool& regular) {
  struct stat st {};
  if (!stat_file(layer_path, st)) {
    // GDAL paths that are not files (virtual file systems, connection strings) cannot be
    // fingerprinted here; GDAL itself reports whether they open.
    if (only_gdal_opens(layer_path)) return std::nullopt;
    throw Error(layer_path + ": no such file");
  }
  Fingerprint f;
  regular = S_ISREG(st.st_mode) || S_ISDIR(st.st_mode);
  if (!regular) {
    f.mtime_ns = mtime_ns(st);
    f.inode = st.st_ino;
    return f;
  }
  if (S_ISDIR(st.st_mode)) {  // a file added or removed
    f.mtime_ns = mtime_ns(st);
    f.inode = std::uint64_t(st.st_ino);
  }
  for (const auto& file : layer_files(layer_path)) {
    struct stat s {};
    if (!stat_file(file, s)) throw Error(file + ": cannot read");
    f.size += std::uint64_t(s.st_size);
    f.mtime_ns = std::max(f.mtime_ns, mtime_ns(s));
    f.inode = f.inode * 0x100000001b3ull ^ std::uint64_t(s.st_ino);
  }
  return f;
}

}  // namespace

bool only_gdal_opens(const std::string& layer_path) {
  struct stat st {};
  return (layer_path.rfind("/vsi", 0) == 0 || layer_path.find(':') != std::string::npos) &&
         !stat_file(layer_path, st);
}

bool is_vrt(const std::string& path) {
  // Only a regular file is read: opening a FIFO would wait for a writer (open_layer refuses
  // it, with a message, once this says no).
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return false;
  std::ifstream f(path, std::ios::binary);
  std::string head(256, '\0');
  f.read(head.data(), std::streamsize(head.size()));
  head.resize(std::size_t(f.gcount()));
  return head.find("<OGRVRTDataSource") != std::string::npos;
}

Fingerprint fingerprint_stat(const std::string& layer_path) {
  bool regular = false;
  return stat_fingerprint(layer_path, regular).value_or(Fingerprint{});
}

struct StreamHash::State {
  XXH3_state_t xxh;
};
StreamHash::StreamHash(std::uint64_t seed) : state_(std::make_unique<State>()) {
  XXH3_64bits_reset_withSeed(&state_->xxh, seed);
}
StreamHash::~StreamHash() = default;
void StreamHash::update(const void* data, std::size_t size) {
#ifdef LOCI_HASH_AVX2
  if (has_avx2()) return detail::hash_update_avx2(&state_->xxh, data, size);
#endif
  XXH3_64bits_update(&state_->xxh, data, size);
}
std::uint64_t StreamHash::digest() const {
  return XXH3_64bits_digest(&state_->xxh);
}

Fingerprint fingerprint_of(const std::string& layer_path) {
  bool regular = false;
  const auto stat = stat_fingerprint(layer_path, regular);
  if (!stat) return {};
  Fingerprint f = *stat;
  if (!regular) return f;
  // Read, not mapped: on virtual machines a page fault costs more than copying the page.
  std::vector<unsigned char> buffer(1 << 20);
  for (const auto& file : layer_files(layer_path)) {
    const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) throw Error(file + ": cannot open (" + std::strerror(errno) + ")");
    StreamHash state(f.hash);
    for (;;) {
      const ssize_t n = ::read(fd, buffer.data(), buffer.size());
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) {
        const int e = errno;
        ::close(fd);
        throw Error(file + ": cannot read (" + std::strerror(e) + ")");
      }
      if (n == 0) break;
      state.update(buffer.data(), std::size_t(n));
    }
    ::close(fd);
    f.hash = state.digest();
  }
  return f;
}

std::string stale_reason(const Fingerprint& was, const Fingerprint& now) {
  if (now.size == 0 && now.mtime_ns == 0 && now.inode == 0)  // nothing on disk (still_fresh)
    return "no file on disk to compare: a path only GDAL opens";
  if (was.size != now.size)
    return "size " + std::to_string(was.size) + " -> " + std::to_string(now.size) + " bytes";
  if (was.hash != now.hash) return "contents changed";
  return "modified after the index was written";
}

bool still_fresh(const std::string& layer_path, const Fingerprint& was, Fingerprint* now) {
  bool regular = false;
  const auto stat = stat_fingerprint(layer_path, regular);
  // A path only GDAL opens has nothing to compare: never fresh (an index of it, which loci
  // index no longer writes, would answer for whatever it holds now).
  if (!stat) {
    if (now) *now = Fingerprint{};
    return false;
  }
  Fingerprint f = *stat;
  // Nor is an index of a VRT: its features live in its sources, which its fingerprint does
  // not see change (an older loci's index of one, the file unchanged, answered from sources
  // edited since).
  if (regular && is_vrt(layer_path)) {
    if (now) *now = f;
    return false;
  }
  if (f.size == was.size && f.mtime_ns == was.mtime_ns && f.inode == was.inode) {
    if (now) *now = was;
    return true;
  }
  if (!regular || f.size != was.size) {
    if (now) *now = f;
    return false;
  }
  // Touched, copied or moved: the content decides.
  f = fingerprint_of(layer_path);
  if (now) *now = f;
  return f.size == was.size && f.hash == was.hash;
}

std::string default_sidecar_path(const std::string& layer_path) {
  std::string p = layer_path;
  while (p.size() > 1 && p.back() == '/')
    p.pop_back();
  return p + ".loci";
}

bool starts_as_sidecar(const std::string& path) {
  char magic[sizeof kMagic] = {};
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  const bool whole = std::fread(magic, 1, sizeof magic, f) == sizeof magic;
  std::fclose(f);
  return whole && std::memcmp(magic, kMagic, sizeof magic) == 0;
}

unsigned sidecar_chunk_shift(std::uint64_t data_bytes, unsigned least) {
  unsigned shift = std::clamp(least, kMinChunkShift, kMaxChunkShift);
  while (shift < kMaxChunkShift && data_bytes > (kMaxChunks << shift))
    ++shift;
  return shift;
}

void write_sidecar(const std::string& path, const PackedRTree2& tree,
                   std::span<const ItemRecord> records, const SidecarInfo& info,
                   const Hierarchies* hierarchies) {
  if (records.size() != tree.size()) throw InvalidArgument("sidecar: one record per item");
  if (info.chunk_shift < kMinChunkShift || info.chunk_shift > kMaxChunkShift)
    throw InvalidArgument("sidecar: chunks of 4 KiB to 1 GiB (a chunk_shift of 12 to 30)");
  const auto blocks = tree.blocks();
  const auto items = tree.item_indices();
  if (hierarchies && (!hierarchies->root_tree || info.per != Per::segment ||
                      hierarchies->roots.size() != hierarchies->fids.size() ||
                      hierarchies->root_tree->size() != hierarchies->roots.size() ||
                      hierarchies->hull_first.size() != hierarchies->fids.size() + 1 ||
                      hierarchies->hull_first.back() != hierarchies->hull_points.size() ||
                      hierarchies->hull_points.size() >= (1ull << 32)))
    throw InvalidArgument(
        "sidecar: hierarchies of a per-segment index, one root and one hull per feature");

  SidecarHeader h{};
  std::memcpy(h.magic, kMagic, 8);
  h.version = kVersion;
  h.byte_order = kByteOrder;
  h.structure = kStructurePackedRTree;
  h.packing = std::uint8_t(info.packing);
  h.coordinate_type = kCoordFloat64;
  h.per = std::uint8_t(info.per);
  h.dimension = 2;
  h.node_size = PackedRTree2::node_size;
  h.flags = (info.has_polygons ? kFlagPolygons : 0) | (info.per_chosen ? kFlagPerChosen : 0);
  h.feature_count = info.features;
  h.item_count = tree.size();
  h.block_count = blocks.size();
  h.slot_count = items.size();
  h.name_offset = sizeof(SidecarHeader);
  h.name_size = info.layer_name.size();
  h.checks_offset = align_up(h.name_offset + h.name_size);
  // The checksum table's length depends on the data's, which starts after the table.
  const std::size_t data_bytes =
      align_up(blocks.size_bytes()) + align_up(items.size_bytes()) + records.size_bytes();
  std::vector<std::uint64_t> level_sizes;
  std::size_t node_count = 0;
  HierarchyLayout hl{};
  if (hierarchies) {
    for (const auto& level : hierarchies->levels) {
      level_sizes.push_back(level.size());
      node_count += level.size();
    }
    h.hierarchy_features = hierarchies->fids.size();
    h.hierarchy_levels = std::uint32_t(level_sizes.size());
    h.hierarchy_nodes = node_count;
    h.hull_count = std::uint32_t(hierarchies->hull_points.size());
    // Laid out from 0 first, for its length.
    hl = hierarchy_layout(0, h.hierarchy_features, h.hierarchy_levels, h.hierarchy_nodes,
                          h.hull_count);
  }
  const std::size_t hierarchy_bytes =
      hierarchies ? align_up(records.size_bytes()) - records.size_bytes() + hl.end : 0;
  const std::size_t all_data = data_bytes + hierarchy_bytes;
  h.chunk_shift = sidecar_chunk_shift(all_data, info.chunk_shift);
  h.chunk_count = all_data == 0 ? 0 : ((all_data - 1) >> h.chunk_shift) + 1;
  h.data_offset = align_up(h.checks_offset + 8 * h.chunk_count);
  h.blocks_offset = h.data_offset;
  h.items_offset = align_up(h.blocks_offset + blocks.size_bytes());
  h.records_offset = align_up(h.items_offset + items.size_bytes());
  h.file_size = h.records_offset + records.size_bytes();
  if (hierarchies) {
    h.hierarchy_offset = align_up(h.file_size);
    hl = hierarchy_layout(h.hierarchy_offset, h.hierarchy_features, h.hierarchy_levels,
                          h.hierarchy_nodes, h.hull_count);
    h.file_size = hl.end;
  }
  const Box2 b = tree.bounds();
  h.bounds[0] = b.min[0];
  h.bounds[1] = b.min[1];
  h.bounds[2] = b.max[0];
  h.bounds[3] = b.max[1];
  h.source_size = info.source.size;
  h.source_mtime_ns = info.source.mtime_ns;
  h.source_hash = info.source.hash;
  h.source_inode = info.source.inode;

  // The data (blocks, item indices, records, each from a 64-byte boundary, zeros between)
  // is hashed and written from the tree's own arrays: the file is never assembled in
  // memory, which for a large index meant faulting in and clearing as many fresh pages.
  struct Piece {
    std::uint64_t offset;
    const void* data;
    std::size_t size;
  };
  std::vector<Piece> pieces{{h.blocks_offset, blocks.data(), blocks.size_bytes()},
                            {h.items_offset, items.data(), items.size_bytes()},
                            {h.records_offset, records.data(), records.size_bytes()}};
  if (hierarchies) {
    pieces.push_back({hl.fids, hierarchies->fids.data(), hierarchies->fids.size_bytes()});
    pieces.push_back({hl.sizes, level_sizes.data(), 8 * level_sizes.size()});
    pieces.push_back({hl.roots, hierarchies->roots.data(), hierarchies->roots.size_bytes()});
    std::uint64_t at = hl.nodes;
    for (const auto& level : hierarchies->levels) {
      pieces.push_back({at, level.data(), level.size_bytes()});
      at += level.size_bytes();
    }
    const auto root_blocks = hierarchies->root_tree->blocks();
    const auto root_items = hierarchies->root_tree->item_indices();
    if (root_blocks.size() != hl.root_block_count || root_items.size() != hl.root_slots)
      throw InvalidArgument("sidecar: the roots' tree does not match the roots");
    pieces.push_back({hl.root_blocks, root_blocks.data(), root_blocks.size_bytes()});
    pieces.push_back({hl.root_items, root_items.data(), root_items.size_bytes()});
    pieces.push_back(
        {hl.hull_first, hierarchies->hull_first.data(), hierarchies->hull_first.size_bytes()});
    pieces.push_back(
        {hl.hull_points, hierarchies->hull_points.data(), hierarchies->hull_points.size_bytes()});
  }
  // The bytes [first, first + size) of the file's data: in place when one piece holds them,
  // else gathered into `buffer`.
  std::vector<std::byte> buffer;
  const auto data_bytes_at = [&](std::uint64_t first, std::size_t size) -> const std::byte* {
    for (const Piece& p : pieces)
      if (first >= p.offset && first + size <= p.offset + p.size)
        return static_cast<const std::byte*>(p.data) + (first - p.offset);
    buffer.assign(size, std::byte{0});
    for (const Piece& p : pieces) {
      const std::uint64_t from = std::max(first, p.offset),
                          to = std::min(first + size, p.offset + p.size);
      if (from < to)
        std::memcpy(buffer.data() + (from - first),
                    static_cast<const std::byte*>(p.data) + (from - p.offset), to - from);
    }
    return buffer.data();
  };

  // The front: the layer name and the checksum table, with their padding.
  std::vector<std::byte> front(h.data_offset - sizeof(SidecarHeader));
  auto put = [&](std::uint64_t offset, const void* data, std::size_t size) {
    if (size) std::memcpy(front.data() + (offset - sizeof(SidecarHeader)), data, size);
  };
  put(h.name_offset, info.layer_name.data(), info.layer_name.size());
  for (std::uint64_t c = 0; c < h.chunk_count; ++c) {
    const std::uint64_t first = h.data_offset + (c << h.chunk_shift);
    const std::size_t bytes = std::min<std::uint64_t>(h.file_size - first, 1ull << h.chunk_shift);
    const std::uint64_t sum = hash_bytes(data_bytes_at(first, bytes), bytes);
    put(h.checks_offset + 8 * c, &sum, 8);
  }
  h.front_checksum = hash_bytes(front.data(), front.size());
  h.header_checksum = hash_bytes(&h, offsetof(SidecarHeader, header_checksum));

  AtomicFile out(path);
  write_all(out.fd(), &h, sizeof h, path);
  write_all(out.fd(), front.data(), front.size(), path);
  static constexpr std::array<std::byte, kAlign> zeros{};
  std::uint64_t at = h.data_offset;
  for (const Piece& p : pieces) {
    write_all(out.fd(), zeros.data(), p.offset - at, path);  // at most kAlign - 1 bytes
    write_all(out.fd(), p.data, p.size, path);
    at = p.offset + p.size;
  }
  write_all(out.fd(), zeros.data(), h.file_size - at, path);
  out.commit();
}

Sidecar Sidecar::open(const std::string& path) {
  const auto m = map_file(path);
  auto refuse = [&](const std::string& why) -> Error {
    return Error(path + ": " + why + "; run 'loci index' to rebuild it");
  };
  if (m->size < sizeof(SidecarHeader)) {
    if (m->size >= 8 && std::memcmp(m->data, kMagic, 8) == 0)
      throw refuse("truncated index file (" + std::to_string(m->size) + " bytes)");
    throw Error(path + ": not a loci index file");
  }
  SidecarHeader h;
  std::memcpy(&h, m->data, sizeof h);
  if (std::memcmp(h.magic, kMagic, 8) != 0) throw Error(path + ": not a loci index file");
  if (h.byte_order != kByteOrder) throw refuse("index written on a machine of other byte order");
  if (h.version > kVersion && h.version < 1000)
    throw Error(path + ": index format version " + std::to_string(h.version) +
                ", written by a newer loci (this one reads " + std::to_string(kVersion) +
                "); use that loci, or run 'loci index' to rebuild it");
  if (h.version != kVersion)
    throw refuse("index format version " + std::to_string(h.version) + ", this loci reads " +
                 std::to_string(kVersion));
  if (h.header_checksum != hash_bytes(&h, offsetof(SidecarHeader, header_checksum)))
    throw refuse("corrupt index file (header checksum mismatch)");
  if (h.file_size != m->size)
    throw refuse(std::string(m->size < h.file_size ? "truncated" : "damaged") + " index file (" +
                 std::to_string(m->size) + " bytes, header says " + std::to_string(h.file_size) +
                 ")");
  if (h.structure != kStructurePackedRTree || h.coordinate_type != kCoordFloat64 ||
      h.dimension != 2 || h.node_size != PackedRTree2::node_size || h.packing > 1 || h.per > 1)
    throw refuse("index of a structure this loci does not read");
  const std::uint64_t node = PackedRTree2::node_size;
  const std::uint64_t expect_blocks =
      h.item_count >= (1ull << 32) ? 0 : PackedRTree2::block_count(std::size_t(h.item_count));
  const std::uint64_t expect_slots =
      h.item_count == 0 ? 0 : (h.item_count + node - 1) / node * node;
  using Block = PackedRTree2::Block;
  auto fits = [&](std::uint64_t offset, std::uint64_t count, std::uint64_t size) {
    return offset % 8 == 0 && offset >= sizeof(SidecarHeader) && offset <= m->size &&
           count <= (m->size - offset) / size;
  };
  const bool chunks_fit =
      h.chunk_shift >= kMinChunkShift && h.chunk_shift <= kMaxChunkShift &&
      h.data_offset == h.blocks_offset && h.data_offset <= m->size && h.checks_offset % 8 == 0 &&
      h.checks_offset >= h.name_offset + h.name_size && fits(h.checks_offset, h.chunk_count, 8) &&
      h.checks_offset + 8 * h.chunk_count <= h.data_offset &&
      h.chunk_count ==
          (m->size == h.data_offset ? 0 : ((m->size - h.data_offset - 1) >> h.chunk_shift) + 1);
  // The hierarchies: only in a per-segment index of at least one item, one root per feature
  // and at most one feature per item, after the records and ending the file.
  const bool hierarchical = h.hierarchy_offset != 0;
  const std::uint64_t records_end =
      h.records_offset + 16 * std::min<std::uint64_t>(h.item_count, m->size / 16);
  const bool hierarchies_fit =
      !hierarchical ? h.hierarchy_features == 0 && h.hierarchy_nodes == 0 &&
                          h.hierarchy_levels == 0 && h.hull_count == 0 && h.file_size == records_end
                    : h.per == std::uint8_t(Per::segment) && h.item_count > 0 &&
                          h.hierarchy_offset == align_up(records_end) && h.hierarchy_features > 0 &&
                          h.hierarchy_features <= h.item_count &&
                          h.hierarchy_features <= m->size / 16 && h.hierarchy_levels > 0 &&
                          h.hierarchy_levels <= 64 && h.hierarchy_nodes >= h.hierarchy_features &&
                          h.hierarchy_nodes <= m->size / sizeof(HierarchyNode) &&
                          h.hull_count <= m->size / sizeof(Point2) &&
                          hierarchy_layout(h.hierarchy_offset, h.hierarchy_features,
                                           h.hierarchy_levels, h.hierarchy_nodes, h.hull_count)
                                  .end == h.file_size;
  if (h.item_count >= (1ull << 32) || h.block_count != expect_blocks ||
      h.slot_count != expect_slots || h.blocks_offset % kAlign != 0 ||
      !fits(h.name_offset, h.name_size, 1) ||
      !fits(h.blocks_offset, h.block_count, sizeof(Block)) ||
      !fits(h.items_offset, h.slot_count, 4) || !fits(h.records_offset, h.item_count, 16) ||
      !chunks_fit || !hierarchies_fit)
    throw refuse("corrupt index file (inconsistent sizes)");
  // Each section where the writer puts it, from the 64-byte boundary after the one before (the
  // sizes are within the file, checked above): a forged offset that would read one section
  // as another, or a section a few bytes off, is refused whatever its checksums.
  if (h.name_offset != sizeof(SidecarHeader) ||
      h.checks_offset != align_up(h.name_offset + h.name_size) ||
      h.data_offset != align_up(h.checks_offset + 8 * h.chunk_count) ||
      h.items_offset != align_up(h.blocks_offset + h.block_count * sizeof(Block)) ||
      h.records_offset != align_up(h.items_offset + 4 * h.slot_count))
    throw refuse("corrupt index file (sections out of place)");
  // The name and the checksum table are read now; the data only where a query reads it.
  if (h.front_checksum !=
      hash_bytes(m->data + sizeof(SidecarHeader), h.data_offset - sizeof(SidecarHeader)))
    throw refuse("corrupt index file (checksum mismatch)");

  Sidecar s;
  s.info_.per = Per(h.per);
  s.info_.packing = Packing(h.packing);
  s.info_.layer_name.assign(reinterpret_cast<const char*>(m->data + h.name_offset), h.name_size);
  s.info_.has_polygons = (h.flags & kFlagPolygons) != 0;
  s.info_.per_chosen = (h.flags & kFlagPerChosen) != 0;
  s.info_.features = h.feature_count;
  s.info_.items = h.item_count;
  s.info_.bounds = {{h.bounds[0], h.bounds[1]}, {h.bounds[2], h.bounds[3]}};
  s.info_.source = {h.source_size, h.source_mtime_ns, h.source_inode, h.source_hash};
  s.info_.file_size = h.file_size;
  s.info_.chunk_shift = h.chunk_shift;
  auto check = std::make_shared<ChunkCheck>(m, path, h.data_offset, h.checks_offset, h.chunk_shift);
  const auto* blocks = reinterpret_cast<const Block*>(m->data + h.blocks_offset);
  const auto* items = reinterpret_cast<const std::uint32_t*>(m->data + h.items_offset);
  s.records_ = {reinterpret_cast<const ItemRecord*>(m->data + h.records_offset),
                std::size_t(h.item_count)};
  s.items_ = {items, std::size_t(h.slot_count)};
  s.tree_ = PackedRTree2::adopt(std::size_t(h.item_count), Packing(h.packing),
                                {blocks, std::size_t(h.block_count)}, s.items_, check, check.get());
  if (hierarchical) {
    const HierarchyLayout l = hierarchy_layout(h.hierarchy_offset, h.hierarchy_features,
                                               h.hierarchy_levels, h.hierarchy_nodes, h.hull_count);
    auto x = std::make_shared<MappedHierarchies>();
    x->features = std::size_t(h.hierarchy_features);
    x->levels = h.hierarchy_levels;
    x->nodes = std::size_t(h.hierarchy_nodes);
    x->fids = reinterpret_cast<const std::int64_t*>(m->data + l.fids);
    x->level_sizes = reinterpret_cast<const std::uint64_t*>(m->data + l.sizes);
    x->roots = reinterpret_cast<const HierarchyRoot*>(m->data + l.roots);
    x->nodes_at = reinterpret_cast<const HierarchyNode*>(m->data + l.nodes);
    x->path = path;
    x->root_blocks = {reinterpret_cast<const Block*>(m->data + l.root_blocks),
                      std::size_t(l.root_block_count)};
    x->root_items = {reinterpret_cast<const std::uint32_t*>(m->data + l.root_items),
                     std::size_t(l.root_slots)};
    x->hull_first = reinterpret_cast<const std::uint32_t*>(m->data + l.hull_first);
    x->hull_points = reinterpret_cast<const Point2*>(m->data + l.hull_points);
    x->hull_count = h.hull_count;
    s.hierarchies_ = std::move(x);
  }
  s.check_ = check;
  return s;
}

std::span<const ItemRecord> Sidecar::records() const {
  check_->touch(records_.data(), records_.size_bytes());
  return records_;
}

void Sidecar::verify() const {
  check_->touch_all();
  tree_.validate();
  // Queries take the tree's own bounds (LayerIndex::adopt); the header's must be the same.
  if (!(tree_.bounds() == info_.bounds))
    throw Error("corrupt index file (the header's bounds are not the tree's)");
}

}  // namespace loci::io
