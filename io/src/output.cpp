// Result writers and all-or-nothing output files: see output.hpp. The ids format is written
// here; csv and GeoJSON read the layer's features through GDAL (feature_output.cpp).
#include "loci/io/output.hpp"

#include <cerrno>
#include <cstring>
#include <string>

#include "block_writer.hpp"
#include "gdal_seam.hpp"
#include "loci/geom/error.hpp"

namespace loci::io {
namespace {

// The rows formatted into a buffer written in blocks (a batch has millions of rows).
void write_ids(std::span<const Answer> answers, bool numbered, std::FILE* out) {
  detail::BlockWriter w(out);
  std::string& row = w.buf();
  for (const auto& a : answers) {
    if (numbered) {
      detail::append_int(row, a.query);
      row += ' ';
    }
    detail::append_int(row, a.fid);
    row += '\n';
    w.row_done();
  }
  w.flush();
}

}  // namespace

Format parse_format(const std::string& name) {
  if (name == "ids") return Format::ids;
  if (name == "csv") return Format::csv;
  if (name == "geojson") return Format::geojson;
  throw InvalidArgument("unknown format '" + name + "' (choose ids, csv or geojson)");
}

OutputFile::OutputFile(const std::string& path, std::FILE* fallback) : fallback_(fallback) {
  if (path.empty()) return;
  file_.emplace(path);  // refuses a layer of several, naming them
  refuse_replacing_binary_dataset(path);
}

void OutputFile::commit() {
  if (file_) {
    file_->commit();
    return;
  }
  if (std::fflush(fallback_) != 0 || std::ferror(fallback_))
    throw Error(std::string("cannot write output (") + std::strerror(errno ? errno : EIO) + ")");
}

void write_answers(const AnswerSource& source, std::span<const Answer> answers, Format format,
                   bool numbered, bool with_distance, bool with_point, const std::string& out_path,
                   std::FILE* fallback) {
  if (format != Format::ids) {
    detail::write_feature_answers(source, answers, format, numbered, with_distance, with_point,
                                  out_path, fallback);
    return;
  }
  OutputFile out(out_path, fallback);
  write_ids(answers, numbered, out.stream());
  out.commit();
}

}  // namespace loci::io
