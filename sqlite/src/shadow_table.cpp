// What the loci virtual tables share: generations, shadow table names, the registry.
#include "shadow_table.hpp"

#include <strings.h>

#include <algorithm>
#include <cstring>

namespace loci::sqlite {

ShadowTable::ShadowTable() {
  std::memset(static_cast<sqlite3_vtab*>(this), 0, sizeof(sqlite3_vtab));
}

ShadowTable::~ShadowTable() {
  if (registry) std::erase(registry->tables, this);
}

void ShadowTable::attach(sqlite3* connection, const char* schema_name, const char* table_name,
                         std::shared_ptr<Registry> on) {
  db = connection;
  schema = schema_name;
  name = table_name;
  registry = std::move(on);
  registry->tables.push_back(this);
}

std::string ShadowTable::shadow(const char* suffix) const {
  return format_sql("\"%w\".\"%w_%s\"", schema.c_str(), name.c_str(), suffix);
}

void ShadowTable::prepare_generation() {
  const std::string meta = shadow("meta");
  get_generation.prepare(db, format_sql("SELECT v FROM %s WHERE k = 'generation'", meta.c_str()));
  set_generation.prepare(db,
                         format_sql("UPDATE %s SET v = ?1 WHERE k = 'generation'", meta.c_str()));
}

sqlite3_int64 ShadowTable::stored_generation() {
  const ResetOnExit reset{get_generation};
  return get_generation.step() ? sqlite3_column_int64(get_generation.get(), 0) : -1;
}

void ShadowTable::bump_generation() {
  set_generation.bind(1, sqlite3_int64(generation + 1));
  set_generation.run();
  ++generation;
}

bool ShadowTable::changed_elsewhere() {
  unsigned v = 0;
  const bool known =
      sqlite3_file_control(db, schema.c_str(), SQLITE_FCNTL_DATA_VERSION, &v) == SQLITE_OK;
  if (known && data_version_known && v == data_version) return false;
  data_version = v;
  data_version_known = known;
  return stored_generation() != generation;
}

void ShadowTable::drop_shadows() {
  std::string sql;
  for (const char* s : shadow_suffixes())
    sql += "DROP TABLE IF EXISTS " + shadow(s) + ";";
  finalize_statements();  // they hold the shadow tables open
  exec(db, sql);
}

void ShadowTable::rename_shadows(const char* new_name) {
  std::string sql;
  for (const char* s : shadow_suffixes())
    sql += format_sql("ALTER TABLE %s RENAME TO \"%w_%s\";", shadow(s).c_str(), new_name, s);
  finalize_statements();  // statements on the old names go before the tables move
  exec(db, sql);
  name = new_name;
  prepare_statements();
}

ShadowTable* Registry::find(std::string_view name) const {
  ShadowTable* found = nullptr;
  for (ShadowTable* t : tables) {
    const std::string qualified = t->schema + "." + t->name;
    const auto same = [&](const std::string& s) {
      return s.size() == name.size() && strncasecmp(s.data(), name.data(), s.size()) == 0;
    };
    if (same(qualified)) return t;
    if (same(t->name) && (!found || t->schema == "main")) found = t;
  }
  return found;
}

ShadowTable* connected_table(sqlite3* db, const Registry& registry, const char* name,
                             const char* function) {
  if (!name) throw SqlError{SQLITE_ERROR, format_sql("%s: the table name is NULL", function)};
  if (ShadowTable* t = registry.find(name)) return t;
  // Not connected on this connection yet: naming it in a statement connects it.
  sqlite3_stmt* s = nullptr;
  const std::string dot = name;
  std::string sql;
  if (const auto p = dot.find('.'); p != std::string::npos && !registry.find(dot.substr(p + 1)))
    sql = format_sql("SELECT 1 FROM \"%w\".\"%w\" LIMIT 0", dot.substr(0, p).c_str(),
                     dot.substr(p + 1).c_str());
  else
    sql = format_sql("SELECT 1 FROM \"%w\" LIMIT 0", name);
  const int rc = sqlite3_prepare_v2(db, sql.c_str(), -1, &s, nullptr);
  sqlite3_finalize(s);
  if (rc != SQLITE_OK)
    throw SqlError{SQLITE_ERROR, format_sql("%s: no such table: %s", function, name)};
  return registry.find(name);
}

std::vector<std::string> column_arguments(int argc, const char* const* argv, const char* module) {
  std::vector<std::string> out;
  for (int i = 3; i < argc; ++i) {
    std::string a = argv[i];
    const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
    a.erase(a.begin(), std::find_if_not(a.begin(), a.end(), blank));
    while (!a.empty() && blank(a.back()))
      a.pop_back();
    if (a.empty()) throw SqlError{SQLITE_ERROR, format_sql("%s: an empty column name", module)};
    out.push_back(std::move(a));
  }
  return out;
}

}  // namespace loci::sqlite
