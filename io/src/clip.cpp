// `loci clip`: the features whose geometry meets a window, each cut to the window with GEOS
// (through OGR), written to a new dataset whose format follows the output's extension.
//
// Clip answers for the features query reports. An invalid polygon (a bowtie) is made valid
// before it is cut, by the even-odd rule over its rings as the queries read it; one whose
// rings meet the window where its area does not is cut as its rings. A feature that only touches
// the window keeps its piece of lower dimension (a polygon sharing an edge leaves a line, a corner
// a point) in formats whose layers hold mixed geometry (GeoJSON, GeoPackage, ...); a shapefile
// holds one geometry type, so there such pieces are dropped and counted. A cut that has parts of
// the feature's dimension keeps only those (the two arms of a U cut off from its bar, without the
// line where the window's edge touches the notch), and the parts left out are counted too.
//
// A polygonal window (--wkt, or the union of a layer's polygons with --window-layer) is the
// windowing problem with a non-rectangular window: the index gives the features meeting the
// window's envelope, the exact test of exact.hpp keeps those that meet the window itself, and
// GEOS cuts them.
#include <algorithm>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <cpl_string.h>

#include "gdal_layer.hpp"
#include "loci/geom/error.hpp"
#include "loci/geom/predicates.hpp"
#include "loci/io/commands.hpp"
#include "shapefile_polygons.hpp"

namespace loci::io {

namespace {

bool polygonal(const OGRGeometry& g) {
  const auto t = wkbFlatten(g.getGeometryType());
  return t == wkbPolygon || t == wkbMultiPolygon;
}

// Adds the polygons of v (a repair's result) to `out`, leaving out what it collapsed to lines
// or points.
void add_polygons_of(const OGRGeometry& v, OGRMultiPolygon& out) {
  const auto vt = wkbFlatten(v.getGeometryType());
  if (vt == wkbPolygon) {
    out.addGeometry(&v);
  } else if (vt == wkbMultiPolygon || vt == wkbGeometryCollection) {
    for (const OGRGeometry* part : *v.toGeometryCollection())
      add_polygons_of(*part, out);
  }
}

// An invalid polygon's area as the queries read it, by the even-odd rule over its rings: each
// ring made valid by itself (a ring that crosses itself encloses what it winds around an odd
// number of times), the rings' areas then combined by symmetric difference. Repairing the
// whole polygon at once dissolves the edges two rings share first: a hole sharing an edge
// with its shell, or repeating it, came out filled. Null when a ring cannot be repaired.
std::unique_ptr<OGRGeometry> even_odd(const OGRPolygon& p) {
  std::vector<std::unique_ptr<OGRGeometry>> areas;
  for (const OGRLinearRing* ring : p) {
    OGRPolygon one;
    one.addRingDirectly(ring->clone());
    one.closeRings();
    const std::unique_ptr<OGRGeometry> v(one.IsValid() ? one.clone() : one.MakeValid());
    if (!v) return nullptr;
    auto parts = std::make_unique<OGRMultiPolygon>();
    add_polygons_of(*v, *parts);
    if (!parts->IsEmpty()) areas.push_back(std::move(parts));
  }
  if (areas.empty()) return std::make_unique<OGRMultiPolygon>();
  // Combined in pairs, then pairs of pairs: each ring's area takes part in O(log rings)
  // differences, not one each against everything combined so far.
  while (areas.size() > 1) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < areas.size(); i += 2) {
      if (i + 1 < areas.size()) {
        areas[n].reset(areas[i]->SymDifference(areas[i + 1].get()));
        if (!areas[n]) return nullptr;
      } else {
        areas[n] = std::move(areas[i]);
      }
      ++n;
    }
    areas.resize(n);
  }
  return std::move(areas.front());
}

// Adds the rings of the polygons of g (a polygon, or a multi-polygon or collection of
// polygons, at any depth) to `out` as lines; false when g holds anything else.
bool add_rings(const OGRGeometry& g, OGRMultiLineString& out) {
  const auto t = wkbFlatten(g.getGeometryType());
  if (t == wkbPolygon) {
    for (const OGRLinearRing* ring : *g.toPolygon()) {
      OGRLineString line;
      line.addSubLineString(ring);
      out.addGeometry(&line);
    }
    return true;
  }
  if (t != wkbMultiPolygon && t != wkbGeometryCollection) return false;
  for (const OGRGeometry* part : *g.toGeometryCollection())
    if (!add_rings(*part, out)) return false;
  return true;
}

// Adds the polygons of g (a polygon, or a multi-polygon or collection of polygons, at any
// depth) to `out`, each made valid by itself (by the even-odd rule over its rings); false
// when g holds anything else or a polygon cannot be repaired. What a repair collapses to lines
// or points is left out.
bool add_valid_polygons(const OGRGeometry& g, OGRMultiPolygon& out) {
  const auto t = wkbFlatten(g.getGeometryType());
  if (t == wkbPolygon) {
    const std::unique_ptr<OGRGeometry> v =
        g.IsValid() ? std::unique_ptr<OGRGeometry>(g.clone()) : even_odd(*g.toPolygon());
    if (!v) return false;
    add_polygons_of(*v, out);
    return true;
  }
  if (t != wkbMultiPolygon && t != wkbGeometryCollection) return false;
  for (const OGRGeometry* part : *g.toGeometryCollection())
    if (!add_valid_polygons(*part, out)) return false;
  return true;
}

// An invalid polygonal geometry made valid as loci's queries read it, a point inside any of
// its polygons being inside: each polygon repaired by itself, then all united (MakeValid of
// the whole takes the overlap of two polygons by crossing parity, as outside). Null when g
// holds anything but polygons, or cannot be repaired.
std::unique_ptr<OGRGeometry> united_polygons(const OGRGeometry& g) {
  OGRMultiPolygon all;
  if (!add_valid_polygons(g, all)) return nullptr;
  if (all.IsEmpty()) return std::unique_ptr<OGRGeometry>(all.clone());
  return std::unique_ptr<OGRGeometry>(all.UnionCascaded());
}

// A ring of a window the user wrote that is no ring: not closed, under four points, or
// without area (its points on one line), said as such (GEOS calls each merely invalid).
void refuse_malformed_rings(const OGRGeometry& window) {
  std::vector<const OGRPolygon*> polygons;
  if (wkbFlatten(window.getGeometryType()) == wkbPolygon)
    polygons.push_back(window.toPolygon());
  else
    for (const OGRGeometry* part : *window.toGeometryCollection())
      if (wkbFlatten(part->getGeometryType()) == wkbPolygon) polygons.push_back(part->toPolygon());
  for (std::size_t p = 0; p < polygons.size(); ++p) {
    int r = 0;
    for (const OGRLinearRing* ring : *polygons[p]) {
      const std::string which = "ring " + std::to_string(r + 1) + " of polygon " +
                                std::to_string(p + 1) + " (" + (r == 0 ? "its shell" : "a hole") +
                                ")";
      ++r;
      const int n = ring->getNumPoints();
      if (n == 0) continue;
      if (detail::unclosed(*ring))
        throw InvalidGeometry("--wkt: " + which +
                              " is not closed: a ring ends at the point it starts from");
      if (n < 4)
        throw InvalidGeometry("--wkt: " + which + " has " + std::to_string(n) +
                              " points; a ring needs at least 4, the last repeating the first");
      // On one line, decided exactly: the first point apart from the start and every point
      // collinear with both (a ring that crosses itself can have an area of 0 too).
      const Point2 a{ring->getX(0), ring->getY(0)};
      int k = 1;
      while (k < n && Point2{ring->getX(k), ring->getY(k)} == a)
        ++k;
      if (k == n)
        throw InvalidGeometry("--wkt: " + which + " has no area: all its points are one point");
      bool line = true;
      for (int i = k + 1; line && i < n; ++i)
        line = orientation(a, {ring->getX(k), ring->getY(k)}, {ring->getX(i), ring->getY(i)}) ==
               Orientation::collinear;
      if (line)
        throw InvalidGeometry("--wkt: " + which + " has no area: its points lie on one line");
    }
  }
}

// The window as one valid polygonal geometry: the rectangle, the WKT, or the union of the
// window layer's polygons; a rectangle of no width or height is a line or a point.
std::unique_ptr<OGRGeometry> window_of(const ClipOptions& o, std::string& system) {
  std::unique_ptr<OGRGeometry> w;
  if (!o.window_wkt.empty()) {
    OGRGeometry* g = nullptr;
    if (OGRGeometryFactory::createFromWkt(o.window_wkt.c_str(), nullptr, &g) != OGRERR_NONE || !g)
      throw InvalidGeometry("--wkt: not a geometry in WKT");
    w.reset(g);
    if (!polygonal(*w))
      throw InvalidGeometry("--wkt: the window must be a POLYGON or MULTIPOLYGON");
    // A window the user wrote is taken as written or refused: repairing it would choose an
    // answer (a hole reaching out of its shell, polygons that overlap: --window-layer unites
    // them).
    if (!w->IsEmpty()) refuse_malformed_rings(*w);
    if (!w->IsEmpty() && !w->IsValid())
      throw InvalidGeometry(
          "--wkt: the window is not a valid polygon (rings that cross, a hole not inside its "
          "shell, or polygons that overlap or touch along an edge); give polygons apart from each "
          "other, or use --window-layer, which unites them");
  } else if (!o.window_layer.empty()) {
    auto wl = detail::open_layer(o.window_layer, o.window_layer_name);
    system = detail::system_of(*wl.layer);
    const detail::ReadCheck check(o.window_layer);
    OGRMultiPolygon all;
    for (auto& f : *wl.layer) {
      check.feature(f->GetFID());
      const OGRGeometry* g = f->GetGeometryRef();
      if (detail::without_points(g, detail::where(o.window_layer, f->GetFID()))) continue;
      if (!polygonal(*g))
        throw InvalidGeometry(detail::where(o.window_layer, f->GetFID()) +
                              " is not a polygon; a window layer holds polygons");
      // Each polygon repaired by itself: the union below then holds where two overlap.
      if (!add_valid_polygons(*g, all))
        throw InvalidGeometry(detail::where(o.window_layer, f->GetFID()) + " is invalid");
    }
    check.finish();
    if (all.IsEmpty()) throw InvalidGeometry(o.window_layer + ": no polygon to clip with");
    w.reset(all.UnionCascaded());
    if (!w) throw Error(o.window_layer + ": the polygons cannot be united");
  } else {
    const Box2& b = o.window;
    check_box(b, "bbox");
    // A window of no width or height is the segment or the point it is: as a collapsed
    // polygon, GEOS would cut nothing from lines crossing it, which query reports.
    if (b.min[0] == b.max[0] && b.min[1] == b.max[1])
      return std::make_unique<OGRPoint>(b.min[0], b.min[1]);
    if (b.min[0] == b.max[0] || b.min[1] == b.max[1]) {
      auto line = std::make_unique<OGRLineString>();
      line->addPoint(b.min[0], b.min[1]);
      line->addPoint(b.max[0], b.max[1]);
      return line;
    }
    auto poly = std::make_unique<OGRPolygon>();
    OGRLinearRing ring;
    ring.addPoint(b.min[0], b.min[1]);
    ring.addPoint(b.max[0], b.min[1]);
    ring.addPoint(b.max[0], b.max[1]);
    ring.addPoint(b.min[0], b.max[1]);
    ring.addPoint(b.min[0], b.min[1]);
    poly->addRing(&ring);
    return poly;
  }
  if (w->IsEmpty()) throw InvalidGeometry("the window is empty");
  if (!w->IsValid()) {
    std::unique_ptr<OGRGeometry> valid(w->MakeValid());
    if (!valid || !polygonal(*valid)) throw InvalidGeometry("the window is an invalid polygon");
    w = std::move(valid);
  }
  return w;
}

// What of `g` can meet the window, or nullptr when that is all of it: of a collection (a
// multi-polygon of islands...) the members, of a polygon the rings, whose envelope meets the
// window's. No ring left out encloses a point of the window, so leaving them out changes
// neither the repaired geometry inside the window nor the cut, and spares GEOS repairing and
// cutting a country's thousands of far islands and lakes.
std::unique_ptr<OGRGeometry> near_window(const OGRGeometry& g, const OGREnvelope& window) {
  const auto meets = [&](const OGRGeometry& m) {
    OGREnvelope e;
    m.getEnvelope(&e);
    return e.Intersects(window);
  };
  std::unique_ptr<OGRGeometry> out;
  const auto type = g.getGeometryType();
  if (wkbFlatten(type) == wkbPolygon) {
    const OGRPolygon& p = *g.toPolygon();
    int holes = 0;
    for (int i = 0; i < p.getNumInteriorRings(); ++i)
      holes += meets(*p.getInteriorRing(i));
    if (holes == p.getNumInteriorRings()) return nullptr;
    auto q = std::make_unique<OGRPolygon>();
    q->addRingDirectly(p.getExteriorRing()->clone());
    for (int i = 0; i < p.getNumInteriorRings(); ++i)
      if (meets(*p.getInteriorRing(i))) q->addRingDirectly(p.getInteriorRing(i)->clone());
    out = std::move(q);
  } else if (OGR_GT_IsSubClassOf(type, wkbGeometryCollection)) {
    const OGRGeometryCollection& c = *g.toGeometryCollection();
    bool all = true;
    std::vector<std::unique_ptr<OGRGeometry>> near;  // nullptr: the member whole
    for (const OGRGeometry* m : c) {
      if (!meets(*m)) {
        all = false;
        continue;
      }
      near.push_back(near_window(*m, window));
      all &= !near.back();
    }
    if (all) return nullptr;
    out.reset(OGRGeometryFactory::createGeometry(type));
    std::size_t j = 0;
    for (const OGRGeometry* m : c) {
      if (!meets(*m)) continue;
      const OGRGeometry* keep = near[j] ? near[j].get() : m;
      ++j;
      if (out->toGeometryCollection()->addGeometry(keep) != OGRERR_NONE) return nullptr;
    }
  } else {
    return nullptr;
  }
  out->assignSpatialReference(g.getSpatialReference());
  return out;
}

// Gathers the members of `g` of dimension `dim`, through nested collections; counts those of
// lower dimension in `lower`.
void members_of_dimension(const OGRGeometry& g, int dim, std::vector<const OGRGeometry*>& out,
                          std::size_t& lower) {
  if (OGR_GT_IsSubClassOf(wkbFlatten(g.getGeometryType()), wkbGeometryCollection)) {
    for (const OGRGeometry* m : *g.toGeometryCollection())
      members_of_dimension(*m, dim, out, lower);
  } else if (!g.IsEmpty()) {
    if (g.getDimension() == dim)
      out.push_back(&g);
    else
      ++lower;
  }
}

// A cut that mixes dimensions (GEOS gives a collection: two arms of a U cut off from its bar,
// and the line where the window's edge touches the notch) made of its members of the highest
// dimension only, as one geometry or a multi-geometry; `dropped` counts the members of lower
// dimension left out. Forced into the layer's type as it came, such a collection's rings would
// have become holes of its first polygon.
std::unique_ptr<OGRGeometry> of_one_dimension(std::unique_ptr<OGRGeometry> piece,
                                              std::size_t& dropped) {
  if (wkbFlatten(piece->getGeometryType()) != wkbGeometryCollection) return piece;
  const int dim = piece->getDimension();
  std::vector<const OGRGeometry*> keep;
  std::size_t lower = 0;
  members_of_dimension(*piece, dim, keep, lower);
  dropped += lower;
  std::unique_ptr<OGRGeometry> out;
  if (keep.size() == 1) {
    out.reset(keep.front()->clone());
  } else {
    out.reset(OGRGeometryFactory::createGeometry(dim == 2   ? wkbMultiPolygon
                                                 : dim == 1 ? wkbMultiLineString
                                                            : wkbMultiPoint));
    for (const OGRGeometry* m : keep) {
      // Members of multi-geometries were gathered one by one: each is a single geometry.
      if (out->toGeometryCollection()->addGeometry(m) != OGRERR_NONE)
        throw Error("cannot gather the pieces of a cut geometry");
    }
  }
  out->assignSpatialReference(piece->getSpatialReference());
  return out;
}

}  // namespace

ClipResult clip_layer(const ClipOptions& options) {
  if (!OGRGeometryFactory::haveGEOS()) throw Error("clipping needs GDAL built with GEOS");
  const bool rectangle = options.window_wkt.empty() && options.window_layer.empty();
  std::string window_system;  // the window layer's coordinate system
  const std::unique_ptr<OGRGeometry> window = window_of(options, window_system);
  refuse_overwriting(options.out_path, options.load.layer_path);
  refuse_overwriting(options.out_path, sidecar_path_of(options.load), "index");
  if (!options.window_layer.empty()) refuse_overwriting(options.out_path, options.window_layer);
  GDALDriver* driver = detail::driver_for(options.out_path);  // before any work
  OutputDataset out(options.out_path);  // refuses a file holding other layers, before any work
  const LayerIndex index = load_index(options.load);
  LayerQuery query(index, options.load.layer_path, index.layer_name());
  Query q;
  q.kind = Query::Kind::bbox;
  if (rectangle) {
    q.box = options.window;
  } else {
    OGREnvelope e;
    window->getEnvelope(&e);
    q.box = {{e.MinX, e.MinY}, {e.MaxX, e.MaxY}};
  }
  std::vector<Answer> answers;
  query.run(q, 1, false, answers);

  auto src = detail::open_layer(options.load.layer_path, index.layer_name());
  if (!options.window_layer.empty())
    detail::check_same_system(options.load.layer_path, detail::system_of(*src.layer),
                              options.window_layer, window_system);
  ClipResult result;
  {
    GDALDatasetUniquePtr ds(
        driver->Create(out.staging_path().c_str(), 0, 0, 0, GDT_Unknown, nullptr));
    if (!ds) throw Error("cannot write " + options.out_path + ": " + CPLGetLastErrorMsg());
    // A polygonal window keeps, of the features meeting its envelope, those meeting it.
    FlatGeometry window_flat;
    if (!rectangle) window_flat = detail::flatten(window.get(), "the window");
    // The pieces first: an invalid polygon (a bowtie) is made valid before it is cut, and a
    // feature the window only touches keeps its degenerate piece (a point or a line), so clip
    // answers exactly what query does.
    struct Piece {
      OGRFeatureUniquePtr feature;
      std::unique_ptr<OGRGeometry> geometry;
    };
    std::vector<Piece> pieces;
    const OGRwkbGeometryType source_type = src.layer->GetGeomType();
    const bool mixed_ok = std::string(driver->GetDescription()) != "ESRI Shapefile";
    bool degenerate = false;
    detail::ShapefilePolygons polygons(options.load.layer_path, *src.layer);
    OGREnvelope window_envelope;
    window->getEnvelope(&window_envelope);
    for (const auto& a : answers) {
      OGRFeatureUniquePtr f(polygons.fetch(a.fid));
      if (!f || !f->GetGeometryRef()) continue;
      const OGRGeometry* g = f->GetGeometryRef();
      if (!rectangle &&
          !meets(detail::flatten(g, detail::where(options.load.layer_path, a.fid)), window_flat))
        continue;
      // Curves are cut as the queries read them, linearised as GDAL does by default (so that
      // an invalid curve polygon is repaired by the even-odd rule below too).
      std::unique_ptr<OGRGeometry> linear;
      if (g->hasCurveGeometry()) {
        linear.reset(g->getLinearGeometry());
        if (!linear)
          throw Error(options.load.layer_path + ": feature " + std::to_string(a.fid) +
                      " has curves GDAL cannot linearise");
        g = linear.get();
      }
      // Triangles, TINs and polyhedral surfaces are cut as the polygons of their faces (GEOS
      // takes no other surface).
      std::unique_ptr<OGRGeometry> faces;
      if (detail::of_faces(g->getGeometryType())) {
        faces.reset(OGRGeometryFactory::forceToMultiPolygon(g->clone()));
        g = faces.get();
      }
      // A ring read closed by the queries (detail::for_each_curve) is cut closed.
      std::unique_ptr<OGRGeometry> closed;
      if (detail::has_unclosed_ring(*g)) {
        closed.reset(g->clone());
        closed->closeRings();
        g = closed.get();
      }
      const std::unique_ptr<OGRGeometry> near = near_window(*g, window_envelope);
      if (near) g = near.get();
      // Polygons of one feature that overlap keep their overlap, as queries count it: an
      // invalid multi-polygon, and a collection of polygons (valid however they overlap, and
      // cut by GEOS as if the overlap were outside), are cut as the union of their polygons.
      const OGRGeometry* const unrepaired = g;
      std::unique_ptr<OGRGeometry> valid;
      const bool invalid = !g->IsValid();
      if (invalid || wkbFlatten(g->getGeometryType()) == wkbGeometryCollection) {
        valid = united_polygons(*g);  // null unless g holds polygons only
        if (!valid && invalid) valid.reset(g->MakeValid());
        if (!valid && invalid)
          throw Error(options.load.layer_path + ": feature " + std::to_string(a.fid) +
                      " is an invalid geometry that cannot be repaired");
        if (valid) g = valid.get();
      }
      std::unique_ptr<OGRGeometry> piece(g->Intersection(window.get()));
      if (!piece)
        throw Error(options.load.layer_path + ": feature " + std::to_string(a.fid) +
                    " cannot be cut to the window (" + CPLGetLastErrorMsg() + ")");
      // A polygonal feature the queries found meeting the window whose cut has nothing: its
      // rings meet the window where its area does not reach it (holes sharing an edge, a hole
      // repeating its shell, a polygon without area, a repair moving an edge by a rounding),
      // and the cut of the rings is its piece, as for a feature that only touches the window.
      OGRMultiLineString rings;
      if (piece->IsEmpty() && add_rings(*unrepaired, rings)) {
        std::unique_ptr<OGRGeometry> lines(rings.Intersection(window.get()));
        if (lines && !lines->IsEmpty()) piece = std::move(lines);
      }
      if (piece->IsEmpty()) continue;
      // Measures are not carried through the cut (GEOS keeps x, y and z): none, rather than
      // a made-up 0 at every vertex.
      piece->setMeasured(FALSE);
      if (piece->getDimension() < f->GetGeometryRef()->getDimension()) {
        if (!mixed_ok) {
          ++result.dropped;
          continue;
        }
        degenerate = true;
      }
      // A feature that is itself a collection of several dimensions keeps its cut as it comes.
      if (wkbFlatten(f->GetGeometryRef()->getGeometryType()) != wkbGeometryCollection)
        piece = of_one_dimension(std::move(piece), result.dropped);
      pieces.push_back({std::move(f), std::move(piece)});
    }
    // A shapefile holds one kind of geometry: a layer that mixes them (GeoJSON, GeoPackage) is
    // refused with the two kinds, before its layer is made.
    if (!mixed_ok)
      for (const Piece& p : pieces)
        if (p.geometry->getDimension() != pieces.front().geometry->getDimension())
          throw Error("cannot write " + options.out_path +
                      ": a shapefile holds one kind of geometry, and the window meets feature " +
                      std::to_string(pieces.front().feature->GetFID()) + " (" +
                      OGRGeometryTypeToName(pieces.front().geometry->getGeometryType()) +
                      ") and feature " + std::to_string(p.feature->GetFID()) + " (" +
                      OGRGeometryTypeToName(p.geometry->getGeometryType()) +
                      "); write a .gpkg or .geojson instead");
    // A layer that says Polygon (as every shapefile of polygons does) may hold features the
    // window cuts into several parts: forced back to one polygon, the parts would turn into
    // holes of the first. Such a layer is written as MultiPolygon (likewise for lines and
    // points).
    OGRwkbGeometryType type =
        degenerate ? wkbUnknown : OGR_GT_SetModifier(source_type, OGR_GT_HasZ(source_type), FALSE);
    if (wkbFlatten(type) != wkbUnknown &&
        !OGR_GT_IsSubClassOf(wkbFlatten(type), wkbGeometryCollection))
      for (const Piece& p : pieces)
        if (wkbFlatten(p.geometry->getGeometryType()) == OGR_GT_GetCollection(wkbFlatten(type))) {
          type = OGR_GT_GetCollection(type);
          break;
        }
    // A CSV keeps the cut geometries as WKT (by default GDAL's CSV driver drops them).
    const bool csv = std::strcmp(driver->GetDescription(), "CSV") == 0;
    const char* as_wkt[] = {"GEOMETRY=AS_WKT", nullptr};
    // A shapefile's .dbf is written in UTF-8 (with a .cpg saying so): GDAL's default,
    // ISO-8859-1, turns every other character into '?'.
    const char* utf8[] = {"ENCODING=UTF-8", nullptr};
    // GeoJSON's coordinates to 17 significant figures, which read back as the same doubles
    // (GDAL's default, 15 decimals, wrote 1e-20 as 0).
    const bool geojson = std::strcmp(driver->GetDescription(), "GeoJSON") == 0;
    const char* exact[] = {"SIGNIFICANT_FIGURES=17", nullptr};
    OGRLayer* layer = ds->CreateLayer(src.layer->GetName(), src.layer->GetSpatialRef(), type,
                                      csv         ? const_cast<char**>(as_wkt)
                                      : geojson   ? const_cast<char**>(exact)
                                      : !mixed_ok ? const_cast<char**>(utf8)
                                                  : nullptr);
    if (!layer) throw Error("cannot write " + options.out_path + ": " + CPLGetLastErrorMsg());
    // Values are copied by position (`fields[i]`: the output field of source field i, -1 for
    // none), not by name: drivers rename fields as they create them (a shapefile cuts names to
    // ten characters, GML replaces spaces), and formats that compare names without case hold
    // Name and NAME once; a name the output already has gets a number, as ogr2ogr does.
    const OGRFeatureDefn* defn = src.layer->GetLayerDefn();
    const bool csv_source = std::strcmp(src.dataset->GetDriver()->GetDescription(), "CSV") == 0;
    std::vector<int> fields(std::size_t(defn->GetFieldCount()), -1);
    // Fields the format gives every layer (KML's Name and Description) take the values of the
    // source's fields of those names.
    const int own = layer->GetLayerDefn()->GetFieldCount();
    // The types the driver says it creates (as ogr2ogr reads them); none listed holds every type.
    const char* listed = driver->GetMetadataItem(GDAL_DMD_CREATIONFIELDDATATYPES);
    const CPLStringList creatable(listed ? CSLTokenizeString(listed) : nullptr);
    for (int i = 0; i < defn->GetFieldCount(); ++i) {
      OGRFieldDefn fd(defn->GetFieldDefn(i));
      // A CSV source shows its geometry column as a field too: a CSV output's WKT replaces it.
      if (csv && csv_source && EQUAL(fd.GetNameRef(), "WKT")) continue;
      const std::string name = fd.GetNameRef();
      const int given = layer->GetLayerDefn()->GetFieldIndex(name.c_str());
      if (given >= 0 && given < own &&
          std::find(fields.begin(), fields.end(), given) == fields.end()) {
        fields[std::size_t(i)] = given;
        continue;
      }
      std::string unique = name;
      for (int k = 2; layer->GetLayerDefn()->GetFieldIndex(unique.c_str()) >= 0 ||
                      (csv && EQUAL(unique.c_str(), "WKT"));
           ++k)
        unique = name + std::to_string(k);
      fd.SetName(unique.c_str());
      const int before = layer->GetLayerDefn()->GetFieldCount();
      CPLErrorReset();
      if (layer->CreateField(&fd) != OGRERR_NONE ||
          layer->GetLayerDefn()->GetFieldCount() != before + 1) {
        // GDAL's reason when it gives one (a shapefile has no list types), else the type.
        const std::string why = CPLGetLastErrorMsg();
        throw Error("cannot write " + options.out_path + ": field " + name + " (" +
                    (why.empty()
                         ? std::string("of type ") + OGRFieldDefn::GetFieldTypeName(fd.GetType()) +
                               ", which the format does not hold"
                         : why) +
                    ")");
      }
      fields[std::size_t(i)] = before;
      // The type made, and whether the driver lists it: only some drivers (the shapefile's)
      // show a conversion in the field they made.
      const OGRFieldDefn* made = layer->GetLayerDefn()->GetFieldDefn(before);
      const std::string type = OGRFieldDefn::GetFieldTypeName(fd.GetType());
      const bool held = !listed || creatable.FindString(type.c_str()) >= 0;
      if (made->GetType() != fd.GetType())
        result.retyped.push_back({name, type, OGRFieldDefn::GetFieldTypeName(made->GetType())});
      else if (!held)
        result.retyped.push_back({name, type, ""});
    }
    for (Piece& p : pieces) {
      std::unique_ptr<OGRGeometry> piece = std::move(p.geometry);
      if (wkbFlatten(type) != wkbUnknown)
        piece.reset(OGRGeometryFactory::forceTo(piece.release(), type));
      OGRFeature o(layer->GetLayerDefn());
      if (o.SetFrom(p.feature.get(), fields.data(), TRUE) != OGRERR_NONE)
        throw Error("cannot write " + options.out_path + ": the fields of feature " +
                    std::to_string(p.feature->GetFID()));
      o.SetGeometryDirectly(piece.release());
      if (layer->CreateFeature(&o) != OGRERR_NONE)
        throw Error("cannot write " + options.out_path + ": feature " +
                    std::to_string(p.feature->GetFID()) + " (" + CPLGetLastErrorMsg() + ")");
      ++result.written;
    }
    // Closing flushes; GDAL reports a failed flush only through its error state.
    CPLErrorReset();
    ds.reset();
    if (CPLGetLastErrorType() == CE_Failure) throw Error("cannot write " + options.out_path);
  }
  out.commit();
  return result;
}

}  // namespace loci::io
