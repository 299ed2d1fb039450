// What the loci virtual tables share: generations, shadow table names, the registry.
#include "shadow_table.hpp"

#include <strings.h>

#include <algorithm>
#include <cstdint>
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
  refuse_if_broken();
  const ResetOnExit reset{get_generation};
  if (get_generation.step() && sqlite3_column_type(get_generation.get(), 0) == SQLITE_INTEGER &&
      sqlite3_column_int64(get_generation.get(), 0) >= 0)
    return sqlite3_column_int64(get_generation.get(), 0);
  throw SqlError{SQLITE_CORRUPT_VTAB,
                 format_sql("%s %s: the stored index is corrupt: %s_meta has no generation (a "
                            "whole number >= 0)",
                            module_name(), name.c_str(), name.c_str())};
}

std::string ShadowTable::check_meta(int format) {
  refuse_if_broken();
  Statement s;
  s.prepare(db, format_sql("SELECT k, v, quote(v) FROM %s", shadow("meta").c_str()));
  bool has_format = false, has_generation = false;
  const auto text = [&](int column) {
    const unsigned char* t = sqlite3_column_text(s.get(), column);
    return std::string(t ? reinterpret_cast<const char*>(t) : "");
  };
  while (s.step()) {
    const std::string key = text(0);
    const bool integer = sqlite3_column_type(s.get(), 1) == SQLITE_INTEGER;
    const sqlite3_int64 v = sqlite3_column_int64(s.get(), 1);
    if (key == "format") {
      if (!integer || v != format)
        return format_sql("%s_meta holds format %s, not %d", name.c_str(), text(2).c_str(), format);
      has_format = true;
    } else if (key == "generation") {
      if (!integer || v < 0)
        return format_sql("%s_meta holds generation %s, not a whole number >= 0", name.c_str(),
                          text(2).c_str());
      has_generation = true;
    }
  }
  if (!has_format) return format_sql("%s_meta has no format", name.c_str());
  if (!has_generation) return format_sql("%s_meta has no generation", name.c_str());
  return "";
}

sqlite3_int64 ShadowTable::first_generation() {
  std::uint64_t r = 0;
  sqlite3_randomness(int(sizeof r), &r);
  return sqlite3_int64(r >> 2);
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
  refuse_if_broken();
  std::string sql;
  for (const char* s : shadow_suffixes())
    sql += format_sql("ALTER TABLE %s RENAME TO \"%w_%s\";", shadow(s).c_str(), new_name, s);
  finalize_statements();  // statements on the old names go before the tables move
  exec(db, sql);
  name = new_name;
  prepare_statements();
}

namespace {

bool same_name(std::string_view a, std::string_view b) {
  return a.size() == b.size() && strncasecmp(a.data(), b.data(), a.size()) == 0;
}

// Whether schema `schema` holds a table (of any kind) called `table`, as SQL names match
// (case-insensitive).
bool holds_table(sqlite3* db, const char* schema, const std::string& table) {
  static const bool metadata = sqlite3_compileoption_used("ENABLE_COLUMN_METADATA") != 0;
  if (metadata)
    return sqlite3_table_column_metadata(db, schema, table.c_str(), nullptr, nullptr, nullptr,
                                         nullptr, nullptr, nullptr) == SQLITE_OK;
  sqlite3_stmt* s = nullptr;
  const std::string sql = format_sql(
      "SELECT 1 FROM \"%w\".sqlite_schema WHERE type = 'table' AND name = ?1 COLLATE NOCASE",
      schema);
  if (sqlite3_prepare_v2(db, sql.c_str(), -1, &s, nullptr) != SQLITE_OK) {
    sqlite3_finalize(s);
    return false;
  }
  sqlite3_bind_text(s, 1, table.data(), int(table.size()), SQLITE_TRANSIENT);
  const bool found = sqlite3_step(s) == SQLITE_ROW;
  sqlite3_finalize(s);
  return found;
}

// The schema SQL would find table `table` in, unqualified: temp, then main, then the attached
// databases in the order attached; null when none holds it.
const char* schema_of(sqlite3* db, const std::string& table) {
  const char* first[] = {"temp", "main"};
  for (const char* schema : first)
    if (holds_table(db, schema, table)) return schema;
  for (int i = 2; const char* schema = sqlite3_db_name(db, i); ++i)
    if (holds_table(db, schema, table)) return schema;
  return nullptr;
}

bool is_schema(sqlite3* db, std::string_view name) {
  for (int i = 0; const char* schema = sqlite3_db_name(db, i); ++i)
    if (same_name(schema, name)) return true;
  return false;
}

// `text` as SQL identifiers, one or two separated by a dot, at least one quoted as SQL quotes
// them ("a""b", [a], `a`; the other may be bare): {table} or {schema, table}; empty when it is
// not that.
std::vector<std::string> quoted_identifiers(std::string_view text) {
  std::vector<std::string> out;
  bool quoted = false;
  std::size_t i = 0;
  while (i < text.size()) {
    const char open = text[i];
    std::string id;
    if (open == '"' || open == '[' || open == '`') {
      const char close = open == '[' ? ']' : open;
      for (++i;; ++i) {
        if (i >= text.size()) return {};
        if (text[i] != close) {
          id += text[i];
        } else if (close != ']' && i + 1 < text.size() && text[i + 1] == close) {
          id += close;  // a doubled quote
          ++i;
        } else {
          break;
        }
      }
      ++i;
      quoted = true;
    } else {
      for (; i < text.size() && text[i] != '.'; ++i) {
        if (text[i] == '"' || text[i] == '[' || text[i] == '`') return {};
        id += text[i];
      }
      if (id.empty()) return {};
    }
    out.push_back(std::move(id));
    if (i == text.size()) break;
    if (text[i] != '.' || out.size() == 2) return {};
    if (++i == text.size()) return {};
  }
  if (!quoted) return {};
  return out;
}

}  // namespace

bool ShadowTable::find_missing_shadow() {
  for (const char* s : shadow_suffixes())
    if (!holds_table(db, schema.c_str(), name + "_" + s)) {
      missing_shadow = name + "_" + s;
      return true;
    }
  return false;
}

void ShadowTable::refuse_if_broken() const {
  if (missing_shadow.empty()) return;
  throw SqlError{SQLITE_CORRUPT_VTAB,
                 format_sql("%s %s: the stored index is corrupt: %s is missing (DROP TABLE "
                            "removes what is left of the table)",
                            module_name(), name.c_str(), missing_shadow.c_str())};
}

ShadowTable* Registry::find(std::string_view schema, std::string_view name) const {
  // The newest first: a table renamed inside a transaction keeps its old object alive, under
  // the new name, until the transaction ends, while SQLite connects a new one that the
  // statements after the rename write through.
  for (auto it = tables.rbegin(); it != tables.rend(); ++it)
    if (same_name((*it)->schema, schema) && same_name((*it)->name, name)) return *it;
  return nullptr;
}

void ReadHold::begin(sqlite3* db, const std::string& schema) {
  if (held_ || sqlite3_stricmp(schema.c_str(), "temp") == 0 ||
      sqlite3_txn_state(db, schema.c_str()) != SQLITE_TXN_NONE)
    return;
  const std::string sql = format_sql("SELECT 1 FROM \"%w\".sqlite_schema", schema.c_str());
  int rc = sqlite3_prepare_v2(db, sql.c_str(), -1, &held_, nullptr);
  if (rc == SQLITE_OK) rc = sqlite3_step(held_);
  if (rc == SQLITE_ROW) return;
  sqlite3_finalize(held_);
  held_ = nullptr;
  if (rc != SQLITE_DONE)  // SQLITE_DONE: no table there (the lookup says so)
    throw SqlError{rc, format_sql("%s: %s", schema.c_str(), sqlite3_errmsg(db))};
}

namespace {

// The schema and table `name` names (see connected_table); throws SqlError naming `function`
// when there is no such table.
std::pair<std::string, std::string> resolved(sqlite3* db, const char* name, const char* function) {
  // "schema.table" where that schema exists and holds that table; otherwise the whole name is
  // a table's, looked up as SQL looks up an unqualified name.
  const std::string whole = name;
  std::string schema, table;
  if (const auto dot = whole.find('.'); dot != std::string::npos) {
    const std::string s = whole.substr(0, dot), t = whole.substr(dot + 1);
    if (is_schema(db, s) && holds_table(db, s.c_str(), t)) schema = s, table = t;
  }
  if (schema.empty()) {
    const char* found = schema_of(db, whole);
    // Quoted as in SQL ('"main"."t"', '"t"'), when no table has the name as it is.
    if (const auto ids = quoted_identifiers(whole); !found && !ids.empty()) {
      if (ids.size() == 2 && is_schema(db, ids[0]) && holds_table(db, ids[0].c_str(), ids[1]))
        schema = ids[0], table = ids[1];
      else if (ids.size() == 1 && (found = schema_of(db, ids[0])))
        schema = found, table = ids[0];
    } else if (found) {
      schema = found;
      table = whole;
    }
    if (schema.empty())
      throw SqlError{SQLITE_ERROR, format_sql("%s: no such table: %s", function, name)};
  }
  return {schema, table};
}

}  // namespace

ShadowTable* connected_table(sqlite3* db, const Registry& registry, const char* name,
                             const char* function, ReadHold& hold) {
  if (!name) throw SqlError{SQLITE_ERROR, format_sql("%s: the table name is NULL", function)};
  // Its database held first (main when the name is found nowhere: another connection may
  // have made it there), then the name looked up again: holding it may have had SQLite read a
  // schema another connection changed (the table dropped, or made again).
  std::string first = "main";
  try {
    first = resolved(db, name, function).first;
  } catch (const SqlError&) {
  }
  hold.begin(db, first);
  const auto [schema, table] = resolved(db, name, function);
  hold.begin(db, schema);  // when `first` was temp, which needs no hold, and is no longer
  if (ShadowTable* t = registry.find(schema, table)) return t;
  // Not connected on this connection yet: naming it in a statement connects it (or says what
  // is wrong with it, a missing shadow table for instance).
  sqlite3_stmt* s = nullptr;
  const std::string sql =
      format_sql("SELECT 1 FROM \"%w\".\"%w\" LIMIT 0", schema.c_str(), table.c_str());
  const int rc = sqlite3_prepare_v2(db, sql.c_str(), -1, &s, nullptr);
  sqlite3_finalize(s);
  if (rc != SQLITE_OK)
    throw SqlError{SQLITE_ERROR, format_sql("%s: %s: %s", function, name, sqlite3_errmsg(db))};
  return registry.find(schema, table);
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
