// The broad-phase contract: what every structure in broadphase/ takes, reports and promises.
//
// A broad phase holds proxies, each a caller's id (Id, 64 bits) with a closed box. Proxies are
// added, moved and removed at any time, in any order, between or after ticks:
//
//   add(id, box)     a new proxy; throws InvalidArgument when the id is already held
//   move(id, box)    the proxy's new box; throws InvalidArgument for an unknown id
//   remove(id)       false when the id is not held
//   clear()          (where offered) removes every proxy, as remove() of each would
//
// A tick is one call that looks at the boxes as they are now:
//
//   pairs(visitor)          every pair of proxies whose boxes meet (closed: touching counts),
//                           each once, as visitor(a, b) with a < b; the order of the pairs is
//                           the structure's own. The visitor returns false to stop early.
//   update(begin, end)      the pairs that began and the pairs that ended since the previous
//                           update() (the first update() reports every pair as begun), the
//                           same way; written once in detail::PairTracker, which diffs two
//                           sorted pair lists. Stopping early stops the reports, not the
//                           bookkeeping: the next update() diffs against the full current set.
//   query(box, visitor)     every proxy whose box meets `box`, as visitor(id, box), the
//                           WindowVisitor of query.hpp; const, may run concurrently. Throws
//                           InvalidGeometry on a NaN, infinite or inverted box.
//
// Each returns a QueryStats counted the same way by every broad phase: nodes_visited is the
// sweep starts, grid cells or tree nodes examined; entries_tested is the box-against-box
// comparisons made; results is the pairs (or proxies) handed to the visitors.
//
// Proxies are addressed inside a structure by 32-bit slots (detail::ProxyTable), so ids may
// be anything the caller likes (array indices are the fast case). Structures model the
// concept BroadPhase below and end with a static_assert that they do, so that fleet queries
// and benchmarks switch between them with one template parameter.
//
// Thread-safety: query(), size(), contains() and validate() may run concurrently with each
// other; add, move, remove, pairs and update need exclusive access (pairs() sorts, rebuilds
// or refreshes state that later ticks reuse).
#pragma once

#include <compare>
#include <concepts>
#include <cstdint>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/index/query.hpp"

namespace loci {

// An overlapping pair of proxies, a < b.
// Pairs reach a PairVisitor (query.hpp) as visitor(a, b) with a < b.
struct IdPair {
  Id a;
  Id b;
  friend constexpr auto operator<=>(const IdPair&, const IdPair&) = default;
};

namespace detail {
struct PairProbe {
  bool operator()(Id, Id) const;
};
}  // namespace detail

// A broad phase: dynamic proxies, all overlapping pairs per tick, incremental begin/end pairs
// and window queries, over D-dimensional closed boxes.
template <class T>
concept BroadPhase = Index<T> && requires(T& t, const T& c, const Box<T::dimension>& b, Id id) {
  t.add(id, b);
  t.move(id, b);
  { t.remove(id) } -> std::same_as<bool>;
  { c.contains(id) } -> std::same_as<bool>;
  { t.pairs(detail::PairProbe{}) } -> std::same_as<QueryStats>;
  { t.pairs() } -> std::same_as<std::vector<IdPair>>;
  { t.update(detail::PairProbe{}, detail::PairProbe{}) } -> std::same_as<QueryStats>;
  { c.query(b, detail::WindowProbe<T::dimension>{}) } -> std::same_as<QueryStats>;
  { c.query(b) } -> std::same_as<std::vector<Id>>;
};

// The vector overload of pairs(), written once: every pair, in the structure's order.
template <class Pairs>
std::vector<IdPair> collect_pairs(Pairs&& pairs) {
  std::vector<IdPair> out;
  pairs([&](Id a, Id b) { return out.push_back({a, b}), true; });
  return out;
}

}  // namespace loci
