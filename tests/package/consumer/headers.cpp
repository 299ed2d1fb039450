// Every public header of the installed package in one translation unit, and the class
// templates of the structures instantiated whole (every member function, not only those
// main.cpp calls), built with -Wall -Wextra -Werror and the headers taken as the consumer's
// own (not system headers, whose warnings compilers hide): what a user building with strict
// warnings meets.
#include "loci_all_headers.hpp"

namespace loci {
template class PackedRTree<2>;
template class PackedRTree<3>;
template class BasicRTree<2, 16, RStarInsertion>;
template class BasicRTree<3, 16, RStarInsertion>;
template class BasicRTree<2, 16, GuttmanInsertion<QuadraticSplit>>;
template class BasicRTree<2, 16, GuttmanInsertion<LinearSplit>>;
template class KdTree<2>;
template class KdTree<3>;
template class PrQuadtree<2>;
template class PrQuadtree<3>;
template class DynamicAabbTree<2>;
template class DynamicAabbTree<3>;
template class BasicSweepPrune<2, false>;
template class BasicSweepPrune<3, true>;
template class UniformGrid<2>;
template class UniformGrid<3>;
template class TprTree<2>;
template class TprTree<3>;
template class StarTree<2>;
template class MovingGrid<2>;
template class MovingScan<2>;
template class MovingScan<3>;
template class ConflictFinder<2>;
template class ConflictMonitor<2>;
template class ConflictMonitor<3>;
}  // namespace loci

// A motion checked as every moving structure checks its reports.
void loci_consumer_check_motion() {
  loci::check_motion(loci::Motion<2>{});
}
