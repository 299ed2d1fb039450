// Uses the installed index, io and SQLite targets on the bundled sample layer and checks each
// answer against a scan of its own: prints "ok" and exits 0, or names what differs and exits 1.
#include <sqlite3.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "loci/index/packed_rtree.hpp"
#include "loci/index/rstar_tree.hpp"
#include "loci/io/layer_reader.hpp"
#include "loci/sqlite/loci_sqlite.h"

namespace {

int failures = 0;

void expect(bool ok, const std::string& what) {
  if (!ok) {
    std::fprintf(stderr, "loci_consumer: %s\n", what.c_str());
    ++failures;
  }
}

bool meets(const loci::Box2& a, const loci::Box2& b) {
  return a.min[0] <= b.max[0] && b.min[0] <= a.max[0] && a.min[1] <= b.max[1] &&
         b.min[1] <= a.max[1];
}

std::set<loci::Id> scan(const std::vector<loci::Box2>& boxes, const loci::Box2& w) {
  std::set<loci::Id> out;
  for (std::size_t i = 0; i < boxes.size(); ++i)
    if (meets(boxes[i], w)) out.insert(i);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: loci_consumer LAYER\n");
    return 2;
  }
  // io: the layer's segments, read through GDAL.
  const loci::io::LayerItems items = loci::io::read_items(argv[1], "", loci::io::Per::segment);
  const std::vector<loci::Box2>& boxes = items.boxes;
  expect(boxes.size() > 1000, "the layer has " + std::to_string(boxes.size()) + " segments");
  loci::Box2 all = loci::Box2::empty();
  for (const loci::Box2& b : boxes)
    all.expand(b);

  // index: a packed tree and an R*-tree over the same boxes, windows against a scan.
  const auto packed = loci::PackedRTree2::build(boxes, loci::Packing::str);
  loci::RStarTree2 dynamic;
  for (std::size_t i = 0; i < boxes.size(); ++i)
    dynamic.insert(boxes[i], i);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> ux(all.min[0], all.max[0]), uy(all.min[1], all.max[1]);
  for (int q = 0; q < 50; ++q) {
    const double x = ux(rng), y = uy(rng);
    const loci::Box2 w{
        {x, y}, {x + 0.05 * (all.max[0] - all.min[0]), y + 0.05 * (all.max[1] - all.min[1])}};
    const std::set<loci::Id> want = scan(boxes, w);
    const std::vector<loci::Id> a = packed.query(w), b = dynamic.query(w);
    expect(std::set<loci::Id>(a.begin(), a.end()) == want && a.size() == want.size(),
           "packed window " + std::to_string(q) + " differs from the scan");
    expect(std::set<loci::Id>(b.begin(), b.end()) == want && b.size() == want.size(),
           "R*-tree window " + std::to_string(q) + " differs from the scan");
  }

  // sqlite: the static entry registered on an in-memory database, then a window in SQL.
  sqlite3* db = nullptr;
  expect(sqlite3_open(":memory:", &db) == SQLITE_OK, "cannot open an in-memory database");
  char* err = nullptr;
  expect(sqlite3_loci_init(db, &err, nullptr) == SQLITE_OK, "sqlite3_loci_init failed");
  sqlite3_free(err);
  auto exec = [&](const std::string& sql) {
    char* e = nullptr;
    if (sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &e) != SQLITE_OK)
      expect(false, sql + ": " + (e ? e : "error"));
    sqlite3_free(e);
  };
  exec("CREATE VIRTUAL TABLE t USING loci_rtree(id, minx, maxx, miny, maxy)");
  exec("BEGIN");
  sqlite3_stmt* ins = nullptr;
  sqlite3_prepare_v2(db, "INSERT INTO t VALUES (?, ?, ?, ?, ?)", -1, &ins, nullptr);
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    sqlite3_bind_int64(ins, 1, std::int64_t(i));
    sqlite3_bind_double(ins, 2, boxes[i].min[0]);
    sqlite3_bind_double(ins, 3, boxes[i].max[0]);
    sqlite3_bind_double(ins, 4, boxes[i].min[1]);
    sqlite3_bind_double(ins, 5, boxes[i].max[1]);
    expect(sqlite3_step(ins) == SQLITE_DONE, "insert " + std::to_string(i) + " failed");
    sqlite3_reset(ins);
  }
  sqlite3_finalize(ins);
  exec("COMMIT");
  const double x = 0.5 * (all.min[0] + all.max[0]), y = 0.5 * (all.min[1] + all.max[1]);
  const loci::Box2 w{{x, y},
                     {x + 0.1 * (all.max[0] - all.min[0]), y + 0.1 * (all.max[1] - all.min[1])}};
  sqlite3_stmt* sel = nullptr;
  sqlite3_prepare_v2(
      db, "SELECT id FROM t WHERE minx <= ?2 AND maxx >= ?1 AND miny <= ?4 AND maxy >= ?3", -1,
      &sel, nullptr);
  sqlite3_bind_double(sel, 1, w.min[0]);
  sqlite3_bind_double(sel, 2, w.max[0]);
  sqlite3_bind_double(sel, 3, w.min[1]);
  sqlite3_bind_double(sel, 4, w.max[1]);
  std::set<loci::Id> got;
  while (sqlite3_step(sel) == SQLITE_ROW)
    got.insert(loci::Id(sqlite3_column_int64(sel, 0)));
  sqlite3_finalize(sel);
  const std::set<loci::Id> want = scan(boxes, w);
  expect(!want.empty() && got == want, "the SQL window gives " + std::to_string(got.size()) +
                                           " rows, the scan " + std::to_string(want.size()));
  sqlite3_close(db);

  if (failures) return 1;
  std::printf("ok: %zu segments, 50 windows, one SQL window of %zu rows\n", boxes.size(),
              want.size());
  return 0;
}
