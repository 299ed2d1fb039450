// MovingGrid<D>: moving points in a uniform grid of their positions at a reference time,
// partitioned by velocity, for update rates the trees cannot sustain.
//
// The update path follows the main-memory grids built for extreme update loads (PGrid,
// Šidlauskas, Šaltenis and Jensen, "Processing of extreme moving-object update and query
// workloads in main memory", VLDB Journal 2014): an update finds its object through an id
// map and moves one record from one cell to another, with no structure above the cells to
// maintain. Predictive queries come from indexing where each object is at a reference time
// t_ref rather than where it was reported, in velocity classes as velocity-partitioned
// indexes do: the velocity range of every axis is cut into `bands` equal bands, and each
// combination of bands (a class) has its own grid. An object of a class whose velocities lie
// in [vlo, vhi] on an axis, at x_ref there at t_ref, is at time s within
// x_ref + [min(vlo, vhi) (s - t_ref), max(...)]: a window at s is looked for in the cells of
// each class shifted back by the class's velocities and widened by the spread of its band
// times |s - t_ref|, and every object of those cells gets the exact test of the contract
// (`inside`, geom/motion.hpp). Windows over an interval and moving windows take the hull of
// that region at the window's two ends (each side is a minimum or maximum of functions linear
// in s). Nearest-n visits each class's cells in rings around the query point shifted the same
// way, nearest ring first across the classes, and stops when no ring can hold a nearer object;
// each class also keeps the extent of its objects' positions at t_ref, which bounds the edge
// cells and every ring from a query point far outside the fleet.
//
// The reference time is clock + horizon / 2 when the grid is laid out, so that queries over
// [clock, clock + horizon] look at most horizon / 2 away from it. A layout (cells sized for
// the count, an axis thinner than a cell's side given one cell, bands for the velocities
// seen, t_ref moved on) costs O(n), so one comes only after at least an eighth as many
// changes as objects since the last, which makes it O(1) a change amortized however the
// clock moves: when the clock has passed t_ref, when that many changes placed objects beyond
// the positions or velocities laid out (a fleet that moves elsewhere or speeds up while the
// clock stands still), when the count doubles or falls to a quarter, and after as many
// changes as objects whatever the clock (so a fleet caught half moved by a layout, spread
// over two places with few cells in each, is laid out again once it has moved on). Between
// layouts the bounds stay exact at every time, before the clock too: only the widening
// grows with |s - t_ref|, and an object whose velocity falls beyond the bands of the last
// layout widens its edge band. Positions are
// extrapolated to t_ref in floating point, and inside() solves for times in absolute time,
// so the regions looked at are padded by 1e-12 of the magnitudes involved (an object at
// 1e100 among objects near 0 makes every query look at most cells: still exact, as slow as
// a scan).
//
// Layout: per cell of each class, a vector of records (report, id, slot); per slot, its cell
// and its index there; an IdMap from ids to slots. Cells are clamped at the grid's edges (an
// object beyond them lies in the edge cell), which keeps every cell index monotone in the
// coordinate, the property the window and ring bounds rest on.
//
// Complexity: insert, update, erase O(1) amortized (an update that stays in its cell writes
// in place); a window visits the cells of its region in every class; nearest-n rings of cells
// until the k-th distance. Memory: (16 + 16 D) bytes an object in its cell, 8 in the slot
// table, plus the id map and the cells' vectors. Thread-safety: const members may run
// concurrently.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "loci/geom/motion.hpp"
#include "loci/index/broadphase/detail/proxy_table.hpp"
#include "loci/index/detail/scratch.hpp"
#include "loci/index/moving/moving_index.hpp"

namespace loci {

template <int D>
struct MovingGridParams {
  double horizon = 60;   // queries are expected over [clock, clock + horizon]
  int bands = 3;         // velocity bands per axis (classes: bands^D)
  double per_cell = 32;  // objects a cell holds on average when the grid is laid out
};

template <int D>
class MovingGrid {
 public:
  static constexpr int dimension = D;
  static constexpr const char* kName = "MovingGrid";

  explicit MovingGrid(const MovingGridParams<D>& p = {}) : params_(p) {
    if (!(p.horizon >= 0) || !(p.horizon <= kMaxCoordinate))
      throw InvalidArgument("MovingGrid: the horizon must be a number from 0 to 1e150");
    if (p.bands < 1 || p.bands > 16)
      throw InvalidArgument("MovingGrid: velocity bands must be between 1 and 16");
    if (!(p.per_cell >= 1) || !std::isfinite(p.per_cell))
      throw InvalidArgument("MovingGrid: objects per cell must be a finite number >= 1");
    classes_ = 1;
    for (int a = 0; a < D; ++a)
      classes_ *= std::uint32_t(p.bands);
  }
  MovingGrid(const MovingGrid&) = default;
  MovingGrid& operator=(const MovingGrid&) = default;
  // Moving leaves `other` empty, keeping its parameters.
  MovingGrid(MovingGrid&& other) noexcept : MovingGrid(other.params_) { swap(other); }
  MovingGrid& operator=(MovingGrid&& other) noexcept {
    MovingGrid(std::move(other)).swap(*this);
    return *this;
  }

  void insert(Id id, const Motion<D>& m) {
    check_motion(m);
    if (map_.find(id) != kNone)
      throw InvalidArgument(std::string(kName) + ": id " + std::to_string(id) + " is already held");
    if (slots_.size() + 1 >= kNone && free_.empty())
      throw InvalidArgument(std::string(kName) + ": too many objects");
    if (cells_.empty()) layout();  // the first object: an empty grid holds no cell
    std::uint32_t s;
    if (!free_.empty()) {
      s = free_.back();
      free_.pop_back();
    } else {
      s = std::uint32_t(slots_.size());
      slots_.push_back({});
    }
    ++count_;
    map_.insert(id, s, count_);
    clock_ = std::max(clock_, m.t);
    put(s, id, m);
    ++changes_;
    maybe_layout();
  }

  void update(Id id, const Motion<D>& m) {
    const std::uint32_t s = map_.find(id);
    if (s == kNone) return insert(id, m);
    check_motion(m);
    clock_ = std::max(clock_, m.t);
    const Point<D> x = reference(m);
    const std::uint32_t c = cell_of(m, x);
    Slot& slot = slots_[s];
    if (c == slot.cell) {
      widen(c, m, x);
      cells_[c][slot.index].m = m;
    } else {
      take(s);
      place(s, id, m, c, x);
    }
    ++changes_;
    maybe_layout();
  }

  bool erase(Id id) {
    const std::uint32_t s = map_.find(id);
    if (s == kNone) return false;
    map_.erase(id);
    take(s);
    free_.push_back(s);
    --count_;
    ++changes_;
    maybe_layout();
    return true;
  }

  void clear() { *this = MovingGrid(params_); }

  bool contains(Id id) const { return map_.find(id) != kNone; }
  std::size_t size() const { return count_; }
  bool empty() const { return count_ == 0; }
  double clock() const { return clock_; }
  const MovingGridParams<D>& params() const { return params_; }
  // The reference time of the present layout, and the layouts made so far.
  double reference_time() const { return t_ref_; }
  std::size_t layouts() const { return layouts_; }
  // The cells of the present layout, over every class (none before the first insertion).
  std::size_t cells() const { return cells_.size(); }

  // The report held for id; throws InvalidArgument when there is none.
  Motion<D> at(Id id) const {
    const std::uint32_t s = map_.find(id);
    if (s == kNone) throw InvalidArgument(std::string(kName) + ": no object " + std::to_string(id));
    return cells_[slots_[s].cell][slots_[s].index].m;
  }

  template <MotionVisitor<D> F>
  QueryStats query(const MovingWindow<D>& w, F&& visit) const {
    check_window(w);
    QueryStats st;
    if (count_ == 0) return st;
    const bool slice = w.t1 == w.t2 && w.from == w.to;
    const double d1 = w.t1 - t_ref_, d2 = w.t2 - t_ref_;
    for (std::uint32_t k = 0; k < classes_; ++k) {
      const Band& b = band_[k];
      if (b.vlo[0] > b.vhi[0]) continue;  // no object has been in this class
      int lo[D], hi[D];
      for (int a = 0; a < D; ++a) {
        // Where x_ref may lie for the object to be in the window at t1 or at t2, and so
        // (each bound linear in the time) at any time between.
        const double w2lo = w.to.min[a], w2hi = w.to.max[a];
        const double l1 = w.from.min[a] - std::max(b.vlo[a] * d1, b.vhi[a] * d1);
        const double u1 = w.from.max[a] - std::min(b.vlo[a] * d1, b.vhi[a] * d1);
        const double l2 = w2lo - std::max(b.vlo[a] * d2, b.vhi[a] * d2);
        const double u2 = w2hi - std::min(b.vlo[a] * d2, b.vhi[a] * d2);
        // Rounding: of the positions at t_ref, of the window's bounds, and of the times
        // inside() solves for in absolute time (at epoch seconds a step of 2^-22 s).
        // (The window's own bounds move too, and are extended to each object's report time.)
        const double pad = kPad * (mag_ +
                                   (vabs_ + std::abs(w.vmin()[a]) + std::abs(w.vmax()[a])) *
                                       (std::abs(d1) + std::abs(d2) + std::abs(w.t1) +
                                        std::abs(w.t2) + std::abs(t_ref_) + tabs_) +
                                   std::abs(w.from.min[a]) + std::abs(w.from.max[a]) +
                                   std::abs(w2lo) + std::abs(w2hi));
        lo[a] = axis_cell(std::min(l1, l2) - pad, a);
        hi[a] = axis_cell(std::max(u1, u2) + pad, a);
      }
      const bool go = for_box(lo, hi, [&](const int* at) {
        const std::vector<Record>& cell = cells_[k * cells_per_class_ + linear(at)];
        ++st.nodes_visited;
        st.entries_tested += cell.size();
        for (const Record& r : cell) {
          const bool in = slice ? intersects(w.from, position(r.m, w.t1)) : inside(r.m, w);
          if (in) {
            ++st.results;
            if (!visit(r.id, r.m)) return false;
          }
        }
        return true;
      });
      if (!go) break;
    }
    return st;
  }
  std::vector<Id> query(const MovingWindow<D>& w) const {
    return collect_ids([&](auto&& v) { return query(w, v); });
  }

  template <MotionNearestVisitor<D> F>
  QueryStats nearest(const Point<D>& q, double s, std::size_t k, F&& visit) const {
    check_point(q, "nearest point");
    detail::check_nearest_time(s);
    detail::check_nearest_count(k);
    QueryStats st;
    if (count_ == 0) return st;
    detail::Lease<NearestScratch> lease;  // nothing allocated per call in steady state
    NearestScratch& x = *lease;
    x.around.resize(classes_);
    x.best.clear();
    x.rings.clear();
    auto& best = x.best;
    auto& rings = x.rings;
    // The k best (squared distance, record) as a max-heap: its top is the k-th.
    auto kth = [&] {
      return best.size() < k ? std::numeric_limits<double>::infinity() : best.front().first;
    };
    const double delta = s - t_ref_;
    for (std::uint32_t c = 0; c < classes_; ++c) {
      const Band& b = band_[c];
      if (b.vlo[0] > b.vhi[0]) continue;  // no object has been in this class
      Around& r = x.around[c];
      // The query point shifted back to t_ref by the middle of the class's velocities, and
      // how far the spread of its velocities (and rounding) moves an object from that.
      for (int a = 0; a < D; ++a) {
        const double mid = 0.5 * b.vlo[a] + 0.5 * b.vhi[a];
        r.q[a] = q[a] - mid * delta;
        r.reach[a] = (0.5 * b.vhi[a] - 0.5 * b.vlo[a]) * std::abs(delta) +
                     kPad * (mag_ + std::abs(q[a]) + std::abs(r.q[a]) +
                             vabs_ * (std::abs(delta) + std::abs(s) + std::abs(t_ref_) + tabs_) +
                             std::abs(origin_[a])) +
                     1e-9 * width_[a];
        r.center[a] = axis_cell(r.q[a], a);
        // How far every object of the class lies from q on this axis, at least.
        r.gap[a] = std::max({0.0, b.lo[a] - r.q[a] - r.reach[a], r.q[a] - b.hi[a] - r.reach[a]});
      }
      rings.push_back({0.0, c, 0});
      std::push_heap(rings.begin(), rings.end(), farther);
    }
    // Rings of cells around each class's shifted point, nearest lower bound first across the
    // classes, until no ring can hold an object nearer than the k-th.
    while (!rings.empty()) {
      std::pop_heap(rings.begin(), rings.end(), farther);
      const Ring ring = rings.back();
      rings.pop_back();
      if (best.size() == k && !(ring.bound < kth())) break;
      const Around& r = x.around[ring.cls];
      for_ring(r.center, ring.r, [&](const int* at) {
        const std::vector<Record>& cell = cells_[ring.cls * cells_per_class_ + linear(at)];
        ++st.nodes_visited;
        if (cell.empty() || (best.size() == k && !(cell_bound(r, at) < kth()))) return;
        st.entries_tested += cell.size();
        for (const Record& rec : cell) {
          const double d2 = squared_distance(position(rec.m, s), q);
          if (best.size() < k) {
            best.push_back({d2, &rec});
            std::push_heap(best.begin(), best.end(), nearer);
          } else if (d2 < best.front().first) {
            std::pop_heap(best.begin(), best.end(), nearer);
            best.back() = {d2, &rec};
            std::push_heap(best.begin(), best.end(), nearer);
          }
        }
      });
      // The next ring's objects lie beyond this ring's block on some axis, and on every axis
      // at least the class's gap away. (Sums only: a bound that overflows stays infinite,
      // and the ring is still visited while fewer than k objects are found.)
      double next = std::numeric_limits<double>::infinity();
      bool more = false;
      for (int a = 0; a < D; ++a) {
        auto beyond = [&](double side) {
          more = true;
          const double g = std::max(side, r.gap[a]);
          double b2 = g * g;
          for (int o = 0; o < D; ++o)
            if (o != a) b2 += r.gap[o] * r.gap[o];
          next = std::min(next, b2);
        };
        if (r.center[a] - ring.r - 1 >= 0)
          beyond(r.q[a] - edge(a, r.center[a] - ring.r) - r.reach[a]);
        if (r.center[a] + ring.r + 1 < int(cells_axis_[a]))
          beyond(edge(a, r.center[a] + ring.r + 1) - r.q[a] - r.reach[a]);
      }
      if (more) {
        rings.push_back({next, ring.cls, ring.r + 1});
        std::push_heap(rings.begin(), rings.end(), farther);
      }
    }
    std::sort_heap(best.begin(), best.end(), nearer);
    for (const auto& [d2, rec] : best) {
      ++st.results;
      detail::check_nearest_distance(d2);
      if (!visit(rec->id, rec->m, std::sqrt(d2))) break;
    }
    return st;
  }
  std::vector<Neighbor> nearest(const Point<D>& q, double s, std::size_t k) const {
    return collect_neighbors([&](auto&& v) { return nearest(q, s, k, v); });
  }

  template <MotionVisitor<D> F>
  void for_each(F&& visit) const {
    for (const std::vector<Record>& cell : cells_)
      for (const Record& r : cell)
        if (!visit(r.id, r.m)) return;
  }

  void validate() const {
    std::size_t held = 0;
    for (std::size_t c = 0; c < cells_.size(); ++c) {
      for (std::uint32_t i = 0; i < cells_[c].size(); ++i) {
        const Record& r = cells_[c][i];
        ++held;
        if (r.slot >= slots_.size() || slots_[r.slot].cell != c || slots_[r.slot].index != i)
          throw Error(std::string(kName) + ": a record's slot does not point back to it");
        if (map_.find(r.id) != r.slot)
          throw Error(std::string(kName) + ": id " + std::to_string(r.id) +
                      " does not map to its slot");
        if (cell_of(r.m) != c)
          throw Error(std::string(kName) + ": id " + std::to_string(r.id) +
                      " is in the wrong cell");
        const Band& b = band_[c / cells_per_class_];
        for (int a = 0; a < D; ++a) {
          if (!(b.vlo[a] <= r.m.v[a] && r.m.v[a] <= b.vhi[a]) || std::abs(r.m.v[a]) > vabs_)
            throw Error(std::string(kName) + ": a velocity lies outside its class's bounds");
          if (!(b.lo[a] <= reference(r.m, a) && reference(r.m, a) <= b.hi[a]))
            throw Error(std::string(kName) + ": a position lies outside its class's bounds");
        }
        if (magnitude(r.m) > mag_ || std::abs(r.m.t) > tabs_)
          throw Error(std::string(kName) + ": a record's magnitude exceeds the grid's");
      }
    }
    if (held != count_) throw Error(std::string(kName) + ": the count does not match the cells");
  }

 private:
  static constexpr double kPad = 1e-12;  // relative padding for rounding (far above 4 ulps)
  static constexpr int kMaxCellsAxis = 4096;

  struct Record {
    Motion<D> m;
    Id id;
    std::uint32_t slot;
  };
  struct Slot {
    std::uint32_t cell = kNone, index = 0;
  };
  // The velocities met in a class since the last layout, per axis (vlo > vhi: none), and
  // the reference positions (lo, hi): the edge cells' contents, bounded.
  struct Band {
    Point<D> vlo, vhi, lo, hi;
  };

  // What a nearest-n query works with, per class and overall.
  struct Around {
    Point<D> q;       // the query point shifted back to t_ref
    double reach[D];  // how far an object of the class lies from its shifted position
    double gap[D];    // how far every object of the class lies from q, at least
    int center[D];    // the cell of q
  };
  struct Ring {
    double bound;  // a lower bound on the squared distance of its objects
    std::uint32_t cls;
    int r;
  };
  struct NearestScratch {
    std::vector<Around> around;
    std::vector<std::pair<double, const Record*>> best;
    std::vector<Ring> rings;
  };
  static bool nearer(const std::pair<double, const Record*>& x,
                     const std::pair<double, const Record*>& y) {
    return x.first < y.first;
  }
  static bool farther(const Ring& x, const Ring& y) { return x.bound > y.bound; }

  // Calls f(cell) for each cell of the box of cell indices [lo, hi] (axis 0 fastest) until f
  // returns false; false when it did.
  template <class F>
  static bool for_box(const int* lo, const int* hi, F&& f) {
    int at[D];
    for (int a = 0; a < D; ++a)
      at[a] = lo[a];
    for (;;) {
      if (!f(static_cast<const int*>(at))) return false;
      int a = 0;
      for (; a < D; ++a) {
        if (at[a] < hi[a]) {
          ++at[a];
          break;
        }
        at[a] = lo[a];
      }
      if (a == D) return true;
    }
  }
  // Calls f(cell) for each cell of the grid at Chebyshev distance r from `center`, once: the
  // first axis at distance r is pinned to one of its two sides, the axes before it range
  // strictly inside, those after it over the whole block.
  template <class F>
  void for_ring(const int* center, int r, F&& f) const {
    for (int pin = 0; pin < D; ++pin) {
      for (int side = 0; side < (r == 0 ? 1 : 2); ++side) {
        const int at_pin = side ? center[pin] + r : center[pin] - r;
        if (at_pin < 0 || at_pin >= int(cells_axis_[pin])) continue;
        int lo[D], hi[D];
        bool none = false;
        for (int a = 0; a < D; ++a) {
          const int inner = a < pin ? r - 1 : r;
          lo[a] = a == pin ? at_pin : std::max(0, center[a] - inner);
          hi[a] = a == pin ? at_pin : std::min(int(cells_axis_[a]) - 1, center[a] + inner);
          none |= lo[a] > hi[a];
        }
        if (none) continue;
        for_box(lo, hi, [&](const int* at) {
          f(at);
          return true;
        });
      }
      if (r == 0) return;  // the center cell alone
    }
  }

  // The object's position at t_ref, on axis a.
  double reference(const Motion<D>& m, int a) const { return m.p[a] + m.v[a] * (t_ref_ - m.t); }
  Point<D> reference(const Motion<D>& m) const {
    Point<D> x;
    for (int a = 0; a < D; ++a)
      x[a] = reference(m, a);
    return x;
  }
  // A bound on the magnitudes of the arithmetic of m's reference position x.
  double magnitude(const Motion<D>& m, const Point<D>& x) const {
    double g = 0;
    for (int a = 0; a < D; ++a)
      g = std::max(g,
                   std::abs(m.p[a]) + std::abs(m.v[a]) * std::abs(t_ref_ - m.t) + std::abs(x[a]));
    return g;
  }
  double magnitude(const Motion<D>& m) const { return magnitude(m, reference(m)); }
  // The cell of coordinate x on axis a, clamped to the grid: monotone in x.
  int axis_cell(double x, int a) const {
    const double f = std::floor((x - origin_[a]) * inverse_[a]);
    if (!(f >= 0)) return 0;  // below the grid (or the grid is one cell wide)
    const double last = double(cells_axis_[a] - 1);
    return f >= last ? int(last) : int(f);
  }
  // The lower edge of cell i on axis a (i > 0).
  double edge(int a, int i) const { return origin_[a] + double(i) * width_[a]; }
  std::uint32_t linear(const int* at) const {
    std::uint32_t i = 0;
    for (int a = D - 1; a >= 0; --a)
      i = i * cells_axis_[a] + std::uint32_t(at[a]);
    return i;
  }
  std::uint32_t class_of(const Motion<D>& m) const {
    std::uint32_t k = 0;
    for (int a = D - 1; a >= 0; --a) {
      const double f = std::floor((m.v[a] - vmin_[a]) * vinverse_[a]);
      const int b = !(f >= 0) ? 0 : f >= double(params_.bands - 1) ? params_.bands - 1 : int(f);
      k = k * std::uint32_t(params_.bands) + std::uint32_t(b);
    }
    return k;
  }
  // The cell of m, x its reference position.
  std::uint32_t cell_of(const Motion<D>& m, const Point<D>& x) const {
    int at[D];
    for (int a = 0; a < D; ++a)
      at[a] = axis_cell(x[a], a);
    return class_of(m) * cells_per_class_ + linear(at);
  }
  std::uint32_t cell_of(const Motion<D>& m) const { return cell_of(m, reference(m)); }
  // A lower bound on the squared distance at the query's time of any object of cell `at` in
  // the class of r.
  double cell_bound(const Around& r, const int* at) const {
    double g2 = 0;
    for (int a = 0; a < D; ++a) {
      double gap = r.gap[a];
      if (at[a] > 0) gap = std::max(gap, edge(a, at[a]) - r.q[a] - r.reach[a]);
      if (at[a] + 1 < int(cells_axis_[a]))
        gap = std::max(gap, r.q[a] - edge(a, at[a] + 1) - r.reach[a]);
      g2 += gap * gap;
    }
    return g2;
  }

  void put(std::uint32_t s, Id id, const Motion<D>& m) {
    const Point<D> x = reference(m);
    place(s, id, m, cell_of(m, x), x);
  }
  // The bounds cell c's class and the grid keep, widened for m (reference position ref).
  void widen(std::uint32_t c, const Motion<D>& m, const Point<D>& ref) {
    Band& b = band_[c / cells_per_class_];
    bool outside = false;
    for (int a = 0; a < D; ++a) {
      const double x = ref[a];
      b.vlo[a] = std::min(b.vlo[a], m.v[a]);
      b.vhi[a] = std::max(b.vhi[a], m.v[a]);
      b.lo[a] = std::min(b.lo[a], x);
      b.hi[a] = std::max(b.hi[a], x);
      vabs_ = std::max(vabs_, std::abs(m.v[a]));
      tabs_ = std::max(tabs_, std::abs(m.t));
      outside |= !(laid_lo_[a] <= x && x <= laid_hi_[a]) ||
                 !(laid_vlo_[a] <= m.v[a] && m.v[a] <= laid_vhi_[a]);
    }
    drift_ += outside;
    mag_ = std::max(mag_, magnitude(m, ref));
  }
  void place(std::uint32_t s, Id id, const Motion<D>& m, std::uint32_t c, const Point<D>& x) {
    widen(c, m, x);
    slots_[s] = {c, std::uint32_t(cells_[c].size())};
    cells_[c].push_back({m, id, s});
  }
  // Takes slot s's record out of its cell (the cell's last record fills the hole).
  void take(std::uint32_t s) {
    const Slot at = slots_[s];
    std::vector<Record>& cell = cells_[at.cell];
    if (at.index + 1 != cell.size()) {
      cell[at.index] = cell.back();
      slots_[cell[at.index].slot].index = at.index;
    }
    cell.pop_back();
    slots_[s] = {};
  }

  // A layout costs O(n + cells), so one follows at least (count + cells) / 8 changes (and
  // O(1) a change amortized, however many classes a few objects have): when the count
  // doubled or fell to a quarter, when the clock passed t_ref, when that many changes placed
  // objects beyond the positions or velocities laid out (a fleet that moved elsewhere, or
  // sped up, while the clock stood still), and after as many changes as objects whatever the
  // clock.
  void maybe_layout() {
    const std::size_t enough = (count_ + cells_.size()) / 8 + 16;
    const bool grew = count_ > 2 * laid_out_ + 16;
    const bool shrank = 4 * count_ + 16 < laid_out_;
    const bool aged = clock_ > t_ref_ && changes_ >= enough;
    const bool turned = changes_ >= count_ + cells_.size() + 16;
    if (grew || shrank || aged || turned || drift_ >= enough) layout();
  }

  // Lays the grid out afresh for the objects held: t_ref, cells and bands.
  void layout() {
    // The records are read from the old cells, moved out (not copied into one list first).
    const std::vector<std::vector<Record>> old = std::move(cells_);
    cells_.clear();
    ++layouts_;
    t_ref_ = std::isfinite(clock_) ? clock_ + 0.5 * params_.horizon : 0.0;
    // Velocity bands over the velocities held, positions' extent at t_ref.
    Point<D> lo, hi, vlo, vhi;
    for (int a = 0; a < D; ++a) {
      lo[a] = vlo[a] = std::numeric_limits<double>::infinity();
      hi[a] = vhi[a] = -std::numeric_limits<double>::infinity();
    }
    for (const std::vector<Record>& cell : old)
      for (const Record& r : cell)
        for (int a = 0; a < D; ++a) {
          const double x = reference(r.m, a);
          lo[a] = std::min(lo[a], x), hi[a] = std::max(hi[a], x);
          vlo[a] = std::min(vlo[a], r.m.v[a]), vhi[a] = std::max(vhi[a], r.m.v[a]);
        }
    const double total = std::max(
        1.0, std::min(double(count_) / (params_.per_cell * double(classes_)), double(1 << 22)));
    // Cells of equal sides over the axes whose extent is at least a side (logarithms: the
    // product of extents near 1e300 would overflow); an axis thinner than a side has one
    // cell, and the side is worked out again over the others, so that the cells number about
    // `total` however thin an axis is.
    bool split[D];
    for (int a = 0; a < D; ++a)
      split[a] = hi[a] > lo[a];
    double side = 1.0;
    for (bool again = true; again;) {
      double log_sum = 0;
      int spread = 0;
      for (int a = 0; a < D; ++a)
        if (split[a]) log_sum += std::log(hi[a] - lo[a]), ++spread;
      if (!spread) break;
      side = std::exp((log_sum - std::log(total)) / spread);
      again = false;
      for (int a = 0; a < D; ++a)
        if (split[a] && hi[a] - lo[a] < side) split[a] = false, again = true;
    }
    cells_per_class_ = 1;
    for (int a = 0; a < D; ++a) {
      origin_[a] = split[a] ? lo[a] : 0.0;
      int n = 1;
      if (split[a]) {
        const double want = std::ceil((hi[a] - lo[a]) / side);
        n = !(want >= 1) ? 1 : want >= kMaxCellsAxis ? kMaxCellsAxis : int(want);
      }
      cells_axis_[a] = std::uint32_t(n);
      width_[a] = n > 1 ? (hi[a] - lo[a]) / n : 1.0;
      inverse_[a] = n > 1 ? double(n) / (hi[a] - lo[a]) : 0.0;
      cells_per_class_ *= std::uint32_t(n);
      vmin_[a] = vhi[a] > vlo[a] ? vlo[a] : 0.0;
      vinverse_[a] = vhi[a] > vlo[a] ? double(params_.bands) / (vhi[a] - vlo[a]) : 0.0;
    }
    cells_.assign(std::size_t(classes_) * cells_per_class_, {});
    band_.assign(classes_, Band{});
    for (Band& b : band_)
      for (int a = 0; a < D; ++a)
        b.vlo[a] = b.lo[a] = std::numeric_limits<double>::infinity(),
        b.vhi[a] = b.hi[a] = -std::numeric_limits<double>::infinity();
    for (int a = 0; a < D; ++a)
      laid_lo_[a] = lo[a], laid_hi_[a] = hi[a], laid_vlo_[a] = vlo[a], laid_vhi_[a] = vhi[a];
    mag_ = 0;
    vabs_ = 0;
    tabs_ = 0;
    for (const std::vector<Record>& cell : old)
      for (const Record& r : cell)
        put(r.slot, r.id, r.m);
    laid_out_ = count_;
    changes_ = 0;
    drift_ = 0;
  }

  void swap(MovingGrid& other) noexcept {
    std::swap(params_, other.params_);
    std::swap(classes_, other.classes_);
    std::swap(cells_per_class_, other.cells_per_class_);
    std::swap(cells_axis_, other.cells_axis_);
    std::swap(origin_, other.origin_);
    std::swap(width_, other.width_);
    std::swap(inverse_, other.inverse_);
    std::swap(vmin_, other.vmin_);
    std::swap(vinverse_, other.vinverse_);
    cells_.swap(other.cells_);
    band_.swap(other.band_);
    slots_.swap(other.slots_);
    free_.swap(other.free_);
    std::swap(map_, other.map_);
    std::swap(count_, other.count_);
    std::swap(laid_out_, other.laid_out_);
    std::swap(changes_, other.changes_);
    std::swap(layouts_, other.layouts_);
    std::swap(drift_, other.drift_);
    std::swap(laid_lo_, other.laid_lo_);
    std::swap(laid_hi_, other.laid_hi_);
    std::swap(laid_vlo_, other.laid_vlo_);
    std::swap(laid_vhi_, other.laid_vhi_);
    std::swap(t_ref_, other.t_ref_);
    std::swap(mag_, other.mag_);
    std::swap(vabs_, other.vabs_);
    std::swap(tabs_, other.tabs_);
    std::swap(clock_, other.clock_);
  }
  MovingGridParams<D> params_;
  std::uint32_t classes_ = 1, cells_per_class_ = 1;
  std::uint32_t cells_axis_[D] = {};
  double origin_[D] = {}, width_[D] = {}, inverse_[D] = {};
  double vmin_[D] = {}, vinverse_[D] = {};
  std::vector<std::vector<Record>> cells_;  // class-major, then cells (axis 0 fastest)
  std::vector<Band> band_;
  std::vector<Slot> slots_;
  std::vector<std::uint32_t> free_;
  detail::IdMap map_;
  std::size_t count_ = 0, laid_out_ = 0, changes_ = 0, layouts_ = 0, drift_ = 0;
  // The extent of the reference positions and velocities at the last layout.
  double laid_lo_[D] = {}, laid_hi_[D] = {}, laid_vlo_[D] = {}, laid_vhi_[D] = {};
  double t_ref_ = 0, mag_ = 0, vabs_ = 0, tabs_ = 0;
  double clock_ = -std::numeric_limits<double>::infinity();
};

static_assert(MovingIndex<MovingGrid<2>>);
static_assert(MovingIndex<MovingGrid<3>>);

}  // namespace loci
