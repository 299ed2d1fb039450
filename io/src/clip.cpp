// `loci clip`: the features whose geometry meets a window, each cut to the window with GEOS
// (through OGR), written to a new dataset whose format follows the output's extension.
//
// Clip answers for the features query reports. An invalid polygon (a bowtie) is made valid
// before it is cut. A feature that only touches the window keeps its piece of lower dimension
// (a polygon sharing an edge leaves a line, a corner a point) in formats whose layers hold mixed
// geometry (GeoJSON, GeoPackage, ...); a shapefile holds one geometry type, so there such
// pieces are dropped and counted.
#include <memory>
#include <string>
#include <vector>

#include "gdal_layer.hpp"
#include "loci/geom/error.hpp"
#include "loci/io/commands.hpp"

namespace loci::io {

std::size_t clip_layer(const ClipOptions& options) {
  if (!OGRGeometryFactory::haveGEOS()) throw Error("clipping needs GDAL built with GEOS");
  check_box(options.window, "bbox");
  refuse_overwriting(options.out_path, options.load.layer_path);
  const LayerIndex index = load_index(options.load);
  LayerQuery query(index, options.load.layer_path, index.layer_name());
  Query q;
  q.kind = Query::Kind::bbox;
  q.box = options.window;
  std::vector<Answer> answers;
  query.run(q, 1, false, answers);

  auto src = detail::open_layer(options.load.layer_path, index.layer_name());
  GDALDriver* driver = detail::driver_for(options.out_path);
  OutputDataset out(options.out_path);
  std::size_t written = 0;
  {
    GDALDatasetUniquePtr ds(
        driver->Create(out.staging_path().c_str(), 0, 0, 0, GDT_Unknown, nullptr));
    if (!ds) throw Error("cannot write " + options.out_path + ": " + CPLGetLastErrorMsg());
    const Box2& w = options.window;
    OGRPolygon window;
    {
      OGRLinearRing ring;
      ring.addPoint(w.min[0], w.min[1]);
      ring.addPoint(w.max[0], w.min[1]);
      ring.addPoint(w.max[0], w.max[1]);
      ring.addPoint(w.min[0], w.max[1]);
      ring.addPoint(w.min[0], w.min[1]);
      window.addRing(&ring);
    }
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
    for (const auto& a : answers) {
      OGRFeatureUniquePtr f(src.layer->GetFeature(a.fid));
      if (!f || !f->GetGeometryRef()) continue;
      const OGRGeometry* g = f->GetGeometryRef();
      std::unique_ptr<OGRGeometry> valid;
      if (!g->IsValid()) {
        valid.reset(g->MakeValid());
        if (!valid)
          throw Error(options.load.layer_path + ": feature " + std::to_string(a.fid) +
                      " is an invalid geometry that cannot be repaired");
        g = valid.get();
      }
      std::unique_ptr<OGRGeometry> piece(g->Intersection(&window));
      if (!piece)
        throw Error(options.load.layer_path + ": feature " + std::to_string(a.fid) +
                    " cannot be cut to the window (" + CPLGetLastErrorMsg() + ")");
      if (piece->IsEmpty()) continue;
      if (piece->getDimension() < f->GetGeometryRef()->getDimension()) {
        if (!mixed_ok) continue;
        degenerate = true;
      }
      pieces.push_back({std::move(f), std::move(piece)});
    }
    const OGRwkbGeometryType type = degenerate ? wkbUnknown : source_type;
    OGRLayer* layer =
        ds->CreateLayer(src.layer->GetName(), src.layer->GetSpatialRef(), type, nullptr);
    if (!layer) throw Error("cannot write " + options.out_path + ": " + CPLGetLastErrorMsg());
    const OGRFeatureDefn* defn = src.layer->GetLayerDefn();
    for (int i = 0; i < defn->GetFieldCount(); ++i) {
      OGRFieldDefn fd(defn->GetFieldDefn(i));
      if (layer->CreateField(&fd) != OGRERR_NONE)
        throw Error("cannot write " + options.out_path + ": field " + fd.GetNameRef());
    }
    for (Piece& p : pieces) {
      std::unique_ptr<OGRGeometry> piece = std::move(p.geometry);
      if (wkbFlatten(type) != wkbUnknown)
        piece.reset(OGRGeometryFactory::forceTo(piece.release(), type));
      OGRFeature o(layer->GetLayerDefn());
      o.SetFrom(p.feature.get());
      o.SetGeometryDirectly(piece.release());
      if (layer->CreateFeature(&o) != OGRERR_NONE)
        throw Error("cannot write " + options.out_path + ": feature " +
                    std::to_string(p.feature->GetFID()));
      ++written;
    }
    // Closing flushes; GDAL reports a failed flush only through its error state.
    CPLErrorReset();
    ds.reset();
    if (CPLGetLastErrorType() == CE_Failure) throw Error("cannot write " + options.out_path);
  }
  out.commit();
  return written;
}

}  // namespace loci::io
