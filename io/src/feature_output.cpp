// write_answers' csv and GeoJSON formats: the answers' features read through GDAL, their
// attributes and geometries written beside loci's columns (see output.hpp).
#include <charconv>
#include <cmath>
#include <cstring>
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "block_writer.hpp"
#include "gdal_layer.hpp"
#include "gdal_seam.hpp"
#include "loci/geom/error.hpp"
#include "shapefile_polygons.hpp"

namespace loci::io {
namespace {

std::string csv_quoted(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) {
    if (c == '"') q += '"';
    q += c;
  }
  return q + "\"";
}

OGRFeatureUniquePtr found(OGRFeatureUniquePtr f, const AnswerSource& src, std::int64_t fid) {
  if (!f) throw Error(detail::where(src.layer_path, fid) + " is not in the layer");
  return f;
}

// The features a list of answers names, each read once whatever the number of answers naming
// it: by FID where the driver reads by FID in place, or else (GeoJSON and the other text
// formats, where GDAL finds a feature by FID by parsing the file from its start) kept from one
// pass over the layer.
class AnswerFeatures {
 public:
  // `by_fid` reads one feature by FID (null when there is none) on a layer read in place.
  AnswerFeatures(detail::OpenLayer& ol, const AnswerSource& src, std::span<const Answer> answers,
                 std::function<OGRFeatureUniquePtr(std::int64_t)> by_fid)
      : src_(src), by_fid_(std::move(by_fid)), whole_(!detail::fast_random_read(*ol.dataset)) {
    if (!whole_ || answers.empty()) return;
    for (const Answer& a : answers)
      kept_.emplace(a.fid, nullptr);
    ol.layer->ResetReading();
    for (OGRFeatureUniquePtr f(ol.layer->GetNextFeature()); f;
         f.reset(ol.layer->GetNextFeature())) {
      const auto it = kept_.find(f->GetFID());
      if (it != kept_.end() && !it->second) it->second = std::move(f);
    }
  }
  // The feature `fid`, valid until the next call. Throws loci::Error when the layer has none.
  const OGRFeature& at(std::int64_t fid) {
    if (!whole_) {
      last_ = found(by_fid_(fid), src_, fid);
      return *last_;
    }
    const auto it = kept_.find(fid);
    if (it == kept_.end() || !it->second)
      throw Error(detail::where(src_.layer_path, fid) + " is not in the layer");
    return *it->second;
  }

 private:
  const AnswerSource& src_;
  std::function<OGRFeatureUniquePtr(std::int64_t)> by_fid_;
  bool whole_;
  std::unordered_map<std::int64_t, OGRFeatureUniquePtr> kept_;
  OGRFeatureUniquePtr last_;
};

// The names the layer's fields are written under beside loci's own columns: a field named like
// one of them (a layer with a field `fid` or `distance`) is written as `layer_NAME`, with `_2`,
// `_3`, ... added while that is taken too, so that no column is written twice and none is lost
// (the output of one query read by the next has both `fid` and `layer_fid`).
std::vector<std::string> attribute_names(const OGRFeatureDefn& defn, bool numbered,
                                         bool with_distance, bool with_point) {
  std::set<std::string> taken = {"fid"};
  if (numbered) taken.insert("query");
  if (with_distance) taken.insert("distance");
  if (with_point) taken.insert({"x", "y"});
  const std::set<std::string> ours = taken;
  for (int i = 0; i < defn.GetFieldCount(); ++i)
    taken.insert(defn.GetFieldDefn(i)->GetNameRef());
  std::vector<std::string> names;
  for (int i = 0; i < defn.GetFieldCount(); ++i) {
    const std::string name = defn.GetFieldDefn(i)->GetNameRef();
    if (!ours.count(name)) {
      names.push_back(name);
      continue;
    }
    std::string renamed = "layer_" + name;
    for (int k = 2; taken.count(renamed); ++k)
      renamed = "layer_" + name + "_" + std::to_string(k);
    taken.insert(renamed);
    names.push_back(renamed);
  }
  return names;
}

void write_csv(const AnswerSource& src, std::span<const Answer> answers, bool numbered,
               bool with_distance, bool with_point, std::FILE* out) {
  auto ol = detail::open_layer(src.layer_path, src.layer_name);
  // The rows hold attributes only: GDAL need not build the geometries (for a shapefile of
  // countries with thousands of islands, sorting their rings takes minutes).
  const char* no_geometry[] = {"OGR_GEOMETRY", nullptr};
  ol.layer->SetIgnoredFields(no_geometry);
  const OGRFeatureDefn* defn = ol.layer->GetLayerDefn();
  std::string line = numbered ? "query,fid" : "fid";
  if (with_distance) line += ",distance";
  if (with_point) line += ",x,y";
  for (const std::string& name : attribute_names(*defn, numbered, with_distance, with_point))
    line += "," + csv_quoted(name);
  std::fprintf(out, "%s\n", line.c_str());
  AnswerFeatures features(ol, src, answers, [&](std::int64_t fid) {
    return detail::read_feature(*ol.layer, fid, src.layer_path);
  });
  for (const auto& a : answers) {
    const OGRFeature* f = &features.at(a.fid);
    line = numbered ? std::to_string(a.query) + "," : "";
    line += std::to_string(a.fid);
    if (with_distance) line += "," + detail::shortest(a.distance);
    if (with_point) line += "," + detail::shortest_pair(a.at[0], a.at[1]);
    for (int i = 0; i < defn->GetFieldCount(); ++i) {
      line += ',';
      if (!f->IsFieldSetAndNotNull(i)) continue;
      if (defn->GetFieldDefn(i)->GetType() == OFTReal) {
        // Every digit that tells the value apart (GDAL's text keeps 15: 0.30000000000000004
        // would read back as 0.3).
        char buf[32];
        const double v = f->GetFieldAsDouble(i);
        const auto end = defn->GetFieldDefn(i)->GetSubType() == OFSTFloat32
                             ? std::to_chars(buf, buf + sizeof buf, float(v)).ptr
                             : std::to_chars(buf, buf + sizeof buf, v).ptr;
        line += csv_quoted(std::string(buf, end));
      } else {
        line += csv_quoted(f->GetFieldAsString(i));
      }
    }
    std::fprintf(out, "%s\n", line.c_str());
  }
}

// g as GeoJSON can hold it: triangles, TINs and polyhedral surfaces (also as members of a
// collection) as the polygons of their faces, which GeoJSON has, and collections without their
// empty members (GDAL's writer left such geometries null, or wrote "geometries": null); null
// when g is written as it is.
std::unique_ptr<OGRGeometry> geojson_geometry(const OGRGeometry* g) {
  if (!g) return nullptr;
  if (detail::of_faces(g->getGeometryType()))
    return std::unique_ptr<OGRGeometry>(OGRGeometryFactory::forceToMultiPolygon(g->clone()));
  if (!OGR_GT_IsSubClassOf(wkbFlatten(g->getGeometryType()), wkbGeometryCollection)) return nullptr;
  // Each member converted once; the collection rebuilt only when one was, or is empty.
  const OGRGeometryCollection& c = *g->toGeometryCollection();
  std::vector<std::unique_ptr<OGRGeometry>> members;
  bool changed = false;
  for (const OGRGeometry* m : c) {
    members.push_back(m->IsEmpty() ? nullptr : geojson_geometry(m));
    changed |= m->IsEmpty() || members.back();
  }
  if (!changed) return nullptr;
  std::unique_ptr<OGRGeometry> out(OGRGeometryFactory::createGeometry(g->getGeometryType()));
  if (!out) return nullptr;
  for (int i = 0; i < c.getNumGeometries(); ++i) {
    const OGRGeometry* m = c.getGeometryRef(i);
    if (m->IsEmpty()) continue;
    const OGRGeometry* member = members[std::size_t(i)] ? members[std::size_t(i)].get() : m;
    if (out->toGeometryCollection()->addGeometry(member) != OGRERR_NONE) return nullptr;
  }
  return out;
}

void write_geojson(const AnswerSource& src, std::span<const Answer> answers, bool numbered,
                   bool with_distance, bool with_point, const std::string& target) {
  auto ol = detail::open_layer(src.layer_path, src.layer_name);
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GeoJSON");
  if (!driver) throw Error("GDAL has no GeoJSON driver");
  CPLErrorReset();
  GDALDatasetUniquePtr ds(driver->Create(target.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
  if (!ds) throw Error("cannot write GeoJSON: " + std::string(CPLGetLastErrorMsg()));
  // Coordinates to 17 significant figures, which read back as the same doubles (GDAL's
  // default, 15 decimals, wrote 1e-20 as 0).
  const char* exact[] = {"SIGNIFICANT_FIGURES=17", nullptr};
  OGRLayer* layer = ds->CreateLayer(ol.layer->GetName(), ol.layer->GetSpatialRef(), wkbUnknown,
                                    const_cast<char**>(exact));
  if (!layer) throw Error("cannot create the GeoJSON layer: " + std::string(CPLGetLastErrorMsg()));
  std::vector<std::pair<int, int>> copied;  // source field, output field
  int out_index = 0;
  auto add_field = [&](const char* name, OGRFieldType type) {
    OGRFieldDefn fd(name, type);
    if (layer->CreateField(&fd) != OGRERR_NONE)
      throw Error("cannot create field " + std::string(name));
    return out_index++;
  };
  const int query_field = numbered ? add_field("query", OFTInteger64) : -1;
  const int fid_field = add_field("fid", OFTInteger64);
  const int distance_field = with_distance ? add_field("distance", OFTReal) : -1;
  const int x_field = with_point ? add_field("x", OFTReal) : -1;
  const int y_field = with_point ? add_field("y", OFTReal) : -1;
  const OGRFeatureDefn* defn = ol.layer->GetLayerDefn();
  const std::vector<std::string> names =
      attribute_names(*defn, numbered, with_distance, with_point);
  for (int i = 0; i < defn->GetFieldCount(); ++i) {
    const OGRFieldDefn* fd = defn->GetFieldDefn(i);
    const std::string& name = names[std::size_t(i)];
    OGRFieldDefn copy(fd);
    copy.SetName(name.c_str());
    if (layer->CreateField(&copy) != OGRERR_NONE) throw Error("cannot create field " + name);
    copied.emplace_back(i, out_index++);
  }
  // A shapefile's polygons of many rings are built without GDAL's sorting of rings.
  detail::ShapefilePolygons polygons(src.layer_path, *ol.layer);
  AnswerFeatures features(ol, src, answers, [&](std::int64_t fid) { return polygons.fetch(fid); });
  for (const auto& a : answers) {
    const OGRFeature* f = &features.at(a.fid);
    OGRFeature out(layer->GetLayerDefn());
    if (query_field >= 0) out.SetField(query_field, static_cast<GIntBig>(a.query));
    out.SetField(fid_field, static_cast<GIntBig>(a.fid));
    if (distance_field >= 0) out.SetField(distance_field, a.distance);
    if (x_field >= 0) out.SetField(x_field, a.at[0]);
    if (y_field >= 0) out.SetField(y_field, a.at[1]);
    for (const auto& [from, to] : copied)
      if (f->IsFieldSetAndNotNull(from))
        out.SetField(to, f->GetRawFieldRef(from));
      else if (f->IsFieldNull(from))
        out.SetFieldNull(to);  // "n": null, as the layer has it (an unset field is left out)
    const std::unique_ptr<OGRGeometry> faces = geojson_geometry(f->GetGeometryRef());
    out.SetGeometry(faces ? faces.get() : f->GetGeometryRef());
    if (layer->CreateFeature(&out) != OGRERR_NONE)
      throw Error("cannot write feature " + std::to_string(a.fid) + " as GeoJSON");
  }
  // Closing flushes; GDAL reports a failed flush only through its error state.
  CPLErrorReset();
  ds.reset();
  if (CPLGetLastErrorType() == CE_Failure) throw Error("cannot finish the GeoJSON output");
}

}  // namespace

namespace detail {

void write_feature_answers(const AnswerSource& source, std::span<const Answer> answers,
                           Format format, bool numbered, bool with_distance, bool with_point,
                           const std::string& out_path, std::FILE* fallback) {
  if (format == Format::geojson) {
    if (out_path.empty()) {
      std::fflush(fallback);
      write_geojson(source, answers, numbered, with_distance, with_point, "/vsistdout/");
      OutputFile(std::string(), fallback).commit();  // a full or closed stdout is an error
      return;
    }
    refuse_replacing_binary_dataset(out_path);  // a dataset's own file: GeoJSON would replace it
    OutputDataset out(out_path);
    write_geojson(source, answers, numbered, with_distance, with_point, out.staging_path());
    out.commit();
    return;
  }
  OutputFile out(out_path, fallback);
  write_csv(source, answers, numbered, with_distance, with_point, out.stream());
  out.commit();
}

}  // namespace detail
}  // namespace loci::io
