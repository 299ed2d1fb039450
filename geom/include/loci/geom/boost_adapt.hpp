// Registers loci::Point<D>, loci::Box<D> and loci::Segment<D> with Boost.Geometry, so that
// Boost algorithms (distance, intersects, within, the rtree, ...) accept loci's types and
// loci code can be checked against Boost on the same objects.
#pragma once

#include <boost/geometry/core/access.hpp>
#include <boost/geometry/core/coordinate_dimension.hpp>
#include <boost/geometry/core/coordinate_system.hpp>
#include <boost/geometry/core/coordinate_type.hpp>
#include <boost/geometry/core/cs.hpp>
#include <boost/geometry/core/tag.hpp>
#include <boost/geometry/core/tags.hpp>
#include <boost/mpl/int.hpp>

#include "loci/geom/box.hpp"
#include "loci/geom/point.hpp"
#include "loci/geom/segment.hpp"

namespace boost::geometry::traits {

template <int D>
struct tag<loci::Point<D>> {
  using type = point_tag;
};
template <int D>
struct coordinate_type<loci::Point<D>> {
  using type = double;
};
template <int D>
struct coordinate_system<loci::Point<D>> {
  using type = cs::cartesian;
};
template <int D>
struct dimension<loci::Point<D>> : boost::mpl::int_<D> {};
template <int D, std::size_t I>
struct access<loci::Point<D>, I> {
  static double get(const loci::Point<D>& p) { return p.c[I]; }
  static void set(loci::Point<D>& p, double v) { p.c[I] = v; }
};

template <int D>
struct tag<loci::Box<D>> {
  using type = box_tag;
};
template <int D>
struct point_type<loci::Box<D>> {
  using type = loci::Point<D>;
};
template <int D, std::size_t I>
struct indexed_access<loci::Box<D>, min_corner, I> {
  static double get(const loci::Box<D>& b) { return b.min.c[I]; }
  static void set(loci::Box<D>& b, double v) { b.min.c[I] = v; }
};
template <int D, std::size_t I>
struct indexed_access<loci::Box<D>, max_corner, I> {
  static double get(const loci::Box<D>& b) { return b.max.c[I]; }
  static void set(loci::Box<D>& b, double v) { b.max.c[I] = v; }
};

template <int D>
struct tag<loci::Segment<D>> {
  using type = segment_tag;
};
template <int D>
struct point_type<loci::Segment<D>> {
  using type = loci::Point<D>;
};
template <int D, std::size_t I>
struct indexed_access<loci::Segment<D>, 0, I> {
  static double get(const loci::Segment<D>& s) { return s.a.c[I]; }
  static void set(loci::Segment<D>& s, double v) { s.a.c[I] = v; }
};
template <int D, std::size_t I>
struct indexed_access<loci::Segment<D>, 1, I> {
  static double get(const loci::Segment<D>& s) { return s.b.c[I]; }
  static void set(loci::Segment<D>& s, double v) { s.b.c[I] = v; }
};

}  // namespace boost::geometry::traits
