// The commands that read a sidecar: query (with its parsers and query files), check, and the
// load that finds a query's index. None of them reads the layer through GDAL when the sidecar
// answers (see gdal_seam.hpp): the `loci` front runs them without loading GDAL.
#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <ios>
#include <mutex>
#include <string_view>
#include <thread>

#include "gdal_seam.hpp"
#include "loci/geom/error.hpp"
#include "loci/index/detail/hilbert.hpp"
#include "loci/io/atomic_file.hpp"
#include "loci/io/commands.hpp"
#include "loci/io/number_text.hpp"
#include "loci/io/sidecar.hpp"
#include "shapefile_records.hpp"

namespace loci::io {

std::size_t printable_at(std::string_view text, std::size_t at) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[at + k]); };
  const unsigned char c = byte(0);
  if (c < 0x80) return c < 0x20 || c == 0x7f ? 0 : 1;
  // A well-formed UTF-8 sequence (no overlong form, surrogate or code point beyond U+10FFFF).
  const std::size_t n = c >= 0xc2 && c <= 0xdf   ? 2
                        : c >= 0xe0 && c <= 0xef ? 3
                        : c >= 0xf0 && c <= 0xf4 ? 4
                                                 : 0;
  if (n == 0 || at + n > text.size()) return 0;
  for (std::size_t k = 1; k < n; ++k)
    if ((byte(k) & 0xc0) != 0x80) return 0;
  if ((c == 0xe0 && byte(1) < 0xa0) || (c == 0xed && byte(1) >= 0xa0) ||
      (c == 0xf0 && byte(1) < 0x90) || (c == 0xf4 && byte(1) >= 0x90))
    return 0;
  // Not a C1 control (U+0080 to U+009F, which terminals act on), the Arabic letter mark
  // (U+061C), nor a mark of direction or a separator of lines (U+200E, U+200F, U+2028 to
  // U+202E, U+2066 to U+2069).
  if (c == 0xc2 && byte(1) < 0xa0) return 0;
  if (c == 0xd8 && byte(1) == 0x9c) return 0;
  if (c == 0xe2 && byte(1) == 0x80 &&
      (byte(2) == 0x8e || byte(2) == 0x8f || (byte(2) >= 0xa8 && byte(2) <= 0xae)))
    return 0;
  if (c == 0xe2 && byte(1) == 0x81 && byte(2) >= 0xa6 && byte(2) <= 0xa9) return 0;
  return n;
}

std::string printable(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = printable_at(text, i);
    if (n == 0) {
      out += '?';
      ++i;
    } else {
      out.append(text.substr(i, n));
      i += n;
    }
  }
  return out;
}

std::string printable_prefix(std::string_view text, std::size_t most) {
  std::string out = printable(text);
  if (out.size() <= most) return out;
  // printable() keeps whole characters: a cut backs off to the start of one.
  std::size_t cut = most;
  while (cut > 0 && (static_cast<unsigned char>(out[cut]) & 0xc0) == 0x80)
    --cut;
  out.resize(cut);
  return out + "...";
}

namespace {

// The text as a message may quote it: at most 60 characters, printable.
std::string quoted(const std::string& text) {
  return "'" + printable_prefix(text, 60) + "'";
}

// Whether a decimal number that std::from_chars found out of a double's range is too large
// (rather than too small): its first significant digit stands at a positive power of ten.
bool beyond_doubles(std::string_view s) {
  long long lead = 0;  // the power of ten of the first significant digit, plus one
  bool point = false, significant = false;
  std::size_t i = s.empty() || s[0] != '-' ? 0 : 1;
  for (; i < s.size() && (std::isdigit(static_cast<unsigned char>(s[i])) || s[i] == '.'); ++i) {
    if (s[i] == '.') {
      point = true;
    } else if (!significant && s[i] == '0') {
      lead -= point;
    } else {
      significant = true;
      lead += !point;
    }
  }
  if (!significant) return false;
  long long exponent = 0;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    const std::size_t from = i + 1 + (i + 1 < s.size() && s[i + 1] == '+');
    const auto r = std::from_chars(s.data() + from, s.data() + s.size(), exponent);
    // An exponent beyond long long: its sign decides.
    if (r.ec == std::errc::result_out_of_range) return s[from] != '-';
  }
  return lead + exponent > 0;
}

// "A,B,..." as n finite numbers; spaces around each are allowed. std::from_chars reads the
// C locale's format whatever the process locale (a user's decimal comma does not change it).
std::vector<double> parse_numbers(const std::string& text, std::size_t n, const char* what,
                                  const char* form) {
  auto bad = [&] {
    return InvalidArgument(std::string("bad ") + what + " " + quoted(text) + ": expected " + form);
  };
  auto too_large = [&] {
    return InvalidArgument(std::string("bad ") + what + " " + quoted(text) +
                           ": values beyond +-1e150 are too large for exact distances");
  };
  std::vector<double> v;
  std::size_t at = 0;
  while (at <= text.size()) {
    const std::size_t comma = std::min(text.find(',', at), text.size());
    std::size_t first = text.find_first_not_of(" \t", at), last = comma;
    while (last > at && (text[last - 1] == ' ' || text[last - 1] == '\t' || text[last - 1] == '\r'))
      --last;
    if (first == std::string::npos || first >= last) throw bad();
    std::string_view field(text.data() + first, last - first);
    if (!detail::drop_plus(field)) throw bad();
    first = std::size_t(field.data() - text.data());
    double d = 0;
    const auto r = std::from_chars(text.data() + first, text.data() + last, d);
    if (r.ec == std::errc::result_out_of_range && r.ptr == text.data() + last &&
        beyond_doubles(std::string_view(text).substr(first, last - first)))
      throw too_large();
    if (r.ec != std::errc() || r.ptr != text.data() + last || !std::isfinite(d)) throw bad();
    if (std::abs(d) > kMaxCoordinate) throw too_large();
    v.push_back(d);
    at = comma + 1;
  }
  if (v.size() != n) throw bad();
  return v;
}

bool file_exists(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0;
}

}  // namespace

Box2 parse_bbox(const std::string& text) {
  const auto v = parse_numbers(text, 4, "bbox", "XMIN,YMIN,XMAX,YMAX");
  const Box2 b{{v[0], v[1]}, {v[2], v[3]}};
  if (v[0] > v[2] || v[1] > v[3])
    throw InvalidArgument("bad bbox " + quoted(text) + ": XMIN > XMAX or YMIN > YMAX");
  return b;
}

Point2 parse_point(const std::string& text) {
  const auto v = parse_numbers(text, 2, "point", "X,Y");
  return {v[0], v[1]};
}

Segment2 parse_segment(const std::string& text) {
  const auto v = parse_numbers(text, 4, "segment", "X0,Y0,X1,Y1");
  return {{v[0], v[1]}, {v[2], v[3]}};
}

Query parse_within(const std::string& text) {
  const auto v = parse_numbers(text, 3, "--within", "X,Y,D");
  if (v[2] < 0) throw InvalidArgument("bad --within " + quoted(text) + ": D must be >= 0");
  Query q;
  q.kind = Query::Kind::within;
  q.point = {v[0], v[1]};
  q.radius = v[2];
  return q;
}

std::string query_line_too_long(const std::string& path, std::size_t line) {
  return path + ": line " + std::to_string(line) + ": longer than " +
         std::to_string(kQueryLineLimit >> 20) + " MiB, not a line of a query file";
}

std::vector<std::pair<std::size_t, Query>> read_query_file(const std::string& path,
                                                           Query::Kind kind, std::size_t k) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw Error(path + ": is a directory, not a query file");
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot read the query file");
  // Read from the buffer directly rather than by std::getline, which takes a failure to grow
  // its line (out of memory) for the end of the file and grows without bound on a stream with
  // no newline: the first line longer than the limit is refused.
  std::streambuf* const buf = in.rdbuf();
  std::vector<std::pair<std::size_t, Query>> out;
  std::string line;
  std::size_t n = 1;
  // A failed read (the file's buffer throws std::ios_base::failure) names the file too.
  const auto read_line = [&] {
    line.clear();
    try {
      for (int c = buf->sbumpc(); c != std::char_traits<char>::eof(); c = buf->sbumpc()) {
        if (c == '\n') return true;
        if (line.size() == kQueryLineLimit) throw Error(query_line_too_long(path, n));
        line.push_back(char(c));
      }
    } catch (const std::ios_base::failure& e) {
      throw Error(path + ": cannot read the query file (line " + std::to_string(n) + ": " +
                  e.code().message() + ")");
    }
    return !line.empty();
  };
  for (; read_line(); ++n) {
    // A UTF-8 byte order mark, as editors on some systems write it, is not part of the text.
    if (n == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') continue;
    while (!line.empty() && (line.back() == '\r' || line.back() == ' '))
      line.pop_back();
    Query q;
    q.kind = kind;
    q.k = k;
    try {
      if (kind == Query::Kind::bbox)
        q.box = parse_bbox(line);
      else
        q.point = parse_point(line);
    } catch (const Error& e) {
      throw Error(path + ": line " + std::to_string(n) + ": " + e.what());
    }
    out.emplace_back(n, q);
  }
  return out;
}
namespace {

// Whether the stored hierarchies are those the tree and records give (the sidecar verified).
bool same_hierarchies(const LayerIndex::Features& stored, const LayerIndex::Features& built) {
  auto same = [](auto a, auto b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size_bytes()) == 0;
  };
  if (!built.hierarchical || !same(stored.fid, built.fid) || !same(stored.roots, built.roots) ||
      stored.levels.size() != built.levels.size() ||
      !same(stored.root_tree.blocks(), built.root_tree.blocks()) ||
      !same(stored.root_tree.item_indices(), built.root_tree.item_indices()) ||
      !same(stored.hull_first, built.hull_first) || !same(stored.hull_points, built.hull_points))
    return false;
  for (std::size_t l = 0; l < built.levels.size(); ++l)
    if (!same(stored.levels[l], built.levels[l])) return false;
  return true;
}

// The order in which a batch's queries run: by the Hilbert key, over the layer's extent, of
// each query's point (a window's centre, a segment's start), ties in query order. The grid
// takes any point (one outside the extent, or a centre that overflows, keys to its border).
std::vector<std::size_t> run_order(const std::vector<std::pair<std::size_t, Query>>& queries,
                                   const Box2& extent) {
  const loci::detail::HilbertGrid<2> grid(extent);
  auto point = [](const Query& q) {
    return q.kind == Query::Kind::bbox      ? q.box.center()
           : q.kind == Query::Kind::segment ? q.segment.a
                                            : q.point;
  };
  std::vector<std::pair<std::uint64_t, std::size_t>> keyed(queries.size());
  for (std::size_t i = 0; i < queries.size(); ++i)
    keyed[i] = {grid.key(point(queries[i].second)), i};
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::size_t> order(queries.size());
  for (std::size_t i = 0; i < keyed.size(); ++i)
    order[i] = keyed[i].second;
  return order;
}

}  // namespace

std::string check_sidecar(const std::string& arg) {
  // A layer given for its sidecar checks the sidecar; a sidecar beside the layer it is named
  // after is checked against it too, as every query checks it.
  std::string path = arg, layer;
  const std::string beside = default_sidecar_path(arg);
  std::error_code ec;
  const bool plain = std::filesystem::is_regular_file(arg, ec) ||
                     std::filesystem::is_directory(arg, ec);  // never opens a FIFO
  if (plain && !starts_as_sidecar(arg)) {
    if (!file_exists(beside))
      throw Error(arg + ": not a loci index file, and " + beside +
                  " does not exist; run 'loci index " + arg + "'");
    path = beside;
    layer = arg;
  }
  // A sidecar named after a layer (LAYER.loci) that is not there is checked alone, and says so.
  std::string unchecked;
  if (layer.empty() && path.size() > 5 && path.ends_with(".loci")) {
    const std::string named = path.substr(0, path.size() - 5);
    if (file_exists(named))
      layer = named;
    else
      unchecked = ", not checked against " + named + " (not found)";
  }
  Sidecar sc = Sidecar::open(path);
  const SidecarInfo info = sc.info();
  const std::size_t chunks = sc.check().chunks();
  try {
    sc.verify();
    if (sc.hierarchies()) {
      const LayerIndex index = LayerIndex::adopt(std::move(sc));
      const LayerIndex::Features built =
          LayerIndex::build_features(index.packed(), index.per(), index.records());
      if (!same_hierarchies(index.features(), built))
        throw Error(
            path +
            ": corrupt index file (the feature hierarchies or hulls do not match the segments); "
            "run 'loci index' to rebuild it");
    }
  } catch (const Error& e) {
    const std::string what = e.what();
    if (what.rfind(path, 0) == 0) throw;
    throw Error(path + ": corrupt index file (" + what + "); run 'loci index' to rebuild it");
  }
  // Queries trust an unchanged size, modification time and inode; check reads the layer's
  // contents then too (an edit of the same size with the time set back). still_fresh read
  // them already where those differ.
  Fingerprint now;
  bool fresh = layer.empty() || still_fresh(layer, info.source, &now);
  if (!layer.empty() && fresh && now.mtime_ns == info.source.mtime_ns &&
      now.inode == info.source.inode) {
    now = fingerprint_of(layer);
    fresh = now.size == info.source.size && now.hash == info.source.hash;
  }
  if (!fresh && only_gdal_opens(layer))
    throw Error(path + ": intact, but " + layer +
                " is a path only GDAL opens: nothing on disk tells whether it changed since");
  if (!fresh && is_vrt(layer))
    throw Error(path + ": intact, but not an index of " + layer +
                " (a VRT is not indexed: its features live in its sources)");
  if (!fresh)
    throw Error(path + ": intact but stale, " + layer + " changed since it was indexed (" +
                stale_reason(info.source, now) + "); run 'loci index " + layer + "'");
  const auto& i = info;
  return path + ": ok, " + (i.packing == Packing::str ? "packed-str" : "packed-hilbert") + " per " +
         to_string(i.per) + ", layer " + i.layer_name + ", " + std::to_string(i.items) +
         " entries, " + std::to_string(chunks) + (chunks == 1 ? " chunk of " : " chunks of ") +
         std::to_string(1u << (i.chunk_shift - 10)) + " KiB verified, " +
         std::to_string(i.file_size) + " bytes" + unchecked;
}

std::string default_layer_name(const std::string& path) {
  std::string ext = path.substr(
      path.find_last_of('.') == std::string::npos ? path.size() : path.find_last_of('.'));
  for (char& c : ext)
    c = char(std::tolower(static_cast<unsigned char>(c)));
  for (const char* single : {".shp", ".geojson", ".json", ".fgb", ".geojsonl", ".geojsons"})
    if (ext == single) return "";
  return detail::layer_name_in(path, "");
}

std::string sidecar_path_of(const LoadOptions& o) {
  return o.index_path.empty() ? default_sidecar_path(o.layer_path) : o.index_path;
}

namespace {

// Throws the error of an index (at `path`, of layer `indexed`) whose layer changed since
// (`was`, now `now`): "stale", or, when GDAL names the layer otherwise, the index of another
// layer. Without GDAL loaded, `gdal_or_hand_over` says whether to hand the command over
// (NeedsGdal) for that name, or to say "stale" without it (the input is read: no hand-over).
[[noreturn]] void refuse_stale(const LoadOptions& o, const std::string& path,
                               const std::string& indexed, const Fingerprint& was,
                               const Fingerprint& now, bool gdal_or_hand_over) {
  if (only_gdal_opens(o.layer_path))
    throw Error(path + ": an index of " + o.layer_path +
                ", a path only GDAL opens, cannot be checked against it (nothing on disk tells "
                "when it changes); query it without an index (loci query builds one in memory)" +
                (o.index_path.empty() ? ", after removing " + path : std::string()));
  // Nor is a VRT indexed: what stands beside it is an older loci's, or another file's.
  if (is_vrt(o.layer_path))
    throw Error(path + ": not an index of " + o.layer_path +
                " (a VRT is not indexed: its features live in its sources); query it without "
                "an index (loci query builds one in memory)" +
                (o.index_path.empty() ? ", after removing " + path : std::string()));
  // A sidecar of another layer altogether says so, rather than "stale".
  std::string actual;
  try {
    actual = detail::layer_name_in(o.layer_path, o.layer_name);
  } catch (const detail::NeedsGdal&) {
    if (gdal_or_hand_over) throw;
  } catch (const Error&) {
  }
  if (!actual.empty() && actual != indexed)
    throw Error(path + ": indexes layer '" + indexed + "', not '" + actual + "' of " +
                o.layer_path + "; run 'loci index " + o.layer_path +
                "' or give its own index with --index");
  // An index given with --index may be another file's as well as a stale one: the command
  // offered rewrites that index, not the layer's default sidecar.
  if (!o.index_path.empty())
    throw Error(path + ": does not match " + o.layer_path + " (" + stale_reason(was, now) +
                "): the index of another file, or of this one before it changed; run 'loci "
                "index " +
                o.layer_path + " -o " + path + "'");
  throw Error(path + ": stale index, " + o.layer_path + " changed since it was indexed (" +
              stale_reason(was, now) + "); run 'loci index " + o.layer_path + "'");
}

}  // namespace

LayerIndex load_index(const LoadOptions& o, std::string* origin, LayerGeometries* geometries) {
  const bool dynamic =
      o.structure && (*o.structure == Structure::rstar || *o.structure == Structure::rtree);
  const std::string path = sidecar_path_of(o);
  if (!o.index_path.empty() && !file_exists(path)) throw Error(path + ": no such index file");
  if (!dynamic && file_exists(path)) {
    Sidecar sc = Sidecar::open(path);
    Fingerprint now;
    if (!still_fresh(o.layer_path, sc.info().source, &now))
      refuse_stale(o, path, sc.info().layer_name, sc.info().source, now, true);
    // --layer as GDAL finds it: a name it does not know is said so, and one differing only in
    // case names the layer indexed.
    if (!o.layer_name.empty() && o.layer_name != sc.info().layer_name) {
      const std::string actual = detail::layer_name_in(o.layer_path, o.layer_name);
      if (actual != sc.info().layer_name)
        throw Error(path + ": indexes layer '" + sc.info().layer_name + "', not '" + actual +
                    "'; give another index file with --index");
    }
    // No --layer means the dataset's first layer; a sidecar of another layer must not answer.
    if (o.layer_name.empty()) {
      const std::string first = default_layer_name(o.layer_path);
      if (!first.empty() && first != sc.info().layer_name)
        throw Error(path + ": indexes layer '" + sc.info().layer_name + "', not the default '" +
                    first + "'; give --layer " + sc.info().layer_name +
                    ", or another index file with --index");
    }
    const bool same_per = !o.per || *o.per == sc.info().per;
    const bool same_packing = !o.structure || (*o.structure == Structure::packed_str) ==
                                                  (sc.info().packing == Packing::str);
    if (same_per && same_packing) {
      if (origin) *origin = "sidecar " + path;
      return LayerIndex::adopt(std::move(sc));
    }
  }
  if (origin) *origin = "built in memory";
  LayerItems items = read_items(o.layer_path, o.layer_name, o.per.value_or(Per::feature),
                                o.progress, geometries != nullptr);
  if (geometries && !items.geometries.empty()) geometries->adopt(std::move(items.geometries));
  return LayerIndex::build(std::move(items), o.structure.value_or(Structure::packed_hilbert));
}

std::optional<LoadedIndex> answers_without_gdal(const QueryOptions& options) {
  // An output file is written here only where nothing is yet (not even a dangling link): one
  // that is there may be a dataset of several layers, which GDAL tells (refuse_replacing_layers).
  std::error_code ec;
  const bool output_taken =
      !options.out_path.empty() && std::filesystem::symlink_status(options.out_path, ec).type() !=
                                       std::filesystem::file_type::not_found;
  const std::string path = sidecar_path_of(options.load);
  if (options.format != Format::ids || output_taken || !file_exists(path)) return std::nullopt;
  try {
    // Per feature, exact answers read the layer's features: here only a shapefile's, whose
    // records the direct reader takes (said from the headers, before the layer is hashed to
    // tell it fresh, which loci-full would do again).
    const Per per = Sidecar::open(path).info().per;
    const bool features_here = !options.candidates && per != Per::segment &&
                               detail::shp::ShapefileFeatures(options.load.layer_path).active();
    if (!options.candidates && per != Per::segment && !features_here) return std::nullopt;
    if (options.load.per && *options.load.per != per) return std::nullopt;
    LoadedIndex loaded;
    loaded.layer = fingerprint_stat(options.load.layer_path);
    loaded.index = std::make_shared<const LayerIndex>(load_index(options.load));
    loaded.features_here = features_here;
    if (options.candidates || loaded.index->per() == Per::segment || features_here) return loaded;
  } catch (...) {  // the command run in full says what is wrong
  }
  return std::nullopt;
}

QueryReport query_layer(const QueryOptions& options, std::FILE* fallback) {
  refuse_overwriting(options.out_path, options.load.layer_path);
  refuse_overwriting(options.out_path, sidecar_path_of(options.load), "index");
  QueryReport report;
  // A text layer is read whole once, for every thread; an index built in memory hands over
  // the geometries it read.
  const auto geometries =
      std::make_shared<LayerGeometries>(options.load.layer_path, options.load.layer_name);
  std::shared_ptr<const LayerIndex> loaded;
  if (options.loaded) {
    loaded = options.loaded->index;
    report.index_origin = "sidecar " + sidecar_path_of(options.load);
    // The layer changed while the queries were read (from a pipe, say): its index is loaded
    // again, as load_index loads it after reading them (indexed again meanwhile, it answers);
    // one that needs GDAL to tell or to answer is stale, or, when the queries can be read
    // again (features_here), handed over. Hashed again only when the layer's size, time or
    // inode changed.
    const Fingerprint* was = loaded->source();
    if (was && !(fingerprint_stat(options.load.layer_path) == options.loaded->layer)) {
      Fingerprint now;
      if (!still_fresh(options.load.layer_path, *was, &now)) {
        try {
          auto again = std::make_shared<const LayerIndex>(load_index(options.load));
          if (!options.candidates && again->per() != Per::segment && !options.loaded->features_here)
            throw detail::NeedsGdal();
          loaded = std::move(again);
        } catch (const detail::NeedsGdal&) {
          if (options.loaded->features_here) throw;  // the command can run again in full
          refuse_stale(options.load, sidecar_path_of(options.load), loaded->layer_name(), *was, now,
                       false);
        }
      }
    }
  } else {
    loaded = std::make_shared<const LayerIndex>(
        load_index(options.load, &report.index_origin, geometries.get()));
  }
  const LayerIndex& index = *loaded;
  bool with_distance = options.batch_kind == Query::Kind::nearest;
  bool with_point = false;
  for (const auto& [number, q] : options.queries) {
    with_distance |= q.kind == Query::Kind::within || q.kind == Query::Kind::nearest || q.first;
    with_point |= q.kind == Query::Kind::segment && !options.candidates;
  }
  const std::size_t n = options.queries.size();
  ProgressTicker ticker(options.progress, double(n));
  // The queries run in the order of their points along a Hilbert curve, cut into chunks that
  // threads take in turn, each thread with its own LayerQuery (its geometry cache and layer
  // handle) over the one immutable index; the answers are joined in query order. Queries
  // near each other in that order read the same nodes and pages of the index: on a large
  // sidecar a batch of random points runs about twice as fast as in file order.
  const std::vector<std::size_t> order = run_order(options.queries, index.bounds());
  constexpr std::size_t kChunk = 64;
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<std::vector<Answer>> parts(chunks);
  struct Place {
    std::size_t chunk, begin, end;  // query i's answers: parts[chunk][begin, end)
  };
  std::vector<Place> place(n);
  auto run_chunk = [&](LayerQuery& lq, std::size_t c) {
    const std::size_t end = std::min(n, (c + 1) * kChunk);
    for (std::size_t s = c * kChunk; s < end; ++s) {
      const std::size_t i = order[s];
      const auto& [number, q] = options.queries[i];
      const std::size_t begin = parts[c].size();
      lq.run(q, number, options.candidates, parts[c]);
      place[i] = {c, begin, parts[c].size()};
    }
    return end - c * kChunk;
  };
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const std::size_t jobs = std::min<std::size_t>(options.jobs ? options.jobs : cores, chunks);
  if (jobs <= 1) {
    LayerQuery lq(index, options.load.layer_path, index.layer_name(), geometries);
    std::size_t done = 0;
    for (std::size_t c = 0; c < chunks; ++c) {
      done += run_chunk(lq, c);
      ticker.tick(double(done));
    }
  } else {
    std::atomic<std::size_t> next{0}, done{0};
    std::atomic<bool> failed{false};
    std::exception_ptr error;
    std::mutex error_mutex;
    // Every thread takes chunks; this one also reports progress between its chunks.
    auto work = [&](bool reporting) {
      try {
        LayerQuery lq(index, options.load.layer_path, index.layer_name(), geometries);
        for (std::size_t c; !failed && (c = next++) < chunks;) {
          done += run_chunk(lq, c);
          if (reporting) ticker.tick(double(done));
        }
      } catch (...) {
        const std::lock_guard lock(error_mutex);
        if (!error) error = std::current_exception();
        failed = true;
      }
    };
    std::vector<std::thread> threads;
    for (std::size_t t = 1; t < jobs; ++t)
      threads.emplace_back(work, false);
    work(true);
    for (auto& t : threads)
      t.join();
    if (error) std::rethrow_exception(error);
    ticker.tick(double(n));
  }
  std::vector<Answer> answers;
  std::size_t total = 0;
  for (const auto& p : parts)
    total += p.size();
  answers.reserve(total);
  for (const Place& at : place)
    answers.insert(answers.end(), parts[at.chunk].begin() + std::ptrdiff_t(at.begin),
                   parts[at.chunk].begin() + std::ptrdiff_t(at.end));
  parts = {};  // not held while the answers are written
  write_answers({options.load.layer_path, index.layer_name()}, answers, options.format,
                options.numbered, with_distance, with_point, options.out_path, fallback);
  report.answers = answers.size();
  return report;
}

}  // namespace loci::io
