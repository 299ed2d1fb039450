// The work behind `loci fleet` (DESIGN.md sections 5 and 6), one function per sub-command in
// the style of commands.hpp: an options struct in, loci::Error with a one-line message out.
//
//   fleet_query      objects inside a window at a time or during an interval, or the k
//                    nearest a point at a time
//   fleet_conflicts  every pair within a distance D at some time of [now, now + H], with its
//                    closest approach
//   fleet_generate   synthetic fleets (uniform, clustered, or in lanes along a line layer),
//                    in the planar or the AIS CSV format
//   fleet_simulate   ticks of position updates and conflict checks, timed
//   fleet_draw       an SVG of the fleet at a time: positions, velocity arrows and the pairs
//                    in conflict, over a layer's linework
//
// Every command answers from the reports in force at its time (fleet.hpp): "now" is the latest
// report time of the input unless `at` is set.
//
// Planar input answers in its own units. AIS input speaks lon/lat: windows and points are
// given in lon/lat (WGS 84), distances are metres (and nautical miles in `_nm` columns), times
// epoch seconds (and UTC dates in `_utc` columns, minutes from now in `_min` columns). A lon/lat
// window is the region between its two meridians and two parallels; in the local frame it is
// a polygon whose edges are curves, drawn with a vertex every 0.01 degree (a chord strays from
// the curve by centimetres). The moving index answers for that polygon's bounding box, and each
// candidate is refined exactly against the polygon: its position at T inside it (--at), or
// its path from T1 to T2 meeting it (--during).
//
// The moving index behind the queries is FleetIndex, one alias in fleet_commands.cpp.
#pragma once

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/io/fleet.hpp"
#include "loci/io/output.hpp"
#include "loci/io/progress.hpp"

namespace loci::io {

struct FleetQueryOptions {
  std::string path;
  enum class Kind { window, nearest } kind = Kind::window;
  Box2 box{};      // window (lon/lat for AIS input)
  Point2 point{};  // nearest (lon/lat for AIS input)
  std::size_t k = 1;
  std::optional<double> at;                         // default: now
  std::optional<std::pair<double, double>> during;  // window over [t1, t2] instead of at
  Format format = Format::ids;
  std::string out_path;  // empty: the fallback stream
};

// What a command read, for the summary line the command line prints.
struct FleetRun {
  std::string summary;  // FleetData::summary()
  std::string units;    // AIS: what the output's units are; empty for planar input
  double now = 0;
  std::size_t answers = 0;
};

FleetRun fleet_query(const FleetQueryOptions& options, std::FILE* fallback);

struct FleetConflictOptions {
  std::string path;
  double within = 0;   // D: planar units, metres for AIS
  double horizon = 0;  // H: time units, seconds for AIS
  std::optional<double> at;
  Format format = Format::csv;  // csv or geojson
  std::string out_path;
};

FleetRun fleet_conflicts(const FleetConflictOptions& options, std::FILE* fallback);

struct FleetGenerateOptions {
  std::size_t count = 100;
  std::uint64_t seed = 1;
  enum class Distribution { uniform, clustered, lanes } distribution = Distribution::uniform;
  std::string along;  // lanes: the line layer (lon/lat for AIS, its own units for CSV)
  FleetFormat format = FleetFormat::planar;
  // Default: 0,0,10000,10000 (planar; lanes: the layer's extent), 8,54.5,13,58 (AIS).
  std::optional<Box2> bbox;
  std::optional<std::pair<double, double>> speed;  // default 1,10 per time unit; AIS 5,20 knots
  std::optional<double> time;  // the last reports' time; default 0, AIS 2023-01-01T00:00:00
  std::size_t reports = 3;     // reports per object
  double interval = 60;        // time between an object's reports
  std::string out_path;
  Progress progress;  // over the objects placed, then the rows written
};

// Returns the number of rows written.
std::size_t fleet_generate(const FleetGenerateOptions& options, std::FILE* fallback);

// Parsers for the flag vocabularies; throw InvalidArgument naming what is accepted.
FleetGenerateOptions::Distribution parse_distribution(const std::string& name);
FleetFormat parse_fleet_format(const std::string& name);  // "csv" or "ais"
// "A,B" with A <= B, both finite.
std::pair<double, double> parse_range(const std::string& text, const char* what);

struct FleetSimulateOptions {
  std::string path;
  std::size_t ticks = 60;
  double within = 0;
  double horizon = 0;
  double update_fraction = 1.0 / 60;  // of the fleet reporting each tick
  double tick = 1;                    // time between ticks (seconds for AIS)
  std::uint64_t seed = 1;
  // Conflicts kept by a ConflictMonitor (index/moving/conflicts.hpp), recomputed in full when
  // the clock passes `slack` (default H / 4) beyond the last full computation; or computed
  // from scratch every tick.
  std::optional<double> slack;
  bool from_scratch = false;
  std::string out_path;
  Progress progress;
};

struct FleetSimulateReport {
  FleetRun run;
  std::size_t objects = 0;
  double mean_update_ms = 0;
  double mean_conflict_ms = 0;
  double mean_pairs = 0;
};

// Each tick, the next share of the fleet (round robin) reports where it is, turned a little
// (seeded), the moving index and the conflicts are brought up to the tick's time, and one CSV
// row is written: `tick,t,updates,update_ms,conflict_ms,pairs,full` (full: 1 when the
// conflicts were computed in full that tick).
FleetSimulateReport fleet_simulate(const FleetSimulateOptions& options, std::FILE* fallback);

struct FleetDrawOptions {
  std::string path;
  std::string over;              // a layer drawn underneath (lon/lat for AIS input), optional
  std::string over_layer;        // its layer name in a multi-layer dataset
  std::optional<double> at;      // default: now
  std::optional<double> within;  // with horizon: the pairs in conflict are drawn too
  std::optional<double> horizon;
  std::optional<double> arrows;  // time an arrow covers (default: the horizon, else 60)
  int width = 1200;              // pixels
  std::string out_path;          // empty: the fallback stream
};

struct FleetDrawReport {
  FleetRun run;
  std::size_t objects = 0;  // positions drawn
  std::size_t pairs = 0;    // conflicts drawn
};

// The objects in force at the time as dots with an arrow to where they will be `arrows` later,
// the pairs in conflict (given within and horizon) as red lines between the two positions at
// their closest approach, their objects in red, over the linework of `over`. The drawing
// covers the fleet and its arrows (lon/lat for AIS input).
FleetDrawReport fleet_draw(const FleetDrawOptions& options, std::FILE* fallback);

}  // namespace loci::io
