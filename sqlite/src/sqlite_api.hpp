// The SQLite API as the extension sees it: through the loader's routine table when built as a
// loadable module, directly when built with SQLITE_CORE for programs that link SQLite in.
#pragma once

#include <sqlite3ext.h>

#include <cmath>
#include <cstdint>
#include <exception>
#include <new>
#include <string>
#include <string_view>

#include "loci/geom/error.hpp"

SQLITE_EXTENSION_INIT3

namespace loci::sqlite {

// An SQL error to hand back: SQLite's result code and the message the user reads.
struct SqlError {
  int code;
  std::string message;
};

// Sets the error message of a virtual table (SQLite frees it).
inline void set_error(sqlite3_vtab* vtab, const std::string& message) {
  sqlite3_free(vtab->zErrMsg);
  vtab->zErrMsg = sqlite3_mprintf("%s", message.c_str());
}

// Runs `body`, turning any exception into an SQL result code and message: nothing thrown in
// C++ crosses into SQLite.
template <class Body>
int guarded(sqlite3_vtab* vtab, Body&& body) noexcept {
  try {
    return body();
  } catch (const SqlError& e) {
    set_error(vtab, e.message);
    return e.code;
  } catch (const std::bad_alloc&) {
    return SQLITE_NOMEM;
  } catch (const std::exception& e) {
    set_error(vtab, e.what());
    return SQLITE_ERROR;
  } catch (...) {
    set_error(vtab, "unexpected error");
    return SQLITE_ERROR;
  }
}

// A prepared statement, finalized on destruction and reset after every use.
class Statement {
 public:
  Statement() = default;
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  ~Statement() { sqlite3_finalize(stmt_); }

  void prepare(sqlite3* db, const std::string& sql) {
    sqlite3_finalize(stmt_);
    stmt_ = nullptr;
    db_ = db;
    if (sqlite3_prepare_v3(db, sql.c_str(), int(sql.size()), SQLITE_PREPARE_PERSISTENT, &stmt_,
                           nullptr) != SQLITE_OK)
      fail();
  }
  void finalize() {
    sqlite3_finalize(stmt_);
    stmt_ = nullptr;
  }
  bool ready() const { return stmt_ != nullptr; }
  sqlite3_stmt* get() const { return stmt_; }

  // Steps once: true for a row, false when done; throws on an error (after a reset).
  bool step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    fail();
  }
  // Runs to completion and resets.
  void run() {
    while (step()) {
    }
    reset();
  }
  void reset() {
    sqlite3_reset(stmt_);
    sqlite3_clear_bindings(stmt_);
  }
  void bind(int i, sqlite3_int64 v) { sqlite3_bind_int64(stmt_, i, v); }
  void bind(int i, double v) { sqlite3_bind_double(stmt_, i, v); }

 private:
  [[noreturn]] void fail() {
    std::string msg = sqlite3_errmsg(db_);
    const int code = sqlite3_errcode(db_);
    if (stmt_) sqlite3_reset(stmt_);
    throw SqlError{code == SQLITE_OK ? SQLITE_ERROR : code, msg};
  }
  sqlite3* db_ = nullptr;
  sqlite3_stmt* stmt_ = nullptr;
};

// Resets a statement when the scope that steps it ends, however it ends.
struct ResetOnExit {
  Statement& statement;
  ~ResetOnExit() { statement.reset(); }
};

// Runs SQL that returns nothing; throws SqlError.
// xOpen and xClose of a module whose cursor type C needs nothing from its table.
template <class C>
int open_cursor(sqlite3_vtab*, sqlite3_vtab_cursor** out) {
  auto* c = new (std::nothrow) C();
  if (!c) return SQLITE_NOMEM;
  *out = c;
  return SQLITE_OK;
}
template <class C>
int close_cursor(sqlite3_vtab_cursor* c) {
  delete static_cast<C*>(c);
  return SQLITE_OK;
}

inline void exec(sqlite3* db, const std::string& sql) {
  char* err = nullptr;
  if (sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &err) != SQLITE_OK) {
    std::string msg = err ? err : sqlite3_errmsg(db);
    sqlite3_free(err);
    throw SqlError{sqlite3_errcode(db), msg};
  }
}

// printf-style SQL with %w / %q / %Q quoting.
template <class... Args>
std::string format_sql(const char* fmt, Args... args) {
  char* s = sqlite3_mprintf(fmt, args...);
  if (!s) throw std::bad_alloc();
  std::string out = s;
  sqlite3_free(s);
  return out;
}

// A number from SQL: an integer, a real, or text that reads as one. Sets `out` and returns
// null, or returns what is wrong with the value ("NULL", "not a number", "not finite").
inline const char* read_number(sqlite3_value* v, double& out) {
  int type = sqlite3_value_type(v);
  if (type == SQLITE_TEXT) type = sqlite3_value_numeric_type(v);
  if (type == SQLITE_NULL) return "NULL";
  if (type != SQLITE_INTEGER && type != SQLITE_FLOAT) return "not a number";
  out = sqlite3_value_double(v);
  return std::isfinite(out) ? nullptr : "not finite";
}

// A row id from SQL: an integer, or a real number or text holding one.
inline bool row_id(sqlite3_value* v, std::int64_t& id) {
  int type = sqlite3_value_type(v);
  if (type == SQLITE_TEXT) type = sqlite3_value_numeric_type(v);
  if (type == SQLITE_INTEGER) {
    id = sqlite3_value_int64(v);
    return true;
  }
  if (type == SQLITE_FLOAT) {
    const double d = sqlite3_value_double(v);
    if (d >= -9223372036854775808.0 && d < 9223372036854775808.0 && d == std::floor(d)) {
      id = std::int64_t(d);
      return true;
    }
  }
  return false;
}

}  // namespace loci::sqlite
