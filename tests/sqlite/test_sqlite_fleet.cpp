// loci_fleet tables and the fleet functions through the real SQLite library: windows, nearest
// and conflicts against brute force over the reports in force (random fleets, fixed seeds,
// reports out of time order, epoch-second times), against the same questions asked of a plain
// table in SQL, transactions and savepoints, close and reopen, two connections, a killed
// writer, errors and corrupt shadow tables.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "loci/geom/motion.hpp"
#include "sqlite_support.hpp"

using loci::Motion2;
using loci::test::Db;
using loci::test::real;
using loci::test::Row;
using loci::test::TempDir;

namespace {

struct Report {
  std::int64_t id;
  Motion2 m;
};

// `objects` objects (ids from -objects/4 on, so some are negative) with `per` reports each at
// random times in [t0, t0 + 100], shuffled out of time order.
std::vector<Report> make_fleet(std::size_t objects, int per, double t0, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> pos(0, 1000), vel(-5, 5), dt(0, 100);
  std::vector<Report> out;
  for (std::size_t i = 0; i < objects; ++i)
    for (int r = 0; r < per; ++r)
      out.push_back({std::int64_t(i) - std::int64_t(objects / 4),
                     Motion2{t0 + dt(rng), {{pos(rng), pos(rng)}}, {{vel(rng), vel(rng)}}}});
  std::shuffle(out.begin(), out.end(), rng);
  return out;
}

void insert(Db& db, const std::string& table, const std::vector<Report>& reports) {
  db.exec("BEGIN");
  sqlite3_stmt* s = nullptr;
  ASSERT_EQ(
      sqlite3_prepare_v2(db.get(), ("INSERT INTO " + table + " VALUES(?, ?, ?, ?, ?, ?)").c_str(),
                         -1, &s, nullptr),
      SQLITE_OK);
  for (const Report& r : reports) {
    sqlite3_bind_int64(s, 1, r.id);
    sqlite3_bind_double(s, 2, r.m.t);
    sqlite3_bind_double(s, 3, r.m.p[0]);
    sqlite3_bind_double(s, 4, r.m.p[1]);
    sqlite3_bind_double(s, 5, r.m.v[0]);
    sqlite3_bind_double(s, 6, r.m.v[1]);
    ASSERT_EQ(sqlite3_step(s), SQLITE_DONE) << sqlite3_errmsg(db.get());
    sqlite3_reset(s);
  }
  sqlite3_finalize(s);
  db.exec("COMMIT");
}

// The report of each id in force at t: its latest with time <= t.
std::map<std::int64_t, Motion2> in_force(const std::vector<Report>& reports, double t) {
  std::map<std::int64_t, Motion2> out;
  for (const Report& r : reports) {
    if (r.m.t > t) continue;
    auto it = out.find(r.id);
    if (it == out.end() || r.m.t > it->second.t) out[r.id] = r.m;
  }
  return out;
}

double latest(const std::vector<Report>& reports) {
  double t = -INFINITY;
  for (const Report& r : reports)
    t = std::max(t, r.m.t);
  return t;
}

std::vector<Row> window_ids(Db& db, double x0, double y0, double x1, double y1, double t) {
  return db.rows("SELECT id FROM loci_fleet_window('f', " + real(x0) + ", " + real(y0) + ", " +
                 real(x1) + ", " + real(y1) + ", " + real(t) + ")");
}

std::vector<Row> brute_window(const std::vector<Report>& reports, double x0, double y0, double x1,
                              double y1, double t) {
  std::vector<Row> out;
  const loci::Box<2> box{{{x0, y0}}, {{x1, y1}}};
  for (const auto& [id, m] : in_force(reports, t))
    if (loci::inside(m, loci::MovingWindow<2>::at(box, t))) out.push_back({std::to_string(id)});
  return out;
}

// The same question asked of a plain table of reports in SQL: the window at T over the report
// in force of each id, positions computed as position() does.
std::string plain_window(const std::string& table, double x0, double y0, double x1, double y1,
                         double t) {
  const std::string T = real(t);
  return "SELECT id FROM (SELECT id, x + vx * (" + T + " - t) AS px, y + vy * (" + T +
         " - t) AS py FROM " + table + " r WHERE t = (SELECT max(t) FROM " + table +
         " WHERE id = r.id AND t <= " + T + ")) WHERE px >= " + real(x0) +
         " AND px <= " + real(x1) + " AND py >= " + real(y0) + " AND py <= " + real(y1) +
         " ORDER BY id";
}

const char* kPlain =
    "CREATE TABLE m(id INTEGER, t REAL, x REAL, y REAL, vx REAL, vy REAL, "
    "PRIMARY KEY(id, t)) WITHOUT ROWID";
const char* kCurrentOfPlain =
    "SELECT id, t, x, y, vx, vy FROM m r WHERE t = (SELECT max(t) FROM m WHERE id = r.id) ORDER "
    "BY id";

class SqliteFleet : public ::testing::TestWithParam<double> {};  // the time origin

TEST_P(SqliteFleet, WindowsMatchBruteForceAtEveryTime) {
  const double t0 = GetParam();
  const auto reports = make_fleet(1500, 3, t0, 31);
  Db db;
  db.exec("CREATE VIRTUAL TABLE f USING loci_fleet(id, t, x, y, vx, vy)");
  db.exec(kPlain);
  insert(db, "f", reports);
  insert(db, "m", reports);
  EXPECT_EQ(db.value("SELECT loci_check('f')"), "ok");
  EXPECT_EQ(db.value("SELECT count(*) FROM f"), "1500");
  EXPECT_EQ(db.rows("SELECT * FROM f ORDER BY id"), db.rows(kCurrentOfPlain));
  const double last = latest(reports);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-100, 1100), side(10, 300), dt(-20, 140);
  for (int q = 0; q < 120; ++q) {
    const double times[] = {t0 - 10, t0 + 50, last, last + 20, t0 + dt(rng)};
    const double t = times[q % 5];
    const double x = u(rng), y = u(rng), w = side(rng), h = side(rng);
    const auto got = window_ids(db, x, y, x + w, y + h, t);
    ASSERT_EQ(got, brute_window(reports, x, y, x + w, y + h, t)) << "t - t0 = " << t - t0;
    ASSERT_EQ(got, db.rows(plain_window("m", x, y, x + w, y + h, t)));
  }
  EXPECT_TRUE(window_ids(db, -1e9, -1e9, 1e9, 1e9, t0 - 1).empty());  // before every report
  // Positions come with the ids.
  const auto rows =
      db.rows("SELECT id, x, y FROM loci_fleet_window('f', 0, 0, 1000, 1000, " + real(last) + ")");
  const auto force = in_force(reports, last);
  ASSERT_FALSE(rows.empty());
  for (const Row& r : rows) {
    const auto p = loci::position(force.at(std::stoll(r[0])), last);
    EXPECT_EQ(r[1], real(p[0]));
    EXPECT_EQ(r[2], real(p[1]));
  }
}

TEST_P(SqliteFleet, ConflictsMatchEveryPair) {
  const double t0 = GetParam();
  const auto reports = make_fleet(400, 2, t0, 32);
  Db db;
  db.exec("CREATE VIRTUAL TABLE f USING loci_fleet(id, t, x, y, vx, vy)");
  insert(db, "f", reports);
  const double last = latest(reports);
  for (const auto& [D, H, now] : std::vector<std::tuple<double, double, double>>{
           {15, 30, last}, {40, 10, last}, {0, 60, last}, {25, 20, t0 + 50}, {25, 0, t0 + 80}}) {
    const auto force = in_force(reports, now);
    std::vector<std::tuple<std::int64_t, std::int64_t, loci::Approach>> expected;
    for (auto a = force.begin(); a != force.end(); ++a)
      for (auto b = std::next(a); b != force.end(); ++b)
        if (auto ap = loci::closest_approach(a->second, b->second, now, H, D))
          expected.push_back({a->first, b->first, *ap});
    const std::string sql = "SELECT * FROM loci_conflicts('f', " + real(D) + ", " + real(H) +
                            (now == last ? std::string() : ", " + real(now)) + ")";
    const auto got = db.rows(sql);
    ASSERT_EQ(got.size(), expected.size()) << sql;
    for (std::size_t i = 0; i < got.size(); ++i) {
      const auto& [a, b, ap] = expected[i];
      ASSERT_EQ(got[i][0], std::to_string(a)) << sql;
      ASSERT_EQ(got[i][1], std::to_string(b)) << sql;
      ASSERT_EQ(got[i][3], real(ap.dcpa)) << sql;
      const double scale = 1e-9 * std::max(1.0, std::abs(now));
      EXPECT_NEAR(std::stod(got[i][2]), ap.tcpa, scale);
      EXPECT_NEAR(std::stod(got[i][4]), ap.t_enter, scale);
      EXPECT_NEAR(std::stod(got[i][5]), ap.t_exit, scale);
    }
    if (D == 15) EXPECT_FALSE(got.empty());
  }
}

TEST_P(SqliteFleet, NearestMatchesBruteForce) {
  const double t0 = GetParam();
  const auto reports = make_fleet(1000, 2, t0, 33);
  Db db;
  db.exec("CREATE VIRTUAL TABLE f USING loci_fleet(id, t, x, y, vx, vy)");
  insert(db, "f", reports);
  const double last = latest(reports);
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(-100, 1100);
  for (int q = 0; q < 60; ++q) {
    const double t = q % 2 ? last + 5 : t0 + 60;
    const double x = u(rng), y = u(rng);
    const std::size_t k = std::size_t(std::vector<int>{1, 7, 50, 2000}[q % 4]);
    std::vector<double> brute;
    for (const auto& [id, m] : in_force(reports, t))
      brute.push_back(
          std::sqrt(loci::squared_distance(loci::position(m, t), loci::Point2{{x, y}})));
    std::sort(brute.begin(), brute.end());
    const auto got = db.rows("SELECT id, distance FROM loci_fleet_nearest('f', " + real(x) + ", " +
                             real(y) + ", " + std::to_string(k) + ", " + real(t) + ")");
    ASSERT_EQ(got.size(), std::min(k, brute.size()));
    for (std::size_t i = 0; i < got.size(); ++i)
      ASSERT_EQ(got[i][1], real(brute[i])) << "rank " << i;
  }
  EXPECT_EQ(db.value("SELECT count(*) FROM loci_fleet_nearest('f', 1, 2, 3)"), "3");  // now
}

INSTANTIATE_TEST_SUITE_P(Origins, SqliteFleet, ::testing::Values(0.0, 1.7e9), [](const auto& info) {
  return info.param == 0 ? "Zero" : "EpochSeconds";
});

TEST(SqliteFleetSql, ReportsReplaceByTimeAndUpdateDeleteFollowTheirRules) {
  Db db;
  db.exec("CREATE VIRTUAL TABLE f USING loci_fleet(id, t, x, y, vx, vy)");
  db.exec("INSERT INTO f VALUES (1, 10, 0, 0, 1, 0), (2, 10, 5, 5, 0, 0)");
  db.exec("INSERT INTO f VALUES (1, 5, -100, 0, 0, 0)");  // older: history only
  EXPECT_EQ(db.rows("SELECT id, t, x FROM f"),
            (std::vector<Row>{{"1", "10", "0"}, {"2", "10", "5"}}));
  EXPECT_EQ(window_ids(db, -101, -1, -99, 1, 7), (std::vector<Row>{{"1"}}));  // the old report
  EXPECT_TRUE(window_ids(db, -1, -1, 100, 100, 4).empty());  // nobody had reported by 4
  db.exec("INSERT INTO f VALUES (1, 12, 50, 0, 0, 0)");      // newer: current
  EXPECT_EQ(db.value("SELECT x FROM f WHERE id = 1"), "50");
  db.exec("INSERT INTO f VALUES (1, 12, 60, 0, 0, 0)");  // same time: replaces
  EXPECT_EQ(db.value("SELECT x FROM f WHERE id = 1"), "60");
  EXPECT_EQ(db.value("SELECT count(*) FROM f_report WHERE id = 1"), "3");
  // OR IGNORE keeps a report already there (it was replaced); a new time is added as ever.
  db.exec("INSERT OR IGNORE INTO f VALUES (1, 12, 99, 0, 0, 0), (1, 5, 99, 0, 0, 0)");
  EXPECT_EQ(db.value("SELECT x FROM f WHERE id = 1"), "60");
  EXPECT_EQ(db.value("SELECT x FROM f_report WHERE id = 1 AND t = 5"), "-100");
  db.exec("UPDATE OR IGNORE f SET t = 5 WHERE id = 1");   // onto the report at 5: both kept
  db.exec("UPDATE OR IGNORE f SET x = 60 WHERE id = 1");  // in place: no conflict
  EXPECT_EQ(db.rows("SELECT t, x FROM f_report WHERE id = 1 ORDER BY t"),
            (std::vector<Row>{{"5", "-100"}, {"10", "0"}, {"12", "60"}}));
  db.exec("INSERT OR IGNORE INTO f VALUES (5, 0, 1, 1, 0, 0)");
  EXPECT_EQ(db.value("SELECT count(*) FROM f WHERE id = 5"), "1");
  db.exec("DELETE FROM f WHERE id = 5");
  // UPDATE rewrites the current report; moving it back in time makes the next one current.
  db.exec("UPDATE f SET x = 70 WHERE id = 1");
  EXPECT_EQ(db.rows("SELECT t, x FROM f WHERE id = 1"), (std::vector<Row>{{"12", "70"}}));
  db.exec("UPDATE f SET t = 1 WHERE id = 1");
  EXPECT_EQ(db.rows("SELECT t, x FROM f WHERE id = 1"), (std::vector<Row>{{"10", "0"}}));
  EXPECT_EQ(db.value("SELECT count(*) FROM f_report WHERE id = 1"), "3");
  db.exec("UPDATE f SET id = 3 WHERE id = 2");
  EXPECT_EQ(db.rows("SELECT id FROM f"), (std::vector<Row>{{"1"}, {"3"}}));
  // An UPDATE to a NULL id or rowid is refused, as on a rowid table, and changes nothing.
  EXPECT_NE(db.error_of("UPDATE f SET id = NULL WHERE id = 3"), "");
  EXPECT_NE(db.error_of("UPDATE f SET rowid = NULL WHERE id = 3"), "");
  EXPECT_EQ(db.rows("SELECT id FROM f"), (std::vector<Row>{{"1"}, {"3"}}));
  // DELETE removes the object and its history.
  db.exec("DELETE FROM f WHERE id = 1");
  EXPECT_EQ(db.value("SELECT count(*) FROM f_report WHERE id = 1"), "0");
  EXPECT_TRUE(window_ids(db, -101, -1, -99, 1, 7).empty());
  EXPECT_EQ(db.value("SELECT loci_check('f')"), "ok");
  // now is the latest report time: 10 (object 3).
  db.exec("INSERT INTO f VALUES (4, 0, 0, 5, 0.5, 0)");
  EXPECT_EQ(db.rows("SELECT id_a, id_b, tcpa, dcpa FROM loci_conflicts('f', 1, 0)"),
            (std::vector<Row>{{"3", "4", "10", "0"}}));
  EXPECT_EQ(db.rows("SELECT id_a, id_b, tcpa FROM loci_conflicts('f', 1, 100, 0)"),
            (std::vector<Row>{}));  // object 3 first reported at 10
  EXPECT_EQ(db.rows("SELECT id_a, id_b, t_enter FROM loci_conflicts('f', 1, 100, 10)"),
            (std::vector<Row>{{"3", "4", "10"}}));
  EXPECT_TRUE(db.rows("SELECT * FROM loci_conflicts('f', 1, 100, -1)").empty());
}

// Writes on the same connection while a scan's cursor is still stepped: each row it still
// returns is the object's current report then (never an object deleted meanwhile, nor a
// report since replaced), at most once, as a rowid table holding the current reports gives
// it; also across a ROLLBACK TO.
TEST(SqliteFleetSql, ACursorSteppedAcrossWritesReturnsReportsAsTheyAre) {
  for (const bool rollback : {false, true}) {
    Db db;
    db.exec("CREATE VIRTUAL TABLE f USING loci_fleet(id, t, x, y, vx, vy)");
    db.exec("CREATE TABLE m(id INTEGER PRIMARY KEY, t REAL, x REAL, y REAL, vx REAL, vy REAL)");
    std::mt19937_64 rng(rollback ? 51 : 50);
    for (int i = 1; i <= 200; ++i)
      db.exec_on({"f", "m"}, "INSERT INTO $T VALUES(" + std::to_string(i) + ", 10, " +
                                 std::to_string(rng() % 100) + ", " + std::to_string(rng() % 100) +
                                 ", 1, 0)");
    if (rollback) db.exec("BEGIN; SAVEPOINT s");
    sqlite3_stmt* q = nullptr;
    ASSERT_EQ(sqlite3_prepare_v2(db.get(), "SELECT id, t, x, y FROM f", -1, &q, nullptr),
              SQLITE_OK);
    std::set<std::string> seen;
    int returned = 0;
    while (sqlite3_step(q) == SQLITE_ROW) {
      Row got;
      for (int c = 0; c < 4; ++c)
        got.push_back(Db::text(q, c));
      ASSERT_TRUE(seen.insert(got[0]).second) << "id " << got[0] << " returned twice";
      EXPECT_EQ(db.rows("SELECT id, t, x, y FROM m WHERE id = " + got[0]), (std::vector<Row>{got}));
      ++returned;
      for (int w = 0; w < 2; ++w) {
        const std::string id = std::to_string(1 + rng() % 200), x = std::to_string(rng() % 100);
        if (rng() % 2)
          db.exec_on({"f", "m"}, "DELETE FROM $T WHERE id = " + id);
        else
          db.exec_on({"f", "m"}, "UPDATE $T SET x = " + x + " WHERE id = " + id);
      }
      if (rollback && returned % 5 == 0) db.exec("ROLLBACK TO s");
    }
    sqlite3_finalize(q);
    if (rollback) db.exec("COMMIT");
    EXPECT_GT(returned, 20);
    EXPECT_EQ(db.rows("SELECT id, t, x, y FROM f ORDER BY id"),
              db.rows("SELECT id, t, x, y FROM m ORDER BY id"));
    EXPECT_EQ(db.value("SELECT loci_check('f')"), "ok");
  }
}

TEST(SqliteFleetSql, RandomWritesFollowRollbackAndSavepoints) {
  Db db;
  db.exec("CREATE VIRTUAL TABLE f USING loci_fleet(id, t, x, y, vx, vy)");
  db.exec(kPlain);
  std::mt19937_64 rng(19);
  std::uniform_real_distribution<double> u(0, 1000), v(-3, 3), tt(0, 100);
  int depth = 0;
  const auto both = [&](const std::string& sql) { db.exec_on({"f", "m"}, sql); };
  for (int step = 0; step < 500; ++step) {
    const int what = int(rng() % 16);
    const std::string id = std::to_string(int(rng() % 200) - 20);
    if (what < 6) {
      both("INSERT OR REPLACE INTO $T VALUES(" + id + ", " + real(tt(rng)) + ", " + real(u(rng)) +
           ", " + real(u(rng)) + ", " + real(v(rng)) + ", " + real(v(rng)) + ")");
    } else if (what == 6) {
      both("DELETE FROM $T WHERE id = " + id);
    } else if (what == 7) {  // a bulk insert
      both(
          "INSERT OR REPLACE INTO $T SELECT value % 300, value * 0.37 % 100, value % 997, "
          "value % 991, 1, -1 FROM (WITH RECURSIVE s(value) AS (SELECT 1 UNION ALL SELECT value "
          "+ 1 FROM s WHERE value < 900) SELECT value FROM s)");
    } else if (what == 8) {
      db.exec(depth == 0 ? "BEGIN" : "SAVEPOINT s" + std::to_string(depth));
      ++depth;
    } else if (what == 9 && depth > 0) {
      --depth;
      db.exec(depth == 0 ? "COMMIT" : "RELEASE s" + std::to_string(depth));
    } else if (what == 10 && depth > 0) {
      --depth;
      db.exec(depth == 0 ? "ROLLBACK"
                         : "ROLLBACK TO s" + std::to_string(depth) + "; RELEASE s" +
                               std::to_string(depth));
    } else if (what < 14) {
      const double x = u(rng), y = u(rng), t = tt(rng) * 1.2;
      ASSERT_EQ(window_ids(db, x, y, x + 200, y + 200, t),
                db.rows(plain_window("m", x, y, x + 200, y + 200, t)))
          << "step " << step;
    } else {
      ASSERT_EQ(db.rows("SELECT * FROM f ORDER BY id"), db.rows(kCurrentOfPlain)) << step;
      ASSERT_EQ(db.value("SELECT loci_check('f')"), "ok") << "step " << step;
    }
  }
  while (depth-- > 0)
    db.exec(depth == 0 ? "COMMIT" : "RELEASE s" + std::to_string(depth));
  EXPECT_EQ(db.rows("SELECT * FROM f ORDER BY id"), db.rows(kCurrentOfPlain));
  // A failed statement leaves nothing of what it had written.
  db.exec("BEGIN");
  EXPECT_NE(db.try_exec("INSERT INTO f VALUES (1000, 1, 2, 3, 4, 5), (1001, 1, NULL, 3, 4, 5)"),
            "");
  db.exec("COMMIT");
  EXPECT_EQ(db.value("SELECT count(*) FROM f WHERE id = 1000"), "0");
  EXPECT_EQ(db.value("SELECT count(*) FROM f_report WHERE id = 1000"), "0");
  EXPECT_EQ(db.value("SELECT loci_check('f')"), "ok");
}

TEST(SqliteFleetSql, SurvivesCloseAndReopenAndSeesOtherConnections) {
  TempDir dir;
  const auto reports = make_fleet(800, 3, 1.7e9, 34);
  const double last = latest(reports);
  std::vector<Row> before, window;
  {
    Db db(dir.file("f.db"));
    db.exec("CREATE VIRTUAL TABLE f USING loci_fleet(id, t, x, y, vx, vy)");
    insert(db, "f", reports);
    db.exec("DELETE FROM f WHERE id % 7 = 0");
    before = db.rows("SELECT * FROM f ORDER BY id");
    window = window_ids(db, 100, 100, 600, 600, last - 30);
  }
  Db db(dir.file("f.db"));
  EXPECT_EQ(db.rows("SELECT * FROM f ORDER BY id"), before);
  EXPECT_EQ(window_ids(db, 100, 100, 600, 600, last - 30), window);
  EXPECT_EQ(db.value("SELECT loci_check('f')"), "ok");
  // Another connection's writes are seen, by the table and by the functions.
  const std::string far = real(last + 1000);
  EXPECT_TRUE(window_ids(db, 5000, 5000, 5001, 5001, last + 1000).empty());
  {
    Db other(dir.file("f.db"));
    other.exec("INSERT INTO f VALUES (99999, " + far + ", 5000.5, 5000.5, 0, 0)");
  }
  EXPECT_EQ(window_ids(db, 5000, 5000, 5001, 5001, last + 1000), (std::vector<Row>{{"99999"}}));
  EXPECT_EQ(db.value("SELECT id FROM loci_fleet_nearest('f', 5000, 5000, 1)"), "99999");
  {
    Db other(dir.file("f.db"));
    other.exec("DELETE FROM f WHERE id = 99999");
  }
  EXPECT_EQ(db.value("SELECT count(*) FROM f WHERE id = 99999"), "0");
  EXPECT_EQ(db.rows("SELECT * FROM f ORDER BY id"), before);
  // Dropped and created again by another connection, with as many writes: the new one answers.
  const auto nearest = [&](Db& d) {
    return d.rows("SELECT id, distance FROM loci_fleet_nearest('f', 300, 300, 5)");
  };
  const auto seen = nearest(db);
  {
    Db other(dir.file("f.db"));
    other.exec("DROP TABLE f; CREATE VIRTUAL TABLE f USING loci_fleet(id, t, x, y, vx, vy)");
    insert(other, "f", make_fleet(800, 3, 1.7e9, 35));
    other.exec("DELETE FROM f WHERE id % 7 = 0");
    other.exec("INSERT INTO f VALUES (99999, " + far + ", 5000.5, 5000.5, 0, 0)");
    other.exec("DELETE FROM f WHERE id = 99999");
  }
  Db fresh(dir.file("f.db"));
  ASSERT_NE(nearest(fresh), seen);
  EXPECT_EQ(nearest(db), nearest(fresh));
  EXPECT_EQ(db.value("SELECT loci_check('f')"), "ok");
}

// A writer killed with SIGKILL in the middle of its transactions leaves the fleet consistent.
TEST(SqliteFleetSql, AWriterKilledMidTransactionLeavesItConsistent) {
  TempDir dir;
  const std::string path = dir.file("k.db");
  {
    Db db(path);
    db.exec("CREATE VIRTUAL TABLE f USING loci_fleet(id, t, x, y, vx, vy)");
    db.exec(kPlain);
  }
  for (int round = 0; round < 3; ++round) {
    const auto transaction = [&](int i) {
      const std::string select =
          " SELECT value % 500, " + std::to_string(round * 1000 + i) +
          " + value * 0.001, value % 997, value % 991, 1, -1 FROM (WITH RECURSIVE s(value) AS "
          "(SELECT 1 UNION ALL SELECT value + 1 FROM s WHERE value < 3000) SELECT value FROM s);";
      const std::string k = std::to_string(i % 9);
      return "BEGIN; INSERT OR REPLACE INTO f" + select + "INSERT OR REPLACE INTO m" + select +
             "DELETE FROM f WHERE id % 9 = " + k + "; DELETE FROM m WHERE id % 9 = " + k +
             "; COMMIT;";
    };
    ASSERT_TRUE(loci::test::kill_a_writer(path, transaction, useconds_t(80000 + round * 50000)))
        << "the writer stopped by itself";
    Db db(path);
    ASSERT_EQ(db.value("SELECT loci_check('f')"), "ok") << "round " << round;
    ASSERT_EQ(db.rows("SELECT * FROM f ORDER BY id"), db.rows(kCurrentOfPlain)) << round;
  }
}

TEST(SqliteFleetSql, BadInputIsAnSqlErrorWithAClearMessage) {
  Db db;
  const auto has = [](const std::string& error, const char* part) {
    return error.find(part) != std::string::npos;
  };
  EXPECT_TRUE(has(db.try_exec("CREATE VIRTUAL TABLE a USING loci_fleet(id, t, x, y)"),
                  "expected the columns (id, t, x, y, vx, vy), got (id, t, x, y)"));
  EXPECT_TRUE(has(db.try_exec("CREATE VIRTUAL TABLE a USING loci_fleet(id, t, x, y, vy, vx)"),
                  "expected the columns"));
  db.exec("CREATE VIRTUAL TABLE f USING loci_fleet(ID, T, X, Y, VX, VY)");  // any case
  // Empty: no latest time, and no pair (not an error about that time).
  EXPECT_EQ(db.rows("SELECT * FROM loci_conflicts('f', 1, 10)").size(), 0u);
  EXPECT_TRUE(has(db.try_exec("INSERT INTO f VALUES (NULL, 0, 0, 0, 0, 0)"), "id is NULL"));
  EXPECT_TRUE(
      has(db.try_exec("INSERT INTO f VALUES ('a', 0, 0, 0, 0, 0)"), "id must be an integer"));
  EXPECT_TRUE(has(db.try_exec("INSERT INTO f VALUES (1, NULL, 0, 0, 0, 0)"), "t is NULL"));
  EXPECT_TRUE(has(db.try_exec("INSERT INTO f VALUES (1, 0, 'x', 0, 0, 0)"), "x is not a number"));
  EXPECT_TRUE(has(db.try_exec("INSERT INTO f VALUES (1, 0, 0, 1e999, 0, 0)"), "y is not finite"));
  EXPECT_TRUE(
      has(db.try_exec("INSERT INTO f VALUES (1, 0, 0, 0, 1e151, 0)"), "vx is beyond 1e150"));
  {  // NaN bound from C arrives as NULL
    sqlite3_stmt* s = nullptr;
    sqlite3_prepare_v2(db.get(), "INSERT INTO f VALUES (1, 0, 0, 0, 0, ?)", -1, &s, nullptr);
    sqlite3_bind_double(s, 1, std::nan(""));
    EXPECT_NE(sqlite3_step(s), SQLITE_DONE);
    EXPECT_TRUE(has(sqlite3_errmsg(db.get()), "vy is NULL"));
    sqlite3_finalize(s);
  }
  EXPECT_EQ(db.value("SELECT count(*) FROM f_report"), "0");
  db.exec("INSERT INTO f VALUES (1, 0, 0, 0, 0, 0)");
  EXPECT_TRUE(has(db.try_exec("UPDATE f SET x = 'no' WHERE id = 1"), "x is not a number"));
  EXPECT_EQ(db.value("SELECT loci_check('f')"), "ok");

  db.exec("CREATE TABLE plain(a)");
  db.exec("CREATE VIRTUAL TABLE boxes USING loci_rtree(id, minx, maxx, miny, maxy)");
  for (const std::string fn : {"loci_fleet_window('%s', 0, 0, 1, 1, 0)",
                               "loci_conflicts('%s', 1, 1)", "loci_fleet_nearest('%s', 0, 0, 1)"}) {
    const auto call = [&](const char* table) {
      std::string s = fn;
      s.replace(s.find("%s"), 2, table);
      return db.error_of("SELECT * FROM " + s);
    };
    EXPECT_TRUE(has(call("nosuch"), "no such table: nosuch")) << fn;
    EXPECT_TRUE(has(call("plain"), "plain is not a loci_fleet table")) << fn;
    EXPECT_TRUE(has(call("boxes"), "boxes is not a loci_fleet table")) << fn;
  }
  EXPECT_TRUE(has(db.error_of("SELECT * FROM loci_nearest('f', 0, 0, 1)"), "not a loci_rtree"));
  EXPECT_TRUE(has(db.error_of("SELECT * FROM loci_conflicts('f', -1, 10)"), "D must be >= 0"));
  EXPECT_TRUE(has(db.error_of("SELECT * FROM loci_conflicts('f', 1, -10)"), "H must be >= 0"));
  EXPECT_TRUE(has(db.error_of("SELECT * FROM loci_conflicts('f', NULL, 10)"), "D is NULL"));
  EXPECT_TRUE(has(db.error_of("SELECT * FROM loci_conflicts('f', 1)"), "('fleet', D, H [, now])"));
  EXPECT_TRUE(has(db.error_of("SELECT * FROM loci_fleet_window('f', 0, 0, 1, 1, 1e999)"),
                  "t is not finite"));
  EXPECT_TRUE(has(db.error_of("SELECT * FROM loci_fleet_window('f', 2, 0, 1, 1, 0)"),
                  "inverted (xmin > xmax)"));
  EXPECT_TRUE(
      has(db.error_of("SELECT * FROM loci_fleet_window('f', 0, 0, 1, 1)"), "six arguments"));
  EXPECT_TRUE(has(db.error_of("SELECT * FROM loci_fleet_nearest('f', 0, 0, 1.5)"), "k must be"));
  EXPECT_TRUE(
      has(db.error_of("SELECT * FROM loci_fleet_nearest('f', 2e150, 0, 1)"), "x is beyond 1e150"));
  EXPECT_TRUE(has(db.error_of("SELECT * FROM loci_fleet_window('f', -1e151, 0, 1, 1, 0)"),
                  "xmin is beyond 1e150"));
  // Positions far beyond 1e150 at the time asked: refused, never an infinite distance or
  // two of them ranked as a tie; after the latest report (the tree) and before it (history).
  db.exec("INSERT INTO f VALUES (2, 10, 0, 0, 1e150, 0), (3, 10, 0, 0, 5e149, 0)");
  EXPECT_EQ(db.value("SELECT id FROM loci_fleet_nearest('f', 0, 0, 2, 1e3) LIMIT 1 OFFSET 1"), "3");
  EXPECT_TRUE(
      has(db.error_of("SELECT * FROM loci_fleet_nearest('f', 0, 0, 2, 1e160)"), "beyond 1e150"));
  EXPECT_TRUE(has(db.error_of("SELECT * FROM loci_fleet_nearest('f', 0, 0, 2, 1e100)"),
                  "too far for its distance"));
  db.exec("INSERT INTO f VALUES (4, 1e12, 0, 0, 0, 0)");
  EXPECT_TRUE(has(db.error_of("SELECT * FROM loci_fleet_nearest('f', 0, 0, 3, 1e11)"),
                  "too far for its distance"));
  EXPECT_EQ(db.value("SELECT id FROM loci_fleet_nearest('f', 0, 0, 1, 1e11)"), "1");
  EXPECT_TRUE(has(db.error_of("SELECT * FROM loci_conflicts('f', 1, 1e160)"), "beyond 1e150"));
  // A horizon or a time whose sum would overflow is refused as such (it was said to be a box
  // of NaN, or an object standing still to move beyond 1e150).
  EXPECT_TRUE(has(db.error_of("SELECT * FROM loci_conflicts('f', 1, 9e307)"),
                  "loci_conflicts: conflict horizon must be at most 1e300"));
  EXPECT_TRUE(has(db.error_of("SELECT * FROM loci_conflicts('f', 1, 1e300, 1.7976931348623e308)"),
                  "loci_conflicts: conflict time plus horizon is beyond the range of doubles"));
  // Refusals from the library name the function asked, as the functions' own errors do.
  for (const char* sql : {"SELECT * FROM loci_fleet_nearest('f', 0, 0, 2, 1e160)",
                          "SELECT * FROM loci_conflicts('f', 1, 1e160)"}) {
    const std::string function = std::string(sql).substr(14, std::string(sql).find('(') - 14);
    const std::string error = db.error_of(sql);
    EXPECT_EQ(error.rfind(function + ": ", 0), 0u) << sql << " -> " << error;
    // (once: "loci_conflicts: conflicts: ..." said the operation twice)
    EXPECT_EQ(error.find(": conflicts: "), std::string::npos) << error;
    EXPECT_EQ(error.find(": nearest: "), std::string::npos) << error;
  }
  db.exec("DELETE FROM f WHERE id IN (2, 3, 4)");
  // The object that would leave the range is named by its SQL id, negative ones too.
  db.exec("INSERT INTO f VALUES (-5, 0, 0, 0, 1e10, 0)");
  EXPECT_TRUE(has(db.error_of("SELECT * FROM loci_conflicts('f', 1, 1e141)"),
                  "conflicts: id -5 moves beyond 1e150"));
  db.exec("DELETE FROM f WHERE id = -5");
  EXPECT_TRUE(has(db.error_of("SELECT loci_check('plain')"), "not a loci_rtree or loci_fleet"));
}

TEST(SqliteFleetSql, CorruptShadowTablesAreReportedNotTrusted) {
  TempDir dir;
  const std::string path = dir.file("c.db");
  {
    Db db(path);
    db.exec("CREATE VIRTUAL TABLE f USING loci_fleet(id, t, x, y, vx, vy)");
    insert(db, "f", make_fleet(50, 2, 0, 35));
    db.exec("UPDATE f_current SET x = 'oops' WHERE id = 3");
  }
  {
    Db db(path);
    EXPECT_NE(db.error_of("SELECT count(*) FROM f").find("not a number"), std::string::npos);
    EXPECT_NE(db.value("SELECT loci_check('f')"), "ok");
    db.exec("UPDATE f_current SET x = 1 WHERE id = 3");
    EXPECT_NE(db.value("SELECT loci_check('f')").find("not the latest report"), std::string::npos);
  }
}

// A fleet table whose shadow table was dropped by hand is reported as corrupt, naming it, and
// can still be dropped.
TEST(SqliteFleetSql, AMissingShadowTableIsNamedAndTheTableCanBeDropped) {
  for (const char* gone : {"f_report", "f_current", "f_meta"}) {
    SCOPED_TRACE(gone);
    TempDir dir;
    const std::string path = dir.file("m.db");
    {
      Db db(path);
      db.exec("CREATE VIRTUAL TABLE f USING loci_fleet(id, t, x, y, vx, vy)");
      insert(db, "f", make_fleet(20, 1, 0, 35));
      db.exec(std::string("DROP TABLE ") + gone);
    }
    Db db(path);
    const std::string corrupt =
        std::string("loci_fleet f: the stored index is corrupt: ") + gone + " is missing";
    EXPECT_TRUE(db.value("SELECT loci_check('f')").find(corrupt) != std::string::npos)
        << db.value("SELECT loci_check('f')");
    for (const char* sql : {"SELECT count(*) FROM f", "SELECT * FROM f WHERE id = 3",
                            "SELECT count(*) FROM loci_fleet_nearest('f', 0, 0, 1)",
                            "SELECT count(*) FROM loci_conflicts('f', 10, 0)",
                            "INSERT INTO f VALUES (1000, 1, 0, 0, 0, 0)",
                            "DELETE FROM f WHERE id = 3", "ALTER TABLE f RENAME TO g"})
      EXPECT_TRUE(db.error_of(sql).find(corrupt) != std::string::npos)
          << sql << ": " << db.error_of(sql);
    EXPECT_EQ(db.try_exec("DROP TABLE f"), "");
    EXPECT_EQ(db.value("SELECT count(*) FROM sqlite_schema WHERE name LIKE 'f%'"), "0");
  }
}

TEST(SqliteFleetSql, ThePlannerUsesTheIdAndFeedsFunctionsFromJoins) {
  Db db;
  db.exec("CREATE VIRTUAL TABLE f USING loci_fleet(id, t, x, y, vx, vy)");
  insert(db, "f", make_fleet(200, 1, 0, 36));
  const auto plan = [&](const std::string& q) {
    std::string all;
    for (const Row& r : db.rows("EXPLAIN QUERY PLAN " + q))
      all += r.back() + "\n";
    return all;
  };
  EXPECT_NE(plan("SELECT * FROM f WHERE id = 5").find("VIRTUAL TABLE INDEX 1"), std::string::npos);
  EXPECT_NE(plan("SELECT * FROM f WHERE x > 5").find("VIRTUAL TABLE INDEX 0"), std::string::npos);
  EXPECT_EQ(db.rows("SELECT id FROM f WHERE id = 5"), (std::vector<Row>{{"5"}}));
  EXPECT_EQ(db.rows("SELECT id FROM f WHERE id = '5'"), (std::vector<Row>{{"5"}}));
  EXPECT_TRUE(db.rows("SELECT id FROM f WHERE id = 5.5").empty());
  db.exec(
      "CREATE TABLE probes(x0, y0, x1, y1, t); INSERT INTO probes VALUES "
      "(0, 0, 1000, 1000, 50), (0, 0, 1000, 1000, 200), (0, 0, -1, -1, 0)");
  EXPECT_EQ(db.value("SELECT count(*) FROM probes p, loci_fleet_window('f', p.x0, p.y0, p.x1, "
                     "p.y1, p.t) w WHERE p.x1 > 0"),
            std::to_string(window_ids(db, 0, 0, 1000, 1000, 50).size() +
                           window_ids(db, 0, 0, 1000, 1000, 200).size()));
  const std::string joined =
      plan("SELECT * FROM probes p, loci_fleet_window('f', p.x0, p.y0, p.x1, p.y1, p.t) w");
  EXPECT_NE(joined.find("SCAN p"), std::string::npos) << joined;
  EXPECT_LT(joined.find("SCAN p"), joined.find("VIRTUAL TABLE")) << joined;
  // Rows come by id and nearest first: ORDER BY costs no sort.
  EXPECT_EQ(plan("SELECT * FROM f ORDER BY id").find("ORDER BY"), std::string::npos);
  EXPECT_EQ(
      plan("SELECT * FROM loci_fleet_nearest('f', 0, 0, 5) ORDER BY distance").find("ORDER BY"),
      std::string::npos);
}

}  // namespace
