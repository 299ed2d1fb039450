// `loci clip`: the features whose geometry meets a window, each cut to the window with GEOS
// (through OGR), written to a new dataset whose format follows the output's extension.
//
// A feature that only touches the window keeps a piece of lower dimension than itself (a
// polygon sharing an edge leaves a line); such pieces are dropped, because a clipped polygon
// layer should stay a polygon layer that every format can hold.
#include <memory>

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
    const OGRwkbGeometryType type = src.layer->GetGeomType();
    OGRLayer* layer =
        ds->CreateLayer(src.layer->GetName(), src.layer->GetSpatialRef(), type, nullptr);
    if (!layer) throw Error("cannot write " + options.out_path + ": " + CPLGetLastErrorMsg());
    const OGRFeatureDefn* defn = src.layer->GetLayerDefn();
    for (int i = 0; i < defn->GetFieldCount(); ++i) {
      OGRFieldDefn fd(defn->GetFieldDefn(i));
      if (layer->CreateField(&fd) != OGRERR_NONE)
        throw Error("cannot write " + options.out_path + ": field " + fd.GetNameRef());
    }
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
    for (const auto& a : answers) {
      OGRFeatureUniquePtr f(src.layer->GetFeature(a.fid));
      if (!f || !f->GetGeometryRef()) continue;
      const OGRGeometry* g = f->GetGeometryRef();
      std::unique_ptr<OGRGeometry> piece(g->Intersection(&window));
      if (!piece || piece->IsEmpty() || piece->getDimension() < g->getDimension()) continue;
      if (wkbFlatten(type) != wkbUnknown)
        piece.reset(OGRGeometryFactory::forceTo(piece.release(), type));
      OGRFeature o(layer->GetLayerDefn());
      o.SetFrom(f.get());
      o.SetGeometryDirectly(piece.release());
      if (layer->CreateFeature(&o) != OGRERR_NONE)
        throw Error("cannot write " + options.out_path + ": feature " + std::to_string(a.fid));
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
