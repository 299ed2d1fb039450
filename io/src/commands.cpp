// The library side of `loci info`, `loci index` and `loci query`: see commands.hpp.
#include "loci/io/commands.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

#include "gdal_layer.hpp"
#include "loci/geom/error.hpp"
#include "loci/index/detail/hilbert.hpp"
#include "loci/io/atomic_file.hpp"
#include "loci/io/sidecar.hpp"

namespace loci::io {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::string fmt(double d) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", d);
  return buf;
}
// Why an index has its granularity, for loci info: " (chosen ...)" or nothing.
std::string granularity_reason(const SidecarInfo& i) {
  if (!i.per_chosen || i.features == 0) return "";
  const std::string limit = std::to_string(kSegmentsPerFeatureForSegments);
  if (i.per == Per::feature)  // the segments were not kept: only that they were few
    return " (chosen by loci index: fewer than " + limit + " segments per feature on average)";
  char mean[32];
  std::snprintf(mean, sizeof mean, "%.0f", double(i.items) / double(i.features));
  return std::string(" (chosen by loci index: ") + mean + " segments per feature on average, " +
         limit + " or more)";
}

}  // namespace

namespace {
// A name in a list of names separated by spaces: as it is, or in single quotes (a quote
// doubled) when it holds a space, a colon, a comma or a quote, or is empty; control characters
// (a newline) as '?', so that the summary keeps one line per item.
std::string listed(const std::string& name) {
  const std::string shown = printable(name);
  if (!shown.empty() && shown.find_first_of(" :,'\"") == std::string::npos) return shown;
  std::string q = "'";
  for (const char c : shown)
    q += c == '\'' ? std::string("''") : std::string(1, c);
  return q + "'";
}
// A word as a shell reads it back: as it is when it holds only characters the shell takes
// literally, else in single quotes (a quote as '\''), and a byte printable() would not show (a
// newline, a Latin-1 letter) as $'\xNN', which bash, zsh and ksh read back as that byte.
std::string shell_word(const std::string& word) {
  if (!word.empty() &&
      word.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-.,/:"
                             "+=@%") == std::string::npos)
    return word;
  std::string q;
  bool open = false;
  for (std::size_t i = 0; i < word.size();) {
    const std::size_t n = printable_at(word, i);
    if (n == 0) {
      if (open) q += '\'', open = false;
      char hex[8];
      std::snprintf(hex, sizeof hex, "$'\\x%02x'", static_cast<unsigned char>(word[i]));
      q += hex;
      ++i;
      continue;
    }
    if (!open) q += '\'', open = true;
    if (word[i] == '\'')
      q += "'\\''";
    else
      q.append(word, i, n);
    i += n;
  }
  if (open) q += '\'';
  return q.empty() ? "''" : q;
}

}  // namespace

std::string describe_layer(const std::string& layer_path, const std::string& layer_name,
                           const Progress& progress) {
  const LayerSummary s = summarize_layer(layer_path, layer_name, progress);
  std::ostringstream o;
  o << "layer:     " << printable(s.layer_name) << " (" << s.driver << ")\n";
  if (s.layer_names.size() > 1) {
    o << "layers:   ";
    for (const auto& n : s.layer_names)
      o << ' ' << listed(n);
    o << '\n';
  }
  o << "features:  " << s.feature_count << '\n';
  o << "geometry: ";
  if (s.geometry_types.empty()) o << " (no features)";
  for (const auto& [type, count] : s.geometry_types)
    o << ' ' << type << " x" << count;
  o << '\n';
  if (!s.extent.is_empty())
    o << "extent:    " << fmt(s.extent.min[0]) << ',' << fmt(s.extent.min[1]) << ','
      << fmt(s.extent.max[0]) << ',' << fmt(s.extent.max[1]) << '\n';
  o << "crs:       " << (s.crs.empty() ? "(none)" : s.crs) << '\n';
  o << "fields:   ";
  if (s.fields.empty()) o << " (none)";
  for (const auto& [name, type] : s.fields)
    o << ' ' << listed(name) << ':' << type;
  o << '\n';
  const std::string sidecar = default_sidecar_path(layer_path);
  o << "index:     ";
  if (is_vrt(layer_path)) {
    o << "none (a VRT is not indexed: its features live in its sources; loci query builds "
         "an index in memory)\n";
    return o.str();
  }
  if (only_gdal_opens(layer_path)) {
    o << "none (a path only GDAL opens is not indexed: nothing on disk tells when it "
         "changes; loci query builds an index in memory)\n";
    return o.str();
  }
  if (std::error_code ec; !std::filesystem::exists(sidecar, ec)) {
    // Of a dataset's other layers than its first, the command names the layer.
    const bool first = s.layer_names.empty() || s.layer_names.front() == s.layer_name;
    o << "none (loci index " << shell_word(layer_path)
      << (first ? std::string() : " --layer " + shell_word(s.layer_name)) << " writes "
      << printable(sidecar) << ")\n";
    return o.str();
  }
  try {
    const Sidecar sc = Sidecar::open(sidecar);
    const auto& i = sc.info();
    Fingerprint now;
    const bool fresh = still_fresh(layer_path, i.source, &now);
    // A sidecar of another layer (of this dataset, fresh, or of another file) is not this
    // layer's, as queries say; one of this layer is fresh or stale.
    const std::string status =
        i.layer_name != s.layer_name
            ? "not this layer's (it indexes layer '" + i.layer_name + "'; give --index)"
        : !fresh ? "stale (" + stale_reason(i.source, now) + ")"
                 : "fresh";
    o << printable(sidecar) << ": " << printable(status) << ", "
      << (i.packing == Packing::str ? "packed-str" : "packed-hilbert") << " per "
      << to_string(i.per) << granularity_reason(i) << ", layer " << printable(i.layer_name) << ", "
      << i.items << " entries, " << i.file_size << " bytes\n";
  } catch (const Error& e) {
    o << "unusable: " << printable(e.what()) << '\n';
  }
  return o.str();
}

IndexReport index_layer(const IndexOptions& options) {
  if (is_vrt(options.layer_path))
    throw Error(options.layer_path +
                ": a VRT's features live in its sources, whose changes an index of it would not "
                "see; query it without an index (loci query builds one in memory), or index "
                "its source");
  if (only_gdal_opens(options.layer_path))
    throw Error(options.layer_path +
                ": not a file on disk (a path only GDAL opens), whose changes an index could "
                "not see; query it without an index (loci query builds one in memory), or "
                "index a copy on disk");
  if (options.structure == Structure::rstar || options.structure == Structure::rtree)
    throw InvalidArgument(std::string("--structure ") + to_string(options.structure) +
                          " is built in memory only; a sidecar holds packed-hilbert or packed-str");
  const auto t0 = std::chrono::steady_clock::now();
  IndexReport r;
  r.path = options.out_path.empty() ? default_sidecar_path(options.layer_path) : options.out_path;
  refuse_overwriting(r.path, options.layer_path);
  // An index given with -o replaces only an index (or an empty file): written over a dataset
  // or a document it would lose it; a device or FIFO cannot be mapped by the queries to come.
  // The default LAYER.loci is the layer's own, replaced whatever it holds.
  {
    std::error_code ec;
    const auto st = std::filesystem::status(r.path, ec);
    if (std::filesystem::exists(st) && !std::filesystem::is_regular_file(st))
      throw Error("refusing to write the index to " + r.path +
                  ": not a regular file (queries map the index file)");
    if (!options.out_path.empty()) refuse_replacing_layers(r.path);  // says which layers
    if (!options.out_path.empty() && std::filesystem::is_regular_file(st) &&
        std::filesystem::file_size(r.path, ec) > 0 && !starts_as_sidecar(r.path))
      throw Error("refusing to write the index over " + r.path +
                  ": it exists and is not a loci index file; remove it or choose another -o");
  }
  // Sizes, times and inodes before reading and after: a layer changing while it is read must
  // not look fresh afterwards. The content hash comes from the reader when it had the bytes
  // (a shapefile read directly), else from a pass of its own.
  const Fingerprint before = fingerprint_stat(options.layer_path);
  // Reading takes most of the bar; packing and writing, which for a shapefile read directly
  // take as long, the rest.
  Progress reading;
  if (options.progress) reading = [&](double f) { options.progress(0.6 * f); };
  LayerItems items = options.per
                         ? read_items(options.layer_path, options.layer_name, *options.per, reading)
                         : read_items_choosing(options.layer_path, options.layer_name, reading);
  Fingerprint source = items.content_hash ? fingerprint_stat(options.layer_path)
                                          : fingerprint_of(options.layer_path);
  if (source.size != before.size || source.mtime_ns != before.mtime_ns ||
      source.inode != before.inode)
    throw Error(options.layer_path +
                ": changed while it was being indexed; run 'loci index' again");
  if (items.content_hash) source.hash = *items.content_hash;
  const Packing packing =
      options.structure == Structure::packed_str ? Packing::str : Packing::hilbert;
  const PackedRTree2 tree = PackedRTree2::build(items.boxes, packing);
  if (options.progress) options.progress(0.8);
  SidecarInfo info;
  info.per = items.per;
  info.per_chosen = !options.per;
  info.features = items.features;
  info.packing = packing;
  info.layer_name = items.layer_name;
  info.has_polygons = items.has_polygons;
  info.source = source;
  // Per segment, the features' hierarchies that nearest-n walks are stored too, so that a
  // query reads them in place instead of building them from every record.
  LayerIndex::Features features;
  if (items.per == Per::segment)
    features = LayerIndex::build_features(&tree, items.per, items.records);
  const Hierarchies stored = features.stored();
  // One sidecar per file: indexing another layer of a dataset replaces the first one's index,
  // which the report says.
  try {
    if (starts_as_sidecar(r.path)) {
      const std::string before = Sidecar::open(r.path).info().layer_name;
      if (before != items.layer_name) r.replaced_layer = before;
    }
  } catch (const Error&) {  // unreadable: replaced as it is
  }
  write_sidecar(r.path, tree, items.records, info, features.hierarchical ? &stored : nullptr);
  if (options.progress) options.progress(1.0);
  r.layer_name = items.layer_name;
  r.per = items.per;
  r.items = items.records.size();
  r.features = items.features;
  r.without_geometry = items.without_geometry;
  r.bytes = Sidecar::open(r.path).info().file_size;
  r.seconds = seconds_since(t0);
  return r;
}

}  // namespace loci::io
