// Fleet<Index>: a moving index plus the history of every object's reports, so that questions
// about any time are answered from the reports in force then (DESIGN.md section 5).
//
// A report (id, Motion{t, p, v}) says where the object is at t and how it moves until its next
// report. An object's trajectory is therefore piecewise linear: report k is in force over
// [t_k, t_{k+1}), the last one from its time on; before its first report the object does not
// exist. Reports may arrive in any time order: each goes into its object's history in time
// order, and a report at a time already present replaces that one.
//
// The index holds every object's latest report. A query whose times all lie at or after the
// latest report time in the fleet (the index's clock) is answered by the index alone: there,
// every object's latest report is the one in force. Anything earlier is answered exactly from
// the histories: each object's pieces that overlap the query's time are tested on their own
// time span (a window over [t1, t2] meets the object if one of its pieces, limited to where that
// piece is in force, meets it). That costs a pass over the reports, the price of asking about
// the past.
//
// conflicts(D, now, H) takes, for each object, the report in force at `now` (objects that
// have not reported by then are absent) and runs find_conflicts on them.
//
// Thread-safety: const members may run concurrently; report() needs exclusive access.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <utility>
#include <vector>

#include "loci/index/detail/scratch.hpp"
#include "loci/index/moving/conflicts.hpp"
#include "loci/index/moving/moving_index.hpp"

namespace loci {

template <class Index>
requires MovingIndex<Index>
class Fleet {
 public:
  static constexpr int D = Index::dimension;

  explicit Fleet(Index index = Index{}) : index_(std::move(index)) {}
  Fleet(const Fleet&) = default;
  Fleet& operator=(const Fleet&) = default;
  // Moving leaves `other` empty, its index with its parameters.
  Fleet(Fleet&& other) noexcept
      : index_(std::move(other.index_)),
        history_(std::exchange(other.history_, {})),
        reports_(std::exchange(other.reports_, 0)) {}
  Fleet& operator=(Fleet&& other) noexcept {
    Fleet(std::move(other)).swap(*this);
    return *this;
  }

  // Adds a report; the index takes it when it is the object's latest.
  void report(Id id, const Motion<D>& m) {
    check_motion(m);
    auto& h = history_[id];
    auto it = std::lower_bound(h.begin(), h.end(), m.t,
                               [](const Motion<D>& a, double t) { return a.t < t; });
    if (it != h.end() && it->t == m.t)
      *it = m;
    else
      it = h.insert(it, m);
    if (it + 1 == h.end()) index_.update(id, m);
    ++reports_;
  }

  std::size_t size() const { return history_.size(); }
  bool empty() const { return history_.empty(); }
  std::size_t reports() const { return reports_; }
  double clock() const { return index_.clock(); }
  const Index& index() const { return index_; }

  // The report of id in force at time s, or nullptr (no such object, or none by then).
  const Motion<D>* in_force(Id id, double s) const {
    const auto h = history_.find(id);
    return h == history_.end() ? nullptr : in_force(h->second, s);
  }

  template <MotionVisitor<D> F>
  QueryStats query(const MovingWindow<D>& w, F&& visit) const {
    check_window(w);
    if (w.t1 >= index_.clock()) return index_.query(w, visit);
    QueryStats st;
    st.nodes_visited = 1;
    for (const auto& [id, h] : history_) {
      for (std::size_t k = 0; k < h.size(); ++k) {
        // Piece k is in force over [h[k].t, h[k + 1].t) (the last one from its time on).
        const bool next = k + 1 < h.size();
        const double from = std::max(w.t1, h[k].t);
        const double to = next ? std::min(w.t2, h[k + 1].t) : w.t2;
        // The piece ends where the next begins: that instant belongs to the next one.
        const bool open_end = next && to == h[k + 1].t;
        if (from > to || (open_end && from == to)) continue;
        ++st.entries_tested;
        if (!piece_meets(h[k], w, from, to, open_end)) continue;
        ++st.results;
        if (!visit(id, h[k])) return st;
        break;
      }
    }
    return st;
  }
  std::vector<Id> query(const MovingWindow<D>& w) const {
    return collect_ids([&](auto&& v) { return query(w, v); });
  }

  template <MotionNearestVisitor<D> F>
  QueryStats nearest(const Point<D>& q, double s, std::size_t k, F&& visit) const {
    if (s >= index_.clock()) return index_.nearest(q, s, k, visit);
    check_point(q, "nearest point");
    detail::check_nearest_time(s);
    detail::check_nearest_count(k);
    QueryStats st;
    st.nodes_visited = 1;
    detail::Scratch<std::pair<Id, const Motion<D>*>> live_lease;
    detail::Scratch<std::pair<double, std::size_t>> out_lease;
    auto& live = *live_lease;
    auto& out = *out_lease;
    for (const auto& [id, h] : history_)
      if (const Motion<D>* m = in_force(h, s)) live.push_back({id, m});
    st.entries_tested = live.size();
    detail::k_smallest(
        live.size(), k,
        [&](std::size_t i) { return squared_distance(position(*live[i].second, s), q); }, out);
    for (const auto& [d2, i] : out) {
      ++st.results;
      detail::check_nearest_distance(d2);
      if (!visit(live[i].first, *live[i].second, std::sqrt(d2))) break;
    }
    return st;
  }
  std::vector<Neighbor> nearest(const Point<D>& q, double s, std::size_t k) const {
    return collect_neighbors([&](auto&& v) { return nearest(q, s, k, v); });
  }

  // Pairs within D during [now, now + H] among the reports in force at now, sorted, a < b.
  std::vector<Conflict> conflicts(double within, double now, double horizon) const {
    std::vector<Id> ids;
    std::vector<Motion<D>> motions;
    for (const auto& [id, h] : history_)
      if (const Motion<D>* m = in_force(h, now)) {
        ids.push_back(id);
        motions.push_back(*m);
      }
    return find_conflicts<D>(ids, motions, within, now, horizon);
  }

  void validate() const {
    index_.validate();
    if (index_.size() != history_.size())
      throw Error("Fleet: the index and the histories hold different objects");
    for (const auto& [id, h] : history_) {
      if (h.empty()) throw Error("Fleet: an object without reports");
      for (std::size_t k = 1; k < h.size(); ++k)
        if (!(h[k - 1].t < h[k].t)) throw Error("Fleet: a history out of time order");
    }
  }

 private:
  static const Motion<D>* in_force(const std::vector<Motion<D>>& h, double s) {
    auto it = std::upper_bound(h.begin(), h.end(), s,
                               [](double t, const Motion<D>& a) { return t < a.t; });
    return it == h.begin() ? nullptr : &*(it - 1);
  }

  // Whether the piece m meets w at some time of [from, to] (of [from, to) when open_end),
  // within [w.t1, w.t2].
  static bool piece_meets(const Motion<D>& m, const MovingWindow<D>& w, double from, double to,
                          bool open_end) {
    if (w.t1 == w.t2) return inside(m, w);
    const LinearSpan span = meets(m, w);
    return !span.empty() && span.hi >= from && (open_end ? span.lo < to : span.lo <= to);
  }

  void swap(Fleet& other) noexcept {
    std::swap(index_, other.index_);
    std::swap(history_, other.history_);
    std::swap(reports_, other.reports_);
  }
  Index index_;
  std::unordered_map<Id, std::vector<Motion<D>>> history_;  // by id, in time order
  std::size_t reports_ = 0;
};

}  // namespace loci
