// A small handle on a real SQLite connection with the built extension loaded, for the suites.
#pragma once

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <signal.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <string>
#include <vector>

namespace loci::test {

using Row = std::vector<std::string>;

class Db {
 public:
  explicit Db(const std::string& path = ":memory:", bool load = true) {
    if (sqlite3_open(path.c_str(), &db_) != SQLITE_OK) ADD_FAILURE() << sqlite3_errmsg(db_);
    if (load) load_extension();
  }
  Db(const Db&) = delete;
  Db& operator=(const Db&) = delete;
  ~Db() { sqlite3_close(db_); }

  void load_extension() {
    sqlite3_enable_load_extension(db_, 1);
    char* err = nullptr;
    if (sqlite3_load_extension(db_, LOCI_SQLITE_EXTENSION, nullptr, &err) != SQLITE_OK)
      ADD_FAILURE() << "cannot load " << LOCI_SQLITE_EXTENSION << ": " << (err ? err : "");
    sqlite3_free(err);
  }

  sqlite3* get() const { return db_; }

  // Runs SQL; fails the test on an error.
  void exec(const std::string& sql) {
    const std::string err = try_exec(sql);
    EXPECT_EQ(err, "") << sql;
  }
  // Runs sql once for each table named, with $T standing for its name: the same statement on
  // the loci table and on the plain table it is checked against.
  void exec_on(std::initializer_list<const char*> tables, const std::string& sql) {
    for (const char* table : tables) {
      std::string s = sql;
      for (std::size_t p; (p = s.find("$T")) != std::string::npos;)
        s.replace(p, 2, table);
      exec(s);
    }
  }
  // Runs SQL; returns the error message, or "" on success.
  std::string try_exec(const std::string& sql) {
    char* err = nullptr;
    const int rc = sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &err);
    std::string msg = rc == SQLITE_OK ? "" : (err ? err : sqlite3_errmsg(db_));
    sqlite3_free(err);
    return msg;
  }

  // Every row of a query, values as text (reals with 17 digits, so they compare exactly).
  std::vector<Row> rows(const std::string& sql, std::string* error = nullptr) {
    std::vector<Row> out;
    sqlite3_stmt* s = nullptr;
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &s, nullptr) != SQLITE_OK) {
      if (error)
        *error = sqlite3_errmsg(db_);
      else
        ADD_FAILURE() << sql << ": " << sqlite3_errmsg(db_);
      return out;
    }
    int rc;
    while ((rc = sqlite3_step(s)) == SQLITE_ROW) {
      Row r;
      for (int i = 0; i < sqlite3_column_count(s); ++i)
        r.push_back(text(s, i));
      out.push_back(std::move(r));
    }
    if (rc != SQLITE_DONE) {
      if (error)
        *error = sqlite3_errmsg(db_);
      else
        ADD_FAILURE() << sql << ": " << sqlite3_errmsg(db_);
    }
    sqlite3_finalize(s);
    return out;
  }
  std::string value(const std::string& sql) {
    const auto r = rows(sql);
    return r.empty() || r[0].empty() ? "<no row>" : r[0][0];
  }
  // The error a statement fails with ("" when it succeeds).
  std::string error_of(const std::string& sql) {
    std::string err;
    rows(sql, &err);
    return err;
  }

  static std::string text(sqlite3_stmt* s, int i) {
    switch (sqlite3_column_type(s, i)) {
      case SQLITE_NULL:
        return "NULL";
      case SQLITE_INTEGER:
        return std::to_string(sqlite3_column_int64(s, i));
      case SQLITE_FLOAT: {
        char buf[40];
        std::snprintf(buf, sizeof buf, "%.17g", sqlite3_column_double(s, i));
        return buf;
      }
      default:
        return reinterpret_cast<const char*>(sqlite3_column_text(s, i));
    }
  }

 private:
  sqlite3* db_ = nullptr;
};

inline std::string real(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

// A directory under /tmp for database files, removed with everything in it.
class TempDir {
 public:
  TempDir() {
    char tmpl[] = "/tmp/loci-sqlite-XXXXXX";
    path_ = ::mkdtemp(tmpl);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string file(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

// Forks a writer that opens `path` with the extension loaded and runs transaction(0),
// transaction(1), ... until it is killed with SIGKILL after `after` microseconds, mid-way
// through one of them. Returns false when the writer stopped by itself first.
inline bool kill_a_writer(const std::string& path,
                          const std::function<std::string(int)>& transaction, useconds_t after) {
  const pid_t pid = ::fork();
  if (pid < 0) return false;
  if (pid == 0) {
    sqlite3* raw = nullptr;
    sqlite3_open(path.c_str(), &raw);
    sqlite3_enable_load_extension(raw, 1);
    if (sqlite3_load_extension(raw, LOCI_SQLITE_EXTENSION, nullptr, nullptr) != SQLITE_OK)
      ::_exit(3);
    for (int i = 0;; ++i)
      if (sqlite3_exec(raw, transaction(i).c_str(), nullptr, nullptr, nullptr) != SQLITE_OK)
        ::_exit(4);
  }
  ::usleep(after);
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFSIGNALED(status);
}

}  // namespace loci::test
