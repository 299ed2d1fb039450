// Writing results: files that appear whole or not at all, and the three answer formats of
// `loci query` (DESIGN.md section 6).
//
// OutputFile and OutputDataset write under a temporary name in the target's directory and
// rename into place on commit(); destroyed without commit() they remove what they wrote, so
// a failure never leaves a partial file. OutputDataset holds a temporary directory because
// some GDAL formats are several files (a shapefile's .shp, .shx, .dbf, .prj) that must all
// move together.
//
// Formats: `ids` prints one FID per line (`QUERY FID` for numbered batches); `csv` prints a
// header `fid,` then the layer's attributes (`query,` first for batches, `distance` after fid
// for within and nearest), RFC 4180 quoting; `geojson` goes through GDAL's GeoJSON driver with
// the geometry and the same columns.
#pragma once

#include <cstdio>
#include <memory>
#include <span>
#include <string>

#include "loci/io/layer_query.hpp"

namespace loci::io {

enum class Format { ids, csv, geojson };

// Accepts "ids", "csv", "geojson"; throws InvalidArgument otherwise.
Format parse_format(const std::string& name);

class OutputFile {
 public:
  // An empty path means `fallback` (stdout), written directly. Throws Error when the target
  // directory cannot hold the file.
  OutputFile(const std::string& path, std::FILE* fallback);
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  std::FILE* stream() const { return stream_; }
  void commit();

 private:
  std::string path_;
  std::string tmp_;
  std::FILE* stream_ = nullptr;
  bool committed_ = false;
};

class OutputDataset {
 public:
  explicit OutputDataset(const std::string& path);
  ~OutputDataset();
  OutputDataset(const OutputDataset&) = delete;
  OutputDataset& operator=(const OutputDataset&) = delete;
  // Where GDAL should create the dataset.
  const std::string& staging_path() const { return staging_; }
  // Moves every file GDAL wrote into the target directory. Call after closing the dataset.
  void commit();

 private:
  std::string path_;
  std::string dir_;
  std::string staging_;
  bool committed_ = false;
};

struct AnswerSource {
  std::string layer_path;
  std::string layer_name;
};

// Throws Error when the output cannot be written or a feature is missing from the layer.
void write_answers(const AnswerSource& source, std::span<const Answer> answers, Format format,
                   bool numbered, bool with_distance, const std::string& out_path,
                   std::FILE* fallback);

}  // namespace loci::io
