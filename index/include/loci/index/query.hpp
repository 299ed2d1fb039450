// The one query contract of loci's indexes: what every structure in index/ takes, returns and
// promises, and the concepts that check a structure keeps to it.
//
// Vocabulary. Entries are named by the caller's 64-bit ids (Id). Boxes are closed (touching
// counts). A window query reports the entries in a Relation with a window; a nearest-n query
// reports the k entries nearest a point, nearest first, with their distances (Neighbor).
//
// Visitors. Every query takes a visitor that is called once per reported entry and returns
// false to stop the query early: `bool(Id, const Box<D>&)` for windows (WindowVisitor),
// `bool(Id, const Box<D>&, double distance)` for nearest-n and radius queries
// (NearestVisitor), `bool(Id, const Interval&)` for 1D structures (IntervalVisitor),
// `bool(Id, const Segment<2>&)` for windowing of map segments (SegmentVisitor),
// `bool(Id, const Point<2>&)` for three-sided point queries (PointVisitor). A structure with
// a cell of its own to report (RegionQuadtree) uses Visitor<F, const Cell&>. Every query
// returns a QueryStats; each has a convenience overload that returns the answer as a
// std::vector, written once here (collect_ids, collect_neighbors).
//
// Adding a structure.
// 1. One header in index/include/loci/index/, named after the structure, starting with an
//    essay: what it is, the paper it follows, layout, invariants, complexity, thread-safety.
// 2. Storage in flat arrays indexed by 32-bit integers; a dynamic structure keeps its nodes in
//    detail::NodePool (free list threaded through the nodes). Machinery two structures share
//    (box tests, best-first traversal, Hilbert keys, packing) lives once in index/detail/,
//    which never includes a concrete structure.
// 3. Queries take a visitor from this file and return QueryStats counted as documented below;
//    the vector overloads call collect_ids / collect_neighbors.
// 4. validate() throws loci::Error naming the first broken invariant; bad input throws
//    InvalidGeometry / InvalidArgument (geom/error.hpp).
// 5. A static_assert at the end of the header that the structure models the concepts below
//    that apply (BoxIndex, PointIndex, NearestIndex, DynamicBoxIndex, DynamicPointIndex,
//    IntervalIndex), so that generic code (LayerIndex, benchmarks, the broad phases) can swap
//    one for another.
// 6. Tests against brute force on random data with fixed seeds, on degenerate data and on a
//    real layer (tests/support has the generators and the churn harness).
#pragma once

#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/geom/error.hpp"
#include "loci/geom/segment.hpp"

namespace loci {

// Entries are named by the caller's 64-bit ids (a FID, a rowid, an array index).
using Id = std::uint64_t;

// "No node": the null value of every 32-bit node index in index/.
inline constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

// Which entries a window query reports.
enum class Relation {
  intersects,  // the entry's box meets the window (closed: touching counts)
  within,      // the entry's box lies inside the window
  contains,    // the entry's box contains the window
};

template <int D>
constexpr bool relates(Relation r, const Box<D>& entry, const Box<D>& window) {
  switch (r) {
    case Relation::within:
      return within(entry, window);
    case Relation::contains:
      return contains(entry, window);
    default:
      return intersects(entry, window);
  }
}

// The work a query did, counted the same way by every structure so that structures can be
// compared on it:
// - nodes_visited: nodes (or leaves, or buckets) whose children or entries were examined;
//   a node reported whole because it lies inside the window is not visited.
// - entries_tested: child boxes and entries (occupied slots only) compared against the query,
//   one per comparison, whether it is a box, a point, an interval or a segment.
// - results: entries handed to the visitor, including the one that stopped the query.
struct QueryStats {
  std::size_t nodes_visited = 0;
  std::size_t entries_tested = 0;
  std::size_t results = 0;

  QueryStats& operator+=(const QueryStats& o) {
    nodes_visited += o.nodes_visited;
    entries_tested += o.entries_tested;
    results += o.results;
    return *this;
  }
};

// One answer of a nearest-n or radius query.
struct Neighbor {
  Id id;
  double distance;  // Euclidean distance from the query point to the entry's box
  friend bool operator==(const Neighbor&, const Neighbor&) = default;
};

// An entry of a box index: a box and what it names (the caller's id in a leaf, a child node's
// index inside a tree).
template <int D>
struct Entry {
  Box<D> box;
  std::uint64_t slot;
};

// A closed 1D interval [lo, hi], the entry of the interval and segment trees. Closed like
// Box<D>: intervals sharing an endpoint overlap and a point at an endpoint stabs. lo == hi is
// valid; lo > hi, NaN and infinities are errors.
struct Interval {
  double lo;
  double hi;

  constexpr bool contains(double x) const { return lo <= x && x <= hi; }
  constexpr bool overlaps(const Interval& o) const { return lo <= o.hi && o.lo <= hi; }
  friend constexpr bool operator==(const Interval&, const Interval&) = default;
};

inline std::string to_string(const Interval& iv) {
  return "[" + std::to_string(iv.lo) + ", " + std::to_string(iv.hi) + "]";
}

// Throws InvalidGeometry naming `what` for a NaN/infinite bound or lo > hi.
inline void check_interval(const Interval& iv, const char* what = "interval") {
  if (!std::isfinite(iv.lo) || !std::isfinite(iv.hi))
    throw InvalidGeometry(std::string(what) + " has a NaN or infinite bound: " + to_string(iv));
  if (iv.lo > iv.hi)
    throw InvalidGeometry(std::string(what) + " is inverted (lo > hi): " + to_string(iv));
}

// Throws InvalidGeometry naming `what` for a NaN or infinite value.
inline void check_coordinate(double x, const char* what = "query value") {
  if (!std::isfinite(x)) throw InvalidGeometry(std::string(what) + " is NaN or infinite");
}

// ---- Visitors ----------------------------------------------------------------------------

// A callable taking Args and answering whether the query goes on.
template <class F, class... Args>
concept Visitor = std::predicate<F&, Args...>;

// visitor(a, b) for each reported pair (of ids, or of indices into the inputs of a join);
// false stops.
template <class F>
concept PairVisitor = Visitor<F, Id, Id>;

template <class F, int D>
concept WindowVisitor = Visitor < F,
        Id, const Box<D>
& > ;

template <class F, int D>
concept NearestVisitor = Visitor < F,
        Id, const Box<D>
&, double > ;

template <class F>
concept IntervalVisitor = Visitor<F, Id, const Interval&>;

template <class F>
concept SegmentVisitor = Visitor < F,
        Id, const Segment<2>
& > ;

template <class F>
concept PointVisitor = Visitor < F,
        Id, const Point<2>
& > ;

// The vector overloads of every structure: `query` is called with a visitor that keeps
// everything it is given.
template <class Query>
std::vector<Id> collect_ids(Query&& query) {
  std::vector<Id> out;
  query([&](Id id, const auto&...) { return out.push_back(id), true; });
  return out;
}

template <class Query>
std::vector<Neighbor> collect_neighbors(Query&& query) {
  std::vector<Neighbor> out;
  query([&](Id id, const auto&, double d) { return out.push_back({id, d}), true; });
  return out;
}

// ---- What a structure provides -----------------------------------------------------------

namespace detail {
// Visitor types for the concepts below: declared, never called.
template <int D>
struct WindowProbe {
  bool operator()(Id, const Box<D>&) const;
};
template <int D>
struct NearestProbe {
  bool operator()(Id, const Box<D>&, double) const;
};
struct IntervalProbe {
  bool operator()(Id, const Interval&) const;
};
}  // namespace detail

// Every structure: its size, and a validate() that throws on a broken invariant.
template <class T>
concept Index = requires(const T& t) {
  { t.size() } -> std::convertible_to<std::size_t>;
  { t.empty() } -> std::same_as<bool>;
  t.validate();
};

// Answers window queries over boxes in any Relation.
template <class T>
concept BoxIndex = Index<T> && requires(const T& t, const Box<T::dimension>& w, Relation r) {
  { t.query(w, detail::WindowProbe<T::dimension>{}, r) } -> std::same_as<QueryStats>;
  { t.query(w, r) } -> std::same_as<std::vector<Id>>;
  { t.bounds() } -> std::same_as<Box<T::dimension>>;
};

// Answers window queries over points (every point inside the closed window).
template <class T>
concept PointIndex = Index<T> && requires(const T& t, const Box<T::dimension>& w) {
  { t.query(w, detail::WindowProbe<T::dimension>{}) } -> std::same_as<QueryStats>;
  { t.query(w) } -> std::same_as<std::vector<Id>>;
};

// Answers nearest-n queries, nearest first, and browses entries by increasing distance.
template <class T>
concept NearestIndex = Index<T> &&
    requires(const T& t, const Point<T::dimension>& p, std::size_t k) {
  { t.nearest(p, k, detail::NearestProbe<T::dimension>{}) } -> std::same_as<QueryStats>;
  { t.nearest(p, k) } -> std::same_as<std::vector<Neighbor>>;
  { t.browse(p, detail::NearestProbe<T::dimension>{}) } -> std::same_as<QueryStats>;
};

// A box index that takes insertions and erasures at any time.
template <class T>
concept DynamicBoxIndex = BoxIndex<T> && requires(T& t, const Box<T::dimension>& b, Id id) {
  t.insert(b, id);
  { t.erase(b, id) } -> std::same_as<bool>;
};

// A point index that takes insertions and erasures at any time.
template <class T>
concept DynamicPointIndex = PointIndex<T> && requires(T& t, const Point<T::dimension>& p, Id id) {
  t.insert(p, id);
  { t.erase(p, id) } -> std::same_as<bool>;
};

// A 1D structure answering stabbing queries over intervals.
template <class T>
concept IntervalIndex = Index<T> && requires(const T& t, double x) {
  { t.stab(x, detail::IntervalProbe{}) } -> std::same_as<QueryStats>;
  { t.stab(x) } -> std::same_as<std::vector<Id>>;
};

}  // namespace loci
