// ShadowTable: what every loci virtual table that keeps its rows in shadow tables shares (the
// loci_rtree and loci_fleet modules), and the registry through which the functions that name
// a table by its name ('t' in loci_nearest('t', ...)) find it.
//
// Shadow tables are ordinary tables named after the virtual table (`t_node`, `t_report`, ...),
// so SQLite's journal makes them follow BEGIN / ROLLBACK / SAVEPOINT / ROLLBACK TO and survive
// a killed process. Each table also holds what it read from them in memory; that copy must be
// dropped after a rollback (the module's xRollback and xRollbackTo do) and when another
// connection committed a change. The second is noticed in two steps: the file's data version
// (SQLITE_FCNTL_DATA_VERSION, one call without I/O) tells that something in the file changed;
// then 'generation' in %_meta, which every transaction that wrote the table has bumped before
// committing, tells whether it was this table.
//
// A table is on its connection's registry from xConnect / xCreate to xDisconnect / xDestroy.
// Thread-safety: as SQLite's connection, one thread at a time.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "sqlite_api.hpp"

namespace loci::sqlite {

struct Registry;

struct ShadowTable : sqlite3_vtab {
  // The name functions use in "%s is not a ... table" (the module's name).
  static constexpr const char* kModule = "loci_rtree or loci_fleet";

  ShadowTable();
  ShadowTable(const ShadowTable&) = delete;
  ShadowTable& operator=(const ShadowTable&) = delete;
  virtual ~ShadowTable();  // leaves the registry

  sqlite3* db = nullptr;
  std::string schema;
  std::string name;
  std::shared_ptr<Registry> registry;

  // Set at xConnect when a shadow table is gone ("t_node"): the table then connects so that
  // DROP TABLE can remove it, and refuses everything else (refuse_if_broken).
  std::string missing_shadow;
  sqlite3_int64 generation = -1;  // the stored 'generation' the in-memory copy was read at
  unsigned data_version = 0;      // the file's data version when `generation` was last checked
  bool data_version_known = false;
  Statement get_generation, set_generation;

  // "ok", or what is wrong with the stored or in-memory rows.
  virtual std::string check() = 0;
  // "loci_rtree" or "loci_fleet", for messages.
  virtual const char* module_name() const = 0;
  // The suffixes of the shadow tables this table has ("node", "report", ...).
  virtual std::vector<const char*> shadow_suffixes() const = 0;
  // Prepares or finalizes every statement on the shadow tables (they keep them open).
  virtual void prepare_statements() = 0;
  virtual void finalize_statements() = 0;

  // Joins `registry` as `name` in `schema`.
  void attach(sqlite3* connection, const char* schema_name, const char* table_name,
              std::shared_ptr<Registry> on);
  // "schema"."name_suffix", quoted for SQL.
  std::string shadow(const char* suffix) const;
  // Records in missing_shadow the first shadow table schema lacks; true when there is one.
  bool find_missing_shadow();
  // Throws SqlError (corrupt) naming the missing shadow table, when there is one.
  void refuse_if_broken() const;
  // Prepares get_generation and set_generation on %_meta(k, v).
  void prepare_generation();
  // 'generation' in %_meta; SqlError (corrupt) when it is missing or not a whole number >= 0,
  // since changes by other connections would then go unnoticed.
  sqlite3_int64 stored_generation();
  // "" when %_meta holds 'format' = `format` and a 'generation' (a whole number >= 0), else
  // what is wrong (loci_check).
  std::string check_meta(int format);
  void bump_generation();  // 'generation' + 1, stored and remembered
  // The 'generation' a new table starts at: random in [0, 2^62), so that a connection holding
  // a table another one dropped (or renamed) and created again under its name sees a change.
  static sqlite3_int64 first_generation();
  // Whether another connection committed a change to this table since `generation` was read.
  bool changed_elsewhere();
  void forget_version() { data_version_known = false; }

  // DROP TABLE of every shadow table (xDestroy), ALTER TABLE ... RENAME of each (xRename).
  void drop_shadows();
  void rename_shadows(const char* new_name);
};

// The loci tables connected on one database connection.
struct Registry {
  std::vector<ShadowTable*> tables;
  // The table `name` of `schema` (both case-insensitive), its newest object when two have the
  // name (one renamed inside the transaction under way); null when absent.
  ShadowTable* find(std::string_view schema, std::string_view name) const;
};

// A read transaction begun on the database of the table a function reads, when that database
// had none, by a statement stepped on it and kept so while this lives. A function naming a
// table holds one while it reads it, as a statement reading the table would: beginning it
// makes SQLite check its copy of that schema against the file (another connection may have
// changed it; SQLite then reads it again and disconnects the tables of the old one, before
// they are looked up, not while they are used) and brings SQLITE_FCNTL_DATA_VERSION up to date
// (a commit by another connection is seen); holding it keeps what is read consistent. Other
// databases are left alone (one locked by another connection does not matter).
class ReadHold {
 public:
  ReadHold() = default;
  ~ReadHold() { sqlite3_finalize(held_); }
  ReadHold(const ReadHold&) = delete;
  ReadHold& operator=(const ReadHold&) = delete;
  // Begins it on `schema` of db (temp aside: no other connection changes it); throws SqlError
  // when that database cannot be read.
  void begin(sqlite3* db, const std::string& schema);

 private:
  sqlite3_stmt* held_ = nullptr;
};

// The table `name`, connecting it if this connection has not yet, its database held by `hold`
// first; null when it exists but is not a loci table. `name` is found as SQL finds a table name in
// FROM (temp, then main, then the attached databases in the order attached), or "schema.table" in
// that schema. Throws SqlError naming `function` when there is no such table, or with SQLite's
// reason when the table cannot be opened (a shadow table missing, say).
ShadowTable* connected_table(sqlite3* db, const Registry& registry, const char* name,
                             const char* function, ReadHold& hold);

// The table `name` of module T (RTreeTable, FleetTable, or ShadowTable for any), its database
// held by `hold` (begun there), to be used while `hold` lives; throws SqlError naming
// `function` when there is none.
template <class T>
T& table_named(sqlite3* db, const Registry& registry, const char* name, const char* function,
               ReadHold& hold) {
  if (auto* typed = dynamic_cast<T*>(connected_table(db, registry, name, function, hold)))
    return *typed;
  throw SqlError{SQLITE_ERROR, format_sql("%s: %s is not a %s table", function, name, T::kModule)};
}

// The value an xUpdate gives for the id of a table whose id column is its rowid (argv[1] the
// new rowid, argv[2] the id column): the rowid where an UPDATE sets it, or an INSERT names it
// instead of the id; NULL for an INSERT that names neither. An UPDATE to a NULL id or rowid
// is refused as datatype mismatch, as a rowid table refuses it. Throws SqlError naming
// `module` and `table`.
inline sqlite3_value* given_id(sqlite3_value** argv, bool has_old, sqlite3_int64 old_id,
                               const char* module, const std::string& table) {
  sqlite3_value* given = argv[2];
  if (has_old && sqlite3_value_type(argv[1]) != SQLITE_NULL &&
      sqlite3_value_int64(argv[1]) != old_id)
    given = argv[1];  // UPDATE ... SET rowid = ...
  else if (!has_old && sqlite3_value_type(argv[2]) == SQLITE_NULL)
    given = argv[1];  // INSERT INTO t(rowid, ...)
  if (has_old &&
      (sqlite3_value_type(given) == SQLITE_NULL || sqlite3_value_type(argv[1]) == SQLITE_NULL))
    throw SqlError{SQLITE_MISMATCH,
                   format_sql("%s %s: datatype mismatch (an UPDATE cannot set the id of id %lld "
                              "to NULL)",
                              module, table.c_str(), (long long)old_id)};
  return given;
}

// The column arguments of CREATE VIRTUAL TABLE (argv[3..]), with blanks around them removed;
// throws SqlError naming `module` for an empty one.
std::vector<std::string> column_arguments(int argc, const char* const* argv, const char* module);

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

// Transaction slots with nothing to do, for the modules' tables.
inline int no_op_transaction(sqlite3_vtab*) {
  return SQLITE_OK;
}
inline int no_op_savepoint(sqlite3_vtab*, int) {
  return SQLITE_OK;
}

// The modules and functions of the extension, each registered on a connection.
int register_rtree(sqlite3* db, const std::shared_ptr<Registry>& registry);
int register_fleet(sqlite3* db, const std::shared_ptr<Registry>& registry);
int register_nearest(sqlite3* db, const std::shared_ptr<Registry>& registry);
int register_fleet_functions(sqlite3* db, const std::shared_ptr<Registry>& registry);

// xShadowName: whether `suffix` names one of a module's shadow tables.
inline int is_shadow_suffix(const char* suffix, std::span<const char* const> suffixes) {
  for (const char* s : suffixes)
    if (sqlite3_stricmp(suffix, s) == 0) return 1;
  return 0;
}

}  // namespace loci::sqlite
