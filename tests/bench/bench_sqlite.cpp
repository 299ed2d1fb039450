// The loci SQLite extension against SQLite's own rtree module and SpatiaLite's KNN, through
// SQL on the same SQLite library, on the boxes of real coastline segments (Natural Earth
// countries-coastline-1m, datasets/fetch.sh):
//   build    BEGIN; INSERT INTO x SELECT * FROM src; COMMIT   (loci_rtree vs rtree)
//   windows  10,000 windows of about 100 hits each, every row stepped (loci vs rtree; the rtree's
//            float32 false hits are counted, and loci's answer is checked against the exact one),
//            each query its own statement in autocommit, then all inside one read transaction
//   nearest  10,000 nearest-10 queries: loci_nearest vs SpatiaLite's KNN (mod_spatialite; the
//            VirtualKNN of Debian's SpatiaLite 5.0), distances compared
//   fleet    100,000 reports (10,000 objects x 10, epoch-second times) inserted into a loci_fleet
//            table in one transaction, and into a plain WITHOUT ROWID table of reports; windows
//            of about 100 objects at a time after the latest report and at a time before it,
//            through loci_fleet_window vs the same question as SQL over the plain table (the
//            report in force per id, positions computed in the query); loci_conflicts
// Medians of --repeat runs. Usage: bench_sqlite [--rows N] [--queries N] [--repeat N] [--no-knn]
//                                               [--fleet-only | --no-fleet]
#include <sqlite3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "loci/geom/motion.hpp"
#include "loci/index/packed_rtree.hpp"
#include "loci/io/layer_reader.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using Box2 = loci::Box<2>;

struct Options {
  std::size_t rows = 1000000;
  std::size_t queries = 10000;
  int repeat = 3;
  bool knn = true;
  bool boxes = true;
  bool fleet = true;
};

[[noreturn]] void die(const std::string& what) {
  std::fprintf(stderr, "bench_sqlite: %s\n", what.c_str());
  std::exit(1);
}

void exec(sqlite3* db, const std::string& sql) {
  char* err = nullptr;
  if (sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &err) != SQLITE_OK)
    die(sql.substr(0, 80) + ": " + (err ? err : "?"));
}

sqlite3_stmt* prepare(sqlite3* db, const std::string& sql) {
  sqlite3_stmt* s = nullptr;
  if (sqlite3_prepare_v2(db, sql.c_str(), -1, &s, nullptr) != SQLITE_OK)
    die(sql + ": " + sqlite3_errmsg(db));
  return s;
}

sqlite3* open_db(const std::string& path) {
  sqlite3* db = nullptr;
  if (sqlite3_open(path.c_str(), &db) != SQLITE_OK) die("cannot open " + path);
  sqlite3_enable_load_extension(db, 1);
  return db;
}

void load(sqlite3* db, const char* file) {
  char* err = nullptr;
  if (sqlite3_load_extension(db, file, nullptr, &err) != SQLITE_OK)
    die(std::string("cannot load ") + file + ": " + (err ? err : "?"));
}

double seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

bool meets(const Box2& b, const Box2& w) {
  return b.min[0] <= w.max[0] && b.max[0] >= w.min[0] && b.min[1] <= w.max[1] &&
         b.max[1] >= w.min[1];
}

// Runs every window through `sql`, collecting the ids of each; returns the seconds taken.
double run_windows(sqlite3* db, const char* table, const std::vector<Box2>& windows,
                   std::vector<std::vector<sqlite3_int64>>& out) {
  sqlite3_stmt* s = prepare(db, std::string("SELECT id FROM ") + table +
                                    " WHERE minx <= ?3 AND maxx >= ?1 AND miny <= ?4 AND "
                                    "maxy >= ?2");
  out.assign(windows.size(), {});
  const auto t0 = Clock::now();
  for (std::size_t q = 0; q < windows.size(); ++q) {
    const Box2& w = windows[q];
    sqlite3_bind_double(s, 1, w.min[0]);
    sqlite3_bind_double(s, 2, w.min[1]);
    sqlite3_bind_double(s, 3, w.max[0]);
    sqlite3_bind_double(s, 4, w.max[1]);
    while (sqlite3_step(s) == SQLITE_ROW)
      out[q].push_back(sqlite3_column_int64(s, 0));
    sqlite3_reset(s);
  }
  const double t = seconds(t0, Clock::now());
  sqlite3_finalize(s);
  return t;
}

struct Near {
  sqlite3_int64 id;
  double distance;
};

double run_nearest(sqlite3* db, const std::string& sql, const std::vector<loci::Point2>& points,
                   std::vector<std::vector<Near>>& out) {
  sqlite3_stmt* s = prepare(db, sql);
  out.assign(points.size(), {});
  const auto t0 = Clock::now();
  for (std::size_t q = 0; q < points.size(); ++q) {
    sqlite3_bind_double(s, 1, points[q][0]);
    sqlite3_bind_double(s, 2, points[q][1]);
    while (sqlite3_step(s) == SQLITE_ROW)
      out[q].push_back({sqlite3_column_int64(s, 0), sqlite3_column_double(s, 1)});
    sqlite3_reset(s);
  }
  const double t = seconds(t0, Clock::now());
  sqlite3_finalize(s);
  return t;
}

// Runs each window at its time through `sql` (?1..?4 the window, ?5 the time), collecting the
// ids; returns the seconds taken.
double run_fleet_windows(sqlite3* db, const std::string& sql, const std::vector<Box2>& windows,
                         const std::vector<double>& times,
                         std::vector<std::vector<sqlite3_int64>>& out) {
  sqlite3_stmt* s = prepare(db, sql);
  out.assign(windows.size(), {});
  const auto t0 = Clock::now();
  for (std::size_t q = 0; q < windows.size(); ++q) {
    sqlite3_bind_double(s, 1, windows[q].min[0]);
    sqlite3_bind_double(s, 2, windows[q].min[1]);
    sqlite3_bind_double(s, 3, windows[q].max[0]);
    sqlite3_bind_double(s, 4, windows[q].max[1]);
    sqlite3_bind_double(s, 5, times[q]);
    while (sqlite3_step(s) == SQLITE_ROW)
      out[q].push_back(sqlite3_column_int64(s, 0));
    sqlite3_reset(s);
    std::sort(out[q].begin(), out[q].end());
  }
  const double t = seconds(t0, Clock::now());
  sqlite3_finalize(s);
  return t;
}

void bench_fleet(const std::string& dir, const Options& o) {
  constexpr std::size_t kObjects = 10000, kPer = 10;
  constexpr double kT0 = 1.7e9, kSide = 100000;  // metres; 600 s of reports
  std::mt19937_64 rng(43);
  std::uniform_real_distribution<double> pos(0, kSide), vel(-12, 12), jitter(0, 60);
  struct Report {
    sqlite3_int64 id;
    loci::Motion2 m;
  };
  std::vector<Report> reports;
  for (std::size_t k = 0; k < kPer; ++k)  // in time order, as a feed delivers them
    for (std::size_t i = 0; i < kObjects; ++i)
      reports.push_back({sqlite3_int64(i + 1), loci::Motion2{kT0 + 60.0 * double(k) + jitter(rng),
                                                             {{pos(rng), pos(rng)}},
                                                             {{vel(rng), vel(rng)}}}});
  double last = 0;
  for (const Report& r : reports)
    last = std::max(last, r.m.t);
  sqlite3* db = open_db(dir + "/fleet.db");
  load(db, LOCI_SQLITE_EXTENSION);
  const auto fill = [&](const char* table) {
    exec(db, "BEGIN");
    sqlite3_stmt* s =
        prepare(db, std::string("INSERT INTO ") + table + " VALUES(?, ?, ?, ?, ?, ?)");
    for (const Report& r : reports) {
      sqlite3_bind_int64(s, 1, r.id);
      sqlite3_bind_double(s, 2, r.m.t);
      sqlite3_bind_double(s, 3, r.m.p[0]);
      sqlite3_bind_double(s, 4, r.m.p[1]);
      sqlite3_bind_double(s, 5, r.m.v[0]);
      sqlite3_bind_double(s, 6, r.m.v[1]);
      if (sqlite3_step(s) != SQLITE_DONE) die(std::string("insert: ") + sqlite3_errmsg(db));
      sqlite3_reset(s);
    }
    sqlite3_finalize(s);
    exec(db, "COMMIT");
  };
  std::vector<double> insert_fleet, insert_plain;
  for (int r = 0; r < o.repeat; ++r) {
    exec(db, "DROP TABLE IF EXISTS f; DROP TABLE IF EXISTS p;");
    exec(db, "CREATE VIRTUAL TABLE f USING loci_fleet(id, t, x, y, vx, vy)");
    exec(db,
         "CREATE TABLE p(id INTEGER, t REAL, x REAL, y REAL, vx REAL, vy REAL, PRIMARY KEY(id, "
         "t)) WITHOUT ROWID");
    auto t0 = Clock::now();
    fill("f");
    insert_fleet.push_back(seconds(t0, Clock::now()));
    t0 = Clock::now();
    fill("p");
    insert_plain.push_back(seconds(t0, Clock::now()));
  }
  const double fi = median(insert_fleet), pi = median(insert_plain);
  std::printf("\nfleet: %zu reports of %zu objects, epoch-second times over %.0f s\n",
              reports.size(), kObjects, last - kT0);
  std::printf(
      "  insert, one transaction: loci_fleet %.3f s (%.0f reports/s), plain table %.3f s, "
      "ratio %.2fx\n",
      fi, double(reports.size()) / fi, pi, pi / fi);

  // Windows of about 100 objects (10,000 in a square of side kSide: side kSide / 10).
  const std::string loci_sql = "SELECT id FROM loci_fleet_window('f', ?1, ?2, ?3, ?4, ?5)";
  const std::string plain_sql =
      "SELECT id FROM (SELECT id, x + vx * (?5 - t) AS px, y + vy * (?5 - t) AS py FROM p a "
      "WHERE t = (SELECT max(t) FROM p WHERE id = a.id AND t <= ?5)) WHERE px >= ?1 AND px <= ?3 "
      "AND py >= ?2 AND py <= ?4";
  std::uniform_real_distribution<double> corner(0, kSide * 0.9);
  for (const auto& [label, at] :
       {std::pair<const char*, double>{"after the latest report", last + 30},
        {"before it (from the history)", last - 200}}) {
    std::vector<Box2> windows(o.queries);
    for (auto& w : windows) {
      const double x = corner(rng), y = corner(rng);
      w = {{{x, y}}, {{x + kSide / 10, y + kSide / 10}}};
    }
    const std::vector<double> times(windows.size(), at);
    // The plain scan reads every report per query: a few suffice for its rate.
    const std::size_t few = std::min<std::size_t>(windows.size(), 20);
    const std::vector<Box2> some(windows.begin(), windows.begin() + std::ptrdiff_t(few));
    const std::vector<double> some_times(times.begin(), times.begin() + std::ptrdiff_t(few));
    std::vector<std::vector<sqlite3_int64>> got, plain;
    std::vector<double> tl, tp;
    const std::size_t loci_queries = at > last ? windows.size() : few;
    const std::vector<Box2> mine(windows.begin(), windows.begin() + std::ptrdiff_t(loci_queries));
    const std::vector<double> mine_times(times.begin(),
                                         times.begin() + std::ptrdiff_t(loci_queries));
    for (int r = 0; r < o.repeat; ++r) {
      tl.push_back(run_fleet_windows(db, loci_sql, mine, mine_times, got) / double(mine.size()));
      tp.push_back(run_fleet_windows(db, plain_sql, some, some_times, plain) / double(few));
    }
    std::size_t hits = 0, differ = 0;
    for (std::size_t q = 0; q < few; ++q)
      differ += got[q] != plain[q];
    for (const auto& g : got)
      hits += g.size();
    const double ql = median(tl), qp = median(tp);
    std::printf("  windows at a time %s, %.0f objects each on average:\n", label,
                double(hits) / double(got.size()));
    std::printf(
        "    loci_fleet_window %9.0f queries/s (%zu queries)\n    plain SQL scan    %9.1f "
        "queries/s (%zu queries)\n    ratio             %9.1fx   answers identical: %s\n",
        1 / ql, mine.size(), 1 / qp, few, qp / ql,
        differ == 0 ? "yes" : ("NO, " + std::to_string(differ) + " differ").c_str());
  }

  // Conflicts over the next 5 minutes within 200 m, and within 1 km.
  for (const double d : {200.0, 1000.0}) {
    std::vector<double> tc;
    std::string pairs;
    for (int r = 0; r < o.repeat; ++r) {
      const auto t0 = Clock::now();
      sqlite3_stmt* s =
          prepare(db, "SELECT count(*) FROM loci_conflicts('f', " + std::to_string(d) + ", 300)");
      if (sqlite3_step(s) != SQLITE_ROW) die(sqlite3_errmsg(db));
      pairs = reinterpret_cast<const char*>(sqlite3_column_text(s, 0));
      sqlite3_finalize(s);
      tc.push_back(seconds(t0, Clock::now()));
    }
    std::printf("  loci_conflicts('f', %.0f, 300): %s pairs among %zu objects in %.3f s\n", d,
                pairs.c_str(), kObjects, median(tc));
  }
  sqlite3_close(db);
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto next = [&] { return i + 1 < argc ? std::strtoull(argv[++i], nullptr, 10) : 0ull; };
    if (a == "--rows")
      o.rows = next();
    else if (a == "--queries")
      o.queries = next();
    else if (a == "--repeat")
      o.repeat = int(std::max(1ull, next()));
    else if (a == "--no-knn")
      o.knn = false;
    else if (a == "--fleet-only")
      o.boxes = false;
    else if (a == "--no-fleet")
      o.fleet = false;
    else
      die("usage: bench_sqlite [--rows N] [--queries N] [--repeat N] [--no-knn] "
          "[--fleet-only | --no-fleet]");
  }
  if (!o.boxes) {
    const std::string dir = std::filesystem::temp_directory_path() / "loci-bench-sqlite";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    std::printf("bench_sqlite: SQLite %s\n", sqlite3_libversion());
    bench_fleet(dir, o);
    std::filesystem::remove_all(dir);
    return 0;
  }

  const std::string layer =
      std::string(LOCI_DATASETS_DIR) + "/cache/countries-coastline-1m/map.geo.json";
  if (!std::filesystem::exists(layer)) die(layer + " is missing: run datasets/fetch.sh");
  std::vector<Box2> boxes;
  for (const auto& s : loci::io::read_segments(layer)) {
    if (boxes.size() == o.rows) break;
    boxes.push_back(s.segment.box());
  }
  std::printf("bench_sqlite: %zu coastline segment boxes, SQLite %s\n", boxes.size(),
              sqlite3_libversion());

  const std::string dir = std::filesystem::temp_directory_path() / "loci-bench-sqlite";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  sqlite3* db = open_db(dir + "/bench.db");
  load(db, LOCI_SQLITE_EXTENSION);
  exec(db, "CREATE TABLE src(id INTEGER PRIMARY KEY, minx REAL, maxx REAL, miny REAL, maxy REAL)");
  exec(db, "BEGIN");
  {
    sqlite3_stmt* s = prepare(db, "INSERT INTO src VALUES(?, ?, ?, ?, ?)");
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
  }
  exec(db, "COMMIT");

  // ---- Build ----
  std::vector<double> build_loci, build_rtree;
  for (int r = 0; r < o.repeat; ++r) {
    exec(db, "DROP TABLE IF EXISTS t; DROP TABLE IF EXISTS r;");
    exec(db, "CREATE VIRTUAL TABLE t USING loci_rtree(id, minx, maxx, miny, maxy)");
    exec(db, "CREATE VIRTUAL TABLE r USING rtree(id, minx, maxx, miny, maxy)");
    auto t0 = Clock::now();
    exec(db, "BEGIN; INSERT INTO t SELECT * FROM src; COMMIT;");
    build_loci.push_back(seconds(t0, Clock::now()));
    t0 = Clock::now();
    exec(db, "BEGIN; INSERT INTO r SELECT * FROM src; COMMIT;");
    build_rtree.push_back(seconds(t0, Clock::now()));
  }
  const double bl = median(build_loci), br = median(build_rtree);
  std::printf("\nbuild (INSERT INTO x SELECT * FROM src, one transaction)\n");
  std::printf(
      "  loci_rtree  %8.3f s\n  rtree       %8.3f s\n  ratio       %8.1fx  (target >= 10x)\n", bl,
      br, br / bl);

  // ---- Windows of about 100 hits ----
  const auto tree = loci::PackedRTree<2>::build(boxes);
  std::mt19937_64 rng(42);
  std::vector<loci::Point2> centres(o.queries);
  for (auto& c : centres) {
    const Box2& b = boxes[rng() % boxes.size()];
    c = b.center();
  }
  const auto windows_of = [&](double side) {
    std::vector<Box2> w(centres.size());
    for (std::size_t i = 0; i < w.size(); ++i)
      w[i] = {{{centres[i][0] - side / 2, centres[i][1] - side / 2}},
              {{centres[i][0] + side / 2, centres[i][1] + side / 2}}};
    return w;
  };
  double lo = 1e-4, hi = 10;
  for (int it = 0; it < 30; ++it) {  // side giving ~100 hits on average over the windows
    const double mid = std::sqrt(lo * hi);
    double total = 0;
    const auto w = windows_of(mid);
    for (const Box2& b : w)
      total += double(tree.query(b).size());
    (total / double(w.size()) < 100 ? lo : hi) = mid;
  }
  const auto windows = windows_of(std::sqrt(lo * hi));
  std::vector<std::vector<sqlite3_int64>> got_loci, got_rtree;
  std::vector<double> win_loci, win_rtree, txn_loci, txn_rtree;
  for (int r = 0; r < o.repeat; ++r) {
    win_loci.push_back(run_windows(db, "t", windows, got_loci));
    win_rtree.push_back(run_windows(db, "r", windows, got_rtree));
  }
  // The same queries inside one read transaction: SQLite then takes its file locks once, not
  // once per statement, and what remains is mostly the index.
  for (int r = 0; r < o.repeat; ++r) {
    std::vector<std::vector<sqlite3_int64>> ignored;
    exec(db, "BEGIN");
    txn_loci.push_back(run_windows(db, "t", windows, ignored));
    txn_rtree.push_back(run_windows(db, "r", windows, ignored));
    exec(db, "COMMIT");
  }
  std::size_t hits = 0, false_hits = 0, wrong = 0;
  for (std::size_t q = 0; q < windows.size(); ++q) {
    std::vector<sqlite3_int64> exact;
    for (sqlite3_int64 id : got_rtree[q])
      if (meets(boxes[std::size_t(id - 1)], windows[q]))
        exact.push_back(id);
      else
        ++false_hits;
    auto mine = got_loci[q];
    std::sort(mine.begin(), mine.end());
    std::sort(exact.begin(), exact.end());
    if (mine != exact || mine.size() != tree.query(windows[q]).size()) ++wrong;
    hits += mine.size();
  }
  const double wl = median(win_loci), wr = median(win_rtree);
  std::printf("\n%zu windows, %.1f hits each on average (every row stepped)\n", windows.size(),
              double(hits) / double(windows.size()));
  std::printf("  loci_rtree  %10.0f queries/s  %6.1f ns per hit  0 false hits\n",
              double(windows.size()) / wl, wl * 1e9 / double(std::max<std::size_t>(hits, 1)));
  std::printf("  rtree       %10.0f queries/s  %6.1f ns per hit  %zu false hits (float32 boxes)\n",
              double(windows.size()) / wr, wr * 1e9 / double(std::max<std::size_t>(hits, 1)),
              false_hits);
  std::printf("  ratio       %10.2fx  (target >= 2x)   answers identical to the exact ones: %s\n",
              wr / wl, wrong == 0 ? "yes" : "NO");
  if (wrong) std::printf("  %zu windows differ\n", wrong);
  const double tl = median(txn_loci), tr = median(txn_rtree);
  std::printf(
      "  inside one read transaction: loci_rtree %.0f queries/s, rtree %.0f queries/s, "
      "ratio %.2fx\n",
      double(windows.size()) / tl, double(windows.size()) / tr, tr / tl);

  // ---- Nearest-10 ----
  std::vector<loci::Point2> points(o.queries);
  std::uniform_real_distribution<double> jitter(-0.5, 0.5);
  for (auto& p : points) {
    const Box2& b = boxes[rng() % boxes.size()];
    p = {{b.center()[0] + jitter(rng), b.center()[1] + jitter(rng)}};
  }
  std::vector<std::vector<Near>> near_loci;
  std::vector<double> nl;
  for (int r = 0; r < o.repeat; ++r)
    nl.push_back(run_nearest(db, "SELECT id, distance FROM loci_nearest('t', ?1, ?2, 10)", points,
                             near_loci));
  const double nlm = median(nl);
  std::printf("\n%zu nearest-10 queries\n  loci_nearest %9.0f queries/s  (target >= 20,000)\n",
              points.size(), double(points.size()) / nlm);
  sqlite3_close(db);

  if (o.knn) {
    sqlite3* sp = open_db(dir + "/spatialite.db");
    char* err = nullptr;
    if (sqlite3_load_extension(sp, "mod_spatialite", nullptr, &err) != SQLITE_OK) {
      std::printf("  SpatiaLite: not measured (%s; apt-get install libsqlite3-mod-spatialite)\n",
                  err ? err : "?");
    } else {
      const auto t0 = Clock::now();
      exec(sp, "SELECT InitSpatialMetadata(1)");
      exec(sp, "CREATE TABLE s(id INTEGER PRIMARY KEY)");
      exec(sp, "SELECT AddGeometryColumn('s', 'geom', 3857, 'POLYGON', 'XY')");
      exec(sp, "BEGIN");
      sqlite3_stmt* s = prepare(sp, "INSERT INTO s VALUES(?1, BuildMbr(?2, ?3, ?4, ?5, 3857))");
      for (std::size_t i = 0; i < boxes.size(); ++i) {
        sqlite3_bind_int64(s, 1, sqlite3_int64(i + 1));
        sqlite3_bind_double(s, 2, boxes[i].min[0]);
        sqlite3_bind_double(s, 3, boxes[i].min[1]);
        sqlite3_bind_double(s, 4, boxes[i].max[0]);
        sqlite3_bind_double(s, 5, boxes[i].max[1]);
        sqlite3_step(s);
        sqlite3_reset(s);
      }
      sqlite3_finalize(s);
      exec(sp, "COMMIT");
      exec(sp, "SELECT CreateSpatialIndex('s', 'geom')");
      std::printf("  (SpatiaLite table and index of the same boxes built in %.1f s)\n",
                  seconds(t0, Clock::now()));
      // SpatiaLite's KNN answers on the polygons; at most 1,024 rows, sized by max_items.
      const std::size_t knn_queries = std::min<std::size_t>(points.size(), 1000);
      std::vector<loci::Point2> few(points.begin(), points.begin() + std::ptrdiff_t(knn_queries));
      std::vector<std::vector<Near>> near_knn;
      std::vector<double> nk;
      for (int r = 0; r < o.repeat; ++r)
        nk.push_back(run_nearest(sp,
                                 "SELECT fid, distance FROM KNN WHERE f_table_name = 's' AND "
                                 "ref_geometry = MakePoint(?1, ?2, 3857) AND max_items = 10",
                                 few, near_knn));
      const double nkm = median(nk);
      std::size_t differ = 0;
      for (std::size_t q = 0; q < few.size(); ++q) {
        const auto& a = near_loci[q];
        const auto& b = near_knn[q];
        bool same = a.size() == b.size();
        for (std::size_t i = 0; same && i < a.size(); ++i)
          same = std::abs(a[i].distance - b[i].distance) <= 1e-9 * std::max(1.0, a[i].distance);
        differ += !same;
      }
      std::printf("  SpatiaLite KNN %7.0f queries/s  (%zu queries)\n", double(few.size()) / nkm,
                  few.size());
      std::printf("  ratio        %9.1fx  (target >= 10x)   distances identical: %s\n",
                  (nkm / double(few.size())) / (nlm / double(points.size())),
                  differ == 0 ? "yes" : ("NO, " + std::to_string(differ) + " differ").c_str());
    }
    sqlite3_close(sp);
  }
  if (o.fleet) bench_fleet(dir, o);
  std::filesystem::remove_all(dir);
  return 0;
}
