// Writing results: files that appear whole or not at all, and the three answer formats of
// `loci query` (DESIGN.md section 6).
//
// Files are written through atomic_file.hpp: whole or not at all, never replacing a device,
// the old file intact on failure.
//
// Formats: `ids` prints one FID per line (`QUERY FID` for numbered batches); `csv` prints a
// header `fid,` then the layer's attributes (`query,` first for batches, `distance` after fid
// for within and nearest), RFC 4180 quoting; `geojson` goes through GDAL's GeoJSON driver with
// the geometry and the same columns.
#pragma once

#include <cstdio>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "loci/io/atomic_file.hpp"
#include "loci/io/layer_query.hpp"

namespace loci::io {

enum class Format { ids, csv, geojson };

// Accepts "ids", "csv", "geojson"; throws InvalidArgument otherwise.
Format parse_format(const std::string& name);

// An answer stream: the file `path` written atomically (AtomicFile), or `fallback` (stdout)
// when the path is empty. commit() reports a failed write (a full disk, a closed pipe) as an
// Error instead of exiting 0 with a truncated answer.
class OutputFile {
 public:
  OutputFile(const std::string& path, std::FILE* fallback);
  std::FILE* stream() { return file_ ? file_->stream() : fallback_; }
  void commit();

 private:
  std::optional<AtomicFile> file_;
  std::FILE* fallback_;
};

using OutputDataset = AtomicDataset;

struct AnswerSource {
  std::string layer_path;
  std::string layer_name;
};

// Throws Error when the output cannot be written or a feature is missing from the layer.
// with_point adds the columns (csv) or fields (GeoJSON) x and y: Answer::at.
void write_answers(const AnswerSource& source, std::span<const Answer> answers, Format format,
                   bool numbered, bool with_distance, bool with_point, const std::string& out_path,
                   std::FILE* fallback);

}  // namespace loci::io
