// What every loci index query shares: ids, the relation a window query asks for, the result
// of a nearest-n query, the stats a query returns, and the visitor concepts.
//
// A window visitor is called as `bool visit(Id id, const Box<D>& box)` and returns false to
// stop the query; a nearest visitor is called as `bool visit(Id id, const Box<D>& box,
// double distance)`, nearest first. Every query returns a QueryStats.
#pragma once

#include <concepts>
#include <cstddef>
#include <cstdint>

#include "loci/geom/box.hpp"

namespace loci {

// Entries are named by the caller's 64-bit ids (a FID, a rowid, an array index).
using Id = std::uint64_t;

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

struct QueryStats {
  std::size_t nodes_visited = 0;   // nodes whose entries were examined
  std::size_t entries_tested = 0;  // child boxes compared against the query
  std::size_t results = 0;         // entries handed to the visitor
};

struct Neighbor {
  Id id;
  double distance;  // Euclidean distance from the query point to the entry's box
  friend bool operator==(const Neighbor&, const Neighbor&) = default;
};

template <class F, int D>
concept WindowVisitor = std::predicate < F&,
        Id, const Box<D>
& > ;

template <class F, int D>
concept NearestVisitor = std::predicate < F&,
        Id, const Box<D>
&, double > ;

}  // namespace loci
