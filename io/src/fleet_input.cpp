// Fleet input: the planar and AIS CSV readers, the local frame, reports in force (fleet.hpp).
#include <ogr_spatialref.h>
#include <sys/stat.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <sstream>

#include "loci/geom/error.hpp"
#include "loci/io/commands.hpp"
#include "loci/io/fleet.hpp"
#include "loci/io/number_text.hpp"

namespace loci::io {
namespace {

constexpr double kKnot = 1852.0 / 3600.0;  // metres per second

// The text as a message may quote it: at most 40 characters, printable.
std::string quoted(std::string_view text) {
  return "'" + printable_prefix(text, 40) + "'";
}

// RFC 4180 records, one at a time. A record's fields are views into the text, or into
// scratch strings when quotes had to be undone; `line` is the line the record starts on.
class CsvRecords {
 public:
  CsvRecords(std::string_view text, const std::string& source) : text_(text), source_(source) {
    if (text_.substr(0, 3) == "\xEF\xBB\xBF") text_.remove_prefix(3);
  }

  // False at the end of the text. Blank lines are skipped.
  bool next(std::vector<std::string_view>& fields) {
    for (;;) {
      if (at_ >= text_.size()) return false;
      line_ = next_line_;
      if (text_[at_] == '\n' || text_[at_] == '\r') {  // a blank line
        skip_newline();
        continue;
      }
      read_record(fields);
      return true;
    }
  }
  std::size_t line() const { return line_; }

  [[noreturn]] void fail(const std::string& what) const {
    throw Error(source_ + ": line " + std::to_string(line_) + ": " + what);
  }

 private:
  void skip_newline() {
    if (text_[at_] == '\r') ++at_;
    if (at_ < text_.size() && text_[at_] == '\n') ++at_;
    ++next_line_;
  }

  void read_record(std::vector<std::string_view>& fields) {
    fields.clear();
    std::size_t used = 0;  // scratch strings in use
    for (;;) {
      if (at_ < text_.size() && text_[at_] == '"') {
        if (used == scratch_.size()) scratch_.emplace_back();
        std::string& s = scratch_[used++];
        s.clear();
        ++at_;
        for (;;) {
          if (at_ >= text_.size()) fail("a quoted field is not closed");
          const char c = text_[at_++];
          if (c == '"') {
            if (at_ < text_.size() && text_[at_] == '"') {
              s += '"';
              ++at_;
              continue;
            }
            break;
          }
          if (c == '\n') ++next_line_;
          s += c;
        }
        fields.push_back(s);
        // Only a separator or the end of the record may follow the closing quote.
        if (at_ < text_.size() && text_[at_] != ',' && text_[at_] != '\n' && text_[at_] != '\r')
          fail("text after a quoted field's closing quote");
      } else {
        // One pass to the field's end, looking for a stray quote on the way.
        std::size_t end = at_;
        for (; end < text_.size(); ++end) {
          const char c = text_[end];
          if (c == ',' || c == '\n' || c == '\r' || c == '"') break;
        }
        if (end < text_.size() && text_[end] == '"') fail("a quote inside an unquoted field");
        fields.push_back(text_.substr(at_, end - at_));
        at_ = end;
      }
      if (at_ < text_.size() && text_[at_] == ',') {
        ++at_;
        continue;
      }
      if (at_ < text_.size()) skip_newline();
      return;
    }
  }

  std::string_view text_;
  const std::string& source_;
  std::size_t at_ = 0;
  std::size_t line_ = 1;
  std::size_t next_line_ = 1;
  std::deque<std::string> scratch_;  // a deque: views into its strings survive its growth
};

std::string_view trimmed(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t'))
    s.remove_suffix(1);
  return s;
}

// A number in the C locale's format; nullopt when the text is not one. NaN and infinities
// are numbers here: the caller decides what they mean.
std::optional<double> number(std::string_view s) {
  s = trimmed(s);
  if (!detail::drop_plus(s)) return std::nullopt;
  double d = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), d);
  if (s.empty() || r.ptr != s.data() + s.size()) return std::nullopt;
  if (r.ec == std::errc::result_out_of_range)  // from_chars leaves d alone: strtod says +-inf or 0
    return std::strtod(std::string(s).c_str(), nullptr);
  if (r.ec != std::errc()) return std::nullopt;
  return d;
}

// Whether a field read as an infinite number spells an infinity ("inf", "-Infinity"), rather
// than a number beyond the range of doubles ("1e400").
bool spells_infinity(std::string_view s) {
  return s.find_first_of("iI") != std::string_view::npos;
}

std::optional<Id> whole_number(std::string_view s) {
  s = trimmed(s);
  Id v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size()) return std::nullopt;
  return v;
}

std::string lowered(std::string_view s) {
  std::string out(trimmed(s));
  for (char& c : out)
    c = char(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

// Column positions by (case-insensitive) name; -1 when absent.
struct Header {
  std::vector<std::string> names;
  int find(const char* name) const {
    for (std::size_t i = 0; i < names.size(); ++i)
      if (names[i] == name) return int(i);
    return -1;
  }
  bool twice(const char* name) const {
    return std::count(names.begin(), names.end(), std::string_view(name)) > 1;
  }
};

// An AIS column's name as MarineCadastre spells it in either of its headers: `BaseDateTime`,
// `LAT`, `LON` (to 2023) or `base_date_time`, `latitude`, `longitude` (since 2024), any case.
std::string ais_name(std::string_view name) {
  std::string n = lowered(name);
  std::erase(n, '_');
  if (n == "latitude") return "lat";
  if (n == "longitude") return "lon";
  return n;
}

Header read_header(CsvRecords& csv, const std::string& source) {
  std::vector<std::string_view> fields;
  if (!csv.next(fields)) throw Error(source + ": empty file, expected a header line");
  Header h;
  for (auto f : fields)
    h.names.push_back(lowered(f));
  return h;
}

// The column `name`, which the header must hold once (which of two would be meant?).
int column(const Header& h, const CsvRecords& csv, const char* name) {
  if (h.twice(name)) csv.fail(std::string("the header names column '") + name + "' twice");
  return h.find(name);
}

int require(const Header& h, const CsvRecords& csv, const char* name, const char* header) {
  const int i = column(h, csv, name);
  if (i < 0)
    csv.fail(std::string("no column '") + name + "' in the header (expected " + header + ")");
  return i;
}

void check_field_count(const CsvRecords& csv, const std::vector<std::string_view>& fields,
                       const Header& h) {
  if (fields.size() != h.names.size())
    csv.fail(std::to_string(fields.size()) + " fields, the header has " +
             std::to_string(h.names.size()));
}

// Sorts by (id, t, row) and keeps, of the rows of one (id, t), the last in the file: a later
// report replaces an earlier one, as an INSERT of one does in the SQL fleet table.
struct Row {
  FleetReport r;
  std::size_t line;
  bool has_velocity;
};

void sort_and_drop_duplicates(std::vector<Row>& rows, SkipCounts& skipped) {
  std::sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) {
    if (a.r.id != b.r.id) return a.r.id < b.r.id;
    if (a.r.m.t != b.r.m.t) return a.r.m.t < b.r.m.t;
    return a.line < b.line;
  });
  std::size_t kept = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (kept > 0 && rows[kept - 1].r.id == rows[i].r.id && rows[kept - 1].r.m.t == rows[i].r.m.t) {
      skipped.add(SkipReason::duplicate);
      rows[kept - 1] = rows[i];
      continue;
    }
    rows[kept++] = rows[i];
  }
  rows.resize(kept);
}

// Velocities of the rows without one, from the neighbouring reports of the same id.
void derive_velocities(std::vector<Row>& rows) {
  for (std::size_t b = 0; b < rows.size();) {
    std::size_t e = b + 1;
    while (e < rows.size() && rows[e].r.id == rows[b].r.id)
      ++e;
    for (std::size_t k = b; k < e; ++k) {
      if (rows[k].has_velocity) continue;
      if (e - b == 1) {
        rows[k].r.m.v = {0, 0};
        continue;
      }
      const Motion2& p = rows[k == b ? b : k - 1].r.m;
      const Motion2& q = rows[k == b ? b + 1 : k].r.m;
      const double dt = q.t - p.t;
      for (int a = 0; a < 2; ++a)
        rows[k].r.m.v[a] = (q.p[a] - p.p[a]) / dt;
    }
    b = e;
  }
}

}  // namespace

const char* to_string(SkipReason reason) {
  static const char* names[kSkipReasons] = {"duplicate",
                                            "LAT not available",
                                            "LON not available",
                                            "SOG not available",
                                            "COG not available",
                                            "LAT out of range",
                                            "LON out of range",
                                            "SOG out of range",
                                            "COG out of range",
                                            "bad date",
                                            "NaN",
                                            "empty value",
                                            "MMSI out of range"};
  return names[std::size_t(reason)];
}

std::size_t SkipCounts::total() const {
  std::size_t n = 0;
  for (std::size_t c : count)
    n += c;
  return n;
}

std::string SkipCounts::summary() const {
  if (total() == 0) return "skipped none";
  std::string s = "skipped " + std::to_string(total()) + " (";
  bool first = true;
  for (std::size_t i = 0; i < kSkipReasons; ++i) {
    if (!count[i]) continue;
    if (!first) s += ", ";
    first = false;
    s += std::to_string(count[i]) + " " + to_string(SkipReason(i));
    if (SkipReason(i) == SkipReason::duplicate && count[i] > 1) s += 's';
  }
  return s + ")";
}

// ---- The local frame ----

struct LocalFrame::Impl {
  OGRSpatialReference geo, local;
  std::unique_ptr<OGRCoordinateTransformation> forward, inverse;
};

LocalFrame::LocalFrame(double lon0, double lat0)
    : lon0_(lon0), lat0_(lat0), impl_(std::make_shared<Impl>()) {
  Impl& f = *impl_;
  f.geo.SetWellKnownGeogCS("WGS84");
  f.geo.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  f.local.SetWellKnownGeogCS("WGS84");
  if (f.local.SetAE(lat0, lon0, 0, 0) != OGRERR_NONE)
    throw Error("cannot make a local frame centred on " + std::to_string(lon0) + "," +
                std::to_string(lat0));
  f.local.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  f.forward.reset(OGRCreateCoordinateTransformation(&f.geo, &f.local));
  f.inverse.reset(OGRCreateCoordinateTransformation(&f.local, &f.geo));
  if (!f.forward || !f.inverse)
    throw Error("PROJ cannot transform between lon/lat and the local frame");
}

Point2 LocalFrame::to_local(double lon, double lat) const {
  double x = lon, y = lat;
  if (!impl_->forward->Transform(1, &x, &y) || !std::isfinite(x) || !std::isfinite(y))
    throw Error("cannot project " + std::to_string(lon) + "," + std::to_string(lat));
  return {x, y};
}

void LocalFrame::to_local(std::span<double> x, std::span<double> y) const {
  if (x.size() != y.size()) throw InvalidArgument("LocalFrame::to_local: spans differ in length");
  std::vector<int> ok(x.size());
  const bool all = impl_->forward->Transform(x.size(), x.data(), y.data(), nullptr, ok.data());
  for (std::size_t i = 0; i < x.size(); ++i)
    if (!all && (!ok[i] || !std::isfinite(x[i]) || !std::isfinite(y[i])))
      throw Error("cannot project point " + std::to_string(i + 1) + " of " +
                  std::to_string(x.size()));
}

Point2 LocalFrame::to_lonlat(const Point2& xy) const {
  // No point of the earth lies farther from another than half a meridian (20,003.93 km): a
  // position beyond it (a vessel extrapolated far ahead) has no longitude and latitude; the
  // projection's inverse would wrap it onto the globe somewhere.
  if (const double r = std::hypot(xy[0], xy[1]); r > 20003931.5)
    throw Error("a position " + std::to_string(std::llround(std::min(r, 1e18) / 1000)) +
                " km from the fleet's centre, beyond the far side of the earth, has no longitude "
                "and latitude (a time too far from the reports?)");
  double x = xy[0], y = xy[1];
  if (!impl_->inverse->Transform(1, &x, &y) || !std::isfinite(x) || !std::isfinite(y))
    throw Error("cannot unproject " + std::to_string(xy[0]) + "," + std::to_string(xy[1]));
  return {x, y};
}

namespace {

// North is found by a step of 1e-5 degrees (about a metre) north, or south near the pole.
double north_step(double lat) {
  return lat > 89.9 ? -1e-5 : 1e-5;
}

// The unit vector from a towards b, reversed for a step south.
Point2 unit_north(const Point2& a, const Point2& b, double step) {
  const double sign = step > 0 ? 1 : -1;
  const double dx = (b[0] - a[0]) * sign, dy = (b[1] - a[1]) * sign;
  const double len = std::hypot(dx, dy);
  return {dx / len, dy / len};
}

// A speed along a course (degrees from true north) given the frame's north there.
Point2 along_course(const Point2& n, double speed, double course) {
  const Point2 e{n[1], -n[0]};  // north turned a quarter clockwise
  const double c = course * std::numbers::pi / 180;
  const double s = std::sin(c), k = std::cos(c);
  return {speed * (s * e[0] + k * n[0]), speed * (s * e[1] + k * n[1])};
}

}  // namespace

Point2 LocalFrame::north(double lon, double lat) const {
  const double step = north_step(lat);
  return unit_north(to_local(lon, lat), to_local(lon, lat + step), step);
}

Point2 LocalFrame::velocity(double lon, double lat, double speed, double course) const {
  return along_course(north(lon, lat), speed, course);
}

std::pair<double, double> LocalFrame::course(const Point2& xy, const Point2& v) const {
  const Point2 ll = to_lonlat(xy);
  const Point2 n = north(ll[0], ll[1]);
  const Point2 e{n[1], -n[0]};
  const double along_e = v[0] * e[0] + v[1] * e[1], along_n = v[0] * n[0] + v[1] * n[1];
  double deg = std::atan2(along_e, along_n) * 180 / std::numbers::pi;
  if (deg < 0) deg += 360;
  if (deg >= 360) deg -= 360;
  return {std::hypot(v[0], v[1]), deg};
}

// ---- Times ----

namespace {

// Days from 1970-01-01 to the civil date y-m-d (proleptic Gregorian; H. Hinnant's method).
long long days_from_civil(long long y, unsigned m, unsigned d) {
  y -= m <= 2;
  const long long era = (y >= 0 ? y : y - 399) / 400;
  const unsigned yoe = unsigned(y - era * 400);
  const unsigned doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + (long long)doe - 719468;
}

bool leap(long long y) {
  return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
}

// Reads exactly `n` digits at s[at].
bool digits(std::string_view s, std::size_t at, std::size_t n, int& v) {
  if (at + n > s.size()) return false;
  v = 0;
  for (std::size_t i = at; i < at + n; ++i) {
    if (s[i] < '0' || s[i] > '9') return false;
    v = v * 10 + (s[i] - '0');
  }
  return true;
}

}  // namespace

std::optional<double> parse_utc(std::string_view s) {
  s = trimmed(s);
  // A UTC date, marked Z or not, or a local one with its offset from UTC (+01:00, -05:00).
  int offset = 0;
  if (!s.empty() && (s.back() == 'Z' || s.back() == 'z')) {
    s.remove_suffix(1);
  } else if (int oh, om; s.size() >= 25 && (s[s.size() - 6] == '+' || s[s.size() - 6] == '-') &&
                         digits(s, s.size() - 5, 2, oh) && s[s.size() - 3] == ':' &&
                         digits(s, s.size() - 2, 2, om)) {
    if (oh > 23 || om > 59) return std::nullopt;
    offset = (s[s.size() - 6] == '+' ? 1 : -1) * (oh * 3600 + om * 60);
    s.remove_suffix(6);
  }
  int y, mo, d, h, mi, se;
  if (s.size() < 19 || !digits(s, 0, 4, y) || s[4] != '-' || !digits(s, 5, 2, mo) || s[7] != '-' ||
      !digits(s, 8, 2, d) || (s[10] != 'T' && s[10] != ' ') || !digits(s, 11, 2, h) ||
      s[13] != ':' || !digits(s, 14, 2, mi) || s[16] != ':' || !digits(s, 17, 2, se))
    return std::nullopt;
  static const int month_days[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  if (mo < 1 || mo > 12 || d < 1 || h > 23 || mi > 59 || se > 59) return std::nullopt;
  if (d > month_days[mo - 1] + (mo == 2 && leap(y))) return std::nullopt;
  double frac = 0;
  if (s.size() > 19) {
    if (s[19] != '.' || s.size() == 20) return std::nullopt;
    for (std::size_t i = 20; i < s.size(); ++i)
      if (s[i] < '0' || s[i] > '9') return std::nullopt;
    const auto f = number(s.substr(19));
    if (!f) return std::nullopt;
    frac = *f;
  }
  return double(days_from_civil(y, unsigned(mo), unsigned(d)) * 86400 + h * 3600 + mi * 60 + se -
                offset) +
         frac;
}

std::string format_utc(double t) {
  if (!std::isfinite(t) || std::abs(t) > 1e13) return "invalid";
  const long long secs = (long long)std::floor(t + 0.5);
  long long days = secs / 86400, rem = secs % 86400;
  if (rem < 0) rem += 86400, --days;
  // Civil date from days (inverse of days_from_civil).
  const long long z = days + 719468;
  const long long era = (z >= 0 ? z : z - 146096) / 146097;
  const unsigned doe = unsigned(z - era * 146097);
  const unsigned yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  const unsigned doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const unsigned mp = (5 * doy + 2) / 153;
  const unsigned d = doy - (153 * mp + 2) / 5 + 1;
  const unsigned m = mp < 10 ? mp + 3 : mp - 9;
  const long long y = (long long)yoe + era * 400 + (m <= 2);
  char buf[48];
  std::snprintf(buf, sizeof buf, "%04lld-%02u-%02uT%02lld:%02lld:%02lldZ", y, m, d, rem / 3600,
                rem / 60 % 60, rem % 60);
  return buf;
}

double parse_time(const std::string& text) {
  if (const auto d = number(text); d && std::isfinite(*d)) return *d;
  if (const auto u = parse_utc(text)) return *u;
  throw InvalidArgument("bad time " + quoted(text) +
                        ": expected a number or a UTC date like 2023-01-01T00:00:07");
}

// ---- Readers ----

std::size_t FleetData::objects() const {
  std::size_t n = 0;
  for (std::size_t i = 0; i < reports.size(); ++i)
    n += i == 0 || reports[i].id != reports[i - 1].id;
  return n;
}

double FleetData::latest() const {
  double t = -std::numeric_limits<double>::infinity();
  for (const FleetReport& r : reports)
    t = std::max(t, r.m.t);
  return t;
}

std::string FleetData::summary() const {
  const bool ais = format == FleetFormat::ais;
  const auto counted = [](std::size_t n, const char* noun) {
    return std::to_string(n) + ' ' + noun + (n == 1 ? "" : "s");
  };
  std::string s = "read " + counted(reports.size(), ais ? "AIS report" : "report") + " of " +
                  counted(objects(), ais ? "vessel" : "object") + "; " + skipped.summary();
  if (heading_not_available)
    s += "; " + std::to_string(heading_not_available) +
         " kept with Heading 511 (not available; heading is not used)";
  if (const double stretch = reach > 1e-9 ? reach / std::sin(reach) - 1 : 0; stretch > 1e-3) {
    char b[160];
    std::snprintf(b, sizeof b,
                  "; the reports lie up to %.0f km from the local frame's centre, where "
                  "distances are stretched by up to %.1f%% (split the file by region for "
                  "exact ones)",
                  reach * 6371.0088, std::min(stretch, 99.9) * 100);
    s += b;
  }
  return s;
}

FleetData read_fleet_csv(std::string_view text, const std::string& source) {
  static const char* kHeader = "id,t,x,y[,vx,vy]";
  CsvRecords csv(text, source);
  const Header h = read_header(csv, source);
  const int ci = require(h, csv, "id", kHeader), ct = require(h, csv, "t", kHeader),
            cx = require(h, csv, "x", kHeader), cy = require(h, csv, "y", kHeader);
  const int cvx = column(h, csv, "vx"), cvy = column(h, csv, "vy");
  if ((cvx < 0) != (cvy < 0)) csv.fail("the header has one of vx, vy but not the other");
  FleetData out;
  out.format = FleetFormat::planar;
  out.source = source;
  std::vector<Row> rows;
  std::vector<std::string_view> f;
  while (csv.next(f)) {
    ++out.rows;
    check_field_count(csv, f, h);
    auto num = [&](int col, const char* name) {
      const auto d = number(f[col]);
      if (!d) csv.fail(std::string(name) + " " + quoted(f[col]) + " is not a number");
      if (std::isinf(*d) && !spells_infinity(f[col]))
        csv.fail(std::string(name) + " " + quoted(f[col]) + " is beyond the range of doubles");
      if (!std::isfinite(*d)) csv.fail(std::string(name) + " is NaN or infinite");
      return *d;
    };
    Row row{};
    row.line = csv.line();
    const auto id = whole_number(f[ci]);
    if (!id) csv.fail("id " + quoted(f[ci]) + " is not a whole number from 0 to 2^64-1");
    row.r.id = *id;
    row.r.m.t = num(ct, "t");
    row.r.m.p = {num(cx, "x"), num(cy, "y")};
    row.has_velocity = cvx >= 0 && !(trimmed(f[cvx]).empty() && trimmed(f[cvy]).empty());
    if (row.has_velocity) row.r.m.v = {num(cvx, "vx"), num(cvy, "vy")};
    try {
      check_motion(row.r.m);
    } catch (const Error& e) {
      csv.fail(e.what());
    }
    rows.push_back(row);
  }
  sort_and_drop_duplicates(rows, out.skipped);
  derive_velocities(rows);
  out.reports.reserve(rows.size());
  for (const Row& r : rows) {
    if (!r.has_velocity && !within_coordinate_range(r.r.m.v))
      throw Error(source + ": line " + std::to_string(r.line) +
                  ": the velocity derived from the reports of id " + std::to_string(r.r.id) +
                  " is beyond 1e150 (reports too close in time)");
    out.reports.push_back(r.r);
  }
  return out;
}

FleetData read_ais_csv(std::string_view text, const std::string& source) {
  static const char* kHeader =
      "MMSI,BaseDateTime,LAT,LON,SOG,COG,... or mmsi,base_date_time,longitude,latitude,sog,cog,...";
  CsvRecords csv(text, source);
  Header h = read_header(csv, source);
  for (std::string& name : h.names)
    name = ais_name(name);
  const int cm = require(h, csv, "mmsi", kHeader), cd = require(h, csv, "basedatetime", kHeader),
            clat = require(h, csv, "lat", kHeader), clon = require(h, csv, "lon", kHeader),
            csog = require(h, csv, "sog", kHeader), ccog = require(h, csv, "cog", kHeader);
  // Heading is not used (the course over ground gives the motion), but its "not available"
  // (511) is counted, so that the summary says how many reports lacked it (not when the header
  // names it twice: a column loci does not use is no reason to refuse the file).
  const int cheading = h.twice("heading") ? -1 : h.find("heading");
  FleetData out;
  out.format = FleetFormat::ais;
  out.source = source;
  struct Raw {
    double lon, lat, sog, cog;
    bool no_heading;
  };
  std::vector<Row> rows;  // positions hold lon/lat until projected
  std::vector<Raw> raw;
  std::vector<std::string_view> f;
  while (csv.next(f)) {
    ++out.rows;
    check_field_count(csv, f, h);
    // The first reason found names the skip; the columns are looked at in a fixed order.
    std::optional<SkipReason> skip;
    // An empty MMSI is a missing value like any other (skipped and counted); one that is not a
    // number is a broken file.
    // MMSIs are nine digits (leading zeros for coast stations and groups): 0, a negative one
    // or a longer one names no vessel (skipped and counted, as the sentinels are).
    const std::string_view mmsi_text = trimmed(f[cm]);
    const bool no_mmsi = mmsi_text.empty();
    const bool negative = mmsi_text.size() > 1 && mmsi_text[0] == '-';
    const auto mmsi =
        no_mmsi ? std::nullopt : whole_number(negative ? mmsi_text.substr(1) : mmsi_text);
    if (no_mmsi)
      skip = SkipReason::missing_value;
    else if (!mmsi)
      csv.fail("MMSI " + quoted(f[cm]) + " is not a whole number");
    else if (negative || *mmsi == 0 || *mmsi > 999999999)
      skip = SkipReason::mmsi_out_of_range;
    auto num = [&](int col, const char* name) {
      if (trimmed(f[col]).empty()) {
        if (!skip) skip = SkipReason::missing_value;
        return 0.0;
      }
      const auto d = number(f[col]);
      if (!d) csv.fail(std::string(name) + " " + quoted(f[col]) + " is not a number");
      // A number beyond doubles is out of its field's range, below; NaN and "inf" are none.
      if (!std::isfinite(*d) && !skip && (std::isnan(*d) || spells_infinity(f[col])))
        skip = SkipReason::not_a_number;
      return *d;
    };
    const double lat = num(clat, "LAT"), lon = num(clon, "LON"), sog = num(csog, "SOG");
    double cog = num(ccog, "COG");
    // A vessel at rest (SOG 0, often moored) has no course to give: its velocity is known.
    if (sog == 0 && cog == 360) cog = 0;
    const auto t = parse_utc(f[cd]);
    if (!skip) {
      if (lat == 91)
        skip = SkipReason::lat_not_available;
      else if (lon == 181)
        skip = SkipReason::lon_not_available;
      else if (!(std::abs(lat) <= 90))
        skip = SkipReason::lat_out_of_range;
      else if (!(std::abs(lon) <= 180))
        skip = SkipReason::lon_out_of_range;
      else if (sog == 102.3)
        skip = SkipReason::sog_not_available;
      else if (!(sog >= 0 && sog <= 102.2))
        skip = SkipReason::sog_out_of_range;
      else if (cog == 360)
        skip = SkipReason::cog_not_available;
      else if (!(cog >= 0 && cog < 360))
        skip = SkipReason::cog_out_of_range;
      else if (!t)
        skip = SkipReason::bad_date;
    }
    if (skip) {
      out.skipped.add(*skip);
      continue;
    }
    Row row{};
    row.line = csv.line();
    row.r.id = *mmsi;
    row.r.m.t = *t;
    row.r.m.p = {double(raw.size()), 0};  // the index of its raw values, until projected
    rows.push_back(row);
    raw.push_back(
        {lon, lat, sog, cog, cheading >= 0 && number(f[cheading]) == std::optional<double>(511)});
  }
  sort_and_drop_duplicates(rows, out.skipped);
  for (const Row& r : rows)
    out.heading_not_available += raw[std::size_t(r.r.m.p[0])].no_heading;
  if (rows.empty()) return out;
  // The frame's centre: the mean position, the longitude averaged on the circle so that a
  // fleet astride the antimeridian is centred on it.
  double sx = 0, sy = 0, slat = 0;
  for (const Row& r : rows) {
    const Raw& w = raw[std::size_t(r.r.m.p[0])];
    sx += std::cos(w.lon * std::numbers::pi / 180);
    sy += std::sin(w.lon * std::numbers::pi / 180);
    slat += w.lat;
  }
  const double lon0 = std::atan2(sy, sx) * 180 / std::numbers::pi;
  out.frame.emplace(lon0, slat / double(rows.size()));
  // The farthest report from the centre, as an angle on the sphere.
  const double rad = std::numbers::pi / 180, phi0 = out.frame->lat0() * rad;
  double least_cos = 1;
  for (const Row& r : rows) {
    const Raw& w = raw[std::size_t(r.r.m.p[0])];
    least_cos = std::min(
        least_cos, std::sin(phi0) * std::sin(w.lat * rad) +
                       std::cos(phi0) * std::cos(w.lat * rad) * std::cos((w.lon - lon0) * rad));
  }
  out.reach = std::acos(std::clamp(least_cos, -1.0, 1.0));
  // Positions, and points a step north of them for the direction of north, projected as two
  // arrays.
  const std::size_t n = rows.size();
  std::vector<double> x(n), y(n), nx(n), ny(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Raw& w = raw[std::size_t(rows[i].r.m.p[0])];
    x[i] = nx[i] = w.lon;
    y[i] = w.lat;
    ny[i] = w.lat + north_step(w.lat);
  }
  try {
    out.frame->to_local(x, y);
    out.frame->to_local(nx, ny);
  } catch (const Error&) {
    // Find the row that fails, to name its line.
    for (const Row& r : rows) {
      const Raw& w = raw[std::size_t(r.r.m.p[0])];
      try {
        out.frame->to_local(w.lon, w.lat);
        out.frame->to_local(w.lon, w.lat + north_step(w.lat));
      } catch (const Error& e) {
        throw Error(source + ": line " + std::to_string(r.line) + ": " + e.what());
      }
    }
    throw;
  }
  out.reports.reserve(n);
  out.lonlat.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    Row& r = rows[i];
    const Raw& w = raw[std::size_t(r.r.m.p[0])];
    r.r.m.p = {x[i], y[i]};
    r.r.m.v =
        along_course(unit_north(r.r.m.p, {nx[i], ny[i]}, north_step(w.lat)), w.sog * kKnot, w.cog);
    out.reports.push_back(r.r);
    out.lonlat.push_back({w.lon, w.lat});
  }
  return out;
}

FleetData read_fleet(std::string_view text, const std::string& source) {
  CsvRecords csv(text, source);
  std::vector<std::string_view> f;
  if (!csv.next(f)) throw Error(source + ": empty file, expected a header line");
  bool mmsi = false, date = false, id = false;
  for (auto name : f) {
    const std::string n = ais_name(trimmed(name));
    mmsi |= n == "mmsi";
    date |= n == "basedatetime";
    id |= n == "id";
  }
  // AIS by its MMSI column, unless the file has the planar id column and no AIS date (then the
  // AIS reader says which of its columns is missing, rather than the planar one).
  return mmsi && (date || !id) ? read_ais_csv(text, source) : read_fleet_csv(text, source);
}

FleetData read_fleet_file(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw Error(path + ": no such file");
  if (S_ISDIR(st.st_mode)) throw Error(path + ": is a directory, not a fleet file");
  if (!S_ISREG(st.st_mode)) throw Error(path + ": not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot read the file");
  std::string text(std::size_t(st.st_size), '\0');
  in.read(text.data(), std::streamsize(text.size()));
  if (in.bad() || std::size_t(in.gcount()) != text.size())
    throw Error(path + ": cannot read the file (it changed while being read?)");
  return read_fleet(text, path);
}

std::vector<FleetReport> in_force(std::span<const FleetReport> sorted, double t) {
  std::vector<FleetReport> out;
  for (std::size_t i = 0; i < sorted.size(); ++i) {
    const bool last_of_id = i + 1 == sorted.size() || sorted[i + 1].id != sorted[i].id;
    if (sorted[i].m.t > t) continue;
    if (last_of_id || sorted[i + 1].m.t > t) out.push_back(sorted[i]);
  }
  return out;
}

}  // namespace loci::io
