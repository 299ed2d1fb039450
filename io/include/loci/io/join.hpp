// Spatial joins of two layers: every pair (left feature, right feature) whose geometries
// satisfy a predicate, decided exactly (DESIGN.md sections 4 and 6).
//
//   intersects   the geometries share a point (closed: touching counts)
//   contains     every point of the right feature lies in the left one, boundary included
//                (OGC's covers; exact.hpp's covers())
//   within       every point of the left feature lies in the right one (covered by)
//   dwithin:D    their distance is at most D; the distance is reported
//
//   closest      the pair at the smallest distance (--closest)
//
// Candidates come from a sort-and-sweep join of the features' envelopes (index/sweep_join.hpp),
// the left ones grown by D for dwithin; each candidate is refined on the flattened geometries,
// each prepared once (exact.hpp: the edges of both near the other's envelope joined the same
// way, point tests on edges bucketed by y), so that two big polygons cost what their close
// edges cost, not the product of their sizes. Rows are sorted by (left, right). The closest
// pair starts from an upper bound (each left feature against the right feature whose envelope
// is nearest its envelope's centre), joins the envelopes within that bound and refines them
// nearest envelope first, tightening the bound, until the next envelope distance exceeds it.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "loci/io/exact.hpp"
#include "loci/io/output.hpp"
#include "loci/io/progress.hpp"

namespace loci::io {

// closest: the one pair of features (of the two layers, or two different features of one
// layer when both sides are the same file) at the smallest distance, with that distance.
enum class JoinPredicate : std::uint8_t { intersects, contains, within, dwithin, closest };

struct JoinOptions {
  std::string left_path, left_name;
  std::string right_path, right_name;
  JoinPredicate predicate = JoinPredicate::intersects;
  double distance = 0;          // dwithin
  Format format = Format::csv;  // csv or ids
  std::string out_path;         // empty: the fallback stream
  Progress progress;            // over the candidate pairs
};

struct JoinRow {
  std::int64_t left;
  std::int64_t right;
  double distance;  // dwithin; 0 otherwise
  friend bool operator<(const JoinRow& a, const JoinRow& b) {
    return a.left != b.left ? a.left < b.left : a.right < b.right;
  }
};

// Accepts "intersects", "contains", "within" and "dwithin:D" (D finite, >= 0); throws
// InvalidArgument otherwise.
void parse_join_predicate(const std::string& text, JoinOptions& options);

std::vector<JoinRow> join_layers(const JoinOptions& options);

// A layer's features as a join reads them: FIDs, flattened geometries and envelopes (features
// with an empty geometry skipped), each geometry prepared for the pair tests on first use.
struct JoinLayer {
  std::vector<std::int64_t> fids;
  std::vector<FlatGeometry> geoms;
  std::vector<Box2> boxes;
  std::string path;    // the file read
  std::string system;  // its coordinate system as WKT, empty when it has none

  JoinLayer() = default;
  JoinLayer(JoinLayer&&) noexcept;
  ~JoinLayer();
  const PreparedGeometry& prepared(std::size_t i) const;

 private:
  mutable std::vector<std::unique_ptr<PreparedGeometry>> prepared_;
};

// Throws loci::Error for a layer that cannot be read or holds a NaN or infinite coordinate.
JoinLayer read_join_layer(const std::string& path, const std::string& name = {});

// join_layers on layers already read; `right` null joins `left` with itself (a feature is not
// its own closest).
std::vector<JoinRow> join_layers(const JoinLayer& left, const JoinLayer* right,
                                 JoinPredicate predicate, double distance = 0,
                                 const Progress& progress = {});

// join_layers written as CSV (header `fid_left,fid_right`, plus `distance` for dwithin and
// closest) or as
// ids (`LEFT RIGHT` per line). Returns the number of rows. Throws InvalidArgument for geojson.
std::size_t write_join(const JoinOptions& options, std::FILE* fallback);

}  // namespace loci::io
