// The work behind each `loci` sub-command, as library functions (the GDAL apps pattern: a
// function per utility taking an options struct, and a thin main that parses arguments into
// it). Everything here reports failure by throwing loci::Error with a one-line message.
//
//   describe_layer   `loci info`: the layer's summary and the state of its sidecar
//   index_layer      `loci index`: reads the layer, packs the tree, writes the sidecar
//   check_sidecar    `loci check`: verifies every byte and invariant of a sidecar
//   load_index       how `loci query` finds its index: a fresh sidecar is mapped, a stale or
//                    corrupt one is refused, no sidecar means building in memory
//   query_layer      `loci query`: one query or a numbered batch, exact or --candidates
//   clip_layer       `loci clip`: features meeting a window, cut to it, written through GDAL
//   draw_index       `loci draw`: an SVG of the layer and the index's nodes by level, or of
//                    the layer's region quadtree cells
#pragma once

#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "loci/io/layer_query.hpp"
#include "loci/io/output.hpp"
#include "loci/io/progress.hpp"

namespace loci::io {

// GDAL prints its own "ERROR n: ..." lines on stderr unless told otherwise; a command-line
// program calls this once so that the only message a user sees is loci's one line (every
// failure GDAL reports is turned into a loci::Error carrying GDAL's message).
void silence_gdal_messages();

// Parse "A,B,C,D" style arguments; throw InvalidArgument quoting the text and the form wanted.
Box2 parse_bbox(const std::string& text);
Point2 parse_point(const std::string& text);
Segment2 parse_segment(const std::string& text);
// "X,Y,D"
Query parse_within(const std::string& text);

// One query per non-empty line (XMIN,YMIN,XMAX,YMAX for bbox, X,Y otherwise); blank lines
// and lines starting with '#' are skipped but still counted, so answers name file lines.
// Throws Error naming the file and line of a bad line, of a line longer than
// kQueryLineLimit, or where reading fails (memory too: never a batch cut short).
std::vector<std::pair<std::size_t, Query>> read_query_file(const std::string& path,
                                                           Query::Kind kind, std::size_t k);
// A query file's lines are at most this long: a longer one (a binary file, an endless stream
// without newlines) is refused before it fills memory, with this message.
inline constexpr std::size_t kQueryLineLimit = std::size_t(1) << 20;
std::string query_line_too_long(const std::string& path, std::size_t line);

// Text as a message or a summary line shows it: control characters (a newline in a file or
// layer name, an escape sequence meant for the terminal), bytes that are not UTF-8 text, and
// the characters that break a line or turn its direction (U+2028, U+202E, ...) as '?', so that
// it keeps to one line and reads as written.
std::string printable(std::string_view text);
// The length in bytes of the character at `at` when printable() keeps it, else 0.
std::size_t printable_at(std::string_view text, std::size_t at);
// printable(text) cut to at most `most` bytes at a character's boundary, "..." after a cut.
std::string printable_prefix(std::string_view text, std::size_t most);

std::string describe_layer(const std::string& layer_path, const std::string& layer_name,
                           const Progress& progress = {});

struct IndexOptions {
  std::string layer_path;
  std::string layer_name;
  std::string out_path;  // empty: default_sidecar_path(layer_path)
  Structure structure = Structure::packed_hilbert;
  // Unset: per segment when the features average at least kSegmentsPerFeatureForSegments
  // segments (big polygons and long lines), else per feature.
  std::optional<Per> per;
  Progress progress;
};

struct IndexReport {
  std::string path;
  std::string layer_name;
  Per per = Per::feature;
  std::size_t items = 0;
  std::uint64_t features = 0;          // features indexed
  std::uint64_t without_geometry = 0;  // features skipped: no geometry, or an empty one
  std::uint64_t bytes = 0;
  double seconds = 0;
  std::string replaced_layer;  // the layer whose index the file held before, when another
};

// Throws InvalidArgument for a structure that cannot be stored (the dynamic trees).
IndexReport index_layer(const IndexOptions& options);

// Verifies a sidecar whole: header, every chunk's checksum, the tree's invariants (boxes are
// the unions of their nodes, item indices a permutation). Returns a one-line summary; throws
// loci::Error naming the file and the first problem found. Given a layer instead, checks its
// sidecar LAYER.loci; either way, when the layer the sidecar is named after exists, a layer
// changed since it was indexed is an error too (queries refuse that sidecar as stale).
std::string check_sidecar(const std::string& path_or_layer);

struct LoadOptions {
  std::string layer_path;
  std::string layer_name;
  std::string index_path;              // empty: default_sidecar_path(layer_path)
  std::optional<Structure> structure;  // set: build that structure in memory if needed
  std::optional<Per> per;              // set: the granularity wanted
  Progress progress;
};

// The sidecar a load reads when it is there: index_path, or the layer's default one.
std::string sidecar_path_of(const LoadOptions& options);

// `origin` receives a short description ("sidecar FILE" or "built in memory").
// With `geometries`, an index built in memory per feature from a text layer hands over the
// geometries it read (LayerGeometries::adopt).
LayerIndex load_index(const LoadOptions& options, std::string* origin = nullptr,
                      LayerGeometries* geometries = nullptr);

// An index loaded before its queries are read, and the layer's size, time and inode then
// (fingerprint_stat), to tell a layer changed meanwhile (see answers_without_gdal).
struct LoadedIndex {
  std::shared_ptr<const LayerIndex> index;
  Fingerprint layer;
  // Per feature: the exact tests read the layer's features without GDAL (a shapefile's
  // records), and query_layer throws NeedsGdal, having written nothing, at a record that needs
  // GDAL to be read.
  bool features_here = false;
};

// Thrown where the work needs GDAL by io/'s build without it (the library loci_io_lean, which
// the `loci` front links), whose process has not loaded GDAL; never by the library built with
// GDAL (the loci::io target).
class NeedsGdal : public Error {
 public:
  NeedsGdal() : Error("this needs GDAL, which this process does not load") {}
};

struct QueryOptions {
  LoadOptions load;
  std::vector<std::pair<std::size_t, Query>> queries;  // number, query
  bool numbered = false;  // batch output: every row starts with the query number
  // A batch's kind of query, known even when its file holds none (the CSV header's columns
  // depend on it, not on whether there are rows).
  std::optional<Query::Kind> batch_kind;
  bool candidates = false;  // box-level answers only
  Format format = Format::ids;
  std::string out_path;  // empty: `fallback`
  Progress progress;     // over the queries of a batch
  unsigned jobs = 0;     // threads for a batch; 0: one per core
  // Set: the index to answer from, loaded from `load` before the queries were read
  // (answers_without_gdal's), not loaded again.
  std::optional<LoadedIndex> loaded;
};

struct QueryReport {
  std::size_t answers = 0;
  std::string index_origin;
};

QueryReport query_layer(const QueryOptions& options, std::FILE* fallback);

// The index query_layer answers `options` from without reading the layer through GDAL: a
// fresh sidecar per segment (or for --candidates), or per feature of a shapefile whose
// records the direct reader takes (the caller can then have the command run in full, reading
// its queries again, should a record need GDAL: see LoadedIndex::features_here), when ids
// go to stdout or to a file not there yet (one that is may be a dataset of several layers,
// which GDAL tells); nullopt otherwise, and on any failure (the command run in full says what
// is wrong). Reads no query file and writes nothing. For the `loci` front, which runs such queries
// without loading GDAL: it gives the index to query_layer (QueryOptions::loaded), which does not
// load it again (a sidecar replaced meanwhile, by one per feature say, would need GDAL once the
// queries were read) but checks again that the layer has not changed: changed, its index is
// loaded again as loci-full loads it, and where that needs GDAL the query is refused as stale
// (loci-full would name another layer when GDAL names the layer otherwise).
std::optional<LoadedIndex> answers_without_gdal(const QueryOptions& options);

struct ClipOptions {
  LoadOptions load;
  Box2 window{};                  // the window, unless one of the two below is given
  std::string window_wkt;         // a polygonal window as WKT (POLYGON or MULTIPOLYGON)
  std::string window_layer;       // a polygonal window: the union of this layer's polygons
  std::string window_layer_name;  // its layer (default: the first)
  std::string out_path;
};

struct ClipResult {
  std::size_t written = 0;  // features written
  std::size_t dropped = 0;  // cut pieces of a lower dimension than their feature left out
  // Fields whose type the output format does not hold, as ogr2ogr warns of them: made of
  // another type (a shapefile's Date for a DateTime, dropping the times of day; `as` names it)
  // or left for the driver to convert (`as` empty: the format lists no such type).
  struct Retyped {
    std::string field, type, as;
  };
  std::vector<Retyped> retyped;
};
ClipResult clip_layer(const ClipOptions& options);

struct DrawOptions {
  std::string
      path;  // a layer, or a .loci sidecar (then the layer is the sidecar's name minus .loci)
  std::string index_path;  // the sidecar of the layer at `path`, when not path + ".loci"
  std::string layer_name;
  std::string out_path;
  int width = 1200;
  int max_levels = 3;    // how many levels above the leaves to draw
  int cell_levels = -1;  // >= 0: draw the layer's region quadtree, cut that often, instead
  Progress progress;
};

// Returns the number of node rectangles (or quadtree cells) drawn.
std::size_t draw_index(const DrawOptions& options);

}  // namespace loci::io
