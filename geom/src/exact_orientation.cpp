// The exact fallback of loci::orientation (see predicates.hpp).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include "loci/geom/predicates.hpp"

namespace loci::detail {

Orientation orientation_exact(double ax, double ay, double bx, double by, double cx, double cy) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using P = Kernel::Point_2;
  switch (CGAL::orientation(P(ax, ay), P(bx, by), P(cx, cy))) {
    case CGAL::LEFT_TURN:
      return Orientation::counterclockwise;
    case CGAL::RIGHT_TURN:
      return Orientation::clockwise;
    default:
      return Orientation::collinear;
  }
}

}  // namespace loci::detail
