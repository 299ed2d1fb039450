// What the windowing structures for map segments share: the segments themselves, a point
// index (the structure's choice: KdTree<2> today) over their 2n endpoints (endpoint 2i + e is
// endpoint e of segment i), and the first half of every windowing query: each segment with an
// endpoint inside the window is reported once, through its first endpoint inside. What remains for
// a structure is the segments that cross the window with both endpoints outside.
#pragma once

#include <concepts>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "loci/geom/error.hpp"
#include "loci/geom/segment.hpp"
#include "loci/index/query.hpp"

namespace loci {

namespace detail {

template <PointIndex Ends>
requires(Ends::dimension == 2) class SegmentEndpoints {
 public:
  SegmentEndpoints() = default;

  // `owner` names the structure in messages. check(i, segment) may throw on a segment the
  // structure does not take. Throws InvalidGeometry on a NaN or infinite coordinate,
  // InvalidArgument for 2^31 - 1 segments or more (ids of endpoints must fit 32 bits).
  template <class Check>
  SegmentEndpoints(std::span<const Segment<2>> segments, const char* owner, Check&& check) {
    if (segments.size() >= 0x7fffffffu)
      throw InvalidArgument(std::string(owner) + " holds at most 2^31 - 2 segments");
    std::vector<Point<2>> ends;
    ends.reserve(2 * segments.size());
    for (std::size_t i = 0; i < segments.size(); ++i) {
      check_segment(segments[i], ("segment " + std::to_string(i)).c_str());
      check(i, segments[i]);
      ends.push_back(segments[i].a);
      ends.push_back(segments[i].b);
    }
    segs_.assign(segments.begin(), segments.end());
    ends_ = Ends::build(ends);
  }

  std::span<const Segment<2>> segments() const { return segs_; }
  // Throws InvalidArgument for an id the structure does not hold.
  const Segment<2>& segment(Id id) const {
    if (id >= segs_.size())
      throw InvalidArgument("no segment with id " + std::to_string(id) + " (ids run from 0 to " +
                            std::to_string(segs_.size()) + " - 1)");
    return segs_[std::size_t(id)];
  }
  std::size_t memory_bytes() const {
    return segs_.size() * sizeof(Segment<2>) + ends_.memory_bytes();
  }

  // Calls visit(id, segment) for every segment with an endpoint in the closed window w, once;
  // adds its work to s and returns false when the visitor stopped.
  template <class Visit>
  bool report_inside(const Box<2>& w, QueryStats& s, Visit& visit) const {
    bool go = true;
    const QueryStats ks = ends_.query(w, [&](Id e, const Box<2>&) {
      const std::size_t i = std::size_t(e / 2);
      if (e % 2 == 1 && intersects(w, segs_[i].a)) return true;
      ++s.results;
      return go = visit(Id(i), segs_[i]);
    });
    s.nodes_visited += ks.nodes_visited;
    s.entries_tested += ks.entries_tested;
    return go;
  }

  // Throws loci::Error, naming `owner`, describing the first broken invariant.
  void validate(const char* owner) const {
    ends_.validate();
    if (ends_.size() != 2 * segs_.size())
      throw Error(std::string(owner) + " invalid: endpoint tree holds " +
                  std::to_string(ends_.size()) + " points for " + std::to_string(segs_.size()) +
                  " segments");
  }

 private:
  std::vector<Segment<2>> segs_;
  Ends ends_;
};

}  // namespace detail
}  // namespace loci
