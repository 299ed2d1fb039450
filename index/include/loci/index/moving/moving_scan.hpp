// MovingScan<D>: moving objects in flat arrays, every query a vectorized scan.
//
// The baseline every moving index must beat, and the right choice for small fleets or
// update-heavy workloads: an update is a few stores, a query looks at every object. Reports
// are kept as structure-of-arrays (time, position and velocity per axis, each a dense
// std::vector of doubles) so the timeslice test (position at s inside the window) compiles to
// straight-line SIMD: per object D multiply-adds and 2 D comparisons, the hits left-packed
// into a buffer with no branch on the outcome. Windows over an interval and moving windows
// use the exact linear-constraint test of geom/motion.hpp on the same arrays.
//
// Layout and invariants: objects occupy indices [0, size()) densely; erase moves the last
// object into the hole, so the arrays never have gaps; an IdMap (ids that are small array
// indices cost one load) finds an object's index.
//
// Complexity: insert, update, erase O(1); query O(n) (about a nanosecond an object for a
// timeslice); nearest O(n log k). Memory: (8 + 8 + 16 D) bytes an object plus the id map.
// clock() is the latest report time given (no bounds depend on it here).
//
// Thread-safety: const members may run concurrently; queries use per-call scratch.
#pragma once

#include <algorithm>
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
class MovingScan {
 public:
  static constexpr int dimension = D;
  static constexpr const char* kName = "MovingScan";

  MovingScan() = default;
  MovingScan(const MovingScan&) = default;
  MovingScan& operator=(const MovingScan&) = default;
  // Moving leaves `other` empty, as if default-constructed.
  MovingScan(MovingScan&& other) noexcept : MovingScan() { swap(other); }
  MovingScan& operator=(MovingScan&& other) noexcept {
    MovingScan(std::move(other)).swap(*this);
    return *this;
  }

  void insert(Id id, const Motion<D>& m) {
    check_motion(m);
    if (map_.find(id) != kNone)
      throw InvalidArgument(std::string(kName) + ": id " + std::to_string(id) + " is already held");
    if (ids_.size() + 1 >= kNone) throw InvalidArgument(std::string(kName) + ": too many objects");
    const auto i = std::uint32_t(ids_.size());
    ids_.push_back(id);
    t_.push_back(m.t);
    for (int a = 0; a < D; ++a) {
      p_[a].push_back(m.p[a]);
      v_[a].push_back(m.v[a]);
    }
    map_.insert(id, i, ids_.size());
    clock_ = std::max(clock_, m.t);
  }

  void update(Id id, const Motion<D>& m) {
    const std::uint32_t i = map_.find(id);
    if (i == kNone) return insert(id, m);
    check_motion(m);
    store(i, m);
    clock_ = std::max(clock_, m.t);
  }

  bool erase(Id id) {
    const std::uint32_t i = map_.find(id);
    if (i == kNone) return false;
    map_.erase(id);
    const auto last = std::uint32_t(ids_.size() - 1);
    if (i != last) {
      ids_[i] = ids_[last];
      store(i, motion(last));
      map_.erase(ids_[i]);
      map_.insert(ids_[i], i, ids_.size());
    }
    ids_.pop_back();
    t_.pop_back();
    for (int a = 0; a < D; ++a) {
      p_[a].pop_back();
      v_[a].pop_back();
    }
    return true;
  }

  void clear() { *this = MovingScan{}; }

  bool contains(Id id) const { return map_.find(id) != kNone; }
  std::size_t size() const { return ids_.size(); }
  bool empty() const { return ids_.empty(); }
  double clock() const { return clock_; }

  // The report held for id; throws InvalidArgument when there is none.
  Motion<D> at(Id id) const {
    const std::uint32_t i = map_.find(id);
    if (i == kNone) throw InvalidArgument(std::string(kName) + ": no object " + std::to_string(id));
    return motion(i);
  }

  template <MotionVisitor<D> F>
  QueryStats query(const MovingWindow<D>& w, F&& visit) const {
    check_window(w);
    QueryStats st;
    st.nodes_visited = 1;
    const std::size_t n = ids_.size();
    st.entries_tested = n;
    // Leased, not a thread_local: a query from inside a visitor gets a buffer of its own.
    detail::Scratch<std::uint32_t> hits_lease;
    std::vector<std::uint32_t>& hits = *hits_lease;
    hits.resize(std::min<std::size_t>(n, kChunk));
    const bool slice = w.t1 == w.t2 && w.from == w.to;
    for (std::size_t base = 0; base < n; base += kChunk) {
      const std::size_t end = std::min(n, base + kChunk);
      const std::size_t found = slice ? scan_slice(w.from, w.t1, base, end, hits.data())
                                      : scan_moving(w, base, end, hits.data());
      for (std::size_t h = 0; h < found; ++h) {
        ++st.results;
        if (!visit(ids_[hits[h]], motion(hits[h]))) return st;
      }
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
    st.nodes_visited = 1;
    st.entries_tested = ids_.size();
    detail::Scratch<std::pair<double, std::size_t>> lease;
    auto& out = *lease;
    detail::k_smallest(
        ids_.size(), k,
        [&](std::size_t i) {
          const double dt = s - t_[i];
          double dd = 0;
          for (int a = 0; a < D; ++a) {
            const double d = p_[a][i] + v_[a][i] * dt - q[a];
            dd += d * d;
          }
          return dd;
        },
        out);
    for (const auto& [dd, i] : out) {
      ++st.results;
      detail::check_nearest_distance(dd);
      if (!visit(ids_[i], motion(std::uint32_t(i)), std::sqrt(dd))) break;
    }
    return st;
  }
  std::vector<Neighbor> nearest(const Point<D>& q, double s, std::size_t k) const {
    return collect_neighbors([&](auto&& v) { return nearest(q, s, k, v); });
  }

  template <MotionVisitor<D> F>
  void for_each(F&& visit) const {
    for (std::uint32_t i = 0; i < ids_.size(); ++i)
      if (!visit(ids_[i], motion(i))) return;
  }

  void validate() const {
    for (int a = 0; a < D; ++a)
      if (p_[a].size() != ids_.size() || v_[a].size() != ids_.size())
        throw Error(std::string(kName) + ": arrays of different lengths");
    if (t_.size() != ids_.size()) throw Error(std::string(kName) + ": arrays of different lengths");
    for (std::uint32_t i = 0; i < ids_.size(); ++i)
      if (map_.find(ids_[i]) != i)
        throw Error(std::string(kName) + ": id " + std::to_string(ids_[i]) +
                    " does not map to its index");
  }

 private:
  static constexpr std::size_t kChunk = 4096;

  Motion<D> motion(std::uint32_t i) const {
    Motion<D> m{};
    m.t = t_[i];
    for (int a = 0; a < D; ++a) {
      m.p[a] = p_[a][i];
      m.v[a] = v_[a][i];
    }
    return m;
  }
  void store(std::uint32_t i, const Motion<D>& m) {
    t_[i] = m.t;
    for (int a = 0; a < D; ++a) {
      p_[a][i] = m.p[a];
      v_[a][i] = m.v[a];
    }
  }

  // Objects in [base, end) whose position at s lies in b; their indices go to out.
  std::size_t scan_slice(const Box<D>& b, double s, std::size_t base, std::size_t end,
                         std::uint32_t* out) const {
    std::size_t found = 0;
    const double* t = t_.data();
    const double* px = p_[0].data();
    const double* py = p_[1].data();
    const double* vx = v_[0].data();
    const double* vy = v_[1].data();
    for (std::size_t i = base; i < end; ++i) {
      const double dt = s - t[i];
      const double x = px[i] + vx[i] * dt;
      const double y = py[i] + vy[i] * dt;
      // Branch-free: each comparison's 0 or 1.
      unsigned in = unsigned(x >= b.min[0]) & unsigned(x <= b.max[0]) & unsigned(y >= b.min[1]) &
                    unsigned(y <= b.max[1]);
      if constexpr (D == 3) {
        const double z = p_[2][i] + v_[2][i] * dt;
        in &= unsigned(z >= b.min[2]) & unsigned(z <= b.max[2]);
      }
      out[found] = std::uint32_t(i);
      found += in;
    }
    return found;
  }

  std::size_t scan_moving(const MovingWindow<D>& w, std::size_t base, std::size_t end,
                          std::uint32_t* out) const {
    std::size_t found = 0;
    for (std::size_t i = base; i < end; ++i) {
      const Motion<D> m = motion(std::uint32_t(i));
      out[found] = std::uint32_t(i);
      found += inside(m, w);
    }
    return found;
  }

  void swap(MovingScan& other) noexcept {
    std::swap(ids_, other.ids_);
    std::swap(t_, other.t_);
    std::swap(p_, other.p_);
    std::swap(v_, other.v_);
    std::swap(map_, other.map_);
    std::swap(clock_, other.clock_);
  }
  std::vector<Id> ids_;
  std::vector<double> t_;
  std::vector<double> p_[D];
  std::vector<double> v_[D];
  detail::IdMap map_;
  double clock_ = -std::numeric_limits<double>::infinity();
};

static_assert(MovingIndex<MovingScan<2>>);
static_assert(MovingIndex<MovingScan<3>>);

}  // namespace loci
