/* The loci SQLite extension, for programs that link SQLite and loci_sqlite_static in:
 *
 *   sqlite3_auto_extension((void (*)(void))sqlite3_loci_init);   // every connection after
 *   sqlite3_loci_init(db, &err, NULL);                             // or one connection
 *
 * registers loci_rtree, loci_nearest, loci_fleet, loci_fleet_window, loci_fleet_nearest,
 * loci_conflicts and loci_check. A program that loads the extension at
 * run time (sqlite3_load_extension(db, "PATH/loci", 0, &err)) needs nothing from here. */
#ifndef LOCI_SQLITE_H
#define LOCI_SQLITE_H

#include <sqlite3.h>

#ifdef __cplusplus
extern "C" {
#endif

int sqlite3_loci_init(sqlite3* db, char** err, const sqlite3_api_routines* api);

#ifdef __cplusplus
}
#endif

#endif
