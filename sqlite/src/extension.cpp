// The extension's entry point and its scalar functions.
//
// Loaded by name: `.load PATH/loci` in the sqlite3 shell, sqlite3_load_extension(db,
// "PATH/loci", 0, &err) from C, SELECT load_extension('PATH/loci') from SQL. SQLite derives the
// entry point sqlite3_loci_init from the file name. Programs that link SQLite in call the same
// function from the static library loci_sqlite_static (sqlite3_auto_extension, see
// include/loci/sqlite/loci_sqlite.h).
#include <map>
#include <memory>
#include <mutex>

#include "shadow_table.hpp"

SQLITE_EXTENSION_INIT1

namespace loci::sqlite {

namespace {

// loci_check('t'): 'ok' or what is wrong with t's index (loci_rtree) or reports (loci_fleet).
void check_function(sqlite3_context* ctx, int, sqlite3_value** argv) {
  try {
    auto& registry = *registry_of(sqlite3_user_data(ctx));
    const char* name = reinterpret_cast<const char*>(sqlite3_value_text(argv[0]));
    sqlite3* db = sqlite3_context_db_handle(ctx);
    ReadHold hold;
    ShadowTable& t = table_named<ShadowTable>(db, registry, name, "loci_check", hold);
    // A shadow table dropped by this connection while the table stays connected is named as
    // missing, as a connection made afterwards names it (not "no such table").
    if (t.missing_shadow.empty()) t.find_missing_shadow();
    const std::string verdict = t.check();
    sqlite3_result_text(ctx, verdict.c_str(), int(verdict.size()), SQLITE_TRANSIENT);
  } catch (const SqlError& e) {
    sqlite3_result_error(ctx, e.message.c_str(), int(e.message.size()));
    sqlite3_result_error_code(ctx, e.code);
  } catch (const std::bad_alloc&) {
    sqlite3_result_error_nomem(ctx);
  } catch (const std::exception& e) {
    sqlite3_result_error(ctx, e.what(), -1);
  }
}

// The registry of the connection db: the one its loci tables and functions already share
// when the extension is loaded again on it (loading registers the modules and functions anew,
// and tables connected earlier must stay visible to the new functions), else a new one. A
// connection's registry lives while SQLite holds a module, function or table of it, so an
// entry left by a closed connection has expired before its address can be reused.
std::shared_ptr<Registry> registry_for(sqlite3* db) {
  static std::mutex guard;
  static std::map<sqlite3*, std::weak_ptr<Registry>> live;
  const std::lock_guard<std::mutex> lock(guard);
  std::erase_if(live, [](const auto& entry) { return entry.second.expired(); });
  if (const auto it = live.find(db); it != live.end())
    if (auto registry = it->second.lock()) return registry;
  auto registry = std::make_shared<Registry>();
  live[db] = registry;
  return registry;
}

int register_all(sqlite3* db, char** err) {
  // The routines the extension calls that came last (sqlite3_db_name) are SQLite 3.39's; an
  // older library's table of routines has no entry for them.
  if (sqlite3_libversion_number() < 3039000) {
    if (err)
      *err = sqlite3_mprintf("loci: needs SQLite 3.39 or later (this is %s)", sqlite3_libversion());
    return SQLITE_ERROR;
  }
  try {
    const std::shared_ptr<Registry> registry = registry_for(db);
    int rc = register_rtree(db, registry);
    if (rc == SQLITE_OK) rc = register_nearest(db, registry);
    if (rc == SQLITE_OK) rc = register_fleet(db, registry);
    if (rc == SQLITE_OK) rc = register_fleet_functions(db, registry);
    if (rc == SQLITE_OK)
      rc = sqlite3_create_function_v2(db, "loci_check", 1, SQLITE_UTF8 | SQLITE_DIRECTONLY,
                                      new_registry_handle(registry), check_function, nullptr,
                                      nullptr, free_registry_handle);
    if (rc != SQLITE_OK && err) *err = sqlite3_mprintf("loci: %s", sqlite3_errmsg(db));
    return rc;
  } catch (...) {
    return SQLITE_NOMEM;
  }
}

}  // namespace

}  // namespace loci::sqlite

extern "C" __attribute__((visibility("default"))) int sqlite3_loci_init(
    sqlite3* db, char** err, const sqlite3_api_routines* api) {
  SQLITE_EXTENSION_INIT2(api);
  return loci::sqlite::register_all(db, err);
}
