// `loci query`: its flags, and its options as query_layer takes them.
#include <cstring>

#include "command_line.hpp"
#include "loci/io/atomic_file.hpp"

namespace loci::cli {

using namespace loci::io;

namespace {

int run_query(const Args& a);

}  // namespace

QueryOptions query_options(const Args& a, bool read_queries) {
  QueryOptions o;
  const std::string& layer = layer_arg(a, "query");
  o.load = load_options(a, layer);
  const char* kinds[] = {"--bbox",   "--bbox-file", "--nearest", "--nearest-file",
                         "--within", "--segment",   "--point",   "--point-file"};
  int given = 0;
  for (const char* k : kinds)
    given += a.has(k);
  if (given != 1)
    throw UsageError(
        "loci query needs exactly one of --bbox, --bbox-file, --nearest, "
        "--nearest-file, --within, --segment, --point, --point-file");
  if (a.has("-k") && !a.has("--nearest") && !a.has("--nearest-file"))
    throw UsageError("-k counts the neighbours of --nearest or --nearest-file");
  const std::size_t k = a.has("-k") ? parse_count("-k", a.get("-k"), 1, kMaxK) : 1;
  Query q;
  q.k = k;
  if (a.has("--bbox")) {
    q.kind = Query::Kind::bbox;
    q.box = parse_bbox(a.get("--bbox"));
  } else if (a.has("--nearest")) {
    q.kind = Query::Kind::nearest;
    q.point = parse_point(a.get("--nearest"));
  } else if (a.has("--within")) {
    q = parse_within(a.get("--within"));
  } else if (a.has("--segment")) {
    q.kind = Query::Kind::segment;
    q.segment = parse_segment(a.get("--segment"));
    q.first = a.has("--first");
  } else if (a.has("--point")) {
    q.kind = Query::Kind::point;
    q.point = parse_point(a.get("--point"));
  }
  if (a.has("--first") && !a.has("--segment"))
    throw UsageError("--first goes with --segment (the feature the segment meets first)");
  // The output's format (and a name saying another) before any query file is read.
  o.format = output_format(a, {Format::ids, Format::csv, Format::geojson}, Format::ids);
  for (const char* file : {"--bbox-file", "--nearest-file", "--point-file"})
    if (a.has(file) && a.has("--output"))
      refuse_overwriting(a.get("--output"), a.get(file), "query file");
  if (!read_queries) {
  } else if (a.has("--bbox-file")) {
    o.queries = read_query_file(a.get("--bbox-file"), Query::Kind::bbox, k);
    o.numbered = true;
    o.batch_kind = Query::Kind::bbox;
  } else if (a.has("--nearest-file")) {
    o.queries = read_query_file(a.get("--nearest-file"), Query::Kind::nearest, k);
    o.numbered = true;
    o.batch_kind = Query::Kind::nearest;
  } else if (a.has("--point-file")) {
    o.queries = read_query_file(a.get("--point-file"), Query::Kind::point, k);
    o.numbered = true;
    o.batch_kind = Query::Kind::point;
  } else {
    o.queries.emplace_back(1, q);
  }
  o.candidates = a.has("--candidates");
  o.out_path = a.get("--output");
  o.progress = progress_bar(a, "querying");
  if (a.has("--jobs"))
    o.jobs = static_cast<unsigned>(parse_count("--jobs", a.get("--jobs"), 1, 1024));
  return o;
}

namespace {

int run_query(const Args& a) {
  query_layer(query_options(a, true), stdout);
  return 0;
}

}  // namespace

const Command& query_command() {
  static const Command command = {
      "query",
      "loci query LAYER (--bbox ... | --bbox-file F | --nearest X,Y [-k N] | ...) [-f FMT] [-o "
      "OUT]",
      "features whose exact geometry meets the query (the index gives candidates)",
      {{"--bbox", "-b", "XMIN,YMIN,XMAX,YMAX", "features meeting the closed window"},
       {"--bbox-file", nullptr, "F",
        "one window per line (- for stdin); rows start with the line number"},
       {"--nearest", "-n", "X,Y", "the k features nearest to the point, nearest first"},
       {"--nearest-file", nullptr, "F",
        "one X,Y per line (- for stdin); rows start with the line number"},
       {"-k", nullptr, "N", "how many neighbours, 1 to 1000000 (default 1)"},
       {"--within", nullptr, "X,Y,D",
        "features at distance <= D from the point (planar, in the layer's units)"},
       {"--segment", nullptr, "X0,Y0,X1,Y1",
        "features meeting the closed segment, with the first point of each (csv: x,y)"},
       {"--first", nullptr, nullptr,
        "with --segment: only the feature met first from X0,Y0 (line of sight), the point and "
        "the distance along the segment"},
       {"--point", nullptr, "X,Y", "features containing or touching the point"},
       {"--point-file", nullptr, "F",
        "point location in batch: one X,Y per line (- for stdin); rows start with the line "
        "number"},
       {"--candidates", nullptr, nullptr,
        "the index's answer before the exact test (it holds the exact answer)"},
       {"--format", "-f", "ids|csv|geojson",
        "output: FIDs (default), CSV with attributes, GeoJSON (default: as -o's name says, "
        ".csv or .geojson)"},
       {"--output", "-o", "OUT", "write to OUT (whole or not at all) instead of stdout", true},
       {"--jobs", "-j", "N", "threads for a batch file (default: one per core)"},
       kIndex,
       kStructure,
       kPer,
       kLayer,
       kQuiet},
      "  loci query countries.shp --bbox 5,45,15,55\n"
      "  loci query countries.shp --nearest 2.35,48.85 -k 3 -f csv\n"
      "  loci query countries.shp --bbox-file windows.txt -o hits.txt\n"
      "  loci query coast.shp --segment 8,55,12,55 --first -f csv\n",
      run_query};
  return command;
}

}  // namespace loci::cli
