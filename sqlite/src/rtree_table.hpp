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

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rtree_index.hpp"
#include "shadow_table.hpp"

namespace loci::sqlite {

struct RTreeTable : ShadowTable {
  static constexpr const char* kModule = "loci_rtree";

  int aux_count = 0;

  std::unique_ptr<RTreeIndex> index;  // null until read
  // Writes through the table and readings of its index, counted: an open cursor compares it
  // with the count it started at.
  std::uint64_t changes = 0;
  std::vector<Hit> spare_hits;  // a cursor's buffer, kept between queries

  Statement read_node, write_node, clear_node, read_delta, put_delta, drop_delta, clear_delta,
      read_dead, put_dead, clear_dead, get_aux, put_aux, drop_aux;

  // The index, read from the shadow tables if needed and checked against changes made by other
  // connections. Throws SqlError.
  RTreeIndex& current();
  // Writes what changed since the last flush (repacking when `may_repack` and worthwhile).
  void flush(bool may_repack);
  // Forgets the in-memory index (after a rollback).
  void forget() {
    index.reset();
    ++changes;
    forget_version();
  }
  // Reads the stored index afresh, without touching the in-memory one. Throws loci::Error or
  // SqlError when it is inconsistent.
  RTreeIndex load_stored();
  std::string check() override;
  const char* module_name() const override { return kModule; }

  std::vector<const char*> shadow_suffixes() const override;
  void prepare_statements() override;
  void finalize_statements() override;
  void write_base();
};

}  // namespace loci::sqlite
