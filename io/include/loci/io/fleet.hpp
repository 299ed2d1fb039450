// Fleet input: position reports of moving objects read from CSV, as the `loci fleet` commands
// and the tests use them (DESIGN.md section 5).
//
// Two formats, told apart by their header (columns are found by name, in any order; extra
// columns are ignored; RFC 4180 quoting is understood, a quoted field may hold commas, quotes
// and line breaks; a UTF-8 byte order mark is skipped):
//
// Planar CSV, header `id,t,x,y[,vx,vy]`: a whole-number id (0 to 2^64-1), a time and a position
// in the caller's units, and the velocity in units per time unit. The vx,vy columns are
// optional, and a row may leave both empty. A missing velocity is derived from the reports of
// the same id sorted by time: report k gets (p_k - p_{k-1}) / (t_k - t_{k-1}), the first
// report of an id gets the velocity of its first pair, and a lone report is stationary.
// Anything malformed is an error naming the file and line: a missing required column, a
// field that is not a number, a row with another field count than the header, a NaN or
// infinite value, a coordinate or velocity beyond 1e150, or a derived velocity beyond it.
//
// AIS CSV as MarineCadastre distributes it, header
// `MMSI,BaseDateTime,LAT,LON,SOG,COG,Heading,VesselName,...`: only MMSI, BaseDateTime, LAT,
// LON, SOG and COG are read (Heading is not used). BaseDateTime is UTC, `2023-01-01T00:00:07`
// (a space for the T, fractional seconds and a trailing Z are accepted), and becomes epoch
// seconds. Real AIS feeds carry sentinels and junk; such a row is skipped and counted by
// reason (SkipCounts), never used: LAT 91, LON 181, SOG 102.3 and COG 360 ("not available"),
// latitudes, longitudes, speeds or courses out of range, an unreadable date, NaN, an empty
// value (a vessel at rest, SOG 0, needs no course: with COG 360 it is kept). A field that is not a
// number at all, a missing required column or a wrong field count are errors naming the line, as
// for the planar format. Positions are projected to a local metric frame (LocalFrame: azimuthal
// equidistant on WGS 84 centred on the mean position of the rows kept, in metres); SOG (knots) and
// COG (degrees from true north) become a velocity in metres per second in that frame, turned by the
// frame's local direction of true north so that the course stays true away from the centre.
//
// Both formats: two reports of one id at the same time are one too many; the last in the
// file is kept (a later report replaces an earlier one, as in the SQL fleet table) and the
// others are skipped and counted as duplicates. Reports may come in any
// order; they are sorted by (id, t). The report of an id in force at time T is its latest
// with t <= T (a later report replaces the earlier one); an id whose every report is after T
// is absent at T. "now" is the latest report time unless the caller sets it.
//
// Thread-safety: the readers are reentrant; a LocalFrame may be used from one thread at a
// time (PROJ transformations keep state).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "loci/geom/motion.hpp"
#include "loci/index/query.hpp"

namespace loci::io {

// One position report.
struct FleetReport {
  Id id;
  Motion2 m;
  friend bool operator==(const FleetReport&, const FleetReport&) = default;
};

// Why a row was skipped instead of used.
enum class SkipReason : std::uint8_t {
  duplicate,          // same id and time as a later row, which replaces it
  lat_not_available,  // AIS LAT 91
  lon_not_available,  // AIS LON 181
  sog_not_available,  // AIS SOG 102.3
  cog_not_available,  // AIS COG 360
  lat_out_of_range,   // |LAT| > 90 (other than 91)
  lon_out_of_range,   // |LON| > 180 (other than 181)
  sog_out_of_range,   // SOG < 0 or > 102.2 (other than 102.3)
  cog_out_of_range,   // COG < 0 or > 360
  bad_date,           // BaseDateTime unreadable or impossible
  not_a_number,       // NaN or infinite
  missing_value,      // an empty required field
  mmsi_out_of_range,  // AIS MMSI 0, negative or of more than nine digits
};
inline constexpr std::size_t kSkipReasons = 13;

// "COG not available", "duplicate", ...
const char* to_string(SkipReason reason);

struct SkipCounts {
  std::array<std::size_t, kSkipReasons> count{};

  void add(SkipReason r) { ++count[std::size_t(r)]; }
  std::size_t operator[](SkipReason r) const { return count[std::size_t(r)]; }
  std::size_t total() const;
  // "skipped 3 (2 COG not available, 1 duplicate)", or "skipped none".
  std::string summary() const;
};

enum class FleetFormat { planar, ais };

// A local metric frame for lon/lat positions: the azimuthal equidistant projection on WGS 84
// centred on (lon0, lat0), in metres, through GDAL/PROJ. Distances from the centre are true;
// across them the scale error is under 0.05% within 300 km of the centre.
class LocalFrame {
 public:
  // Throws Error when PROJ cannot make the projection.
  LocalFrame(double lon0, double lat0);

  double lon0() const { return lon0_; }
  double lat0() const { return lat0_; }

  // Throws Error when a point cannot be transformed.
  Point2 to_local(double lon, double lat) const;
  Point2 to_lonlat(const Point2& xy) const;
  // Many points at once, in place: lon/lat in, frame coordinates out (PROJ is much faster on
  // arrays than point by point). Throws Error naming the position of a point that fails.
  void to_local(std::span<double> lon_x, std::span<double> lat_y) const;

  // The unit vector of true north in the frame at (lon, lat).
  Point2 north(double lon, double lat) const;
  // The frame velocity (m/s) of a speed (m/s) along a course (degrees from true north).
  Point2 velocity(double lon, double lat, double speed, double course) const;
  // The speed (m/s) and course (degrees from true north, [0, 360)) of a frame velocity at a
  // frame position.
  std::pair<double, double> course(const Point2& xy, const Point2& v) const;

 private:
  struct Impl;
  double lon0_, lat0_;
  std::shared_ptr<Impl> impl_;
};

struct FleetData {
  FleetFormat format = FleetFormat::planar;
  std::string source;                // the file name (or what the caller called the text)
  std::vector<FleetReport> reports;  // sorted by (id, t), one report per id and time
  std::size_t rows = 0;              // data rows read, kept or skipped
  SkipCounts skipped;
  // AIS: reports kept whose Heading is 511, "not available" (heading is not used: the course
  // over ground gives the motion).
  std::size_t heading_not_available = 0;
  std::optional<LocalFrame> frame;  // AIS: the frame positions and velocities are in
  // AIS: each report's position as read (lon, lat), by index into `reports`: where the object
  // is while it has not moved from it, exactly (the frame's round trip is not).
  std::vector<Point2> lonlat;
  // AIS: how far the reports lie from the frame's centre (an angle, in radians, on the
  // sphere): the azimuthal frame keeps distances from its centre but stretches those across
  // them by up to reach / sin(reach), which summary() says when it passes 0.1%.
  double reach = 0;

  // Distinct ids.
  std::size_t objects() const;
  // The latest report time; -infinity when there is none.
  double latest() const;
  // "read 1234 AIS reports of 56 vessels; skipped 3 (2 COG not available, 1 duplicate)", and
  // "; 5 kept with Heading 511 (not available; heading is not used)" when there are such.
  std::string summary() const;
};

// Read a fleet from text; `source` names it in messages. Throw Error "SOURCE: line N: ..." on
// malformed input (see the top of this file).
FleetData read_fleet_csv(std::string_view text, const std::string& source);
FleetData read_ais_csv(std::string_view text, const std::string& source);
// Either format, chosen by the header (MMSI and BaseDateTime columns mean AIS).
FleetData read_fleet(std::string_view text, const std::string& source);
// Reads the file whole; throws Error for a missing, unreadable or empty file or a directory.
FleetData read_fleet_file(const std::string& path);

// The report of each id in force at t (latest with report time <= t), ordered by id.
std::vector<FleetReport> in_force(std::span<const FleetReport> sorted_reports, double t);

// "2023-01-01T00:00:07" (UTC; "T" or a space, optional fractional seconds and "Z") as epoch
// seconds; nullopt when it is not such a date.
std::optional<double> parse_utc(std::string_view text);
// Epoch seconds as "2023-01-01T00:00:07Z" (fractions of a second rounded to the second).
std::string format_utc(double epoch_seconds);
// A time given on the command line: a number, or a UTC date as parse_utc reads it. Throws
// InvalidArgument quoting the text.
double parse_time(const std::string& text);

}  // namespace loci::io
