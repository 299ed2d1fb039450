// loci-full: the command-line face of the library (DESIGN.md section 6), every command, with
// GDAL. The `loci` front (front.cpp) hands it what it does not answer itself.
//
// This file only parses arguments, draws progress and prints; the work is done by the
// functions of loci/io/commands.hpp, one per sub-command. Every command's flags are declared
// once, in the table at the bottom, and that table is also what `--help` prints, so the help
// cannot drift from what is accepted. Failures print one line `loci: error: ...` and exit 1.
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "bench.hpp"
#include "command_line.hpp"
#include "loci/geom/error.hpp"
#include "loci/io/atomic_file.hpp"
#include "loci/io/commands.hpp"
#include "loci/io/fleet_commands.hpp"
#include "loci/io/intersections.hpp"
#include "loci/io/join.hpp"
#include "loci/io/layer_cells.hpp"
#include "loci/io/number_text.hpp"

namespace {

using namespace loci;
using namespace loci::cli;
using namespace loci::io;

// "1 pair", "2 pairs".
std::string counted(std::uint64_t n, const char* noun) {
  return std::to_string(n) + ' ' + noun + (n == 1 ? "" : "s");
}

// A drawing of 2^L x 2^L cells: past 12 levels (16 million cells) the SVG stops being something
// a viewer opens.
constexpr std::size_t kMaxCellLevels = 12;

// A text or GeoJSON output that would replace a dataset is refused before the work (the
// refusal came after a join or conflict search had run to its end); an index and a clip judge
// their targets themselves.
void refuse_replacing_output(const Command& c, const Args& args) {
  const std::string command = c.name;
  if (args.has("--output") && command != "index" && command != "clip") {
    refuse_replacing_layers(args.get("--output"));
    refuse_replacing_binary_dataset(args.get("--output"));
  }
}

int run_info(const Args& a) {
  const std::string& layer = layer_arg(a, "info");
  std::fputs(describe_layer(layer, a.get("--layer"), progress_bar(a, "reading")).c_str(), stdout);
  return 0;
}

int run_index(const Args& a) {
  IndexOptions o;
  o.layer_path = layer_arg(a, "index");
  o.layer_name = a.get("--layer");
  o.out_path = a.get("--output");
  check_output_name(a, "loci");
  if (a.has("--structure"))
    o.structure = parse_flag("--structure", a.get("--structure"), parse_structure);
  const LoadOptions lo = load_options(a, o.layer_path);
  o.per = lo.per;
  o.progress = progress_bar(a, "indexing");
  const IndexReport r = index_layer(o);
  if (!a.has("--quiet")) {
    std::string what = r.per == Per::segment
                           ? counted(r.items, "segment") + " of " + counted(r.features, "feature")
                           : counted(r.items, "feature");
    // Features without points are left out of every index: say how many, or they go unseen.
    std::string skipped;
    if (r.without_geometry > 0)
      skipped = "; skipped " + counted(r.without_geometry, "feature") +
                " without a geometry or with an empty one";
    std::fprintf(stderr, "loci: indexed %s of layer '%s' into %s (%llu bytes, %.2f s)%s\n",
                 what.c_str(), printable(r.layer_name).c_str(), printable(r.path).c_str(),
                 static_cast<unsigned long long>(r.bytes), r.seconds, skipped.c_str());
    if (!r.replaced_layer.empty())
      std::fprintf(stderr,
                   "loci: %s held the index of layer '%s', now replaced (one index per file: "
                   "give another with -o to keep both)\n",
                   printable(r.path).c_str(), printable(r.replaced_layer).c_str());
  }
  return 0;
}

int run_clip(const Args& a) {
  ClipOptions o;
  o.load = load_options(a, layer_arg(a, "clip"));
  if (a.has("--bbox") + a.has("--wkt") + a.has("--window-layer") != 1)
    throw UsageError(
        "loci clip needs exactly one window: --bbox XMIN,YMIN,XMAX,YMAX, --wkt POLYGON or "
        "--window-layer POLYGONS");
  if (!a.has("--output")) throw UsageError("loci clip needs -o OUT");
  if (a.has("--bbox")) o.window = parse_bbox(a.get("--bbox"));
  o.window_wkt = a.get("--wkt");
  o.window_layer = a.get("--window-layer");
  o.window_layer_name = a.get("--window-layer-name");
  o.out_path = a.get("--output");
  const ClipResult r = clip_layer(o);
  // Values changed on the way are said even with --quiet.
  for (const ClipResult::Retyped& f : r.retyped) {
    const std::string out = printable(o.out_path), field = printable(f.field);
    if (f.as.empty())
      std::fprintf(stderr, "loci: warning: %s has no %s fields: GDAL converts field %s\n",
                   out.c_str(), f.type.c_str(), field.c_str());
    else
      std::fprintf(stderr, "loci: warning: %s has no %s fields: field %s written as %s\n",
                   out.c_str(), f.type.c_str(), field.c_str(), f.as.c_str());
  }
  if (!a.has("--quiet")) {
    std::fprintf(stderr, "loci: %zu feature%s clipped into %s\n", r.written,
                 r.written == 1 ? "" : "s", printable(o.out_path).c_str());
    if (r.dropped > 0)
      std::fprintf(stderr,
                   "loci: %zu piece%s of lower dimension left out (points or lines where the "
                   "window only touches a feature, or beside its cut parts)\n",
                   r.dropped, r.dropped == 1 ? "" : "s");
  }
  return 0;
}

int run_intersections(const Args& a) {
  if (a.positional.empty() || a.positional.size() > 2)
    throw UsageError(
        "loci intersections needs LAYER and optionally LAYER2 (see loci "
        "intersections --help)");
  IntersectionsOptions o;
  o.layer_path = a.positional[0];
  o.layer_name = a.get("--layer");
  // --layer2 without LAYER2 names the second layer of LAYER's own dataset.
  if (a.positional.size() == 2)
    o.other_path = a.positional[1];
  else if (a.has("--layer2"))
    o.other_path = o.layer_path;
  o.other_name = a.get("--layer2");
  o.format = output_format(a, {Format::csv, Format::geojson}, Format::csv);
  o.pairs_only = a.has("--pairs-only");
  o.out_path = a.get("--output");
  if (a.has("--jobs"))
    o.jobs = static_cast<unsigned>(parse_count("--jobs", a.get("--jobs"), 1, 1024));
  o.progress = progress_bar(a, "reading");
  const std::size_t n = write_intersections(o, stdout);
  if (!a.has("--quiet") && !o.out_path.empty())
    std::fprintf(stderr, "loci: %s written into %s\n", counted(n, "row").c_str(),
                 printable(o.out_path).c_str());
  return 0;
}

int run_join(const Args& a) {
  if (a.positional.size() != 2)
    throw UsageError("loci join needs LEFT and RIGHT layers (see loci join --help)");
  if (a.has("--predicate") && a.has("--closest"))
    throw UsageError("loci join takes --predicate or --closest, not both");
  if (!a.has("--predicate") && !a.has("--closest"))
    throw UsageError(
        "loci join needs --predicate intersects|contains|within|dwithin:D or --closest");
  JoinOptions o;
  o.left_path = a.positional[0];
  o.left_name = a.get("--layer");
  o.right_path = a.positional[1];
  o.right_name = a.get("--layer2");
  if (a.has("--closest"))
    o.predicate = JoinPredicate::closest;
  else
    parse_flag("--predicate", a.get("--predicate"), [&](const std::string& t) {
      parse_join_predicate(t, o);
      return 0;
    });
  o.format = output_format(a, {Format::csv, Format::ids}, Format::csv);
  o.out_path = a.get("--output");
  o.progress = progress_bar(a, "joining");
  const std::size_t n = write_join(o, stdout);
  if (!a.has("--quiet") && !o.out_path.empty())
    std::fprintf(stderr, "loci: %s written into %s\n", counted(n, "pair").c_str(),
                 printable(o.out_path).c_str());
  return 0;
}

int run_draw(const Args& a) {
  DrawOptions o;
  o.path = layer_arg(a, "draw");
  o.layer_name = a.get("--layer");
  o.index_path = a.get("--index");
  o.out_path = a.get("--output");  // empty: stdout
  check_output_name(a, "svg");
  if (a.has("--levels") && a.has("--cells"))
    throw UsageError(
        "loci draw takes --levels (index nodes) or --cells (quadtree cells), not both");
  if (a.has("--levels")) o.max_levels = int(parse_count("--levels", a.get("--levels"), 1, 64));
  if (a.has("--width")) o.width = int(parse_count("--width", a.get("--width"), 16, 100000));
  if (a.has("--cells"))
    o.cell_levels = int(parse_flag("--cells", a.get("--cells"), [](const std::string& t) {
      return parse_count("level count", t, 0, kMaxCellLevels);
    }));
  o.progress = progress_bar(a, o.cell_levels >= 0 ? "cells" : "indexing");
  const std::size_t n = draw_index(o);
  if (!a.has("--quiet"))
    std::fprintf(stderr, "loci: %s drawn%s\n",
                 counted(n, o.cell_levels >= 0 ? "cell" : "node").c_str(),
                 o.out_path.empty() ? "" : (" into " + printable(o.out_path)).c_str());
  return 0;
}

int run_bench(const Args& a) {
  BenchOptions o;
  o.layer_path = layer_arg(a, "bench");
  o.layer_name = a.get("--layer");
  const LoadOptions lo = load_options(a, o.layer_path);
  o.per = lo.per.value_or(Per::segment);
  if (a.has("--queries")) o.queries = parse_count("--queries", a.get("--queries"), 1, 100000000);
  if (a.has("-k")) o.k = parse_count("-k", a.get("-k"), 1, kMaxK);
  o.progress = progress_bar(a, "reading");
  std::fputs(bench_layer(o).c_str(), stdout);
  return 0;
}

// ---- loci fleet ----

// A real number given to `flag`, finite and >= 0 (> 0 when `positive`).
double parse_nonnegative(const char* flag, const std::string& text, bool positive = false) {
  double v = 0;
  std::string_view digits = text;
  const bool plus_ok = io::detail::drop_plus(digits);  // "+5" as every number is read
  const auto r = std::from_chars(digits.data(), digits.data() + digits.size(), v);
  if (!plus_ok || digits.empty() || r.ec != std::errc() || r.ptr != digits.data() + digits.size() ||
      !std::isfinite(v) || v < 0 || (positive && v == 0))
    throw UsageError(std::string("bad ") + flag + " '" + text.substr(0, 40) +
                     "': expected a finite number " + (positive ? "> 0" : ">= 0"));
  return v;
}

const std::string& fleet_file(const Args& a, const char* command) {
  if (a.positional.size() != 1)
    throw UsageError(std::string("loci fleet ") + command +
                     " needs exactly one FILE (see loci fleet " + command + " --help)");
  return a.positional[0];
}

std::optional<double> at_flag(const Args& a) {
  if (!a.has("--at")) return std::nullopt;
  return parse_flag("--at", a.get("--at"), parse_time);
}

// The summary line of what was read, and for AIS input what the output's units are.
void print_fleet_run(const Args& a, const FleetRun& r) {
  if (a.has("--quiet")) return;
  std::fprintf(stderr, "loci: %s\n", printable(r.summary).c_str());
  if (!r.units.empty()) std::fprintf(stderr, "loci: %s\n", r.units.c_str());
}

int run_fleet_query(const Args& a) {
  FleetQueryOptions o;
  o.path = fleet_file(a, "query");
  if (a.has("--bbox") == a.has("--nearest"))
    throw UsageError("loci fleet query needs exactly one of --bbox and --nearest");
  if (a.has("--at") && a.has("--during")) throw UsageError("give --at or --during, not both");
  if (a.has("--bbox")) {
    o.box = parse_flag("--bbox", a.get("--bbox"), parse_bbox);
  } else {
    o.kind = FleetQueryOptions::Kind::nearest;
    o.point = parse_flag("--nearest", a.get("--nearest"), parse_point);
    if (a.has("--during"))
      throw UsageError("--nearest answers at one time: use --at, not --during");
  }
  if (a.has("-k") && !a.has("--nearest")) throw UsageError("-k counts the neighbours of --nearest");
  if (a.has("-k")) o.k = parse_count("-k", a.get("-k"), 1, kMaxK);
  o.at = at_flag(a);
  if (a.has("--during"))
    o.during = parse_flag("--during", a.get("--during"),
                          [](const std::string& t) { return parse_range(t, "interval"); });
  o.format = output_format(a, {Format::ids, Format::csv, Format::geojson}, Format::ids);
  o.out_path = a.get("--output");
  print_fleet_run(a, fleet_query(o, stdout));
  return 0;
}

int run_fleet_conflicts(const Args& a) {
  FleetConflictOptions o;
  o.path = fleet_file(a, "conflicts");
  if (!a.has("--within") || !a.has("--horizon"))
    throw UsageError("loci fleet conflicts needs --within D and --horizon H");
  o.within = parse_nonnegative("--within", a.get("--within"));
  o.horizon = parse_nonnegative("--horizon", a.get("--horizon"));
  o.at = at_flag(a);
  o.format = output_format(a, {Format::csv, Format::geojson}, Format::csv);
  o.out_path = a.get("--output");
  const FleetRun r = fleet_conflicts(o, stdout);
  print_fleet_run(a, r);
  if (!a.has("--quiet"))
    std::fprintf(stderr, "loci: %s in conflict\n", counted(r.answers, "pair").c_str());
  return 0;
}

int run_fleet_generate(const Args& a) {
  if (!a.positional.empty())
    throw UsageError("loci fleet generate takes no FILE (it writes -o OUT, or stdout)");
  FleetGenerateOptions o;
  if (!a.has("--count")) throw UsageError("loci fleet generate needs --count N");
  o.count = parse_count("--count", a.get("--count"), 1, 100000000);
  if (a.has("--seed")) o.seed = parse_count("--seed", a.get("--seed"), 0, std::size_t(-1) / 2);
  o.along = a.get("--along");
  // --along lays lanes: alone it asks for them, and with another distribution it would be
  // unused.
  if (a.has("--distribution"))
    o.distribution = parse_flag("--distribution", a.get("--distribution"), parse_distribution);
  else if (a.has("--along"))
    o.distribution = FleetGenerateOptions::Distribution::lanes;
  if (a.has("--along") && o.distribution != FleetGenerateOptions::Distribution::lanes)
    throw UsageError("--along lays lanes: it goes with --distribution lanes, not " +
                     a.get("--distribution"));
  if (a.has("--format")) o.format = parse_flag("--format", a.get("--format"), parse_fleet_format);
  if (a.has("--bbox")) o.bbox = parse_flag("--bbox", a.get("--bbox"), parse_bbox);
  if (a.has("--speed"))
    o.speed = parse_flag("--speed", a.get("--speed"),
                         [](const std::string& t) { return parse_range(t, "speed range"); });
  if (a.has("--time")) o.time = parse_flag("--time", a.get("--time"), parse_time);
  if (a.has("--reports")) o.reports = parse_count("--reports", a.get("--reports"), 1, 100000);
  if (a.has("--interval")) o.interval = parse_nonnegative("--interval", a.get("--interval"));
  o.out_path = a.get("--output");
  check_output_name(a, "csv");  // AIS files are CSV too
  o.progress = progress_bar(a, "generating");
  const std::size_t n = fleet_generate(o, stdout);
  if (!a.has("--quiet"))
    std::fprintf(stderr, "loci: %s of %s written%s\n", counted(n, "report").c_str(),
                 counted(o.count, "object").c_str(),
                 o.out_path.empty() ? "" : (" into " + printable(o.out_path)).c_str());
  return 0;
}

int run_fleet_draw(const Args& a) {
  FleetDrawOptions o;
  o.path = fleet_file(a, "draw");
  o.over = a.get("--over");
  o.over_layer = a.get("--layer");
  o.at = at_flag(a);
  if (a.has("--within")) o.within = parse_nonnegative("--within", a.get("--within"));
  if (a.has("--horizon")) o.horizon = parse_nonnegative("--horizon", a.get("--horizon"));
  if (a.has("--within") != a.has("--horizon"))
    throw UsageError("loci fleet draw draws conflicts with both --within D and --horizon H");
  if (a.has("--arrows")) o.arrows = parse_nonnegative("--arrows", a.get("--arrows"));
  if (a.has("--width")) o.width = int(parse_count("--width", a.get("--width"), 16, 20000));
  o.out_path = a.get("--output");
  check_output_name(a, "svg");
  const FleetDrawReport r = fleet_draw(o, stdout);
  print_fleet_run(a, r.run);
  if (!a.has("--quiet"))
    std::fprintf(stderr, "loci: drew %s and %s in conflict\n", counted(r.objects, "object").c_str(),
                 counted(r.pairs, "pair").c_str());
  return 0;
}

int run_fleet_simulate(const Args& a) {
  FleetSimulateOptions o;
  o.path = fleet_file(a, "simulate");
  if (!a.has("--ticks") || !a.has("--within") || !a.has("--horizon"))
    throw UsageError("loci fleet simulate needs --ticks N, --within D and --horizon H");
  o.ticks = parse_count("--ticks", a.get("--ticks"), 1, 10000000);
  o.within = parse_nonnegative("--within", a.get("--within"));
  o.horizon = parse_nonnegative("--horizon", a.get("--horizon"));
  if (a.has("--update-fraction"))
    o.update_fraction = parse_nonnegative("--update-fraction", a.get("--update-fraction"));
  if (a.has("--tick")) o.tick = parse_nonnegative("--tick", a.get("--tick"), true);
  if (a.has("--seed")) o.seed = parse_count("--seed", a.get("--seed"), 0, std::size_t(-1) / 2);
  if (a.has("--slack")) o.slack = parse_nonnegative("--slack", a.get("--slack"));
  o.from_scratch = a.has("--from-scratch");
  o.out_path = a.get("--output");
  check_output_name(a, "csv");
  o.progress = progress_bar(a, "simulating");
  const FleetSimulateReport r = fleet_simulate(o, stdout);
  print_fleet_run(a, r.run);
  if (!a.has("--quiet"))
    std::fprintf(stderr,
                 "loci: %zu objects, %zu ticks: %.3f ms updating and %.3f ms finding conflicts "
                 "per tick on average, %.1f pairs\n",
                 r.objects, o.ticks, r.mean_update_ms, r.mean_conflict_ms, r.mean_pairs);
  return 0;
}

const std::vector<Command>& commands() {
  static const std::vector<Command> table = {
      {"info",
       "loci info LAYER [--layer NAME]",
       "layer summary: features, geometry types, extent, fields, index status",
       {kLayer, kQuiet},
       "  loci info countries.shp\n",
       run_info},
      {"index",
       "loci index LAYER [-o FILE] [--structure S] [--per feature|segment] [--layer NAME]",
       "writes the sidecar index LAYER.loci (or FILE), read by later queries in place",
       {{"--output", "-o", "FILE", "where to write the index (default: LAYER.loci)"},
        {"--structure", nullptr, "S",
         "the sidecar's packing: packed-hilbert (default) or packed-str"},
        kPer,
        kLayer,
        kQuiet},
       "  loci index countries.shp\n  loci index coastline.geojson --per segment -o coast.loci\n",
       run_index},
      check_command(),
      query_command(),
      {"clip",
       "loci clip LAYER (--bbox XMIN,YMIN,XMAX,YMAX | --wkt POLYGON | --window-layer POLYGONS) "
       "-o OUT",
       "windowing: the features meeting the window, cut to it (format from OUT's extension)",
       {{"--bbox", "-b", "XMIN,YMIN,XMAX,YMAX", "the window"},
        {"--wkt", nullptr, "WKT",
         "a polygonal window: a valid POLYGON or MULTIPOLYGON in WKT (polygons apart)"},
        {"--window-layer", nullptr, "POLYGONS",
         "a polygonal window: the union of the polygons of this layer"},
        {"--window-layer-name", nullptr, "NAME", "layer of POLYGONS (default: its first)"},
        {"--output", "-o", "OUT", "output dataset: .geojson, .shp, .gpkg, .fgb, ..."},
        kIndex,
        kStructure,
        kPer,
        kLayer,
        kQuiet},
       "  loci clip countries.shp --bbox 5,45,15,55 -o alps.gpkg\n"
       "  loci clip roads.shp --window-layer parks.shp -o park-roads.gpkg\n",
       run_clip},
      {"intersections",
       "loci intersections LAYER [LAYER2] [-f csv|geojson] [--pairs-only] [-o OUT]",
       "where the layer's linework meets itself, or LAYER2's: feature pairs and points",
       {{"--format", "-f", "csv|geojson",
         "CSV `fid_a,fid_b,x,y` (default) or GeoJSON points with both FIDs (default: as -o's "
         "name says, .csv or .geojson)"},
        {"--pairs-only", nullptr, nullptr, "only the feature pairs (`fid_a,fid_b`)"},
        {"--output", "-o", "OUT", "write to OUT (whole or not at all) instead of stdout", true},
        {"--jobs", "-j", "N", "threads (default: one per core; the rows do not depend on it)"},
        kLayer,
        {"--layer2", nullptr, "NAME",
         "layer of LAYER2 (default: its first); without LAYER2, a layer of LAYER's dataset"},
        kQuiet},
       "  loci intersections roads.shp rivers.shp -f csv\n"
       "  loci intersections map.gpkg --layer roads --layer2 rivers\n"
       "  loci intersections coastline.geojson --pairs-only\n",
       run_intersections},
      {"join",
       "loci join LEFT RIGHT (--predicate intersects|contains|within|dwithin:D | --closest) [-f "
       "csv|ids] "
       "[-o OUT]",
       "pairs of features of two layers whose exact geometries meet, or lie within D",
       {{"--predicate", "-p", "intersects|contains|within|dwithin:D",
         "intersects: the geometries share a point (touching counts); contains / within: every "
         "point of RIGHT lies in LEFT / of LEFT in RIGHT, boundary included; dwithin:D: at "
         "distance <= D, reported"},
        {"--closest", nullptr, nullptr,
         "instead: the pair at the smallest distance (two different features when LEFT and "
         "RIGHT are the same layer), with the distance"},
        {"--format", "-f", "csv|ids",
         "CSV `fid_left,fid_right` (plus `distance` for dwithin and --closest; default) or "
         "`LEFT RIGHT` lines (-o's name must not say another format)"},
        {"--output", "-o", "OUT", "write to OUT (whole or not at all) instead of stdout", true},
        kLayer,
        {"--layer2", nullptr, "NAME", "layer of RIGHT (default: its first)"},
        kQuiet},
       "  loci join counties.shp roads.shp --predicate intersects\n"
       "  loci join ports.shp coast.shp --predicate dwithin:0.05 -f csv\n",
       run_join},
      {"draw",
       "loci draw LAYER|LAYER.loci [-o OUT.svg] [--index FILE] [--levels N | --cells L] "
       "[--width PX]",
       "SVG of the layer's linework and the packed index's nodes, one colour per level, or "
       "its region quadtree cells",
       {{"--output", "-o", "OUT.svg", "the drawing (whole or not at all) instead of stdout", true},
        {"--levels", nullptr, "N",
         "how many levels to draw, from the root down (1 to 64, default 3)"},
        {"--cells", nullptr, "L",
         "draw the layer's region quadtree cut L times (0 to 12) instead: polygon interiors, "
         "the cells the linework runs through (MX cells), empty blocks"},
        {"--width", nullptr, "PX", "width in pixels (16 to 100000, default 1200)"},
        kIndex,
        kPer,
        kLayer,
        kQuiet},
       "  loci draw countries.shp -o countries-index.svg --levels 2\n"
       "  loci draw countries.shp -o countries-cells.svg --cells 8\n",
       run_draw},
      {"fleet query",
       "loci fleet query FILE (--bbox XMIN,YMIN,XMAX,YMAX [--at T | --during T1,T2] | "
       "--nearest X,Y [-k N] [--at T]) [-f ids|csv|geojson] [-o OUT]",
       "moving objects in a window at a time or over an interval, or the k nearest a point "
       "(FILE: CSV id,t,x,y[,vx,vy] or AIS CSV MMSI,BaseDateTime,LAT,LON,SOG,COG,...)",
       {{"--bbox", "-b", "XMIN,YMIN,XMAX,YMAX",
         "objects in the closed window (lon/lat for AIS input)"},
        {"--nearest", "-n", "X,Y",
         "the k objects nearest the point, nearest first (lon/lat for AIS)"},
        {"-k", nullptr, "N", "how many neighbours, 1 to 1000000 (default 1)"},
        {"--at", nullptr, "T",
         "the time asked about: a number, or a UTC date 2023-01-01T00:00:07 (default: now, the "
         "latest report)"},
        {"--during", nullptr, "T1,T2", "objects in the window at some time of [T1, T2]"},
        {"--format", "-f", "ids|csv|geojson",
         "ids (default), CSV id,[distance,]t,x,y (AIS: id,[distance,distance_nm,]t,time_utc,"
         "lon,lat, distance in metres), GeoJSON points (default: as -o's name says, .csv or "
         ".geojson)"},
        {"--output", "-o", "OUT", "write to OUT (whole or not at all) instead of stdout", true},
        kQuiet},
       "  loci fleet query fleet.csv --bbox 0,0,100,100 --at 30\n"
       "  loci fleet query ais.csv --nearest 10.5,56.0 -k 5 -f csv\n",
       run_fleet_query},
      {"fleet conflicts",
       "loci fleet conflicts FILE --within D --horizon H [--at T] [-f csv|geojson] [-o OUT]",
       "pairs of moving objects within distance D at some time of [now, now + H], with their "
       "closest approach",
       {{"--within", nullptr, "D", "the distance (planar units; metres for AIS input)"},
        {"--horizon", nullptr, "H", "how far ahead (time units; seconds for AIS input)"},
        {"--at", nullptr, "T",
         "now (default: the latest report time; reports after it within the horizon are "
         "followed)"},
        {"--format", "-f", "csv|geojson",
         "CSV id_a,id_b,tcpa,dcpa,t_enter,t_exit,... (default) or GeoJSON lines between the "
         "two positions at tcpa (default: as -o's name says)"},
        {"--output", "-o", "OUT", "write to OUT (whole or not at all) instead of stdout", true},
        kQuiet},
       "  loci fleet conflicts fleet.csv --within 5 --horizon 60\n"
       "  loci fleet conflicts ais.csv --within 1852 --horizon 1800 -f geojson -o cpa.geojson\n",
       run_fleet_conflicts},
      {"fleet generate",
       "loci fleet generate --count N [--seed S] [--distribution uniform|clustered|lanes "
       "--along LAYER] [--format csv|ais] [--bbox ...] [--speed MIN,MAX] [--time T0] [-o OUT]",
       "a synthetic fleet, in the planar CSV or the AIS CSV format",
       {{"--count", nullptr, "N", "objects (vessels) to generate"},
        {"--seed", nullptr, "S", "random seed (default 1)"},
        {"--distribution", nullptr, "uniform|clustered|lanes",
         "where objects are: uniform (default; lanes with --along), in clusters, or in lanes "
         "along --along's lines"},
        {"--along", nullptr, "LAYER",
         "line or polygon layer the lanes follow, off its lines, each course off its polygons "
         "(lon/lat for AIS)"},
        {"--format", "-f", "csv|ais", "planar id,t,x,y,vx,vy (default) or MarineCadastre AIS"},
        {"--bbox", "-b", "XMIN,YMIN,XMAX,YMAX",
         "area (default 0,0,10000,10000, or the --along layer's extent; AIS 8,54.5,13,58 in "
         "lon/lat)"},
        {"--speed", nullptr, "MIN,MAX", "speed range (default 1,10 per time unit; AIS 5,20 knots)"},
        {"--time", nullptr, "T0",
         "each object's last report at T0 or a whole number of time units before it, up to half "
         "an --interval (default 0; AIS 2023-01-01T00:00:00)"},
        {"--reports", nullptr, "R", "reports per object (default 3)"},
        {"--interval", nullptr, "S", "time between an object's reports (default 60; AIS: >= 1)"},
        {"--output", "-o", "OUT", "the fleet file (whole or not at all) instead of stdout", true},
        kQuiet},
       "  loci fleet generate --count 1000 -o fleet.csv\n"
       "  loci fleet generate --count 300 --format ais --distribution lanes --along "
       "coastline.geojson -o ais.csv\n",
       run_fleet_generate},
      {"fleet draw",
       "loci fleet draw FILE [--over LAYER] [--at T] [--within D --horizon H] [--arrows T] [-o "
       "OUT.svg]",
       "an SVG of the fleet at a time: positions, velocity arrows and the pairs in conflict over "
       "a layer",
       {{"--over", nullptr, "LAYER", "a layer drawn underneath (lon/lat for AIS input)"},
        kLayer,
        {"--at", nullptr, "T", "the time drawn (default: the latest report time)"},
        {"--within", nullptr, "D", "with --horizon: draw the pairs within D (metres for AIS)"},
        {"--horizon", nullptr, "H", "with --within: how far ahead (seconds for AIS)"},
        {"--arrows", nullptr, "T", "time an arrow covers (default: the horizon, else 60)"},
        {"--width", nullptr, "PX", "drawing width in pixels (default 1200)"},
        {"--output", "-o", "OUT", "the SVG (whole or not at all) instead of stdout", true},
        kQuiet},
       "  loci fleet draw ais.csv --over coastline.geojson --within 926 --horizon 1200 -o "
       "fleet.svg\n",
       run_fleet_draw},
      {"fleet simulate",
       "loci fleet simulate FILE --ticks N --within D --horizon H [--update-fraction F] [--tick S]",
       "ticks of position updates and conflict checks, timed (CSV "
       "tick,t,updates,update_ms,conflict_ms,pairs,full)",
       {{"--ticks", nullptr, "N", "how many ticks"},
        {"--within", nullptr, "D", "conflict distance (metres for AIS input)"},
        {"--horizon", nullptr, "H", "conflict horizon (seconds for AIS input)"},
        {"--update-fraction", nullptr, "F",
         "share of the fleet reporting each tick, round robin, with a small random turn (a "
         "number from 0 to 1; default 0.0166667, one in 60)"},
        {"--tick", nullptr, "S", "time between ticks (default 1)"},
        {"--seed", nullptr, "S", "random seed of the turns (default 1)"},
        {"--slack", nullptr, "S",
         "conflicts are kept up to date incrementally and recomputed in full once the clock "
         "is more than S past the last full computation (default H/4)"},
        {"--from-scratch", nullptr, nullptr, "compute the conflicts from scratch every tick"},
        {"--output", "-o", "OUT", "write the per-tick CSV to OUT instead of stdout", true},
        kQuiet},
       "  loci fleet simulate ais.csv --ticks 600 --within 1852 --horizon 1800\n",
       run_fleet_simulate},
      {"bench",
       "loci bench LAYER [--per feature|segment] [--queries N] [-k N]",
       "the layer's boxes in loci's packed R-tree and in Boost.Geometry's rtree, side by side",
       {{"--queries", nullptr, "N", "windows and nearest-n queries to time (default 10000)"},
        {"-k", nullptr, "N", "neighbours per nearest-n query, 1 to 1000000 (default 10)"},
        {"--per", nullptr, "feature|segment", "boxes of features or of segments (default segment)"},
        kLayer,
        kQuiet},
       "  loci bench coastline.geojson --queries 20000\n",
       run_bench},
  };
  return table;
}

void print_help() {
  std::printf(
      "usage: loci COMMAND [options]\n\n"
      "Spatial indexes for map layers (any vector layer GDAL opens).\n\ncommands:\n");
  for (const auto& c : commands())
    std::printf("  %-16s %s\n", c.name, c.summary);
  std::printf(
      "\nloci COMMAND --help (loci fleet SUB --help) documents every option of COMMAND; an\n"
      "option's value follows it (-k 3, --bbox 0,0,1,1) or is joined to it (-k3, --bbox=...).\n"
      "Exit status 0 on success, 1 on failure with one line 'loci: error: ...' on stderr.\n"
      "loci --version prints the version.\n\n"
      "example:\n  loci index countries.shp && loci query countries.shp --bbox 5,45,15,55\n");
}

void print_fleet_help() {
  std::printf(
      "usage: loci fleet SUBCOMMAND [options]\n\nMoving fleets: planar CSV "
      "(id,t,x,y[,vx,vy]) or AIS CSV (MMSI,BaseDateTime,LAT,LON,SOG,COG,...).\n\n"
      "subcommands:\n");
  for (const auto& c : commands())
    if (std::strncmp(c.name, "fleet ", 6) == 0) std::printf("  %-10s %s\n", c.name + 6, c.summary);
  std::printf("\nloci fleet SUBCOMMAND --help documents every option.\n");
}

}  // namespace

int main(int argc, char** argv) {
  loci::io::silence_gdal_messages();
  const auto is_help = [](const char* a) {
    return !std::strcmp(a, "--help") || !std::strcmp(a, "-h");
  };
  if (argc == 2 && (!std::strcmp(argv[1], "--version") || !std::strcmp(argv[1], "-V"))) {
    std::printf("loci %s\n", LOCI_VERSION);
    return help_status();
  }
  // Without a command: the help on stdout, and the failure said in one line on stderr.
  if (argc < 2 || is_help(argv[1])) {
    print_help();
    if (argc >= 2) return help_status();
    std::fflush(stdout);
    std::fprintf(stderr, "loci: error: no command given (see loci --help)\n");
    return 1;
  }
  // `loci fleet SUB ...` is the command "fleet SUB" of the table.
  std::string name = argv[1];
  int first = 2;
  if (name == "fleet") {
    if (argc < 3 || is_help(argv[2])) {
      print_fleet_help();
      if (argc >= 3) return help_status();
      std::fflush(stdout);
      std::fprintf(stderr, "loci: error: no fleet command given (see loci fleet --help)\n");
      return 1;
    }
    name += std::string(" ") + argv[2];
    first = 3;
  }
  for (const auto& c : commands())
    if (c.name == name) return run_command(c, first, argc, argv, refuse_replacing_output);
  const std::string shown = printable_prefix(name, 40);
  const bool fleet = name.rfind("fleet ", 0) == 0;
  std::fprintf(stderr, "loci: error: unknown command '%s' (see loci %s--help)\n", shown.c_str(),
               fleet ? "fleet " : "");
  return 1;
}
