// The static library's entry point, registered with sqlite3_auto_extension: every connection
// opened afterwards has loci_rtree, loci_nearest and loci_check without loading a file.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <string>

#include "loci/sqlite/loci_sqlite.h"

TEST(SqliteStatic, AutoExtensionRegistersEveryConnection) {
  ASSERT_EQ(sqlite3_auto_extension(reinterpret_cast<void (*)(void)>(sqlite3_loci_init)), SQLITE_OK);
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(":memory:", &db), SQLITE_OK);
  char* err = nullptr;
  ASSERT_EQ(sqlite3_exec(db,
                         "CREATE VIRTUAL TABLE t USING loci_rtree(id, minx, maxx, miny, maxy);"
                         "INSERT INTO t VALUES (1, 0, 1, 0, 1), (2, 4, 5, 4, 5);",
                         nullptr, nullptr, &err),
            SQLITE_OK)
      << (err ? err : "");
  sqlite3_stmt* s = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db, "SELECT id FROM loci_nearest('t', 4.5, 3, 1)", -1, &s, nullptr),
            SQLITE_OK);
  ASSERT_EQ(sqlite3_step(s), SQLITE_ROW);
  EXPECT_EQ(sqlite3_column_int64(s, 0), 2);
  sqlite3_finalize(s);
  sqlite3_close(db);
  sqlite3_reset_auto_extension();
}
