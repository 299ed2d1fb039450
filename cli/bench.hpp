// `loci bench`: a user's own layer on loci and on Boost.Geometry's rtree, side by side.
// (Part of the loci executable only: the installed library carries no peer.)
//
// The layer's boxes (per feature or per segment) go into loci's packed R-tree (Hilbert) and
// into boost::geometry::index::rtree with its bulk-loading constructor and the R* parameters
// at the same fan-out (16), the fairest peer: both are packed, both are queried with the
// same windows and points from one fixed seed. Windows are centred on random entries with a
// size drawn so that answers range from a handful to a few hundred boxes. Every answer count
// is compared, so a faster wrong answer cannot pass unnoticed.
#pragma once

#include <cstddef>
#include <string>

#include "loci/io/layer_reader.hpp"

namespace loci::io {

struct BenchOptions {
  std::string layer_path;
  std::string layer_name;
  Per per = Per::segment;
  std::size_t queries = 10000;
  std::size_t k = 10;
  Progress progress;
};

// Returns the report as text; throws Error when the two libraries disagree.
std::string bench_layer(const BenchOptions& options);

}  // namespace loci::io
