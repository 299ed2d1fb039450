// The loci SQLite extension through the real SQLite library: loci_rtree against a plain table
// answering the same SQL (brute force, exact) and against SQLite's own rtree, loci_nearest
// against brute force, transactions, reopening, a killed writer, errors and corruption.
#include <gtest/gtest.h>

#include <memory>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "loci/index/packed_rtree.hpp"
#include "sqlite_support.hpp"
#include "support/random_data.hpp"
#ifdef LOCI_HAVE_IO
#include "loci/io/layer_reader.hpp"
#endif

using loci::Box;
using loci::test::Db;
using loci::test::real;
using loci::test::Row;
using loci::test::TempDir;

namespace {

// m(id, minx, maxx, miny, maxy): the plain table every answer is checked against.
void make_tables(Db& db, const std::vector<Box<2>>& boxes, bool with_rtree = false) {
  db.exec("CREATE TABLE m(id INTEGER PRIMARY KEY, minx REAL, maxx REAL, miny REAL, maxy REAL)");
  db.exec("CREATE VIRTUAL TABLE t USING loci_rtree(id, minx, maxx, miny, maxy)");
  if (with_rtree) db.exec("CREATE VIRTUAL TABLE r USING rtree(id, minx, maxx, miny, maxy)");
  // nums(value): 1 .. 10000, for bulk statements.
  db.exec(
      "CREATE TABLE nums AS WITH RECURSIVE s(value) AS (SELECT 1 UNION ALL SELECT value + 1 "
      "FROM s WHERE value < 10000) SELECT value FROM s");
  db.exec("BEGIN");
  sqlite3_stmt* s = nullptr;
  sqlite3_prepare_v2(db.get(), "INSERT INTO m VALUES(?, ?, ?, ?, ?)", -1, &s, nullptr);
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    sqlite3_bind_int64(s, 1, sqlite3_int64(i + 1));
    sqlite3_bind_double(s, 2, boxes[i].min[0]);
    sqlite3_bind_double(s, 3, boxes[i].max[0]);
    sqlite3_bind_double(s, 4, boxes[i].min[1]);
    sqlite3_bind_double(s, 5, boxes[i].max[1]);
    sqlite3_step(s);
    sqlite3_reset(s);
  }
  sqlite3_finalize(s);
  db.exec("INSERT INTO t SELECT * FROM m");
  if (with_rtree) db.exec("INSERT INTO r SELECT * FROM m");
  db.exec("COMMIT");
}

std::vector<Row> ids(Db& db, const std::string& table, const std::string& where) {
  return db.rows("SELECT id FROM " + table + " WHERE " + where + " ORDER BY id");
}

std::vector<Row> all(Db& db, const std::string& table) {
  return db.rows("SELECT id, minx, maxx, miny, maxy FROM " + table + " ORDER BY id");
}

// A random WHERE clause over the coordinate columns, in every form SQL allows.
std::string random_where(std::mt19937_64& rng, const std::vector<Box<2>>& boxes) {
  static const char* cols[] = {"minx", "maxx", "miny", "maxy"};
  std::uniform_real_distribution<double> u(-50, 1050);
  const auto value = [&](int col) -> std::string {
    switch (rng() % 6) {
      case 0: {  // exactly a stored coordinate
        const auto& b = boxes[rng() % boxes.size()];
        const double v = col == 0 ? b.min[0] : col == 1 ? b.max[0] : col == 2 ? b.min[1] : b.max[1];
        return real(v);
      }
      case 1:
        return std::to_string(int(u(rng)));  // an integer literal
      default:
        return real(u(rng));
    }
  };
  const int form = int(rng() % 5);
  if (form == 4) {  // boxes holding an interval: the bounds on min lie below those on max
    const auto& b = boxes[rng() % boxes.size()];
    std::uniform_real_distribution<double> t(-0.2, 1.2);
    std::string w;
    for (int a = 0; a < 2; ++a) {
      if (a == 1 && rng() % 2) break;
      double lo = b.min[a] + t(rng) * (b.max[a] - b.min[a]);
      double hi = b.min[a] + t(rng) * (b.max[a] - b.min[a]);
      if (lo > hi) std::swap(lo, hi);
      if (a) w += " AND ";
      w += std::string(cols[2 * a]) + (rng() % 2 ? " < " : " <= ") + real(lo) + " AND " +
           cols[2 * a + 1] + (rng() % 2 ? " > " : " >= ") + real(hi);
    }
    return w;
  }
  if (form == 0) {  // the window of SQLite's rtree documentation
    double x1 = u(rng), x2 = u(rng), y1 = u(rng), y2 = u(rng);
    if (x1 > x2) std::swap(x1, x2);
    if (y1 > y2) std::swap(y1, y2);
    return "minx <= " + real(x2) + " AND maxx >= " + real(x1) + " AND miny <= " + real(y2) +
           " AND maxy >= " + real(y1);
  }
  static const char* ops[] = {"<=", ">=", "<", ">", "="};
  std::string w;
  const int n = 1 + int(rng() % 4);
  for (int i = 0; i < n; ++i) {
    const int col = int(rng() % 4);
    if (!w.empty()) w += " AND ";
    if (rng() % 5 == 0) {
      std::string a = value(col), b = value(col);
      w += std::string(cols[col]) + " BETWEEN " + a + " AND " + b;
    } else {
      w += std::string(cols[col]) + " " + ops[rng() % (form == 3 ? 5 : 4)] + " " + value(col);
    }
  }
  return w;
}

class SqliteRtree : public ::testing::TestWithParam<loci::test::Shape> {};

// Windows of side `reach` starting a hair beyond the top right corner of 200 of the boxes (in
// tables made with the rtree): loci's answer must be the exact one, and the rtree's must hold
// it. Returns the rtree's false hits.
std::size_t hair_beyond_corners(Db& db, const std::vector<Box<2>>& boxes, double reach) {
  std::size_t rtree_false_hits = 0;
  for (std::size_t i = 0; i < 200; ++i) {
    const auto& b = boxes[(i * 7919) % boxes.size()];
    const double x1 = std::nextafter(b.max[0], INFINITY), y1 = std::nextafter(b.max[1], INFINITY);
    const std::string where = "minx <= " + real(x1 + reach) + " AND maxx >= " + real(x1) +
                              " AND miny <= " + real(y1 + reach) + " AND maxy >= " + real(y1);
    const auto exact = ids(db, "m", where);
    EXPECT_EQ(ids(db, "t", where), exact) << where;
    const auto rtree = ids(db, "r", where);
    for (const auto& row : exact)
      EXPECT_TRUE(std::find(rtree.begin(), rtree.end(), row) != rtree.end())
          << "rtree missed a row: " << where;
    rtree_false_hits += rtree.size() - std::min(rtree.size(), exact.size());
  }
  return rtree_false_hits;
}

TEST_P(SqliteRtree, WindowsMatchBruteForceAndSqliteRtreeWithoutItsFalseHits) {
  const auto boxes = loci::test::make_boxes<2>(GetParam(), 3000, 11);
  Db db;
  make_tables(db, boxes, true);
  EXPECT_EQ(db.value("SELECT loci_check('t')"), "ok");
  std::mt19937_64 rng(5);
  for (int q = 0; q < 300; ++q) {
    const std::string where = random_where(rng, boxes);
    ASSERT_EQ(ids(db, "t", where), ids(db, "m", where)) << where;
  }
  // Windows starting a hair beyond a box's corner: SQLite's rtree rounds its float32 boxes
  // outward and reports the box; loci does not.
  const std::size_t rtree_false_hits = hair_beyond_corners(db, boxes, 1);
  if (GetParam() != loci::test::Shape::on_a_line) EXPECT_GT(rtree_false_hits, 0u);
}

TEST_P(SqliteRtree, NearestMatchesBruteForce) {
  const auto boxes = loci::test::make_boxes<2>(GetParam(), 2000, 12);
  Db db;
  make_tables(db, boxes);
  // Some rows written after the packed build, some packed rows deleted and moved: the answer
  // comes from the base and the delta at once.
  db.exec("DELETE FROM t WHERE id % 17 = 0; DELETE FROM m WHERE id % 17 = 0;");
  db.exec(
      "UPDATE t SET minx = minx - 3, maxx = maxx + 1 WHERE id % 13 = 0;"
      "UPDATE m SET minx = minx - 3, maxx = maxx + 1 WHERE id % 13 = 0;");
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-100, 1100);
  for (int q = 0; q < 100; ++q) {
    const double x = u(rng), y = u(rng);
    const std::size_t k = std::size_t(std::vector<int>{1, 5, 37, 3000}[q % 4]);
    std::vector<std::pair<double, std::string>> brute;
    for (const Row& r : all(db, "m")) {
      const double dx = std::max({std::stod(r[1]) - x, 0.0, x - std::stod(r[2])});
      const double dy = std::max({std::stod(r[3]) - y, 0.0, y - std::stod(r[4])});
      brute.push_back({std::sqrt(dx * dx + dy * dy), r[0]});
    }
    std::sort(brute.begin(), brute.end());
    const auto got = db.rows("SELECT id, distance FROM loci_nearest('t', " + real(x) + ", " +
                             real(y) + ", " + std::to_string(k) + ")");
    ASSERT_EQ(got.size(), std::min(k, brute.size()));
    std::set<std::string> inside, expected_inside;
    const std::string kth = got.empty() ? "" : got.back()[1];
    for (std::size_t i = 0; i < got.size(); ++i) {
      ASSERT_EQ(got[i][1], real(brute[i].first)) << "rank " << i;  // nearest first, exact
      if (got[i][1] != kth) inside.insert(got[i][0]), expected_inside.insert(brute[i].second);
    }
    EXPECT_EQ(inside, expected_inside);  // ties at the k-th distance may come in any order
  }
  // Usable in joins: three neighbours for every probe point.
  db.exec(
      "CREATE TABLE probes(x REAL, y REAL); INSERT INTO probes VALUES (0, 0), (500, 500), "
      "(1000, 0)");
  EXPECT_EQ(db.value("SELECT count(*) FROM probes p, loci_nearest('t', p.x, p.y, 3) n"), "9");
  EXPECT_EQ(db.value("SELECT count(*) FROM loci_nearest('t', 1, 2, 0)"), "0");
  // Unqualified, x and y are the probes' (the argument columns are arg_x, arg_y, ...), in a
  // join and in a correlated subquery; the argument columns read back what was given, so a
  // condition on one holds.
  EXPECT_EQ(db.value("SELECT count(*) FROM probes, loci_nearest('t', x, y, 3)"), "9");
  EXPECT_EQ(db.value("SELECT sum((SELECT count(*) FROM loci_nearest('t', x, y, 2))) FROM probes"),
            "6");
  EXPECT_EQ(db.value("SELECT count(*) FROM loci_nearest('t', 0, 0, 3) WHERE arg_k = 3"), "3");
  EXPECT_EQ(db.value("SELECT count(*) FROM loci_nearest('t', 0, 0, 3) WHERE arg_k = 2"), "0");
  EXPECT_EQ(db.value("SELECT arg_table || ',' || arg_x || ',' || arg_y || ',' || arg_k FROM "
                     "loci_nearest('t', 1.5, 2, 1)"),
            "t,1.5,2,1");
}

INSTANTIATE_TEST_SUITE_P(Shapes, SqliteRtree, ::testing::ValuesIn(loci::test::kAllShapes),
                         [](const auto& info) { return loci::test::name(info.param); });

TEST(SqliteRtreeSql, ComparisonsFollowSqlRulesForEveryOperandType) {
  Db db;
  std::vector<Box<2>> boxes;
  for (int i = 0; i < 50; ++i)
    boxes.push_back({{{double(i), double(i % 7)}}, {{i + 0.5, i % 7 + 2.0}}});
  boxes.push_back({{{9007199254740992.0, 0}}, {{9007199254740994.0, 1}}});  // 2^53, 2^53 + 2
  make_tables(db, boxes);
  for (const char* where : {"minx <= '3'",
                            "minx >= '3'",
                            "minx = 'a'",
                            "minx < x'00'",
                            "minx > NULL",
                            "maxx <= NULL",
                            "minx = 3",
                            "minx = 3.0",
                            "minx BETWEEN 4 AND 9",
                            "maxy > 7",
                            "minx >= 9007199254740993",
                            "minx <= 9007199254740993",
                            "maxx = 9007199254740994",
                            "maxx < 9007199254740993",
                            "maxx > 9007199254740993",
                            "minx = 9007199254740993",
                            "minx <= 10 AND minx >= 12",
                            "minx <= 3 AND maxx >= 3.25",
                            "minx < 3.25 AND maxx > 3.25 AND maxx < 40",
                            "minx <= 3 AND maxx >= 3.5 AND miny <= 3 AND maxy >= 4",
                            "minx <= 3 AND maxx > 3.5",
                            "minx >= 4 AND maxx <= 3.75",
                            "minx >= 1e999",
                            "minx <= -1e999",
                            "maxx < 1e999",
                            "miny > -1e308 AND maxy < 1e308 AND minx > 20.25"}) {
    EXPECT_EQ(ids(db, "t", where), ids(db, "m", where)) << where;
  }
  // Lookups by id, with the id in any type SQLite accepts.
  for (const char* where : {"id = 7", "rowid = 7", "id = 7.0", "id = '7'", "id = 7.5", "id = 0",
                            "id = NULL", "id = 52"})
    EXPECT_EQ(ids(db, "t", where), ids(db, "m", where)) << where;
}

TEST(SqliteRtreeSql, ThePlannerUsesTheIndex) {
  Db db;
  make_tables(db, loci::test::make_boxes<2>(loci::test::Shape::uniform, 100, 1));
  const auto plan = [&](const std::string& q) {
    std::string all;
    for (const Row& r : db.rows("EXPLAIN QUERY PLAN " + q))
      all += r.back() + "\n";
    return all;
  };
  EXPECT_NE(plan("SELECT id FROM t WHERE minx <= 5 AND maxx >= 1 AND miny <= 5 AND maxy >= 1")
                .find("VIRTUAL TABLE INDEX 2"),
            std::string::npos);
  EXPECT_NE(plan("SELECT * FROM t WHERE id = 5").find("VIRTUAL TABLE INDEX 1"), std::string::npos);
  EXPECT_NE(plan("SELECT * FROM t WHERE maxy BETWEEN 1 AND 2").find("VIRTUAL TABLE INDEX 2"),
            std::string::npos);
  // A join probing the index for every row of another table.
  db.exec("CREATE TABLE w(x1, y1, x2, y2)");
  EXPECT_NE(plan("SELECT w.rowid, t.id FROM w JOIN t ON t.minx <= w.x2 AND t.maxx >= w.x1 AND "
                 "t.miny <= w.y2 AND t.maxy >= w.y1")
                .find("VIRTUAL TABLE INDEX 2"),
            std::string::npos);
}

TEST(SqliteRtreeSql, AuxColumnsTravelWithTheirRows) {
  Db db;
  db.exec("CREATE VIRTUAL TABLE t USING loci_rtree(id, x0, x1, y0, y1, +name, +weight)");
  db.exec("INSERT INTO t VALUES (1, 0, 1, 0, 1, 'one', 1.5), (2, 2, 3, 2, 3, 'two', NULL)");
  db.exec("INSERT INTO t(x0, x1, y0, y1, name) VALUES (5, 6, 5, 6, 'auto')");
  EXPECT_EQ(db.rows("SELECT id, name, weight FROM t WHERE x0 >= 1 ORDER BY id"),
            (std::vector<Row>{{"2", "two", "NULL"}, {"3", "auto", "NULL"}}));
  db.exec("UPDATE t SET id = 10, name = 'ten' WHERE id = 1");
  EXPECT_EQ(db.rows("SELECT id, name, weight FROM t WHERE id = 10"),
            (std::vector<Row>{{"10", "ten", "1.5"}}));
  db.exec("INSERT OR REPLACE INTO t VALUES (2, 7, 8, 7, 8, 'two again', 2)");
  EXPECT_EQ(db.rows("SELECT id, x0, name FROM t ORDER BY id"),
            (std::vector<Row>{{"2", "7", "two again"}, {"3", "5", "auto"}, {"10", "0", "ten"}}));
  EXPECT_EQ(db.value("SELECT loci_check('t')"), "ok");
}

// An UPDATE that sets the id (or the rowid) to NULL is refused, as a rowid table refuses it
// (datatype mismatch), rather than moving the row to a new id: a remapping by a subquery that
// finds no row for some id leaves the table as it was.
TEST(SqliteRtreeSql, UpdateToANullIdIsRefused) {
  Db db;
  db.exec("CREATE VIRTUAL TABLE t USING loci_rtree(id, x0, x1, y0, y1, +name)");
  db.exec("CREATE TABLE plain(id INTEGER PRIMARY KEY, name)");
  db.exec("CREATE TABLE remap(old INTEGER, new INTEGER)");
  db.exec("INSERT INTO t VALUES (1, 0, 1, 0, 1, 'a'), (2, 2, 3, 2, 3, 'b'), (3, 4, 5, 4, 5, 'c')");
  db.exec("INSERT INTO plain VALUES (1, 'a'), (2, 'b'), (3, 'c')");
  db.exec("INSERT INTO remap VALUES (1, 11), (2, 12)");
  const std::vector<Row> before{{"1", "a"}, {"2", "b"}, {"3", "c"}};
  for (const char* table : {"plain", "t"}) {
    const std::string name = table;
    EXPECT_NE(db.error_of("UPDATE " + name +
                          " SET id = (SELECT new FROM remap WHERE old = " + name + ".id)"),
              "")
        << table;
    EXPECT_NE(db.error_of("UPDATE " + name + " SET id = NULL WHERE id = 2"), "") << table;
    EXPECT_NE(db.error_of("UPDATE " + name + " SET rowid = NULL WHERE id = 3"), "") << table;
    EXPECT_EQ(db.rows("SELECT id, name FROM " + name + " ORDER BY id"), before) << table;
  }
  EXPECT_EQ(db.value("SELECT loci_check('t')"), "ok");
}

// A NULL id takes one more than the largest live id, as in a rowid table: the top id erased is
// not remembered, negative ids count, an empty table starts at 1. Checked in the packed base
// (after a commit reloads it), in the unpacked rows, and after a rollback.
TEST(SqliteRtreeSql, NewIdsFollowTheRowidTableRule) {
  Db db;
  db.exec("CREATE VIRTUAL TABLE t USING loci_rtree(id, minx, maxx, miny, maxy)");
  db.exec("CREATE TABLE m(id INTEGER PRIMARY KEY, minx REAL, maxx REAL, miny REAL, maxy REAL)");
  const auto both = [&](const std::string& sql) { db.exec_on({"t", "m"}, sql); };
  const auto check = [&](const char* when) {
    EXPECT_EQ(all(db, "t"), all(db, "m")) << when;
    EXPECT_EQ(db.value("SELECT loci_check('t')"), "ok") << when;
  };
  both("INSERT INTO $T VALUES (NULL, 0, 1, 0, 1)");
  both("INSERT INTO $T VALUES (-7, 0, 1, 0, 1), (12, 2, 3, 2, 3), (5, 4, 5, 4, 5)");
  both("DELETE FROM $T WHERE id = 12");
  both("INSERT INTO $T VALUES (NULL, 6, 7, 6, 7)");
  check("after the top id was erased");
  both("DELETE FROM $T WHERE id > 0");
  both("INSERT INTO $T VALUES (NULL, 8, 9, 8, 9)");
  check("with only a negative id left");
  db.exec("BEGIN");
  both("INSERT INTO $T SELECT id + 100, minx, maxx, miny, maxy FROM $T");
  db.exec("COMMIT");
  both("DELETE FROM $T WHERE id > 100");
  both("INSERT INTO $T VALUES (NULL, 1, 2, 1, 2)");
  check("after a commit and deleting the top of the packed rows");
  db.exec("BEGIN");
  both("INSERT INTO $T VALUES (1000, 0, 1, 0, 1)");
  db.exec("ROLLBACK");
  both("INSERT INTO $T VALUES (NULL, 3, 4, 3, 4)");
  check("after a rolled-back insert of a high id");
  both("DELETE FROM $T");
  both("INSERT INTO $T VALUES (NULL, 5, 6, 5, 6)");
  check("emptied");
  // With the largest id taken, a NULL id takes an unused one (at random, as in a rowid table;
  // it failed with SQLITE_FULL).
  db.exec("INSERT INTO t VALUES (9223372036854775807, 0, 1, 0, 1)");
  for (int i = 0; i < 3; ++i)
    db.exec("INSERT INTO t(minx, maxx, miny, maxy) VALUES (1, 1, 1, 1)");
  EXPECT_EQ(db.value("SELECT count(*) FROM t"), "5");
  EXPECT_EQ(db.value("SELECT count(DISTINCT id) FROM t WHERE id > 0"), "5");
  EXPECT_EQ(db.value("SELECT loci_check('t')"), "ok");
}

// A scan lists rows in ascending id order, as a rowid table's does, whether they sit in the
// packed base, in the delta or in both (a base row updated): a statement renumbering rows
// then meets the conflicts it meets on any table (UPDATE SET id = id - 1 failed, id + 1 passed,
// the other way round from every rowid table), and ORDER BY id needs no sort.
TEST(SqliteRtreeSql, ScansComeInIdOrderAsInARowidTable) {
  Db db;
  db.exec("CREATE VIRTUAL TABLE t USING loci_rtree(id, minx, maxx, miny, maxy, +tag)");
  db.exec(
      "CREATE TABLE m(id INTEGER PRIMARY KEY, minx REAL, maxx REAL, miny REAL, maxy REAL, tag)");
  const auto both = [&](const std::string& sql) { db.exec_on({"t", "m"}, sql); };
  std::mt19937_64 rng(31);
  std::uniform_int_distribution<int> coord(0, 1000);
  std::string values;
  for (int i = 0; i < 5000; ++i) {  // ids 1..5000, in no relation to the boxes' Hilbert order
    const int x = coord(rng), y = coord(rng);
    values += (i ? ",(" : "(") + std::to_string(5000 - i) + "," + std::to_string(x) + "," +
              std::to_string(x + 1) + "," + std::to_string(y) + "," + std::to_string(y + 1) +
              ",'r" + std::to_string(5000 - i) + "')";
  }
  db.exec("INSERT INTO m VALUES " + values);
  db.exec("BEGIN; INSERT INTO t SELECT * FROM m; COMMIT");  // packed at the commit
  ASSERT_EQ(db.value("SELECT count(*) FROM t_delta"), "0");
  both("DELETE FROM $T WHERE id % 7 = 0");
  both("UPDATE $T SET minx = minx + 0.5 WHERE id % 5 = 0");
  both("INSERT INTO $T VALUES (-4, 1, 2, 1, 2, 'neg'), (1500000, 3, 4, 3, 4, 'big')");
  both("INSERT INTO $T SELECT id + 5000, minx, maxx, miny, maxy, tag FROM $T WHERE id % 11 = 0");
  ASSERT_NE(db.value("SELECT count(*) FROM t_delta"), "0");
  const auto ids = [&](const char* table) {
    return db.rows(std::string("SELECT id, tag FROM ") + table);  // no ORDER BY: scan order
  };
  EXPECT_EQ(ids("t"), ids("m"));
  EXPECT_EQ(db.rows("SELECT id FROM t ORDER BY id"), db.rows("SELECT id FROM m ORDER BY id"));
  EXPECT_EQ(db.value("EXPLAIN QUERY PLAN SELECT * FROM t ORDER BY id").find("TEMP B-TREE"),
            std::string::npos);
  both("UPDATE $T SET id = id - 1");
  EXPECT_EQ(all(db, "t"), all(db, "m"));
  for (const char* table : {"t", "m"})
    EXPECT_NE(db.error_of(std::string("UPDATE ") + table + " SET id = id + 1"), "") << table;
  EXPECT_EQ(all(db, "t"), all(db, "m"));  // the failed statement undone alike
  EXPECT_EQ(db.rows("SELECT id, tag FROM t ORDER BY id"),
            db.rows("SELECT id, tag FROM m ORDER BY id"));
  EXPECT_EQ(db.value("SELECT loci_check('t')"), "ok");
}

// Random INSERT, UPDATE, DELETE, bulk inserts and deletes, applied to t and m alike, under
// BEGIN / COMMIT / ROLLBACK, SAVEPOINT / RELEASE / ROLLBACK TO; after every step t answers
// like m and loci_check passes.
TEST(SqliteRtreeSql, RandomWritesFollowRollbackAndSavepoints) {
  Db db;
  make_tables(db, loci::test::make_boxes<2>(loci::test::Shape::uniform, 500, 3));
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(0, 1000);
  int depth = 0;  // open savepoints, BEGIN counted as one
  const auto both = [&](const std::string& sql) { db.exec_on({"t", "m"}, sql); };
  for (int step = 0; step < 400; ++step) {
    const int what = int(rng() % 20);
    const std::string x = real(u(rng)), y = real(u(rng));
    const std::string id = std::to_string(1 + rng() % 900);
    if (what < 5) {
      both("INSERT OR REPLACE INTO $T VALUES(" + id + ", " + x + ", " + x + " + 4, " + y + ", " +
           y + " + 2)");
    } else if (what < 8) {
      both("UPDATE $T SET minx = minx + 1, maxx = maxx + 2 WHERE id % 29 = " + id + " % 29");
    } else if (what < 10) {
      both("DELETE FROM $T WHERE id = " + id + " OR (minx < " + x + " AND minx > " + x + " - 5)");
    } else if (what == 10) {  // a bulk insert, large enough for a repack at commit
      both(
          "INSERT OR REPLACE INTO $T SELECT value + 1000, value % 997, value % 997 + 1, value "
          "% 991, value % 991 + 3 FROM nums WHERE value <= 6000");
    } else if (what == 11) {
      both("DELETE FROM $T WHERE id > 1000 AND id % 3 != 0");
    } else if (what == 12) {
      db.exec(depth == 0 ? "BEGIN" : "SAVEPOINT s" + std::to_string(depth));
      ++depth;
    } else if (what == 13 && depth > 0) {
      --depth;
      db.exec(depth == 0 ? "COMMIT" : "RELEASE s" + std::to_string(depth));
    } else if (what == 14 && depth > 0) {
      --depth;
      db.exec(depth == 0 ? "ROLLBACK"
                         : "ROLLBACK TO s" + std::to_string(depth) + "; RELEASE s" +
                               std::to_string(depth));
    } else if (what == 15) {
      const std::string where = "minx <= " + x + " + 100 AND maxx >= " + x + " AND miny <= " + y +
                                " + 100 AND maxy >= " + y;
      ASSERT_EQ(ids(db, "t", where), ids(db, "m", where)) << "step " << step;
    } else if (what == 16) {
      ASSERT_EQ(all(db, "t"), all(db, "m")) << "step " << step;
      ASSERT_EQ(db.value("SELECT loci_check('t')"), "ok") << "step " << step;
    }
  }
  while (depth-- > 0)
    db.exec(depth == 0 ? "COMMIT" : "RELEASE s" + std::to_string(depth));
  EXPECT_EQ(all(db, "t"), all(db, "m"));
  EXPECT_EQ(db.value("SELECT loci_check('t')"), "ok");
}

// Writes on the same connection while a query's cursor is still stepped: each row it still
// returns is the row as it is then (present, in the window, its box and aux values current),
// never a deleted row or an old box beside new aux values; at most once each.
TEST(SqliteRtreeSql, ACursorSteppedAcrossWritesReturnsRowsAsTheyAre) {
  for (const bool rollback : {false, true}) {
    Db db;
    db.exec("CREATE VIRTUAL TABLE t USING loci_rtree(id, minx, maxx, miny, maxy, +a)");
    db.exec(
        "CREATE TABLE m(id INTEGER PRIMARY KEY, minx REAL, maxx REAL, miny REAL, maxy REAL, a)");
    std::mt19937_64 rng(rollback ? 41 : 40);
    for (int i = 1; i <= 300; ++i) {
      const std::string x = std::to_string(rng() % 100), y = std::to_string(rng() % 100);
      db.exec_on({"t", "m"}, "INSERT INTO $T VALUES(" + std::to_string(i) + ", " + x + ", " + x +
                                 " + 1, " + y + ", " + y + " + 1, 'v" + std::to_string(i) + "')");
    }
    if (rollback) db.exec("BEGIN; SAVEPOINT s");
    const char* window = " WHERE minx >= 10 AND maxx <= 80 AND miny >= 0 AND maxy <= 90";
    sqlite3_stmt* q = nullptr;
    ASSERT_EQ(
        sqlite3_prepare_v2(
            db.get(), (std::string("SELECT id, minx, maxx, miny, maxy, a FROM t") + window).c_str(),
            -1, &q, nullptr),
        SQLITE_OK);
    std::set<std::string> seen;
    int returned = 0, writes = 0;
    while (sqlite3_step(q) == SQLITE_ROW) {
      Row got;
      for (int c = 0; c < 6; ++c)
        got.push_back(Db::text(q, c));
      ASSERT_TRUE(seen.insert(got[0]).second) << "id " << got[0] << " returned twice";
      // The row as the plain table holds it now, and in the window now.
      EXPECT_EQ(db.rows("SELECT id, minx, maxx, miny, maxy, a FROM m WHERE id = " + got[0] +
                        " AND " + (window + 7)),
                (std::vector<Row>{got}));
      ++returned;
      // Then writes: rows deleted, moved (in or out of the window), their aux changed.
      for (int w = 0; w < 3; ++w, ++writes) {
        const std::string id = std::to_string(1 + rng() % 300), x = std::to_string(rng() % 100);
        switch (rng() % 3) {
          case 0:
            db.exec_on({"t", "m"}, "DELETE FROM $T WHERE id = " + id);
            break;
          case 1:
            db.exec_on({"t", "m"}, "UPDATE $T SET minx = " + x + ", maxx = " + x +
                                       " + 2, a = 'moved' WHERE id = " + id);
            break;
          default:
            db.exec_on({"t", "m"}, "UPDATE $T SET a = 'renamed' WHERE id = " + id);
        }
      }
      if (rollback && returned % 5 == 0) {
        // Back to the savepoint on both: the rows not yet returned are those of the start.
        db.exec("ROLLBACK TO s");
      }
    }
    sqlite3_finalize(q);
    if (rollback) db.exec("COMMIT");
    EXPECT_GT(returned, 20);
    EXPECT_GT(writes, 60);
    EXPECT_EQ(all(db, "t"), all(db, "m"));
    EXPECT_EQ(db.rows("SELECT id, a FROM t ORDER BY id"),
              db.rows("SELECT id, a FROM m ORDER BY id"));
    EXPECT_EQ(db.value("SELECT loci_check('t')"), "ok");
  }
}

// Loading the extension again on a connection (a script that loads it twice) keeps the
// tables made before usable by the functions it registers anew.
TEST(SqliteRtreeSql, LoadingTwiceKeepsEarlierTablesVisible) {
  Db db;
  db.exec("CREATE VIRTUAL TABLE s USING loci_rtree(id, minx, maxx, miny, maxy)");
  db.exec("CREATE VIRTUAL TABLE f USING loci_fleet(id, t, x, y, vx, vy)");
  db.exec("INSERT INTO s VALUES (1, 0, 1, 0, 1), (2, 5, 6, 5, 6)");
  db.exec("INSERT INTO f VALUES (1, 0, 0, 0, 1, 0), (2, 0, 10, 0, -1, 0)");
  db.load_extension();
  EXPECT_EQ(db.value("SELECT id FROM loci_nearest('s', 5, 5, 1)"), "2");
  EXPECT_EQ(db.value("SELECT loci_check('s')"), "ok");
  EXPECT_EQ(db.value("SELECT count(*) FROM loci_conflicts('f', 1, 10)"), "1");
  EXPECT_EQ(db.value("SELECT loci_check('f')"), "ok");
  db.exec("INSERT INTO s VALUES (3, 9, 9, 9, 9)");
  EXPECT_EQ(db.value("SELECT id FROM loci_nearest('s', 10, 10, 1)"), "3");
}

// load_extension() from SQL, as a script or an application that loads extensions by
// statement does (the C API call is the other way in).
TEST(SqliteRtreeSql, LoadsThroughTheSqlFunction) {
  Db db(":memory:", false);
  EXPECT_NE(db.try_exec("CREATE VIRTUAL TABLE s USING loci_rtree(id, minx, maxx, miny, maxy)"), "");
  sqlite3_enable_load_extension(db.get(), 1);  // the SQL function too (db_config: C only)
  db.exec(std::string("SELECT load_extension('") + LOCI_SQLITE_EXTENSION + "')");
  db.exec("CREATE VIRTUAL TABLE s USING loci_rtree(id, minx, maxx, miny, maxy)");
  db.exec("INSERT INTO s VALUES (1, 0, 1, 0, 1), (2, 5, 6, 5, 6)");
  EXPECT_EQ(db.value("SELECT id FROM loci_nearest('s', 5, 5, 1)"), "2");
  EXPECT_EQ(db.value("SELECT loci_check('s')"), "ok");
}

// Rows written in one transaction are packed at its commit when they number 4,096 or more
// (a bulk INSERT ... SELECT), not left in the delta; fewer stay in the delta.
TEST(SqliteRtreeSql, BulkInsertIsPackedAtCommit) {
  const auto boxes = loci::test::make_boxes<2>(loci::test::Shape::uniform, 5000, 17);
  Db db;
  make_tables(db, boxes);  // one transaction: INSERT INTO t SELECT * FROM m
  EXPECT_EQ(db.value("SELECT count(*) FROM t_delta"), "0");
  EXPECT_NE(db.value("SELECT count(*) FROM t_node"), "0");
  EXPECT_EQ(db.value("SELECT count(*) FROM t"), "5000");
  EXPECT_EQ(db.value("SELECT loci_check('t')"), "ok");
  db.exec(
      "BEGIN; INSERT INTO t SELECT id + 10000, minx, maxx, miny, maxy FROM m WHERE id <= 100;"
      "COMMIT");
  EXPECT_EQ(db.value("SELECT count(*) FROM t_delta"), "100");
  EXPECT_EQ(db.value("SELECT loci_check('t')"), "ok");
}

TEST(SqliteRtreeSql, SurvivesCloseAndReopen) {
  TempDir dir;
  const auto boxes = loci::test::make_boxes<2>(loci::test::Shape::clustered, 6000, 4);
  std::vector<Row> before;
  {
    Db db(dir.file("a.db"));
    make_tables(db, boxes);
    db.exec("DELETE FROM t WHERE id % 5 = 0; DELETE FROM m WHERE id % 5 = 0");
    db.exec("INSERT INTO t VALUES (99999, 1, 2, 3, 4); INSERT INTO m VALUES (99999, 1, 2, 3, 4)");
    before = all(db, "t");
    EXPECT_EQ(before, all(db, "m"));
  }
  Db db(dir.file("a.db"));
  EXPECT_EQ(all(db, "t"), before);
  EXPECT_EQ(db.value("SELECT loci_check('t')"), "ok");
  const std::string where = "minx <= 600 AND maxx >= 400 AND miny <= 600 AND maxy >= 400";
  EXPECT_EQ(ids(db, "t", where), ids(db, "m", where));
  // A second connection's write is seen by the first.
  {
    Db other(dir.file("a.db"));
    other.exec("INSERT INTO t VALUES (123456, 500, 501, 500, 501)");
  }
  EXPECT_EQ(db.value("SELECT count(*) FROM t WHERE id = 123456"), "1");
  EXPECT_EQ(db.value("SELECT id FROM loci_nearest('t', 500.5, 500.5, 1)"), "123456");
}

// A table another connection dropped, or renamed, and created again under its name: the
// functions answer from the new one, whose writes started from the same count.
TEST(SqliteRtreeSql, FunctionsFollowATableReplacedByAnotherConnection) {
  TempDir dir;
  Db db(dir.file("r.db"));
  db.exec(
      "CREATE VIRTUAL TABLE t USING loci_rtree(id, minx, maxx, miny, maxy);"
      "INSERT INTO t VALUES (1, 0, 0, 0, 0)");
  EXPECT_EQ(db.value("SELECT id FROM loci_nearest('t', 5, 5, 1)"), "1");
  {
    Db other(dir.file("r.db"));
    other.exec(
        "DROP TABLE t; CREATE VIRTUAL TABLE t USING loci_rtree(id, minx, maxx, miny, maxy);"
        "INSERT INTO t VALUES (2, 5, 5, 5, 5)");
  }
  EXPECT_EQ(db.rows("SELECT id, distance FROM loci_nearest('t', 5, 5, 5)"),
            (std::vector<Row>{{"2", "0"}}));
  EXPECT_EQ(db.value("SELECT loci_check('t')"), "ok");
  {
    Db other(dir.file("r.db"));
    other.exec(
        "ALTER TABLE t RENAME TO u;"
        "CREATE VIRTUAL TABLE t USING loci_rtree(id, minx, maxx, miny, maxy);"
        "INSERT INTO t VALUES (9, 1, 1, 1, 1)");
  }
  EXPECT_EQ(db.rows("SELECT id FROM loci_nearest('t', 5, 5, 5)"), (std::vector<Row>{{"9"}}));
  EXPECT_EQ(db.rows("SELECT id FROM loci_nearest('u', 5, 5, 5)"), (std::vector<Row>{{"2"}}));
  EXPECT_EQ(db.value("SELECT loci_check('t')"), "ok");
}

// Another connection changing the schema (any table) or the rows of an attached database:
// loci_check and the table functions read the schema and rows as they are now, never a table
// object SQLite frees when it reads the schema again (loci_check, whose statement reads no
// table, once crashed there), nor an attached table's index from before the commit.
TEST(SqliteRtreeSql, FunctionsSeeOtherConnectionsSchemaChangesAndAttachedCommits) {
  TempDir dir;
  Db db(dir.file("s.db"));
  db.exec(
      "CREATE VIRTUAL TABLE t USING loci_rtree(id, minx, maxx, miny, maxy);"
      "CREATE VIRTUAL TABLE f USING loci_fleet(id, t, x, y, vx, vy);"
      "INSERT INTO t VALUES (1, 0, 0, 0, 0); INSERT INTO f VALUES (1, 0, 0, 0, 1, 0)");
  const auto other = [&](const std::string& file, const std::string& sql) {
    Db o(dir.file(file));
    o.exec(sql);
  };
  for (const char* change : {"CREATE TABLE unrelated(a)", "DROP TABLE unrelated", "VACUUM"}) {
    EXPECT_EQ(db.value("SELECT loci_check('t')"), "ok");
    EXPECT_EQ(db.value("SELECT loci_check('f')"), "ok");
    other("s.db", change);
    EXPECT_EQ(db.value("SELECT loci_check('t')"), "ok") << change;
    other("s.db", std::string(change) == "VACUUM" ? "CREATE TABLE again(a)" : "VACUUM");
    EXPECT_EQ(db.value("SELECT loci_check('f')"), "ok") << change;
    EXPECT_EQ(db.value("SELECT id FROM loci_nearest('t', 5, 5, 1)"), "1") << change;
    db.exec("DROP TABLE IF EXISTS again");
  }
  other("s.db", "DROP TABLE t");
  EXPECT_NE(db.error_of("SELECT loci_check('t')").find("loci_check: no such table: t"),
            std::string::npos)
      << db.error_of("SELECT loci_check('t')");
  // In an attached database, rows another connection commits are seen by the functions, and
  // its schema changes too.
  db.exec("ATTACH '" + dir.file("a.db") +
          "' AS a; CREATE VIRTUAL TABLE a.u USING loci_rtree(id, minx, maxx, miny, maxy);"
          "CREATE VIRTUAL TABLE a.g USING loci_fleet(id, t, x, y, vx, vy);"
          "INSERT INTO a.u VALUES (1, 0, 0, 0, 0); INSERT INTO a.g VALUES (1, 0, 0, 0, 0, 0)");
  EXPECT_EQ(db.rows("SELECT id, distance FROM loci_nearest('a.u', 0, 0, 10)"),
            (std::vector<Row>{{"1", "0"}}));
  EXPECT_EQ(db.rows("SELECT id FROM loci_fleet_window('a.g', -1, -1, 1, 1, 0)"),
            (std::vector<Row>{{"1"}}));
  other("a.db",
        "INSERT INTO u VALUES (2, 3, 3, 4, 4); DELETE FROM u WHERE id = 1;"
        "INSERT INTO g VALUES (2, 0, 0.5, 0.5, 0, 0); DELETE FROM g WHERE id = 1");
  EXPECT_EQ(db.rows("SELECT id, distance FROM loci_nearest('a.u', 0, 0, 10)"),
            (std::vector<Row>{{"2", "5"}}));
  EXPECT_EQ(db.rows("SELECT id FROM loci_fleet_window('a.g', -1, -1, 1, 1, 0)"),
            (std::vector<Row>{{"2"}}));
  EXPECT_EQ(db.rows("SELECT id FROM loci_fleet_nearest('a.g', 0, 0, 5)"),
            (std::vector<Row>{{"2"}}));
  other("a.db", "CREATE TABLE unrelated(a)");
  EXPECT_EQ(db.value("SELECT loci_check('a.u')"), "ok");
  EXPECT_EQ(db.rows("SELECT id FROM loci_nearest('a.u', 0, 0, 10)"), (std::vector<Row>{{"2"}}));
  other("a.db",
        "DROP TABLE u; CREATE VIRTUAL TABLE u USING loci_rtree(id, minx, maxx, miny, maxy);"
        "INSERT INTO u VALUES (7, 1, 1, 1, 1)");
  EXPECT_EQ(db.rows("SELECT id FROM loci_nearest('a.u', 0, 0, 10)"), (std::vector<Row>{{"7"}}));
  EXPECT_EQ(db.value("SELECT loci_check('a.u')"), "ok");
  // Only the table's own database is read: another one, attached and locked by another
  // connection, does not stand in the way.
  db.exec("ATTACH '" + dir.file("b.db") + "' AS b; CREATE TABLE b.x(v)");
  {
    Db locker(dir.file("b.db"));
    locker.exec("BEGIN EXCLUSIVE; INSERT INTO x VALUES (1)");
    EXPECT_EQ(db.rows("SELECT id FROM loci_fleet_window('f', -1, -1, 1, 1, 0)"),
              (std::vector<Row>{{"1"}}));
    EXPECT_EQ(db.rows("SELECT id FROM loci_nearest('a.u', 0, 0, 10)"), (std::vector<Row>{{"7"}}));
    EXPECT_EQ(db.value("SELECT loci_check('f')"), "ok");
    locker.exec("COMMIT");
  }
}

// A writer killed with SIGKILL in the middle of its transactions (including the repack at
// commit) leaves database and index consistent: SQLite's journal puts the shadow tables back.
TEST(SqliteRtreeSql, AWriterKilledMidTransactionLeavesItConsistent) {
  TempDir dir;
  const std::string path = dir.file("k.db");
  {
    Db db(path);
    make_tables(db, loci::test::make_boxes<2>(loci::test::Shape::uniform, 2000, 6));
  }
  for (int round = 0; round < 4; ++round) {
    const auto transaction = [&](int i) {
      const std::string base = std::to_string(100000 + (round * 1000 + i) * 10000);
      return "BEGIN;"
             "INSERT INTO t SELECT value + " +
             base +
             ", value % 1000, value % 1000 + 1, value % "
             "777, value % 777 + 1 FROM nums WHERE value <= 5000;"
             "INSERT INTO m SELECT value + " +
             base +
             ", value % 1000, value % 1000 + 1, value % "
             "777, value % 777 + 1 FROM nums WHERE value <= 5000;"
             "DELETE FROM t WHERE id % 7 = " +
             std::to_string(i % 7) + "; DELETE FROM m WHERE id % 7 = " + std::to_string(i % 7) +
             "; COMMIT;";
    };
    ASSERT_TRUE(loci::test::kill_a_writer(path, transaction, useconds_t(60000 + round * 45000)))
        << "the writer stopped by itself";
    Db db(path);
    ASSERT_EQ(db.value("SELECT loci_check('t')"), "ok") << "round " << round;
    ASSERT_EQ(all(db, "t"), all(db, "m")) << "round " << round;
  }
}

TEST(SqliteRtreeSql, BadInputIsAnSqlErrorWithAClearMessage) {
  Db db;
  EXPECT_NE(db.try_exec("CREATE VIRTUAL TABLE a USING loci_rtree(id, minx, maxx)")
                .find("expected (id, minx, maxx, miny, maxy"),
            std::string::npos);
  EXPECT_NE(db.try_exec("CREATE VIRTUAL TABLE a USING loci_rtree(id, x0, x1, y0, y1, z0, z1)")
                .find("2-dimensional"),
            std::string::npos);
  EXPECT_NE(
      db.try_exec("CREATE VIRTUAL TABLE a USING loci_rtree(id, x0, +a, x1, y0, y1)").find("+aux"),
      std::string::npos);
  db.exec("CREATE VIRTUAL TABLE t USING loci_rtree(id, minx, maxx, miny, maxy)");
  EXPECT_NE(db.try_exec("INSERT INTO t VALUES (1, NULL, 1, 0, 1)").find("minx is NULL"),
            std::string::npos);
  EXPECT_NE(db.try_exec("INSERT INTO t VALUES (1, 0, 'abc', 0, 1)").find("maxx is not a number"),
            std::string::npos);
  EXPECT_NE(db.try_exec("INSERT INTO t VALUES (1, 0, 1e999, 0, 1)").find("not finite"),
            std::string::npos);
  EXPECT_NE(db.try_exec("INSERT INTO t VALUES (1, 0, 1, 0, 2e150)").find("maxy is beyond 1e150"),
            std::string::npos);
  EXPECT_NE(db.try_exec("INSERT INTO t VALUES (1, 2, 1, 0, 1)").find("minx > maxx"),
            std::string::npos);
  EXPECT_NE(db.try_exec("INSERT INTO t VALUES ('x', 0, 1, 0, 1)").find("id must be an integer"),
            std::string::npos);
  {  // NaN bound from C arrives as NULL
    sqlite3_stmt* s = nullptr;
    sqlite3_prepare_v2(db.get(), "INSERT INTO t VALUES (1, ?, 1, 0, 1)", -1, &s, nullptr);
    sqlite3_bind_double(s, 1, std::nan(""));
    EXPECT_NE(sqlite3_step(s), SQLITE_DONE);
    sqlite3_finalize(s);
  }
  db.exec("INSERT INTO t VALUES (1, 0, 1, 0, 1)");
  EXPECT_NE(db.try_exec("INSERT INTO t VALUES (1, 0, 1, 0, 1)").find("UNIQUE constraint failed"),
            std::string::npos);
  // A failed statement in a transaction leaves the rows it had written undone.
  db.exec("BEGIN");
  EXPECT_NE(db.try_exec("INSERT INTO t VALUES (2, 0, 1, 0, 1), (3, 0, 1, 0, 1), (1, 0, 1, 0, 1)"),
            "");
  EXPECT_EQ(db.value("SELECT count(*) FROM t"), "1");
  db.exec("COMMIT");
  EXPECT_EQ(db.value("SELECT count(*) FROM t"), "1");
  EXPECT_EQ(db.value("SELECT loci_check('t')"), "ok");

  EXPECT_NE(db.error_of("SELECT * FROM loci_nearest('nosuch', 0, 0, 1)").find("no such table"),
            std::string::npos);
  db.exec("CREATE TABLE plain(a)");
  EXPECT_NE(
      db.error_of("SELECT * FROM loci_nearest('plain', 0, 0, 1)").find("not a loci_rtree table"),
      std::string::npos);
  EXPECT_NE(db.error_of("SELECT * FROM loci_nearest('t', NULL, 0, 1)").find("x is NULL"),
            std::string::npos);
  EXPECT_NE(db.error_of("SELECT * FROM loci_nearest('t', 0, -1e200, 1)").find("y is beyond 1e150"),
            std::string::npos);
  // Windows compare without squaring: any finite bound is fine.
  EXPECT_EQ(db.value("SELECT count(*) FROM t WHERE minx <= 1e300 AND maxx >= -1e300"), "1");
  EXPECT_NE(db.error_of("SELECT * FROM loci_nearest('t', 0, 0, -1)").find("k must be"),
            std::string::npos);
  EXPECT_NE(db.error_of("SELECT * FROM loci_nearest('t', 0, 0)").find("four arguments"),
            std::string::npos);
  EXPECT_NE(db.error_of("SELECT * FROM loci_nearest WHERE arg_table = 't' AND arg_x > 0 AND "
                        "arg_y = 0 AND arg_k = 1")
                .find("takes = or IN only"),
            std::string::npos);
  EXPECT_EQ(db.error_of("SELECT * FROM loci_nearest('t', 0, 0)").find("= or IN"),
            std::string::npos);
  EXPECT_NE(db.error_of("SELECT loci_check('nosuch')").find("no such table"), std::string::npos);
}

TEST(SqliteRtreeSql, CorruptShadowTablesAreReportedNotTrusted) {
  TempDir dir;
  const std::string path = dir.file("c.db");
  {
    Db db(path);
    make_tables(db, loci::test::make_boxes<2>(loci::test::Shape::uniform, 5000, 8));
    db.exec("UPDATE t_node SET data = substr(data, 1, 1000) WHERE n = 1");
  }
  {
    Db db(path);
    // The messages name the table's shadow tables ("t_node"), not their pattern ("%_node").
    const std::string error = db.error_of("SELECT count(*) FROM t");
    EXPECT_NE(error.find("loci_rtree t: the stored index is corrupt: the t_node payload"),
              std::string::npos)
        << error;
    EXPECT_NE(db.value("SELECT loci_check('t')"), "ok");
  }
  {
    Db db(path);
    db.exec("DELETE FROM t_node WHERE n = 1; INSERT INTO t_node VALUES (1, zeroblob(1048576))");
    EXPECT_NE(db.error_of("SELECT count(*) FROM t").find("corrupt"), std::string::npos);
  }
  {
    Db db(path);
    db.exec("DELETE FROM t_node; INSERT INTO t_delta VALUES (5, 2, 1, 0, 0)");
    EXPECT_NE(db.error_of("SELECT count(*) FROM t").find("corrupt"), std::string::npos);
  }
  // %_meta: its format and its generation (without which other connections' changes would go
  // unnoticed) are checked, and a query refuses a table whose generation is gone; a delta box
  // no write would store (beyond 1e150) is refused too. loci_check said ok to each.
  const auto fresh = [&](const std::string& damage) {
    {
      Db db(path);
      db.exec("DROP TABLE IF EXISTS t");
      db.exec("CREATE VIRTUAL TABLE t USING loci_rtree(id, minx, maxx, miny, maxy)");
      db.exec("INSERT INTO t VALUES (1, 0, 1, 0, 1)");
      db.exec(damage);
    }
    return std::make_unique<Db>(path);
  };
  EXPECT_EQ(fresh("DELETE FROM t_meta")->value("SELECT loci_check('t')"), "t_meta has no format");
  EXPECT_EQ(fresh("DELETE FROM t_meta WHERE k = 'generation'")->value("SELECT loci_check('t')"),
            "t_meta has no generation");
  EXPECT_EQ(fresh("UPDATE t_meta SET v = 99 WHERE k = 'format'")->value("SELECT loci_check('t')"),
            "t_meta holds format 99, not 1");
  EXPECT_EQ(
      fresh("UPDATE t_meta SET v = 'x' WHERE k = 'generation'")->value("SELECT loci_check('t')"),
      "t_meta holds generation 'x', not a whole number >= 0");
  EXPECT_NE(fresh("DELETE FROM t_meta WHERE k = 'generation'")
                ->error_of("SELECT count(*) FROM t")
                .find("the stored index is corrupt: t_meta has no generation"),
            std::string::npos);
  EXPECT_EQ(fresh("UPDATE t_delta SET maxx = 1e200")->value("SELECT loci_check('t')"),
            "t_delta holds a box no write would store (id 1)");
}

// The functions find a table by name as SQL finds it in FROM: temp, then main, then the
// attached databases in the order attached; "schema.table" in that schema, whichever tables
// the connection has already opened. Two tables called t (in main and in an attached
// database, then one in temp too) were mixed up: the bare name answered from the one opened
// first, and "aux.t" was refused once main's t was open.
TEST(SqliteRtreeSql, FunctionsFindTablesAsSqlDoes) {
  TempDir dir;
  {
    Db setup(dir.file("main.db"));
    setup.exec("ATTACH '" + dir.file("aux.db") + "' AS aux");
    for (const char* schema : {"main", "aux"}) {
      const std::string id = std::string(schema) == "main" ? "1" : "2";
      setup.exec(std::string("CREATE VIRTUAL TABLE ") + schema +
                 ".t USING loci_rtree(id, minx, maxx, miny, maxy)");
      setup.exec(std::string("INSERT INTO ") + schema + ".t VALUES (" + id + ", 0, 1, 0, 1)");
      setup.exec(std::string("CREATE VIRTUAL TABLE ") + schema +
                 ".f USING loci_fleet(id, t, x, y, vx, vy)");
      setup.exec(std::string("INSERT INTO ") + schema + ".f VALUES (" + id + ", 0, 0, 0, 0, 0)");
    }
  }
  for (const bool aux_first : {true, false}) {
    Db db(dir.file("main.db"));
    db.exec("ATTACH '" + dir.file("aux.db") + "' AS aux");
    const auto nearest = [&](const char* name) {
      return db.value(std::string("SELECT id FROM loci_nearest('") + name + "', 0, 0, 5)");
    };
    const auto window = [&](const char* name) {
      return db.value(std::string("SELECT id FROM loci_fleet_window('") + name +
                      "', -1, -1, 1, 1, 0)");
    };
    if (aux_first) {
      EXPECT_EQ(nearest("aux.t"), "2");
      EXPECT_EQ(window("aux.f"), "2");
    }
    EXPECT_EQ(nearest("t"), "1") << aux_first;
    EXPECT_EQ(window("f"), "1") << aux_first;
    EXPECT_EQ(db.value("SELECT id FROM t"), "1");
    EXPECT_EQ(nearest("aux.t"), "2") << aux_first;
    EXPECT_EQ(nearest("MAIN.T"), "1");
    EXPECT_EQ(window("aux.f"), "2") << aux_first;
    EXPECT_EQ(db.value("SELECT loci_check('aux.t')"), "ok");
    EXPECT_EQ(db.value("SELECT loci_check('t')"), "ok");
    // A table in temp comes first, as in FROM.
    db.exec("CREATE VIRTUAL TABLE temp.t USING loci_rtree(id, minx, maxx, miny, maxy)");
    db.exec("INSERT INTO temp.t VALUES (7, 0, 1, 0, 1)");
    EXPECT_EQ(db.value("SELECT id FROM t"), "7");
    EXPECT_EQ(nearest("t"), "7");
    EXPECT_EQ(nearest("main.t"), "1");
    // Quoted as in SQL (they were "no such table").
    EXPECT_EQ(nearest("\"main\".\"t\""), "1");
    EXPECT_EQ(nearest("[aux].`t`"), "2");
    EXPECT_EQ(nearest("\"t\""), "7");
    EXPECT_EQ(window("\"aux\".\"f\""), "2");
    EXPECT_EQ(nearest("main.\"t\""), "1");
    EXPECT_EQ(nearest("\"aux\".t"), "2");
    EXPECT_NE(
        db.error_of("SELECT * FROM loci_nearest('\"main\".\"t', 0, 0, 1)").find("no such table"),
        std::string::npos);
    EXPECT_NE(db.error_of("SELECT * FROM loci_nearest('nosuch.t', 0, 0, 1)")
                  .find("loci_nearest: no such table: nosuch.t"),
              std::string::npos);
  }
}

// A table written, renamed and written again inside one transaction: the functions read the
// table as it is, not the object SQLite keeps for the old name until the transaction ends.
TEST(SqliteRtreeSql, FunctionsFollowARenameInsideATransaction) {
  Db db;
  db.exec("CREATE VIRTUAL TABLE t USING loci_rtree(id, minx, maxx, miny, maxy)");
  db.exec("INSERT INTO t VALUES (1, 0, 0, 0, 0)");
  db.exec("CREATE VIRTUAL TABLE f USING loci_fleet(id, t, x, y, vx, vy)");
  db.exec("INSERT INTO f VALUES (1, 0, 0, 0, 0, 0)");
  db.exec("BEGIN");
  db.exec("INSERT INTO t VALUES (2, 0, 0, 0, 0)");
  db.exec("ALTER TABLE t RENAME TO u");
  db.exec("INSERT INTO u VALUES (3, 0, 0, 0, 0)");
  db.exec("DELETE FROM u WHERE id = 1");
  const char* nearest =
      "SELECT group_concat(id) FROM (SELECT id FROM loci_nearest('u', 0, 0, 5) "
      "ORDER BY id)";
  EXPECT_EQ(db.value(nearest), "2,3");
  EXPECT_EQ(db.value("SELECT loci_check('u')"), "ok");
  db.exec("INSERT INTO f VALUES (2, 0, 5, 0, 0, 0)");
  db.exec("ALTER TABLE f RENAME TO g");
  db.exec("INSERT INTO g VALUES (3, 0, 8, 0, 0, 0)");
  EXPECT_EQ(db.value("SELECT group_concat(id) FROM (SELECT id FROM "
                     "loci_fleet_window('g', -10, -10, 10, 10, 0) ORDER BY id)"),
            "1,2,3");
  EXPECT_EQ(db.value("SELECT count(*) FROM loci_conflicts('g', 10, 0)"), "3");
  EXPECT_EQ(db.value("SELECT id FROM loci_fleet_nearest('g', 8, 0, 1)"), "3");
  EXPECT_EQ(db.value("SELECT loci_check('g')"), "ok");
  db.exec("COMMIT");
  EXPECT_EQ(db.value(nearest), "2,3");
  EXPECT_EQ(db.value("SELECT count(*) FROM loci_conflicts('g', 10, 0)"), "3");
}

// A table whose shadow table is gone (dropped by hand) is reported as corrupt, naming that
// table, by every statement that reads or writes it and by loci_check; DROP TABLE still
// removes what is left of it, and the name can then be used again.
TEST(SqliteRtreeSql, AMissingShadowTableIsNamedAndTheTableCanBeDropped) {
  for (const char* gone : {"t_node", "t_delta", "t_dead", "t_meta", "t_aux"}) {
    SCOPED_TRACE(gone);
    TempDir dir;
    {
      Db db(dir.file("s.db"));
      db.exec("CREATE VIRTUAL TABLE t USING loci_rtree(id, minx, maxx, miny, maxy, +name)");
      db.exec("INSERT INTO t VALUES (1, 0, 0, 0, 0, 'a')");
      db.exec(std::string("DROP TABLE ") + gone);
    }
    const std::string corrupt =
        std::string("loci_rtree t: the stored index is corrupt: ") + gone + " is missing";
    {
      // Dropped by the connection that has the table connected: loci_check says the same.
      Db db(dir.file("same.db"));
      db.exec("CREATE VIRTUAL TABLE t USING loci_rtree(id, minx, maxx, miny, maxy, +name)");
      db.exec("INSERT INTO t VALUES (1, 0, 0, 0, 0, 'a')");
      EXPECT_EQ(db.value("SELECT loci_check('t')"), "ok");
      db.exec(std::string("DROP TABLE ") + gone);
      EXPECT_NE(db.value("SELECT loci_check('t')").find(corrupt), std::string::npos)
          << db.value("SELECT loci_check('t')");
    }
    Db db(dir.file("s.db"));
    EXPECT_NE(db.value("SELECT loci_check('t')").find(corrupt), std::string::npos)
        << db.value("SELECT loci_check('t')");
    for (const char* sql : {"SELECT * FROM loci_nearest('t', 0, 0, 1)", "SELECT count(*) FROM t",
                            "SELECT id FROM t WHERE minx <= 1 AND maxx >= -1",
                            "INSERT INTO t VALUES (2, 0, 1, 0, 1, 'b')", "DELETE FROM t",
                            "ALTER TABLE t RENAME TO u"})
      EXPECT_NE(db.error_of(sql).find(corrupt), std::string::npos)
          << sql << ": " << db.error_of(sql);
    EXPECT_EQ(db.try_exec("DROP TABLE t"), "");
    EXPECT_EQ(db.value("SELECT count(*) FROM sqlite_schema WHERE name LIKE 't%'"), "0");
    db.exec("CREATE VIRTUAL TABLE t USING loci_rtree(id, minx, maxx, miny, maxy)");
    db.exec("INSERT INTO t VALUES (7, 0, 1, 0, 1)");
    EXPECT_EQ(db.value("SELECT id FROM t WHERE minx <= 0.5 AND maxx >= 0.5"), "7");
    EXPECT_EQ(db.value("SELECT loci_check('t')"), "ok");
  }
}

// A base stored with its items in builder order (as the first versions of the extension wrote
// it) answers like one numbered in packed order: the stored payload is renumbered by a random
// permutation, item slots and ids together, so it holds the same rows.
TEST(SqliteRtreeSql, ABaseStoredInBuilderOrderAnswersTheSame) {
  using Packed = loci::PackedRTree<2, 16>;
  TempDir dir;
  const std::string path = dir.file("o.db");
  const auto boxes = loci::test::make_boxes<2>(loci::test::Shape::clustered, 5000, 12);
  std::vector<Row> before;
  {
    Db db(path);
    make_tables(db, boxes);
    before = all(db, "t");
  }
  {
    Db raw(path, false);
    std::vector<std::string> chunks;
    for (const Row& r : raw.rows("SELECT hex(data) FROM t_node ORDER BY n")) {
      std::string bytes;
      for (std::size_t i = 0; i + 1 < r[0].size(); i += 2)
        bytes += char(std::stoi(r[0].substr(i, 2), nullptr, 16));
      chunks.push_back(bytes);
    }
    ASSERT_GE(chunks.size(), 2u);
    std::uint64_t n = 0;
    std::memcpy(&n, chunks[0].data() + 16, sizeof n);
    ASSERT_EQ(n, boxes.size());
    std::string payload;
    for (std::size_t c = 1; c < chunks.size(); ++c)
      payload += chunks[c];
    const std::size_t items_at = Packed::block_count(n) * sizeof(Packed::Block);
    const std::size_t ids_at = items_at + Packed::layout(n)[0].blocks * 16 * sizeof(std::uint32_t);
    std::vector<std::uint32_t> perm(n);
    for (std::uint32_t i = 0; i < n; ++i)
      perm[i] = i;
    std::shuffle(perm.begin(), perm.end(), std::mt19937_64(5));
    std::vector<std::int64_t> ids(n), moved(n);
    std::memcpy(ids.data(), payload.data() + ids_at, n * sizeof(std::int64_t));
    for (std::size_t pos = 0; pos < n; ++pos) {
      std::uint32_t item = 0;
      std::memcpy(&item, payload.data() + items_at + pos * 4, 4);
      ASSERT_EQ(item, pos);  // as written today
      std::memcpy(payload.data() + items_at + pos * 4, &perm[pos], 4);
      moved[perm[pos]] = ids[pos];
    }
    std::memcpy(payload.data() + ids_at, moved.data(), n * sizeof(std::int64_t));
    std::size_t at = 0;
    for (std::size_t c = 1; c < chunks.size(); ++c) {
      sqlite3_stmt* s = nullptr;
      sqlite3_prepare_v2(raw.get(), "UPDATE t_node SET data = ? WHERE n = ?", -1, &s, nullptr);
      sqlite3_bind_blob(s, 1, payload.data() + at, int(chunks[c].size()), SQLITE_TRANSIENT);
      sqlite3_bind_int64(s, 2, sqlite3_int64(c));
      ASSERT_EQ(sqlite3_step(s), SQLITE_DONE);
      sqlite3_finalize(s);
      at += chunks[c].size();
    }
  }
  Db db(path);
  EXPECT_EQ(db.value("SELECT loci_check('t')"), "ok");
  EXPECT_EQ(all(db, "t"), before);
  std::mt19937_64 rng(6);
  for (int q = 0; q < 200; ++q) {
    const std::string where = random_where(rng, boxes);
    ASSERT_EQ(ids(db, "t", where), ids(db, "m", where)) << where;
  }
  EXPECT_EQ(db.value("SELECT count(*) FROM loci_nearest('t', 500, 500, 7)"), "7");
  // A write and a reopen keep it whole.
  db.exec("DELETE FROM t WHERE id % 3 = 0; DELETE FROM m WHERE id % 3 = 0");
  const std::string where = "minx <= 700 AND maxx >= 300 AND miny <= 700 AND maxy >= 300";
  EXPECT_EQ(ids(db, "t", where), ids(db, "m", where));
  Db again(path);
  EXPECT_EQ(all(again, "t"), all(again, "m"));
  EXPECT_EQ(again.value("SELECT loci_check('t')"), "ok");
}

#ifdef LOCI_HAVE_IO
// Real boxes: every segment of the bundled coastline sample.
TEST(SqliteRtreeSql, BundledSampleSegmentsMatchBruteForce) {
  const auto segs = loci::io::read_segments(std::string(LOCI_DATASETS_DIR) +
                                            "/samples/coastline-denmark.geojson");
  ASSERT_GT(segs.size(), 1000u);
  std::vector<Box<2>> boxes;
  for (const auto& s : segs)
    boxes.push_back(s.segment.box());
  Db db;
  make_tables(db, boxes, true);
  std::mt19937_64 rng(21);
  for (int q = 0; q < 200; ++q) {
    const auto& b = boxes[rng() % boxes.size()];
    const double w = 0.01 * double(1 + rng() % 30);
    const std::string where = "minx <= " + real(b.max[0] + w) + " AND maxx >= " + real(b.min[0]) +
                              " AND miny <= " + real(b.max[1] + w) +
                              " AND maxy >= " + real(std::nextafter(b.max[1], INFINITY));
    const auto exact = ids(db, "m", where);
    ASSERT_EQ(ids(db, "t", where), exact) << where;
    // SQLite's rtree holds every exact row (and may add false hits).
    const auto rtree = ids(db, "r", where);
    for (const auto& row : exact)
      ASSERT_TRUE(std::find(rtree.begin(), rtree.end(), row) != rtree.end()) << where;
  }
  // Windows a hair beyond a segment's corner: the rtree's float32 boxes report the segment,
  // loci does not.
  EXPECT_GT(hair_beyond_corners(db, boxes, 0.01), 50u);
  // Nearest-10 against brute force over the boxes, nearest first.
  for (const auto& [px, py] : {std::pair{10.5, 55.5}, {8.0, 57.0}, {12.6, 55.7}, {11.0, 54.0}}) {
    const double x = px, y = py;  // named, not bound: the lambda captures them
    const auto distance = [x, y](const Box<2>& b) {
      const double dx = std::max({b.min[0] - x, 0.0, x - b.max[0]});
      const double dy = std::max({b.min[1] - y, 0.0, y - b.max[1]});
      return std::sqrt(dx * dx + dy * dy);
    };
    std::vector<double> brute;
    for (const auto& b : boxes)
      brute.push_back(distance(b));
    std::sort(brute.begin(), brute.end());
    const auto near =
        db.rows("SELECT id, distance FROM loci_nearest('t', " + real(x) + ", " + real(y) + ", 10)");
    ASSERT_EQ(near.size(), 10u);
    for (std::size_t i = 0; i < near.size(); ++i) {
      EXPECT_EQ(near[i][1], real(brute[i])) << x << ',' << y << " rank " << i;
      const auto& b = boxes[std::stoul(near[i][0]) - 1];
      EXPECT_EQ(near[i][1], real(distance(b)));
    }
  }
}
#endif

}  // namespace
