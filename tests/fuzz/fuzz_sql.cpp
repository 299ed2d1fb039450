// Fuzz target: SQL against a database with the loci extension registered. The input is read as
// a program: each byte picks a statement (insert, update, delete, window query, nearest,
// transaction control, loci_check, or raw SQL text from the input), later bytes its values,
// among them the awkward ones (NULL, text, blobs, 1e999, integers past 2^53, inverted boxes).
// Every write goes to the loci_rtree t and a plain table m alike; every query must answer as m
// does (windows through SQL on m, nearest-n against every row of m by brute force) and
// loci_check must say ok, until raw SQL has run (it may touch either table alone).
// Fleet statements do the same with the loci_fleet f and a plain table of reports p: reports
// inserted and objects deleted on both, windows at any time (before the latest report too)
// through loci_fleet_window against the same question in SQL over p, conflicts and nearest with
// awkward arguments, and f's current states against p's latest report of each id.
// SQL errors are expected; a crash, a sanitizer report or a disagreement is a finding.
#include <sqlite3.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "loci/sqlite/loci_sqlite.h"

namespace {

struct Input {
  const std::uint8_t* p;
  std::size_t n;
  std::uint8_t byte() {
    if (n == 0) return 0;
    --n;
    return *p++;
  }
  bool done() const { return n == 0; }
};

std::string value(Input& in) {
  const std::uint8_t b = in.byte();
  switch (b % 16) {
    case 0:
      return "NULL";
    case 1:
      return "'abc'";
    case 2:
      return "x'00ff'";
    case 3:
      return "1e999";
    case 4:
      return "-1e999";
    case 5:
      return "9007199254740993";
    case 6:
      return "'" + std::to_string(b) + "'";
    case 7:
      return std::to_string(int(in.byte()) - 128) + ".5";
    default:
      return std::to_string(int(in.byte()) - 128);
  }
}

std::vector<std::vector<std::string>> rows(sqlite3* db, const std::string& sql, bool& ok) {
  std::vector<std::vector<std::string>> out;
  sqlite3_stmt* s = nullptr;
  ok = sqlite3_prepare_v2(db, sql.c_str(), -1, &s, nullptr) == SQLITE_OK;
  if (!ok) return out;
  int rc;
  while ((rc = sqlite3_step(s)) == SQLITE_ROW) {
    std::vector<std::string> r;
    for (int i = 0; i < sqlite3_column_count(s); ++i) {
      const unsigned char* t = sqlite3_column_text(s, i);
      r.push_back(t ? reinterpret_cast<const char*>(t) : "NULL");
    }
    out.push_back(std::move(r));
  }
  ok = rc == SQLITE_DONE;
  sqlite3_finalize(s);
  return out;
}

// The rows of a query as doubles (ids too: they stay below 64 here).
std::vector<std::vector<double>> numbers(sqlite3* db, const std::string& sql, bool& ok) {
  std::vector<std::vector<double>> out;
  sqlite3_stmt* s = nullptr;
  ok = sqlite3_prepare_v2(db, sql.c_str(), -1, &s, nullptr) == SQLITE_OK;
  if (!ok) return out;
  int rc;
  while ((rc = sqlite3_step(s)) == SQLITE_ROW) {
    std::vector<double> r;
    for (int i = 0; i < sqlite3_column_count(s); ++i)
      r.push_back(sqlite3_column_double(s, i));
    out.push_back(std::move(r));
  }
  ok = rc == SQLITE_DONE;
  sqlite3_finalize(s);
  return out;
}

[[noreturn]] void finding(const std::string& what) {
  std::fprintf(stderr, "fuzz_sql: %s\n", what.c_str());
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  sqlite3* db = nullptr;
  sqlite3_open(":memory:", &db);
  sqlite3_loci_init(db, nullptr, nullptr);
  sqlite3_exec(db,
               "CREATE VIRTUAL TABLE t USING loci_rtree(id, minx, maxx, miny, maxy, +tag);"
               "CREATE TABLE m(id INTEGER PRIMARY KEY, minx REAL, maxx REAL, miny REAL, maxy "
               "REAL, tag);"
               "CREATE VIRTUAL TABLE f USING loci_fleet(id, t, x, y, vx, vy);"
               "CREATE TABLE p(id INTEGER, t REAL, x REAL, y REAL, vx REAL, vy REAL, "
               "PRIMARY KEY(id, t)) WITHOUT ROWID;",
               nullptr, nullptr, nullptr);
  Input in{data, size};
  bool mirrored = true, fleet_mirrored = true;
  static const char* cols[] = {"minx", "maxx", "miny", "maxy", "id"};
  static const char* ops[] = {"<", "<=", ">", ">=", "="};
  while (!in.done()) {
    const std::uint8_t op = in.byte();
    std::string sql;  // run on t and m (or f and p), with $T for the table
    bool fleet = false;
    switch (op % 16) {
      case 0:
      case 1: {
        const std::string x = std::to_string(int(in.byte()) - 128),
                          y = std::to_string(int(in.byte()) - 128);
        const std::string w = std::to_string(in.byte() % 8), h = std::to_string(in.byte() % 8);
        sql = "INSERT OR " + std::string(op % 2 ? "REPLACE" : "IGNORE") + " INTO $T VALUES(" +
              std::to_string(in.byte() % 64) + ", " + x + ", " + x + " + " + w + ", " + y + ", " +
              y + " + " + h + ", " + value(in) + ")";
        break;
      }
      case 2:  // awkward values, usually refused
        sql = "INSERT INTO $T VALUES(" + value(in) + ", " + value(in) + ", " + value(in) + ", " +
              value(in) + ", " + value(in) + ", NULL)";
        break;
      case 3:
        sql = "UPDATE $T SET " + std::string(cols[in.byte() % 5]) + " = " + value(in) +
              " WHERE id % 7 = " + std::to_string(in.byte() % 7);
        break;
      case 4:
        sql = "DELETE FROM $T WHERE " + std::string(cols[in.byte() % 5]) + " " +
              ops[in.byte() % 5] + " " + value(in);
        break;
      case 5: {
        std::string where;
        for (int i = 0, n = 1 + in.byte() % 4; i < n; ++i)
          where += (i ? " AND " : "") + std::string(cols[in.byte() % 5]) + " " +
                   ops[in.byte() % 5] + " " + value(in);
        if (mirrored) {
          bool ok1, ok2;
          const auto a = rows(db, "SELECT id, tag FROM t WHERE " + where + " ORDER BY id", ok1);
          const auto b = rows(db, "SELECT id, tag FROM m WHERE " + where + " ORDER BY id", ok2);
          if (ok1 && ok2 && a != b) finding("t and m disagree on " + where);
        }
        continue;
      }
      case 6: {
        bool ok;
        rows(db,
             "SELECT * FROM loci_nearest('t', " + value(in) + ", " + value(in) + ", " + value(in) +
                 ")",
             ok);
        continue;
      }
      case 10: {  // nearest-n checked against every row of m: the same distances, in order
        const double x = int(in.byte()) - 128 + (in.byte() % 2 ? 0.5 : 0.0);
        const double y = int(in.byte()) - 128;
        const std::size_t k = in.byte() % 40;
        if (!mirrored) continue;
        bool ok1, ok2;
        const auto got = numbers(db,
                                 "SELECT id, distance FROM loci_nearest('t', " + std::to_string(x) +
                                     ", " + std::to_string(y) + ", " + std::to_string(k) + ")",
                                 ok1);
        const auto all = numbers(db, "SELECT id, minx, maxx, miny, maxy FROM m", ok2);
        if (!ok1 || !ok2) continue;
        std::vector<std::pair<double, double>> brute;  // (distance, id)
        for (const auto& r : all) {
          const double dx = x < r[1] ? r[1] - x : x > r[2] ? x - r[2] : 0;
          const double dy = y < r[3] ? r[3] - y : y > r[4] ? y - r[4] : 0;
          brute.push_back({std::sqrt(dx * dx + dy * dy), r[0]});
        }
        std::sort(brute.begin(), brute.end());
        if (got.size() != std::min(k, brute.size()))
          finding("loci_nearest gave " + std::to_string(got.size()) +
                  " rows for k = " + std::to_string(k) + " over " + std::to_string(brute.size()));
        for (std::size_t i = 0; i < got.size(); ++i) {
          if (got[i][1] != brute[i].first)
            finding("loci_nearest rank " + std::to_string(i) + ": distance " +
                    std::to_string(got[i][1]) + ", brute force " + std::to_string(brute[i].first));
          // Ties may come in any order: an id must at least lie at its stated distance.
          bool found = false;
          for (const auto& [d, id] : brute)
            found |= id == got[i][0] && d == got[i][1];
          if (!found) finding("loci_nearest: id " + std::to_string(got[i][0]) + " misplaced");
        }
        continue;
      }
      case 7: {
        static const char* control[] = {"BEGIN",       "COMMIT",        "ROLLBACK",
                                        "SAVEPOINT a", "ROLLBACK TO a", "RELEASE a",
                                        "SAVEPOINT b", "ROLLBACK TO b", "RELEASE b"};
        sqlite3_exec(db, control[in.byte() % 9], nullptr, nullptr, nullptr);
        continue;
      }
      case 8: {
        bool ok;
        const auto r = rows(db, "SELECT loci_check('t')", ok);
        if (ok && (r.empty() || r[0][0] != "ok"))
          finding("loci_check: " + (r.empty() ? "" : r[0][0]));
        if (mirrored) {
          const auto a = rows(db, "SELECT * FROM t ORDER BY id", ok);
          const auto b = rows(db, "SELECT * FROM m ORDER BY id", ok);
          if (a != b) finding("t and m hold different rows");
        }
        continue;
      }
      case 9: {  // raw SQL from the input
        const std::size_t len = in.byte() % 64;
        std::string text;
        for (std::size_t i = 0; i < len && !in.done(); ++i)
          text += char(in.byte());
        sqlite3_exec(db, text.c_str(), nullptr, nullptr, nullptr);
        mirrored = fleet_mirrored = false;
        continue;
      }
      case 12: {  // a report: small numbers, or an awkward value now and then
        fleet = true;
        const auto num = [&] {
          return in.byte() % 8 == 0 ? value(in) : std::to_string(int(in.byte()) - 128);
        };
        sql = "INSERT OR REPLACE INTO $T VALUES(" + std::to_string(in.byte() % 16) + ", " + num() +
              ", " + num() + ", " + num() + ", " + num() + ", " + num() + ")";
        break;
      }
      case 13:
        fleet = true;
        sql = "DELETE FROM $T WHERE id = " + std::to_string(in.byte() % 16);
        break;
      case 14: {
        const std::string x = std::to_string(int(in.byte()) - 128),
                          y = std::to_string(int(in.byte()) - 128),
                          T = std::to_string(int(in.byte()) - 128);
        const std::string x1 = x + " + " + std::to_string(in.byte() % 64),
                          y1 = y + " + " + std::to_string(in.byte() % 64);
        bool ok1, ok2;
        const auto a = rows(db,
                            "SELECT id FROM loci_fleet_window('f', " + x + ", " + y + ", " + x1 +
                                ", " + y1 + ", " + T + ")",
                            ok1);
        const auto b =
            rows(db,
                 "SELECT id FROM (SELECT id, x + vx * (" + T + " - t) AS px, y + vy * (" + T +
                     " - t) AS py FROM p r WHERE t = (SELECT max(t) FROM p WHERE id "
                     "= r.id AND t <= " +
                     T + ")) WHERE px >= " + x + " AND px <= " + x1 + " AND py >= " + y +
                     " AND py <= " + y1 + " ORDER BY id",
                 ok2);
        if (fleet_mirrored && ok1 && ok2 && a != b) finding("f and p disagree at " + T);
        continue;
      }
      case 15: {
        bool ok;
        if (in.byte() % 2)
          rows(db,
               "SELECT * FROM loci_conflicts('f', " + value(in) + ", " + value(in) + ", " +
                   value(in) + ")",
               ok);
        else
          rows(db,
               "SELECT * FROM loci_fleet_nearest('f', " + value(in) + ", " + value(in) + ", " +
                   value(in) + ", " + value(in) + ")",
               ok);
        const auto r = rows(db, "SELECT loci_check('f')", ok);
        if (ok && (r.empty() || r[0][0] != "ok"))
          finding("loci_check(f): " + (r.empty() ? "" : r[0][0]));
        if (fleet_mirrored) {
          const auto a = rows(db, "SELECT * FROM f ORDER BY id", ok);
          const auto b = rows(db,
                              "SELECT * FROM p r WHERE t = (SELECT max(t) FROM p WHERE id = r.id) "
                              "ORDER BY id",
                              ok);
          if (a != b) finding("f and p hold different current reports");
        }
        continue;
      }
      default: {
        bool ok;
        rows(db, "SELECT count(*) FROM t WHERE id = " + value(in), ok);
        continue;
      }
    }
    // Run the write on both tables; when one refuses and the other does not, they differ.
    std::string on_t = sql, on_m = sql;
    for (std::size_t p; (p = on_t.find("$T")) != std::string::npos;)
      on_t.replace(p, 2, fleet ? "f" : "t");
    for (std::size_t p; (p = on_m.find("$T")) != std::string::npos;)
      on_m.replace(p, 2, fleet ? "p" : "m");
    bool& same = fleet ? fleet_mirrored : mirrored;
    const int a = sqlite3_exec(db, on_t.c_str(), nullptr, nullptr, nullptr);
    if (a == SQLITE_OK) {
      if (sqlite3_exec(db, on_m.c_str(), nullptr, nullptr, nullptr) != SQLITE_OK) same = false;
    } else {
      same = false;  // the loci table refused a row the plain one would take: stop comparing
    }
  }
  sqlite3_close(db);
  return 0;
}
