// `loci intersections`: where the linework of a layer crosses itself, or meets another layer's
// (DESIGN.md sections 4 and 6). Lines and the rings of polygons are linework; points are not.
//
// Every pair of features whose linework shares at least one point is reported with the points
// they share: a crossing or touching point once, a collinear overlap by its two ends. Within
// one layer the pair is (fid_a, fid_b) with fid_a < fid_b, and a feature whose linework meets
// itself other than where consecutive segments join is reported as (fid, fid); between two
// layers fid_a is from the first, fid_b from the second. Rows are sorted by fid_a, fid_b, x, y
// and a point shared by several segment pairs of the same two features comes once.
//
// Exact: candidate segment pairs come from a sort-and-sweep join of their boxes and each is
// decided by the exact segment intersection (index/segment_intersections.hpp); crossing points
// are the true points rounded to the nearest double.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>
#include <tuple>
#include <vector>

#include "loci/geom/point.hpp"
#include "loci/geom/segment.hpp"
#include "loci/io/layer_reader.hpp"
#include "loci/io/output.hpp"
#include "loci/io/progress.hpp"

namespace loci::io {

struct IntersectionsOptions {
  std::string layer_path;
  std::string layer_name;
  std::string other_path;  // empty: the layer against itself
  std::string other_name;
  Format format = Format::csv;  // csv or geojson
  bool pairs_only = false;      // feature pairs without points
  std::string out_path;         // empty: the fallback stream
  unsigned jobs = 0;            // threads; 0: one per core
  Progress progress;            // over the features read
};

struct IntersectionRow {
  std::int64_t fid_a;
  std::int64_t fid_b;
  Point2 p;
  auto key() const { return std::tuple(fid_a, fid_b, p[0], p[1]); }
  friend bool operator<(const IntersectionRow& r, const IntersectionRow& s) {
    return r.key() < s.key();
  }
  friend bool operator==(const IntersectionRow& r, const IntersectionRow& s) {
    return r.key() == s.key();
  }
};

// A layer's linework as read (read_segments), with which segments are consecutive in one line
// or ring: the pairs a self-intersection search does not report for their shared vertex.
struct Linework {
  std::vector<Segment2> segs;
  std::vector<std::int64_t> fid;
  std::vector<std::uint32_t> first, last;  // the first and last segment of each one's line

  explicit Linework(const std::vector<SegmentRecord>& records);
  // Consecutive segments of one line or ring, the closing pair of a closed one included.
  bool adjacent(std::size_t i, std::size_t j) const {
    if (first[i] != first[j]) return false;
    if (i + 1 == j || j + 1 == i) return true;
    const std::size_t lo = std::min(i, j), hi = std::max(i, j);
    return lo == first[i] && hi == last[i] && segs[lo].a == segs[hi].b;
  }
};

// The rows of find_intersections on linework already read (other null: a against itself), on
// `jobs` threads (0: one per core); the rows do not depend on the number of threads.
std::vector<IntersectionRow> intersection_rows(const Linework& a, const Linework* other,
                                               bool pairs_only, unsigned jobs = 0);

// The rows described above (with pairs_only, one row per pair and p unset). Throws loci::Error
// for a layer that cannot be read or holds a NaN or infinite coordinate, and for two layers in
// different coordinate systems. `system`, when given, receives the (first) layer's as WKT.
std::vector<IntersectionRow> find_intersections(const IntersectionsOptions& options,
                                                std::string* system = nullptr);

// find_intersections, written as CSV (header `fid_a,fid_b,x,y`, or `fid_a,fid_b`) or as GeoJSON
// points with both FIDs. Returns the number of rows. Throws InvalidArgument for -f ids.
std::size_t write_intersections(const IntersectionsOptions& options, std::FILE* fallback);

}  // namespace loci::io
