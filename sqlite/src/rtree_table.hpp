// The loci_rtree virtual table: one connection's view of one table, its shadow tables and its
// in-memory index.
//
// Shadow tables (all in the table's schema, named after it):
//   %_node(n INTEGER PRIMARY KEY, data BLOB)   row 0 the header, rows 1.. the packed base
//   %_delta(id INTEGER PRIMARY KEY, minx, maxx, miny, maxy)   rows written since the base
//   %_dead(id INTEGER PRIMARY KEY)             base entries deleted or changed since
//   %_meta(k TEXT PRIMARY KEY, v)              'format' and 'generation'
//   %_aux(id INTEGER PRIMARY KEY, ...)         the +aux columns, when there are any
//
// Transactions. Writes change the in-memory index and remember the ids they touched; the
// touched rows are flushed to %_delta and %_dead when a savepoint opens (so ROLLBACK TO finds
// them there) and at commit (xSync), which repacks instead when the changes are large. ROLLBACK
// and ROLLBACK TO drop the in-memory index and it is read again from the shadow tables, which
// SQLite's journal has put back. Every flush bumps 'generation'; another connection's change
// is noticed by the data version of the file and then by the generation, and the index is read
// again.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "rtree_index.hpp"
#include "sqlite_api.hpp"

namespace loci::sqlite {

struct RTreeTable;

// The loci_rtree tables connected on one database connection, for the functions that name a
// table by its name.
struct Registry {
  std::vector<RTreeTable*> tables;
  // The table called `name` (case-insensitive; "schema.name" also works); null when absent.
  RTreeTable* find(std::string_view name) const;
};

struct RTreeTable : sqlite3_vtab {
  sqlite3* db = nullptr;
  std::string schema;
  std::string name;
  int aux_count = 0;
  std::shared_ptr<Registry> registry;

  std::unique_ptr<RTreeIndex> index;  // null until read
  std::vector<Hit> spare_hits;        // a cursor's buffer, kept between queries
  sqlite3_int64 generation = -1;
  unsigned data_version = 0;
  bool data_version_known = false;

  Statement get_generation, set_generation, read_node, write_node, clear_node, read_delta,
      put_delta, drop_delta, clear_delta, read_dead, put_dead, clear_dead, get_aux, put_aux,
      drop_aux;

  // The index, read from the shadow tables if needed and checked against changes made by other
  // connections. Throws SqlError.
  RTreeIndex& current();
  // Writes what changed since the last flush (repacking when `may_repack` and worthwhile).
  void flush(bool may_repack);
  // Forgets the in-memory index (after a rollback).
  void forget() {
    index.reset();
    data_version_known = false;
  }
  // Reads the stored index afresh, without touching the in-memory one. Throws loci::Error or
  // SqlError when it is inconsistent.
  RTreeIndex load_stored();
  // "ok", or what is wrong with the stored or in-memory index.
  std::string check();

  std::string shadow(const char* suffix) const;
  void prepare_statements();
  void finalize_statements();
  void bump_generation();
  sqlite3_int64 stored_generation();  // 'generation' in %_meta, -1 when missing
  void write_base();
};

// The registry as SQLite carries it (a module's or a function's client data): a heap copy of
// the shared pointer, freed by free_registry_handle when SQLite drops the module or function.
inline void* new_registry_handle(const std::shared_ptr<Registry>& r) {
  return new std::shared_ptr<Registry>(r);
}
inline const std::shared_ptr<Registry>& registry_of(void* handle) {
  return *static_cast<std::shared_ptr<Registry>*>(handle);
}
inline void free_registry_handle(void* handle) {
  delete static_cast<std::shared_ptr<Registry>*>(handle);
}

// Registers the loci_rtree module (and the shared registry) on a connection.
int register_rtree(sqlite3* db, const std::shared_ptr<Registry>& registry);
// Registers the table-valued function loci_nearest (nearest_table.cpp).
int register_nearest(sqlite3* db, const std::shared_ptr<Registry>& registry);

// The loci_rtree table `name`, connecting it if this connection has not yet; throws SqlError
// naming `function` when there is no such loci_rtree table.
RTreeTable& table_named(sqlite3* db, const Registry& registry, const char* name,
                        const char* function);

}  // namespace loci::sqlite
