// Fleet input: the planar CSV (header orders, quoting, velocities derived from consecutive
// reports, reports out of order, duplicates, malformed lines as one-line errors naming the
// line), the AIS CSV on a committed sample holding every sentinel, a bad date and a duplicate
// (each skipped and counted), the local frame (round trips, true distances and courses),
// reports in force at a time, and UTC dates.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "loci/geom/error.hpp"
#include "loci/io/fleet.hpp"

using namespace loci;
using namespace loci::io;

namespace {

const std::string kData = LOCI_FLEET_DATA;

// The message of the Error that reading `text` throws, or "" when it reads.
std::string error_of(const std::string& text) {
  try {
    read_fleet(text, "f.csv");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(FleetCsv, ColumnsByNameInAnyOrderWithExtraColumns) {
  const FleetData a = read_fleet_csv("id,t,x,y,vx,vy\n7,1,2,3,4,5\n", "a");
  const FleetData b = read_fleet_csv("VY, name ,x,T,Id,vx,y\n5,\"boat, the\",2,1,7,4,3\n", "b");
  ASSERT_EQ(a.reports.size(), 1u);
  EXPECT_EQ(a.reports, b.reports);
  EXPECT_EQ(a.reports[0], (FleetReport{7, {1, {2, 3}, {4, 5}}}));
  EXPECT_EQ(a.format, FleetFormat::planar);
  EXPECT_EQ(b.summary(), "read 1 report of 1 object; skipped none");
}

TEST(FleetCsv, QuotingLineBreaksBlankLinesCrLfAndByteOrderMark) {
  const FleetData d = read_fleet_csv(
      "\xEF\xBB\xBFid,note,t,x,y\r\n\r\n1,\"two\nlines, \"\"quoted\"\"\",0,1,1\r\n2,,0,5,5", "q");
  ASSERT_EQ(d.reports.size(), 2u);
  EXPECT_EQ(d.reports[1].m.p, (Point2{5, 5}));
  // A line number after a quoted line break counts the break.
  const std::string e = error_of("id,note,t,x,y\n1,\"a\nb\",0,1,1\n2,x,zero,1,1\n");
  EXPECT_NE(e.find("line 4:"), std::string::npos) << e;
}

TEST(FleetCsv, MissingVelocityIsDerivedFromConsecutiveReportsSortedByTime) {
  // Out of order in the file; id 2 is alone; id 3 gives its velocity on one row only.
  const FleetData d = read_fleet_csv(
      "id,t,x,y,vx,vy\n"
      "1,20,30,10,,\n"
      "1,0,0,0,,\n"
      "2,5,1,1,,\n"
      "1,10,10,0,,\n"
      "3,0,0,0,,\n"
      "3,4,8,0,9,9\n",
      "d");
  ASSERT_EQ(d.reports.size(), 6u);
  EXPECT_EQ(d.reports[0], (FleetReport{1, {0, {0, 0}, {1, 0}}}));    // the first pair's velocity
  EXPECT_EQ(d.reports[1], (FleetReport{1, {10, {10, 0}, {1, 0}}}));  // (p1 - p0) / (t1 - t0)
  EXPECT_EQ(d.reports[2], (FleetReport{1, {20, {30, 10}, {2, 1}}}));
  EXPECT_EQ(d.reports[3], (FleetReport{2, {5, {1, 1}, {0, 0}}}));  // alone: stationary
  EXPECT_EQ(d.reports[4], (FleetReport{3, {0, {0, 0}, {2, 0}}}));
  EXPECT_EQ(d.reports[5], (FleetReport{3, {4, {8, 0}, {9, 9}}}));  // given, kept
  // Without vx,vy columns at all.
  const FleetData e = read_fleet_csv("t,y,x,id\n0,0,0,4\n2,4,0,4\n", "e");
  EXPECT_EQ(e.reports[1].m.v, (Point2{0, 2}));
  EXPECT_EQ(e.objects(), 1u);
  EXPECT_EQ(e.latest(), 2);
}

// The last line of an (id, t) replaces the earlier ones, as a later INSERT does in SQL.
TEST(FleetCsv, DuplicateReportsAreSkippedAndCountedTheLastKept) {
  const FleetData d =
      read_fleet_csv("id,t,x,y,vx,vy\n1,0,0,0,1,1\n1,0,9,9,1,1\n1,0,8,8,1,1\n", "d");
  ASSERT_EQ(d.reports.size(), 1u);
  EXPECT_EQ(d.reports[0].m.p, (Point2{8, 8}));
  EXPECT_EQ(d.skipped[SkipReason::duplicate], 2u);
  EXPECT_EQ(d.rows, 3u);
  EXPECT_EQ(d.summary(), "read 1 report of 1 object; skipped 2 (2 duplicates)");
}

TEST(FleetCsv, MalformedInputIsOneLineErrorNamingFileAndLine) {
  struct Case {
    const char* text;
    const char* expect;
  };
  const Case cases[] = {
      {"", "f.csv: empty file"},
      {"id,t,x\n1,0,0\n", "f.csv: line 1: no column 'y'"},
      {"id,t,x,y,vx\n1,0,0,0,0\n", "line 1: the header has one of vx, vy"},
      {"id,ID,t,x,y\n1,2,0,0,0\n", "line 1: the header names column 'id' twice"},
      {"id,t,x,y,vx,vy,VY\n1,0,0,0,0,0,1\n", "line 1: the header names column 'vy' twice"},
      {"id,t,x,y\n1,0,0\n", "f.csv: line 2: 3 fields, the header has 4"},
      {"id,t,x,y\n1,0,0,0\n1,1,0,0,5\n", "line 3: 5 fields"},
      {"id,t,x,y\n1,0,abc,0\n", "line 2: x 'abc' is not a number"},
      {"id,t,x,y\n-1,0,0,0\n", "line 2: id '-1' is not a whole number"},
      {"id,t,x,y\n1,NaN,0,0\n", "line 2: t is NaN or infinite"},
      {"id,t,x,y\n1,0,inf,0\n", "line 2: x is NaN or infinite"},
      {"id,t,x,y,vx,vy\n1,0,0,0,1e400,0\n", "line 2: vx '1e400' is beyond the range of doubles"},
      {"id,t,x,y,vx,vy\n1,0,0,0,-Infinity,0\n", "line 2: vx is NaN or infinite"},
      {"id,t,x,y\n1,0,+-5,0\n", "line 2: x '+-5' is not a number"},
      {"id,t,x,y\n1,++5,0,0\n", "line 2: t '++5' is not a number"},
      {"id,t,x,y\n1,0,2e150,0\n", "line 2: report has a position or velocity beyond 1e150"},
      {"id,t,x,y\n1,1e200,0,0\n", "line 2: report has a time beyond 1e150"},
      {"id,t,x,y\n1,0,1e150,0\n1,1e-300,-1e150,0\n", "line 2: the velocity derived"},
      {"id,t,x,y\n1,0,\"0,0\n", "line 2: a quoted field is not closed"},
      {"id,t,x,y\n1,0,\"0\"x,0\n", "line 2: text after a quoted field"},
      {"id,t,x,y\n1,0,0\"0,0\n", "line 2: a quote inside an unquoted field"},
  };
  for (const Case& c : cases) {
    const std::string e = error_of(c.text);
    EXPECT_NE(e.find(c.expect), std::string::npos) << c.text << " -> " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

TEST(FleetCsv, EpochSecondsWithSubSecondMotion) {
  const FleetData d =
      read_fleet_csv("id,t,x,y\n1,1700000000.25,0,0\n1,1700000000.75,0.5,-0.25\n", "epoch");
  ASSERT_EQ(d.reports.size(), 2u);
  EXPECT_EQ(d.reports[1].m.v, (Point2{1, -0.5}));
  const auto now = in_force(d.reports, 1700000000.5);
  ASSERT_EQ(now.size(), 1u);
  EXPECT_EQ(now[0].m.t, 1700000000.25);
  EXPECT_EQ(position(now[0].m, 1700000000.5), (Point2{0.25, -0.125}));
}

TEST(FleetInForce, LatestReportAtOrBeforeTheTimeAndAbsentBeforeTheFirst) {
  const FleetData d =
      read_fleet_csv("id,t,x,y,vx,vy\n1,10,1,0,0,0\n1,0,0,0,0,0\n2,5,2,0,0,0\n3,20,3,0,0,0\n", "f");
  auto ids_at = [&](double t) {
    std::vector<std::pair<Id, double>> out;
    for (const FleetReport& r : in_force(d.reports, t))
      out.emplace_back(r.id, r.m.t);
    return out;
  };
  EXPECT_EQ(ids_at(-1), (std::vector<std::pair<Id, double>>{}));
  EXPECT_EQ(ids_at(0), (std::vector<std::pair<Id, double>>{{1, 0}}));
  EXPECT_EQ(ids_at(9.5), (std::vector<std::pair<Id, double>>{{1, 0}, {2, 5}}));
  EXPECT_EQ(ids_at(10), (std::vector<std::pair<Id, double>>{{1, 10}, {2, 5}}));
  EXPECT_EQ(ids_at(100), (std::vector<std::pair<Id, double>>{{1, 10}, {2, 5}, {3, 20}}));
}

TEST(FleetAis, EverySentinelBadDateNanAndDuplicateIsSkippedAndCounted) {
  const FleetData d = read_fleet_file(kData + "/ais-sentinels.csv");
  EXPECT_EQ(d.format, FleetFormat::ais);
  EXPECT_EQ(d.rows, 19u);
  for (std::size_t r = 0; r < kSkipReasons; ++r)
    EXPECT_EQ(d.skipped.count[r], 1u) << to_string(SkipReason(r));
  EXPECT_EQ(d.reports.size(), 6u);
  EXPECT_EQ(d.objects(), 4u);
  EXPECT_EQ(d.summary(),
            "read 6 AIS reports of 4 vessels; skipped 13 (1 duplicate, 1 LAT not available, 1 LON "
            "not available, 1 SOG not available, 1 COG not available, 1 LAT out of range, 1 LON "
            "out of range, 1 SOG out of range, 1 COG out of range, 1 bad date, 1 NaN, 1 empty "
            "value, 1 MMSI out of range); 1 kept with Heading 511 (not available; heading is not "
            "used)");
  // MMSI 0, a negative one and one of ten digits name no vessel: skipped and counted (two
  // ships sent as MMSI 0 were one vessel, and -1 refused the file).
  const std::string row = ",2023-01-01T00:00:00,55.0,10.0,10.0,90.0\n";
  const FleetData odd =
      read_fleet("MMSI,BaseDateTime,LAT,LON,SOG,COG\n0" + row + "0" + row + "-1" + row +
                     "1000000000" + row + "999999999" + row + "000000001" + row,
                 "odd.csv");
  EXPECT_EQ(odd.skipped[SkipReason::mmsi_out_of_range], 4u);
  ASSERT_EQ(odd.reports.size(), 2u);
  EXPECT_EQ(odd.reports[0].id, 1u);
  EXPECT_EQ(odd.reports[1].id, 999999999u);
  // Heading 511 is counted, not skipped: heading is not used, the course gives the motion.
  EXPECT_EQ(d.heading_not_available, 1u);
  // Sorted by (MMSI, time); of the two reports at 00:01:00, the later line is kept.
  EXPECT_EQ(d.reports[0].id, 219000001u);
  EXPECT_EQ(d.reports[0].m.t, 1672531200);
  EXPECT_EQ(d.reports[1].m.t, 1672531260);
  const Point2 kept = d.frame->to_lonlat(d.reports[1].m.p);
  EXPECT_NEAR(kept[0], 10.0095, 1e-9);
  EXPECT_EQ(d.reports[2].id, 219000003u);
  EXPECT_EQ(d.reports[2].m.t, 1672531200);
  EXPECT_EQ(d.reports[3].m.t, 1672531320);
  // 10 knots due east, 5 knots due south.
  EXPECT_NEAR(d.reports[0].m.v[0], 10 * 1852.0 / 3600, 0.02);
  EXPECT_NEAR(d.reports[0].m.v[1], 0, 0.02);
  const FleetReport& south = d.reports[4];
  EXPECT_EQ(south.id, 219000008u);
  EXPECT_NEAR(std::hypot(south.m.v[0], south.m.v[1]), 5 * 1852.0 / 3600, 1e-9);
  EXPECT_NEAR(south.m.v[1], -5 * 1852.0 / 3600, 1e-3);
}

// A vessel at rest reports SOG 0 and often COG 360 ("not available"): kept, standing still;
// COG 360 with a speed is skipped.
TEST(FleetAis, AVesselAtRestWithoutCourseStandsStill) {
  const std::string h = "MMSI,BaseDateTime,LAT,LON,SOG,COG\n";
  const FleetData d = read_fleet(
      h + "1,2023-01-01T00:00:00,55,10,0,360\n" + "2,2023-01-01T00:00:00,55.01,10,3,360\n",
      "moored");
  ASSERT_EQ(d.reports.size(), 1u);
  EXPECT_EQ(d.reports[0].id, 1u);
  EXPECT_EQ(d.reports[0].m.v[0], 0.0);
  EXPECT_EQ(d.reports[0].m.v[1], 0.0);
  EXPECT_EQ(d.skipped.total(), 1u);
}

// An empty MMSI is a missing value, skipped and counted like an empty position; the other
// vessels are read.
TEST(FleetAis, AnEmptyMmsiIsSkippedAsAnEmptyValue) {
  const std::string h = "MMSI,BaseDateTime,LAT,LON,SOG,COG\n";
  const FleetData d = read_fleet(h + " ,2023-01-01T00:00:00,55,10,10,0\n" +
                                     "2,2023-01-01T00:00:00,55.01,10,0,360\n" +
                                     "3,2023-01-01T00:00:00,55.01,10,0,360\n",
                                 "no-mmsi");
  ASSERT_EQ(d.reports.size(), 2u);
  EXPECT_EQ(d.reports[0].id, 2u);
  EXPECT_EQ(d.skipped[SkipReason::missing_value], 1u);
  EXPECT_EQ(d.summary(), "read 2 AIS reports of 2 vessels; skipped 1 (1 empty value)");
}

TEST(FleetAis, MalformedRowsAreErrorsNamingTheLine) {
  const std::string h = "MMSI,BaseDateTime,LAT,LON,SOG,COG\n";
  EXPECT_NE(error_of(h + "1,2023-01-01T00:00:00,55,10,x,1\n").find("line 2: SOG 'x' is not a"),
            std::string::npos);
  EXPECT_NE(error_of(h + "abc,2023-01-01T00:00:00,55,10,1,1\n").find("line 2: MMSI"),
            std::string::npos);
  EXPECT_NE(error_of(h + "1,2023-01-01T00:00:00,55,10\n").find("line 2: 4 fields"),
            std::string::npos);
  EXPECT_NE(error_of("MMSI,BaseDateTime,LAT,LON,SOG\n").find("no column 'cog'"), std::string::npos);
  EXPECT_NE(error_of(h + "1,2023-01-01T00:00:00,+-55,10,1,1\n").find("line 2: LAT '+-55' is not"),
            std::string::npos);
  // An AIS file whose date column is named otherwise is said to lack BaseDateTime (it was read
  // as a planar file lacking `id`).
  EXPECT_NE(error_of("MMSI,DateTime,LAT,LON,SOG,COG\n").find("no column 'basedatetime'"),
            std::string::npos)
      << error_of("MMSI,DateTime,LAT,LON,SOG,COG\n");
  // A number beyond doubles is out of its field's range; NaN and infinities are not numbers.
  const FleetData beyond = read_fleet(h + "1,2023-01-01T00:00:00,1e400,10,1,1\n" +
                                          "2,2023-01-01T00:00:00,55,10,1e999,1\n" +
                                          "3,2023-01-01T00:00:00,55,-inf,1,1\n",
                                      "beyond");
  EXPECT_EQ(beyond.skipped[SkipReason::lat_out_of_range], 1u);
  EXPECT_EQ(beyond.skipped[SkipReason::sog_out_of_range], 1u);
  EXPECT_EQ(beyond.skipped[SkipReason::not_a_number], 1u);
  EXPECT_NE(error_of("MMSI,BaseDateTime,LAT,LON,SOG,COG,Lat\n").find("column 'lat' twice"),
            std::string::npos);
  // Header only: no vessels, no frame.
  const FleetData d = read_fleet(h, "h");
  EXPECT_EQ(d.format, FleetFormat::ais);
  EXPECT_TRUE(d.reports.empty());
}

TEST(FleetAis, FrameRoundTripTrueDistancesAndCourses) {
  const LocalFrame f(10.5, 56.0);
  EXPECT_EQ(f.to_local(10.5, 56.0), (Point2{0, 0}));
  for (double lon = 8; lon <= 13; lon += 0.7)
    for (double lat = 54.5; lat <= 58; lat += 0.5) {
      const Point2 back = f.to_lonlat(f.to_local(lon, lat));
      EXPECT_NEAR(back[0], lon, 1e-9);
      EXPECT_NEAR(back[1], lat, 1e-9);
    }
  // One degree of latitude along the central meridian is 111.3 km at 56 degrees north.
  EXPECT_NEAR(f.to_local(10.5, 57.0)[1] - f.to_local(10.5, 56.0)[1], 111360, 150);
  // Courses are true away from the centre: north is turned by the meridians' convergence.
  for (const Point2& at : {Point2{10.5, 56.0}, Point2{8.0, 54.5}, Point2{13.0, 58.0}})
    for (double course = 0; course < 360; course += 22.5) {
      const Point2 v = f.velocity(at[0], at[1], 5, course);
      const auto [speed, back] = f.course(f.to_local(at[0], at[1]), v);
      EXPECT_NEAR(speed, 5, 1e-9);
      EXPECT_NEAR(std::remainder(back - course, 360), 0, 1e-6);
    }
  const Point2 n = f.north(13.0, 58.0);
  EXPECT_LT(n[0], -0.01);  // east of the centre, north leans west in the frame
  // Beyond half a meridian from the centre a position has no lon/lat (it was wrapped onto the
  // globe: a vessel 80,000 km from a point was shown at that point).
  EXPECT_THROW(f.to_lonlat({80040379, 0}), Error);
  EXPECT_THROW(f.to_lonlat({0, -2.1e7}), Error);
  EXPECT_NO_THROW(f.to_lonlat({0, 1.9e7}));
}

TEST(FleetTime, UtcDatesReadAndWritten) {
  EXPECT_EQ(parse_utc("2023-01-01T00:00:07"), 1672531207.0);
  EXPECT_EQ(parse_utc("2023-01-01 00:00:07Z"), 1672531207.0);
  EXPECT_EQ(parse_utc("2024-02-29T12:00:00.5"), 1709208000.5);
  EXPECT_EQ(parse_utc("1970-01-01T00:00:00"), 0.0);
  // A local time with its offset from UTC (such dates were skipped as bad).
  EXPECT_EQ(parse_utc("2023-01-01T01:00:07+01:00"), 1672531207.0);
  EXPECT_EQ(parse_utc("2022-12-31T19:00:07.25-05:00"), 1672531207.25);
  EXPECT_FALSE(parse_utc("2023-01-01T00:00:00+24:00"));
  EXPECT_FALSE(parse_utc("2023-01-01T00:00:00+01:00Z"));
  for (const char* bad : {"2023-02-29T00:00:00", "2023-13-01T00:00:00", "2023-01-01T24:00:00",
                          "2023-01-01", "2023-01-01T00:00:0x", "2023-01-01T00:00:00.", ""})
    EXPECT_FALSE(parse_utc(bad)) << bad;
  EXPECT_EQ(format_utc(1672531207.4), "2023-01-01T00:00:07Z");
  EXPECT_EQ(format_utc(-1), "1969-12-31T23:59:59Z");
  EXPECT_EQ(parse_time("1.7e9"), 1.7e9);
  EXPECT_EQ(parse_time("2023-01-01T00:00:07"), 1672531207.0);
  EXPECT_THROW(parse_time("soon"), InvalidArgument);
  EXPECT_THROW(parse_time("nan"), InvalidArgument);
}

}  // namespace
