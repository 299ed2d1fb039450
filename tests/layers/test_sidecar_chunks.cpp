// The sidecar's data is verified chunk by chunk as queries read it (format 3): opening reads
// nothing of the data, a small query verifies a few chunks of many, a flipped byte anywhere in
// the data is refused exactly when its chunk is read and never answers, verify() (loci check)
// finds every one, and answers from an intact file equal the in-memory tree's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "loci/io/layer_query.hpp"
#include "loci/io/sidecar.hpp"
#include "support/scratch.hpp"

// The reference: XXH3 as the header computes it in this file (its default instructions).
#define XXH_INLINE_ALL
#include <xxhash.h>

namespace loci::io {
namespace {

struct Fixture {
  std::vector<Box2> boxes;
  std::vector<ItemRecord> records;
  test::Scratch file{"loci-chunks", ".loci"};  // removed with the fixture
  std::string path = file.str();
  std::string bytes;
  std::size_t data_offset = 0;  // where the blocks start in the file
};

// chunk_shift: loci writes 4 KiB chunks (12) and reads files written with 64 KiB ones (16).
Fixture make(std::size_t n, std::uint64_t seed, unsigned chunk_shift = 12) {
  Fixture f;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> pos(0, 1000), size(0, 3);
  for (std::size_t i = 0; i < n; ++i) {
    const Point2 a{pos(rng), pos(rng)};
    f.boxes.push_back({a, {a[0] + size(rng), a[1] + size(rng)}});
    f.records.push_back({std::int64_t(i * 7 + 1), 0, 0});
  }
  const PackedRTree2 tree = PackedRTree2::build(f.boxes);
  SidecarInfo info;
  info.layer_name = "boxes";
  info.items = n;
  info.bounds = tree.bounds();
  info.chunk_shift = chunk_shift;
  write_sidecar(f.path, tree, f.records, info);
  std::ifstream in(f.path, std::ios::binary);
  f.bytes.assign(std::istreambuf_iterator<char>(in), {});
  // The blocks are stored as the tree holds them: find them in the file.
  const auto blocks = tree.blocks();
  const std::string head(reinterpret_cast<const char*>(blocks.data()), 256);
  f.data_offset = f.bytes.find(head);
  EXPECT_NE(f.data_offset, std::string::npos);
  return f;
}

void put(const Fixture& f, const std::string& bytes) {
  std::ofstream(f.path, std::ios::binary | std::ios::trunc) << bytes;
}

std::vector<std::int64_t> window_fids(const Sidecar& s, const Box2& w) {
  std::vector<std::int64_t> out;
  const auto records = s.mapped_records();
  s.tree().query(w, [&](Id id, const Box2&) {
    EXPECT_LT(id, records.size());
    s.check().touch(&records[id], sizeof(ItemRecord));
    out.push_back(records[id].fid);
    return true;
  });
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::int64_t> brute_fids(const Fixture& f, const Box2& w) {
  std::vector<std::int64_t> out;
  for (std::size_t i = 0; i < f.boxes.size(); ++i)
    if (intersects(f.boxes[i], w)) out.push_back(f.records[i].fid);
  std::sort(out.begin(), out.end());
  return out;
}

TEST(SidecarChunks, OpeningReadsNoDataAndASmallQueryAFewChunks) {
  for (const unsigned shift : {12u, 16u}) {
    const Fixture f = make(60000, 1, shift);
    const Sidecar s = Sidecar::open(f.path);
    EXPECT_EQ(s.info().chunk_shift, shift);
    const std::size_t chunks = s.check().chunks();
    EXPECT_EQ(chunks, ((f.bytes.size() - f.data_offset - 1) >> shift) + 1);
    EXPECT_GT(chunks, 40u);
    EXPECT_EQ(s.check().verified(), 0u);
    const Box2 w{{500, 500}, {503, 503}};
    EXPECT_EQ(window_fids(s, w), brute_fids(f, w));
    EXPECT_GT(s.check().verified(), 0u);
    EXPECT_LE(s.check().verified(), 12u) << "of " << chunks;
    s.verify();
    EXPECT_EQ(s.check().verified(), chunks);
  }
}

// Chunks of a page: what a small query hashes is a few pages, not a few 64 KiB chunks.
TEST(SidecarChunks, ASmallQueryHashesFewerBytesInPages) {
  std::size_t bytes[2];
  for (const unsigned shift : {12u, 16u}) {
    const Fixture f = make(60000, 1, shift);
    const Sidecar s = Sidecar::open(f.path);
    for (int i = 0; i < 20; ++i) {
      const Box2 w{{50.0 * i, 40.0 * i}, {50.0 * i + 2, 40.0 * i + 2}};
      EXPECT_EQ(window_fids(s, w), brute_fids(f, w));
    }
    bytes[shift == 16] = s.check().verified() << shift;
  }
  EXPECT_LT(bytes[0] * 4, bytes[1]) << bytes[0] << " bytes against " << bytes[1];
}

TEST(SidecarChunks, ChunksOutsideFourKiBToOneGiBAreNotWritten) {
  for (const unsigned shift : {0u, 11u, 31u, 64u}) {
    Fixture f;
    f.boxes = {{{0, 0}, {1, 1}}};
    f.records = {{1, 0, 0}};
    SidecarInfo info;
    info.items = 1;
    info.chunk_shift = shift;
    EXPECT_THROW(write_sidecar(f.path, PackedRTree2::build(f.boxes), f.records, info),
                 InvalidArgument)
        << shift;
  }
}

// Opening hashes the checksum table whole: chunks grow past 4 KiB only where the table would
// hold more than 2^17 sums, so that opening costs at most that whatever the file's size.
TEST(SidecarChunks, TheChecksumTableStaysWithinOneMiB) {
  constexpr std::uint64_t MiB = 1 << 20;
  EXPECT_EQ(sidecar_chunk_shift(0), 12u);
  EXPECT_EQ(sidecar_chunk_shift(285 * MiB), 12u);
  EXPECT_EQ(sidecar_chunk_shift(512 * MiB), 12u);
  EXPECT_EQ(sidecar_chunk_shift(512 * MiB + 1), 13u);
  EXPECT_EQ(sidecar_chunk_shift(1024 * MiB), 13u);
  EXPECT_EQ(sidecar_chunk_shift(1024 * MiB + 1), 14u);
  EXPECT_EQ(sidecar_chunk_shift(MiB * MiB), 23u);  // 1 TiB: 8 MiB chunks
  EXPECT_EQ(sidecar_chunk_shift(std::uint64_t(1) << 62), 30u);
  EXPECT_EQ(sidecar_chunk_shift(MiB, 16), 16u);  // the least asked for
  EXPECT_EQ(sidecar_chunk_shift(MiB, 40), 30u);
  // Up to 2^47 bytes (128 TiB), where chunks reach 1 GiB.
  for (std::uint64_t bytes = 1; bytes <= (std::uint64_t(1) << 47); bytes = bytes * 3 + 1) {
    const unsigned s = sidecar_chunk_shift(bytes);
    EXPECT_LE(((bytes - 1) >> s) + 1, std::uint64_t(1) << 17) << bytes;
    if (s > 12) EXPECT_GT(((bytes - 1) >> (s - 1)) + 1, std::uint64_t(1) << 17) << bytes;
  }
}

TEST(SidecarChunks, AFlippedByteIsRefusedWhenItsChunkIsRead) {
  for (const unsigned shift : {12u, 16u}) {
    const Fixture f = make(20000, 2, shift);
    std::mt19937_64 rng(3);
    std::size_t refused_small = 0, refused_whole = 0;
    for (int i = 0; i < 40; ++i) {
      std::string bad = f.bytes;
      const std::size_t at = f.data_offset + rng() % (bad.size() - f.data_offset);
      bad[at] = char(bad[at] ^ (1 << (rng() % 8)));
      put(f, bad);
      const Sidecar s = Sidecar::open(f.path);  // the data is not read: opening succeeds
      // The chunk holding the byte is refused as soon as it is touched; the others are not.
      // The records end the file: from them back to the start of the data.
      const std::size_t records_offset = f.bytes.size() - f.records.size() * sizeof(ItemRecord);
      const auto* base = reinterpret_cast<const std::byte*>(s.mapped_records().data()) -
                         (records_offset - f.data_offset);
      const std::byte* flipped = base + (at - f.data_offset);
      EXPECT_THROW(s.check().touch(flipped, 1), Error) << "byte " << at;
      const std::size_t other = (at - f.data_offset + 70000) % (f.bytes.size() - f.data_offset);
      if ((other >> shift) != ((at - f.data_offset) >> shift))
        EXPECT_NO_THROW(s.check().touch(base + other, 1));
      EXPECT_THROW(s.verify(), Error);
      // A fresh mapping: queries answer exactly or are refused, never otherwise.
      const Sidecar t = Sidecar::open(f.path);
      const Box2 w{{double(rng() % 990), double(rng() % 990)}, {0, 0}};
      const Box2 window{w.min, {w.min[0] + 10, w.min[1] + 10}};
      try {
        EXPECT_EQ(window_fids(t, window), brute_fids(f, window)) << "byte " << at;
      } catch (const Error& e) {
        ++refused_small;
        EXPECT_NE(std::string(e.what()).find(f.path), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("corrupt"), std::string::npos) << e.what();
      }
      std::size_t whole_refused = 0;
      try {
        EXPECT_EQ(window_fids(t, t.tree().bounds()), brute_fids(f, t.tree().bounds()));
      } catch (const Error&) {
        ++whole_refused;
      }
      refused_whole += whole_refused;
    }
    // Small windows read few chunks: most flips are elsewhere and do not stop them.
    EXPECT_LT(refused_small, 40u);
    // A whole-layer window reads every leaf, item index and record: nearly all flips stop it.
    EXPECT_GT(refused_whole, 30u);
  }
}

TEST(SidecarChunks, CorruptFrontIsRefusedAtOpen) {
  const Fixture f = make(3000, 4, 16);
  std::mt19937_64 rng(5);
  for (int i = 0; i < 20; ++i) {
    std::string bad = f.bytes;
    const std::size_t at = rng() % f.data_offset;  // header, name, checksum table
    bad[at] = char(bad[at] ^ (1 << (rng() % 8)));
    put(f, bad);
    EXPECT_THROW(Sidecar::open(f.path), Error) << "byte " << at;
  }
  put(f, f.bytes);
  EXPECT_NO_THROW(Sidecar::open(f.path).verify());
}

// A header forged with its own checksum recomputed: `field` (8 bytes of the header holding
// `was`, found by its value) set to `now`.
std::string forged(const Fixture& f, const void* was, const void* now) {
  std::string bytes = f.bytes;
  std::size_t at = std::string::npos;
  for (std::size_t k = 0; k + 8 <= 256; k += 8)
    if (std::memcmp(bytes.data() + k, was, 8) == 0) {
      EXPECT_EQ(at, std::string::npos) << "the value is in the header twice";
      at = k;
    }
  EXPECT_NE(at, std::string::npos);
  if (at == std::string::npos) return bytes;
  std::memcpy(bytes.data() + at, now, 8);
  // The header's checksum is its last field: XXH3 of the bytes before it.
  for (std::size_t k = 248; k > 0; k -= 8) {
    std::uint64_t stored;
    std::memcpy(&stored, f.bytes.data() + k, 8);
    if (stored == XXH3_64bits(f.bytes.data(), k)) {
      const std::uint64_t sum = XXH3_64bits(bytes.data(), k);
      std::memcpy(bytes.data() + k, &sum, 8);
      return bytes;
    }
  }
  ADD_FAILURE() << "no header checksum found";
  return bytes;
}

// Sections read where the header says but the writer never puts them (the item indices read
// from the checksum table) are refused at open, whatever the checksums say.
TEST(SidecarChunks, SectionsOutOfPlaceAreRefusedAtOpen) {
  const Fixture f = make(3000, 4);
  const std::uint64_t items_offset =
      f.data_offset + PackedRTree2::block_count(3000) * sizeof(PackedRTree2::Block);
  ASSERT_EQ(items_offset % 64, 0u);
  const std::uint64_t moved = 320;
  put(f, forged(f, &items_offset, &moved));
  try {
    (void)Sidecar::open(f.path);
    ADD_FAILURE() << "opened";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("out of place"), std::string::npos) << e.what();
  }
}

// Queries take the tree's bounds, not the header's copy, and loci check compares the two.
TEST(SidecarChunks, ForgedBoundsAreNotTakenAndCheckRefusesThem) {
  const Fixture f = make(3000, 5);
  const Box2 truth = PackedRTree2::build(f.boxes).bounds();
  const double max_x = truth.max[0], less = truth.max[0] / 2;
  put(f, forged(f, &max_x, &less));
  const Sidecar s = Sidecar::open(f.path);
  EXPECT_EQ(s.info().bounds.max[0], less);
  EXPECT_THROW(s.verify(), Error);
  const LayerIndex index = LayerIndex::adopt(Sidecar::open(f.path));
  EXPECT_EQ(index.bounds(), truth);
}

// The checksums are XXH3-64 whatever instructions compute them (AVX2 where the processor has
// them): whole buffers and streams fed in uneven pieces, of every length around XXH3's
// internal sizes (16, 128, 240 bytes, 1 KB stripes, 64 KB), against the header's own values.
TEST(SidecarHash, IsXxh3WhateverTheInstructions) {
  EXPECT_EQ(hash_bytes("", 0), 0x2D06800538D394C2ull);  // XXH3-64 of nothing, seed 0
  std::mt19937_64 rng(21);
  std::vector<unsigned char> data(300000);
  for (auto& b : data)
    b = static_cast<unsigned char>(rng());
  std::vector<std::size_t> sizes;
  for (std::size_t n = 0; n <= 1100; ++n)
    sizes.push_back(n);
  for (std::size_t n : {4095, 4096, 4097, 65535, 65536, 65537, 200003, 300000})
    sizes.push_back(n);
  for (const std::size_t n : sizes) {
    const std::uint64_t seed = n % 3 == 0 ? 0 : rng();
    const std::uint64_t want = XXH3_64bits_withSeed(data.data(), n, seed);
    ASSERT_EQ(hash_bytes(data.data(), n, seed), want) << n;
    StreamHash stream(seed);
    for (std::size_t at = 0; at < n;) {
      const std::size_t piece = std::min<std::size_t>(n - at, 1 + rng() % 5000);
      stream.update(data.data() + at, piece);
      at += piece;
    }
    ASSERT_EQ(stream.digest(), want) << n;
  }
}

}  // namespace
}  // namespace loci::io
