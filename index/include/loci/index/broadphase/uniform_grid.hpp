// UniformGrid<D>: a spatial hash of equal cells, rebuilt every tick.
//
// Space is cut into cubes of side h; each proxy is entered into every cell its box touches,
// the cells are hashed into a table of buckets (Teschner et al., "Optimized spatial hashing
// for collision detection of deformable objects", 2003), and the proxies sharing a cell are
// compared. The grid is unbounded: cells are named by their integer coordinates, so objects
// may leave any world the caller has in mind.
//
// Cell size. Unless the caller fixes it, h is chosen every tick from the boxes: the median of
// their largest extents (sampled), so that a typical box touches at most 2 cells per axis and a
// cell holds a handful of boxes. The seeds of the deformable-models survey (lecture 001) find
// the same optimum: cells about the size of the objects.
//
// One report per pair without a set of reported pairs: boxes a and b that meet share every
// cell that their intersection touches, and the pair is reported only from the cell that holds
// the intersection's min corner. Both boxes are entered in that cell because the cell index of
// a coordinate is monotone, so the pair is found there and nowhere else.
//
// Large boxes. A box touching more than kMaxCells cells is kept out of the grid and compared
// with every proxy instead (O(n) each): one huge box among small ones does not fill thousands
// of cells. Coordinates whose cell index would overflow are clamped to the outermost cells,
// which stay correct (the index is still monotone) and merely get crowded.
//
// Layout per tick: one array of (cell, slot) entries, counting-sorted by bucket into a second
// array, then each bucket's entries compared pairwise. Entries of different cells that hash
// to the same bucket are told apart by their cell key.
//
// Queries: query(box) scans the proxies (O(n)).
//
// Complexity per tick: O(n + entries + sum over cells of occupancy^2) expected, plus
// O(n) per large box. Memory O(n).
//
// Thread-safety as broad_phase.hpp says.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/index/broadphase/broad_phase.hpp"
#include "loci/index/broadphase/detail/pair_tracker.hpp"
#include "loci/index/broadphase/detail/proxy_table.hpp"

namespace loci {

template <int D>
class UniformGrid {
  static_assert(D == 2 || D == 3, "the grid packs 2D or 3D cell coordinates");

 public:
  static constexpr int dimension = D;
  // A box touching more cells than this is compared with every proxy instead.
  static constexpr std::int64_t kMaxCells = D == 2 ? 64 : 216;

  // cell_size <= 0 (the default) chooses the cell size from the boxes at every tick.
  explicit UniformGrid(double cell_size = 0) : fixed_cell_(cell_size > 0 ? cell_size : 0) {
    if (!(cell_size <= 0 || std::isfinite(cell_size)))
      throw InvalidArgument("UniformGrid: cell size must be finite");
  }
  UniformGrid(const UniformGrid&) = default;
  UniformGrid& operator=(const UniformGrid&) = default;
  // Moving leaves `other` empty, keeping its parameters.
  UniformGrid(UniformGrid&& other) noexcept : UniformGrid(other.fixed_cell_) { swap(other); }
  UniformGrid& operator=(UniformGrid&& other) noexcept {
    UniformGrid(std::move(other)).swap(*this);
    return *this;
  }

  void add(Id id, const Box<D>& b) { proxies_.add(id, b, kName); }
  void move(Id id, const Box<D>& b) {
    check_box(b, "proxy box");
    proxies_.set_box(proxies_.slot_of(id, kName), b);
  }
  bool remove(Id id) {
    const std::uint32_t s = proxies_.find(id);
    if (s == kNone) return false;
    proxies_.remove(s);
    return true;
  }
  // Removes every proxy, as remove() would: the next update() reports their pairs as ended.
  void clear() { proxies_.clear(); }

  bool contains(Id id) const { return proxies_.find(id) != kNone; }
  std::size_t size() const { return proxies_.size(); }
  bool empty() const { return size() == 0; }
  // The cell side of the last tick.
  double cell_size() const { return cell_; }

  template <PairVisitor F>
  QueryStats pairs(F&& visit) {
    choose_cell_size();
    fill();
    QueryStats st;
    if (!pairs_in_cells(visit, st)) return st;
    pairs_with_large(visit, st);
    return st;
  }
  std::vector<IdPair> pairs() {
    return collect_pairs([&](auto&& v) { return pairs(v); });
  }

  template <PairVisitor Begin, PairVisitor End>
  QueryStats update(Begin&& begin, End&& end) {
    return tracker_.update([&](auto&& v) { return pairs(v); }, begin, end);
  }

  template <WindowVisitor<D> F>
  QueryStats query(const Box<D>& w, F&& visit) const {
    return proxies_.scan(w, visit);
  }
  std::vector<Id> query(const Box<D>& w) const {
    return collect_ids([&](auto&& v) { return query(w, v); });
  }

  void validate() const {
    proxies_.validate(kName);
    if (!(cell_ > 0) || !std::isfinite(cell_))
      throw Error("UniformGrid: cell size is not positive");
  }

 private:
  static constexpr const char* kName = "UniformGrid";
  // Cell indices are clamped to +-kLimit so that each fits its share of the 64-bit key.
  static constexpr double kLimit = D == 2 ? 1073741823.0 : 1048575.0;
  static constexpr int kBits = D == 2 ? 32 : 21;

  struct Cell {
    std::uint64_t key;   // packed integer cell coordinates (8 bytes)
    std::uint32_t slot;  // the proxy entered in the cell
  };

  std::int64_t index(double x) const {
    return std::int64_t(std::clamp(std::floor(x * inv_cell_), -kLimit, kLimit));
  }
  static std::uint64_t pack(const std::int64_t* c) {
    std::uint64_t k = 0;
    for (int a = 0; a < D; ++a)
      k = (k << kBits) | (std::uint64_t(c[a]) & ((std::uint64_t(1) << kBits) - 1));
    return k;
  }
  std::uint64_t key_of(const Point<D>& p) const {
    std::int64_t c[D];
    for (int a = 0; a < D; ++a)
      c[a] = index(p[a]);
    return pack(c);
  }
  std::uint32_t bucket(std::uint64_t key) const {
    return std::uint32_t((key * 0x9E3779B97F4A7C15ull) >> shift_);
  }

  void choose_cell_size() {
    if (fixed_cell_ > 0) {
      cell_ = fixed_cell_;
    } else {
      sample_.clear();
      const std::uint32_t slots = proxies_.slots();
      const std::uint32_t step = std::max<std::uint32_t>(1, slots / 1024);
      for (std::uint32_t s = 0; s < slots; s += step) {
        if (!proxies_.alive(s)) continue;
        const Box<D>& b = proxies_.box(s);
        double e = 0;
        for (int a = 0; a < D; ++a)
          e = std::max(e, b.extent(a));
        sample_.push_back(e);
      }
      double h = 0;
      if (!sample_.empty()) {
        auto mid = sample_.begin() + sample_.size() / 2;
        std::nth_element(sample_.begin(), mid, sample_.end());
        h = *mid;
      }
      // Boxes of no extent (points) still want cells of a useful size: spread them.
      if (!(h > 0)) h = fallback_cell();
      cell_ = h;
    }
    // Subnormal sides (boxes of extent 1e-310) would make 1 / cell infinite and a coordinate
    // of 0 a NaN cell: cells are at least 2^-1000 wide (any finite coordinate times the
    // inverse is then a number, clamped as the others). A median extent that overflows (boxes
    // from -1e308 to 1e308) gives the widest finite cell instead of an infinite one.
    cell_ = std::clamp(cell_, 0x1p-1000, std::numeric_limits<double>::max());
    inv_cell_ = 1.0 / cell_;
  }

  // For point-like boxes: about one proxy per cell over their bounds.
  double fallback_cell() const {
    Box<D> all = Box<D>::empty();
    for (std::uint32_t s = 0; s < proxies_.slots(); ++s)
      if (proxies_.alive(s)) all.expand(proxies_.box(s));
    double e = 0;
    for (int a = 0; a < D; ++a)
      e = std::max(e, all.is_empty() ? 0.0 : all.extent(a));
    const double n = double(std::max<std::size_t>(1, size()));
    const double h = e / std::pow(n, 1.0 / D);
    return h > 0 && std::isfinite(h) ? h : 1.0;
  }

  // Enters every small proxy into its cells and sorts the entries by bucket.
  void fill() {
    cells_.clear();
    large_.clear();
    for (std::uint32_t s = 0; s < proxies_.slots(); ++s) {
      if (!proxies_.alive(s)) continue;
      const Box<D>& b = proxies_.box(s);
      std::int64_t lo[D], hi[D];
      std::int64_t count = 1;
      for (int a = 0; a < D; ++a) {
        lo[a] = index(b.min[a]);
        hi[a] = index(b.max[a]);
        count *= std::min<std::int64_t>(hi[a] - lo[a] + 1, kMaxCells + 1);
        count = std::min<std::int64_t>(count, kMaxCells + 1);
      }
      if (count > kMaxCells) {
        large_.push_back(s);
        continue;
      }
      std::int64_t c[D];
      for (int a = 0; a < D; ++a)
        c[a] = lo[a];
      for (;;) {
        cells_.push_back({pack(c), s});
        int a = D - 1;
        while (a >= 0 && c[a] == hi[a])
          c[a] = lo[a], --a;
        if (a < 0) break;
        ++c[a];
      }
    }
    const std::size_t want = std::bit_ceil(std::max<std::size_t>(16, 2 * cells_.size()));
    shift_ = 64 - std::countr_zero(want);
    start_.assign(want + 1, 0);
    for (const Cell& e : cells_)
      ++start_[bucket(e.key) + 1];
    for (std::size_t i = 1; i <= want; ++i)
      start_[i] += start_[i - 1];
    sorted_.resize(cells_.size());
    fill_.assign(start_.begin(), start_.end() - 1);
    for (const Cell& e : cells_)
      sorted_[fill_[bucket(e.key)]++] = e;
    if (large_flag_.size() < proxies_.slots()) large_flag_.resize(proxies_.slots());
    std::fill(large_flag_.begin(), large_flag_.end(), 0);
    for (std::uint32_t s : large_)
      large_flag_[s] = 1;
  }

  template <class F>
  bool report(F& visit, std::uint32_t s, std::uint32_t t, QueryStats& st) const {
    ++st.results;
    const Id a = proxies_.id(s), b = proxies_.id(t);
    return a < b ? visit(a, b) : visit(b, a);
  }

  template <class F>
  bool pairs_in_cells(F& visit, QueryStats& st) const {
    const std::size_t buckets = start_.size() - 1;
    for (std::size_t k = 0; k < buckets; ++k) {
      const std::uint32_t first = start_[k], last = start_[k + 1];
      if (last - first < 2) continue;
      ++st.nodes_visited;
      for (std::uint32_t p = first; p < last; ++p) {
        const Cell cp = sorted_[p];
        const Box<D>& bp = proxies_.box(cp.slot);
        for (std::uint32_t q = p + 1; q < last; ++q) {
          const Cell cq = sorted_[q];
          if (cq.key != cp.key) continue;
          ++st.entries_tested;
          const Box<D>& bq = proxies_.box(cq.slot);
          if (!intersects(bp, bq)) continue;
          Point<D> corner;
          for (int a = 0; a < D; ++a)
            corner[a] = std::max(bp.min[a], bq.min[a]);
          if (key_of(corner) != cp.key) continue;
          if (!report(visit, cp.slot, cq.slot, st)) return false;
        }
      }
    }
    return true;
  }

  // Each large box against every proxy; a pair of large boxes from the lower slot.
  template <class F>
  void pairs_with_large(F& visit, QueryStats& st) const {
    for (std::uint32_t s : large_) {
      ++st.nodes_visited;
      const Box<D>& bs = proxies_.box(s);
      for (std::uint32_t t = 0; t < proxies_.slots(); ++t) {
        if (t == s || !proxies_.alive(t) || (large_flag_[t] && t < s)) continue;
        ++st.entries_tested;
        if (intersects(bs, proxies_.box(t)) && !report(visit, s, t, st)) return;
      }
    }
  }

  void swap(UniformGrid& other) noexcept {
    std::swap(proxies_, other.proxies_);
    std::swap(tracker_, other.tracker_);
    std::swap(fixed_cell_, other.fixed_cell_);
    std::swap(cell_, other.cell_);
    std::swap(inv_cell_, other.inv_cell_);
    std::swap(shift_, other.shift_);
    sample_.swap(other.sample_);
    cells_.swap(other.cells_);
    sorted_.swap(other.sorted_);
    start_.swap(other.start_);
    fill_.swap(other.fill_);
    large_.swap(other.large_);
    large_flag_.swap(other.large_flag_);
  }
  detail::ProxyTable<D> proxies_;
  detail::PairTracker tracker_;
  double fixed_cell_ = 0;  // the caller's cell size, or 0 to choose per tick
  double cell_ = 1;        // cell side of the last tick
  double inv_cell_ = 1;
  int shift_ = 60;                    // 64 - log2(bucket count)
  std::vector<double> sample_;        // largest extents of a sample of boxes
  std::vector<Cell> cells_;           // (cell, slot) entries in slot order
  std::vector<Cell> sorted_;          // the same, grouped by bucket
  std::vector<std::uint32_t> start_;  // first entry of each bucket in sorted_, plus the end
  std::vector<std::uint32_t> fill_;   // counting-sort cursors
  std::vector<std::uint32_t> large_;  // slots kept out of the grid
  std::vector<std::uint8_t> large_flag_;
};

static_assert(BroadPhase<UniformGrid<2>>);
static_assert(BroadPhase<UniformGrid<3>>);

}  // namespace loci
