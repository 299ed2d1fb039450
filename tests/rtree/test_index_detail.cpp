// The shared index machinery: Hilbert keys, radix sort, STR tiling, SoA node tests.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>
#include <random>
#include <stdexcept>
#include <thread>

#include "loci/index/detail/hilbert.hpp"
#include "loci/index/detail/radix_sort.hpp"
#include "loci/index/detail/scratch.hpp"
#include "loci/index/detail/soa_boxes.hpp"
#include "loci/index/detail/str_partition.hpp"
#include "support/random_data.hpp"

using namespace loci;
using namespace loci::detail;

namespace {

// The cells of the 2^k-wide corner cube must take the first 2^(kD) keys, each cell one key,
// and consecutive keys must name face-adjacent cells: the defining property of the curve.
template <int D, class Key>
void expect_hilbert_walk(int k, Key key) {
  const std::uint32_t side = 1u << k;
  std::size_t cells = 1;
  for (int a = 0; a < D; ++a)
    cells *= side;
  std::vector<std::pair<std::uint64_t, std::array<std::uint32_t, D>>> walk;
  for (std::size_t c = 0; c < cells; ++c) {
    std::array<std::uint32_t, D> x;
    std::size_t rest = c;
    for (int a = 0; a < D; ++a)
      x[a] = std::uint32_t(rest % side), rest /= side;
    walk.push_back({key(x), x});
  }
  std::sort(walk.begin(), walk.end());
  for (std::size_t i = 0; i < walk.size(); ++i) {
    ASSERT_EQ(walk[i].first, i);
    if (i == 0) continue;
    int steps = 0;
    for (int a = 0; a < D; ++a)
      steps += std::abs(int(walk[i].second[a]) - int(walk[i - 1].second[a]));
    ASSERT_EQ(steps, 1) << "keys " << i - 1 << " and " << i << " are not adjacent";
  }
}

}  // namespace

TEST(Hilbert, TableDriven2DIsAHilbertWalk) {
  for (int k : {1, 2, 3, 5, 8})
    expect_hilbert_walk<2>(k, [](auto x) { return hilbert_key_2d(x[0], x[1]); });
}

TEST(Hilbert, Generic2DIsAHilbertWalk) {
  for (int k : {1, 4, 6})
    expect_hilbert_walk<2>(k, [](auto x) {
      std::uint32_t c[2] = {x[0], x[1]};
      return hilbert_key_generic<2>(c);
    });
}

TEST(Hilbert, Generic3DIsAHilbertWalk) {
  for (int k : {1, 3, 5})
    expect_hilbert_walk<3>(k, [](auto x) {
      std::uint32_t c[3] = {x[0], x[1], x[2]};
      return hilbert_key_generic<3>(c);
    });
}

TEST(Hilbert, FullRangeKeysAreDistinctAndBounded) {
  std::mt19937_64 rng(3);
  std::vector<std::uint64_t> keys;
  for (int i = 0; i < 5000; ++i) {
    const std::uint32_t x = rng() & 0xffff, y = rng() & 0xffff;
    keys.push_back(hilbert_key_2d(x, y));
    EXPECT_LT(keys.back(), std::uint64_t(1) << 32);
  }
  EXPECT_EQ(hilbert_key_2d(0, 0), 0u);
  EXPECT_EQ(hilbert_key_2d(0xffff, 0), (std::uint64_t(1) << 32) - 1);  // ends at the far x corner
}

// The grid's cells whatever its extent: wider than a double reaches (max - min overflows),
// narrower than 65535 / DBL_MAX (65535 / extent overflows), flat; points outside it or NaN go to
// its border cells. Extents are powers of two, so that the cells are exact.
TEST(Hilbert, GridOverExtremeExtents) {
  const auto cells = [](std::uint32_t x, std::uint32_t y) { return hilbert_key_2d(x, y); };
  const double big = 0x1p1023, tiny = 0x1p-1010;
  const HilbertGrid<2> wide(Box2{{-big, -big}, {big, big}});
  EXPECT_EQ(wide.key({-big, -big}), cells(0, 0));
  EXPECT_EQ(wide.key({big, big}), cells(0xffff, 0xffff));
  EXPECT_EQ(wide.key({0, -big / 2}), cells(0x7fff, 0x3fff));
  const HilbertGrid<2> narrow(Box2{{0, 0}, {tiny, 1}});
  EXPECT_EQ(narrow.key({0, 0}), cells(0, 0));
  EXPECT_EQ(narrow.key({tiny, 1}), cells(0xffff, 0xffff));
  EXPECT_EQ(narrow.key({tiny / 2, 0.25}), cells(0x7fff, 0x3fff));
  EXPECT_EQ(narrow.key({-1, 2}), cells(0, 0xffff));
  EXPECT_EQ(narrow.key({std::nan(""), 0}), cells(0, 0));
  // A line of points whose region is widened by one ulp (PrQuadtree::build): the flat axis.
  const HilbertGrid<2> line(Box2{{0, 0}, {8, 0x1p-1074}});
  EXPECT_EQ(line.key({8, 0x1p-1074}), cells(0xffff, 0));
  const HilbertGrid<3> wide3(Box3{{-big, -big, -big}, {big, big, big}});
  std::uint32_t corner[3] = {(1u << 21) - 1, (1u << 21) - 1, (1u << 21) - 1};
  EXPECT_EQ(wide3.key({big, big, big}), hilbert_key<3>(corner));
}

TEST(RadixSort, MatchesStableSort) {
  std::mt19937_64 rng(4);
  for (int bits : {5, 32, 63}) {
    std::vector<KeyedIndex> v(20000);
    for (std::uint32_t i = 0; i < v.size(); ++i)
      v[i] = {rng() & ((std::uint64_t(1) << bits) - 1) & ~std::uint64_t(bits == 5 ? 0 : 3), i};
    auto ref = v;
    std::stable_sort(ref.begin(), ref.end(), [](auto& a, auto& b) { return a.key < b.key; });
    radix_sort(v, bits);
    for (std::size_t i = 0; i < v.size(); ++i) {
      ASSERT_EQ(v[i].key, ref[i].key);
      ASSERT_EQ(v[i].index, ref[i].index);
    }
  }
}

// Small inputs are sorted by insertion: the same stable order as the counting passes, at every
// size up to the threshold and just past it, with many equal keys and offset bits.
TEST(RadixSort, SmallInputsMatchStableSort) {
  std::mt19937_64 rng(9);
  for (std::size_t n = 0; n <= kInsertionSortMax + 3; ++n)
    for (int first : {0, 7}) {
      const int bits = 20;
      std::vector<KeyedIndex> v(n);
      for (std::uint32_t i = 0; i < n; ++i)
        v[i] = {(rng() % 16) << (first + 16) | (rng() & ((std::uint64_t(1) << first) - 1)), i};
      auto key = [&](std::uint64_t k) { return (k >> first) & ((std::uint64_t(1) << bits) - 1); };
      auto ref = v;
      std::stable_sort(ref.begin(), ref.end(),
                       [&](auto& a, auto& b) { return key(a.key) < key(b.key); });
      radix_sort(v, first, bits, [](const KeyedIndex& k) { return k.key; });
      for (std::size_t i = 0; i < n; ++i) {
        ASSERT_EQ(v[i].key, ref[i].key) << n;
        ASSERT_EQ(v[i].index, ref[i].index) << n;
      }
    }
}

// The kept second buffer gives the same order as a fresh one, sort after sort, on keys whose
// sorted bits start above bit 0 (the bits below them left in input order).
TEST(RadixSort, KeptBufferAndOffsetBits) {
  std::mt19937_64 rng(6);
  std::vector<KeyedIndex> spare;
  for (int round = 0; round < 4; ++round) {
    const int first = round * 9, bits = 64 - first - 3 * round;
    std::vector<KeyedIndex> v(5000 + 3000 * round);
    for (std::uint32_t i = 0; i < v.size(); ++i)
      v[i] = {rng() >> (round * 3), i};
    auto mask = [&](std::uint64_t k) {
      return bits >= 64 ? k >> first : (k >> first) & ((std::uint64_t(1) << bits) - 1);
    };
    auto ref = v;
    std::stable_sort(ref.begin(), ref.end(),
                     [&](auto& a, auto& b) { return mask(a.key) < mask(b.key); });
    radix_sort(
        v, first, bits, [](const KeyedIndex& k) { return k.key; }, spare);
    for (std::size_t i = 0; i < v.size(); ++i) {
      ASSERT_EQ(v[i].key, ref[i].key) << round;
      ASSERT_EQ(v[i].index, ref[i].index) << round;
    }
  }
}

namespace {
// A type of its own, so that the pool starts empty and the objects alive can be counted.
struct Leased {
  static inline int alive = 0;
  int mark = 0;
  Leased() { ++alive; }
  ~Leased() { --alive; }
};
}  // namespace

// A lease hands back the object the thread's previous lease returned, as it was left; nested
// leases hold different objects; a dropped lease or one ended by an exception destroys its
// object instead of returning it.
TEST(Lease, ReturnsNestsDropsAndForgetsOnExceptions) {
  {
    Lease<Leased> a;
    a->mark = 1;
  }
  EXPECT_EQ(Leased::alive, 1);
  {
    Lease<Leased> b;
    EXPECT_EQ(b->mark, 1);  // the same object, not a new one
    Lease<Leased> c;        // nested: the pool is empty, so a new one
    EXPECT_EQ(c->mark, 0);
    EXPECT_EQ(Leased::alive, 2);
    c->mark = 2;
  }
  EXPECT_EQ(Leased::alive, 2);  // both back in the pool
  {
    Lease<Leased> d, e;
    EXPECT_EQ(d->mark + e->mark, 3);
    e.drop();
  }
  EXPECT_EQ(Leased::alive, 1);
  try {
    Lease<Leased> f;
    f->mark = 7;
    throw std::runtime_error("in the middle of a call");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(Leased::alive, 0);
  {
    Lease<Leased> g;
    EXPECT_EQ(g->mark, 0);
  }
  // A lease taken while an exception is already in flight (in a destructor during unwinding)
  // still returns its object when it ends normally.
  struct Unwinding {
    ~Unwinding() {
      Lease<Leased> h;
      h->mark = 9;
    }
  };
  try {
    Unwinding u;
    throw std::runtime_error("unwinding");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(Leased::alive, 1);
  Lease<Leased> i;
  EXPECT_EQ(i->mark, 9);
}

namespace {
struct LeasedLate {
  static inline std::atomic<int> alive = 0, made = 0;
  LeasedLate() { ++alive, ++made; }
  ~LeasedLate() { --alive; }
};
struct LeasesAtExit {
  ~LeasesAtExit() {
    Lease<LeasedLate> late;
    (void)*late;
  }
};
}  // namespace

// A lease taken at a thread's exit, after the thread's pool is gone (from the destructor of
// a thread-local made before the pool), gets an object of its own and frees it.
TEST(Lease, AfterThePoolIsGone) {
  std::thread([] {
    thread_local LeasesAtExit made_first;
    (void)&made_first;
    Lease<LeasedLate> early;
    (void)*early;
  }).join();
  EXPECT_EQ(LeasedLate::made, 2);  // the late lease did not find the early one's object
  EXPECT_EQ(LeasedLate::alive, 0);
}

// Scratch buffers come back empty with their capacity kept.
TEST(Lease, ScratchComesBackClearedWithItsCapacity) {
  const double* data = nullptr;
  {
    Scratch<double> s;
    s->assign(1000, 1.0);
    data = s->data();
  }
  Scratch<double> t;
  EXPECT_TRUE(t->empty());
  EXPECT_GE(t->capacity(), 1000u);
  EXPECT_EQ(t->data(), data);
}

TEST(StrTile, GroupsAreSlabsThenTiles) {
  std::mt19937_64 rng(5);
  std::vector<Point2> pts(1000);
  for (auto& p : pts)
    p = test::random_point<2>(rng);
  std::vector<std::size_t> cuts;
  for (std::size_t c = 0; c <= 1000; c += 100)
    cuts.push_back(c);  // 10 groups: 4 slabs
  str_tile<2>(pts.data(), std::span<const std::size_t>(cuts),
              [](const Point2& p, int a) { return p[a]; });
  // slabs of 3 groups (300 points) are ordered along x
  for (std::size_t s = 0; s + 1 < 4; ++s) {
    double max_x = -1, next_min_x = 1e18;
    for (std::size_t i = s * 300; i < std::min<std::size_t>(1000, (s + 1) * 300); ++i)
      max_x = std::max(max_x, pts[i][0]);
    for (std::size_t i = (s + 1) * 300; i < std::min<std::size_t>(1000, (s + 2) * 300); ++i)
      next_min_x = std::min(next_min_x, pts[i][0]);
    EXPECT_LE(max_x, next_min_x);
  }
  // within a slab, groups are ordered along y
  for (std::size_t g = 0; g + 1 < 3; ++g) {
    double max_y = -1, next_min_y = 1e18;
    for (std::size_t i = g * 100; i < (g + 1) * 100; ++i)
      max_y = std::max(max_y, pts[i][1]);
    for (std::size_t i = (g + 1) * 100; i < (g + 2) * 100; ++i)
      next_min_y = std::min(next_min_y, pts[i][1]);
    EXPECT_LE(max_y, next_min_y);
  }
}

// The cell of item c on `axis` of a D-axis tiling.
template <int D>
std::uint64_t axis_cell(const CellItem& c, int axis) {
  constexpr int bits = cell_bits<D>();
  return (c.cells >> (bits * axis)) & ((std::uint64_t(1) << bits) - 1);
}

// The slabs of a level of str_tile_cells: runs of `per` groups (single groups on the last axis).
template <int D>
std::size_t groups_per_slab(std::size_t k, int axis) {
  if (axis == D - 1) return 1;
  const auto slabs = std::size_t(std::ceil(std::pow(double(k), 1.0 / (D - axis)) - 1e-9));
  return (k + slabs - 1) / slabs;
}

// Reference for str_tile_cells: at each level a stable comparison sort of the whole range by
// the axis's cell, then the same slabs.
template <int D>
void reference_cells(CellItem* base, std::span<const std::size_t> groups, int axis = 0) {
  const std::size_t k = groups.size() - 1;
  if (k <= 1) return;
  std::stable_sort(base + groups.front(), base + groups.back(),
                   [&](const CellItem& x, const CellItem& y) {
                     return axis_cell<D>(x, axis) < axis_cell<D>(y, axis);
                   });
  if (axis == D - 1) return;
  const std::size_t per = groups_per_slab<D>(k, axis);
  for (std::size_t first = 0; first < k; first += per)
    reference_cells<D>(base, groups.subspan(first, std::min(per, k - first) + 1), axis + 1);
}

// The tiling property at every level: no item of a slab has a greater cell on the level's axis
// than an item of the next slab.
template <int D>
void expect_tiled(const CellItem* base, std::span<const std::size_t> groups, int axis = 0) {
  const std::size_t k = groups.size() - 1;
  if (k <= 1) return;
  const std::size_t per = groups_per_slab<D>(k, axis);
  std::uint64_t below = 0;  // the greatest cell of the slabs so far
  for (std::size_t first = 0; first < k; first += per) {
    const std::size_t last = std::min(first + per, k);
    std::uint64_t lo = ~std::uint64_t(0), hi = 0;
    for (std::size_t i = groups[first]; i < groups[last]; ++i) {
      lo = std::min(lo, axis_cell<D>(base[i], axis));
      hi = std::max(hi, axis_cell<D>(base[i], axis));
    }
    if (groups[first] < groups[last]) {
      ASSERT_LE(below, lo) << "axis " << axis << " slab at group " << first;
      below = hi;
    }
    if (axis < D - 1) expect_tiled<D>(base, groups.subspan(first, last - first + 1), axis + 1);
  }
}

template <int D>
void check_cells_tiling(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<CellItem> tmp;
  constexpr int bits = cell_bits<D>();
  for (std::size_t n : {0, 1, 5, 24, 32, 64, 65, 1000, 20000}) {
    // random cells, few distinct cells, all equal, distinct cells on every axis, and buckets
    // of the top bits holding a few items each, tied in the bits below (the sort of a bucket
    // a boundary cuts)
    for (int form = 0; form < 5; ++form) {
      if (form == 3 && n > (std::size_t(1) << bits)) continue;
      std::vector<CellItem> v(n);
      for (std::uint32_t i = 0; i < n; ++i)
        v[i] = {form == 0 ? rng() : form == 1 ? rng() & 0x0003000300030003 : 42, i};
      if (form == 4)
        for (std::uint32_t i = 0; i < n; ++i) {
          v[i].cells = 0;
          for (int a = 0; a < D; ++a)
            v[i].cells |= ((rng() & 0xff) << (bits - 8) | (rng() & 1)) << (bits * a);
        }
      if (form == 3)
        for (int a = 0; a < D; ++a) {
          std::vector<std::uint64_t> c(std::size_t(1) << bits);
          std::iota(c.begin(), c.end(), 0);
          std::shuffle(c.begin(), c.end(), rng);
          for (std::uint32_t i = 0; i < n; ++i)
            v[i].cells = (a == 0 ? 0 : v[i].cells) | c[i] << (bits * a);
        }
      std::vector<std::size_t> groups;
      // Small inputs in groups of two or three, so that their ties meet slab boundaries.
      const std::size_t k =
          std::max<std::size_t>(1, n / (n <= 32 ? 2 + rng() % 2 : 1 + rng() % 40));
      for (std::size_t g = 0; g <= k; ++g)
        groups.push_back(n * g / k);
      auto ref = v;
      str_tile_cells<D>(v.data(), std::span<const std::size_t>(groups), tmp);
      reference_cells<D>(ref.data(), std::span<const std::size_t>(groups));
      const std::string where =
          "D " + std::to_string(D) + " n " + std::to_string(n) + " form " + std::to_string(form);
      // The same items, each whole.
      auto by_index = [](const CellItem& x, const CellItem& y) { return x.index < y.index; };
      auto sorted = v;
      std::sort(sorted.begin(), sorted.end(), by_index);
      for (std::uint32_t i = 0; i < n; ++i)
        ASSERT_EQ(sorted[i].index, i) << where;
      std::vector<CellItem> orig(n);
      for (const CellItem& c : ref)
        orig[c.index] = c;
      for (std::uint32_t i = 0; i < n; ++i)
        ASSERT_EQ(sorted[i].cells, orig[i].cells) << where;
      expect_tiled<D>(v.data(), std::span<const std::size_t>(groups));
      // The first level's slabs hold the items a stable sort gives them, ties included (ties
      // on the first axis are split at a slab boundary by input order).
      if (k > 1) {
        const std::size_t per = groups_per_slab<D>(k, 0);
        for (std::size_t first = 0; first < k; first += per) {
          const std::size_t last = std::min(first + per, k);
          std::vector<std::uint32_t> got, want;
          for (std::size_t i = groups[first]; i < groups[last]; ++i)
            got.push_back(v[i].index), want.push_back(ref[i].index);
          std::sort(got.begin(), got.end());
          std::sort(want.begin(), want.end());
          ASSERT_EQ(got, want) << where << " slab at group " << first;
        }
      }
      // Without ties the groups are those of full sorts at every level, item for item.
      if (form == 3)
        for (std::size_t g = 0; g < k; ++g) {
          std::vector<std::uint32_t> got, want;
          for (std::size_t i = groups[g]; i < groups[g + 1]; ++i)
            got.push_back(v[i].index), want.push_back(ref[i].index);
          std::sort(got.begin(), got.end());
          std::sort(want.begin(), want.end());
          ASSERT_EQ(got, want) << where << " group " << g;
        }
    }
  }
}

TEST(StrTileCells, TilesEveryLevelAsFullSortsWould) {
  check_cells_tiling<2>(11);
  check_cells_tiling<4>(12);
  check_cells_tiling<6>(13);  // 10 bits an axis
}

TEST(SoaBoxes, MasksMatchScalarTests) {
  std::mt19937_64 rng(6);
  SoaBoxes<3, 16> node;
  node.clear();
  const auto boxes = test::make_boxes<3>(test::Shape::uniform, 12, 8);  // 4 slots stay empty
  for (int i = 0; i < 12; ++i)
    node.set(i, boxes[i]);
  for (int q = 0; q < 500; ++q) {
    const auto w = test::random_window<3>(rng, 600);
    std::uint32_t meets = 0, in = 0, holds = 0;
    for (int i = 0; i < 12; ++i) {
      meets |= std::uint32_t(intersects(boxes[i], w)) << i;
      in |= std::uint32_t(within(boxes[i], w)) << i;
      holds |= std::uint32_t(contains(boxes[i], w)) << i;
    }
    ASSERT_EQ(node.intersecting(w), meets);
    ASSERT_EQ(node.inside(w) & 0xfff, in);  // an empty slot lies inside anything
    ASSERT_EQ(node.containing(w), holds);
    double d2[16];
    const Point3 p = test::random_point<3>(rng);
    node.squared_distances(p, d2);
    for (int i = 0; i < 12; ++i)
      ASSERT_DOUBLE_EQ(d2[i], squared_distance(p, boxes[i]));
  }
}
