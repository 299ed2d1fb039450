// Table-valued functions answered whole when SQLite filters them: loci_nearest,
// loci_fleet_window, loci_fleet_nearest and loci_conflicts.
//
// Each is an eponymous virtual table whose declared columns are the answer's columns followed
// by one HIDDEN column per argument (arg_table, arg_x, ...: names a caller's own columns are
// unlikely to have, so that `loci_nearest('t', x, y, 1)` in a subquery over a table with
// columns x and y reads that table's); `FROM f('t', 1, 2)` constrains the hidden columns to the
// arguments in order, and they read back the arguments given. The planner is told that a plan
// without every required argument cannot run (SQLITE_CONSTRAINT from xBestIndex), so joins that
// feed an argument from another table
// (`FROM probes p, loci_nearest('t', p.x, p.y, 3)`) run the function once per row of the other
// table. The answer is computed at xFilter into a flat array of integer and real cells.
#pragma once

#include <cmath>
#include <memory>
#include <span>
#include <vector>

#include "loci/geom/point.hpp"
#include "shadow_table.hpp"

namespace loci::sqlite {

// The answer of one call: `columns` cells per row, row after row.
class FunctionRows {
 public:
  struct Cell {
    bool integer;
    sqlite3_int64 i;
    double d;
  };
  void clear() { cells_.clear(); }
  void add(sqlite3_int64 v) { cells_.push_back({true, v, 0}); }
  void add(double v) { cells_.push_back({false, 0, v}); }
  const Cell& at(std::size_t row, int column, int columns) const {
    return cells_[row * std::size_t(columns) + std::size_t(column)];
  }
  std::size_t rows(int columns) const { return cells_.size() / std::size_t(columns); }

 private:
  std::vector<Cell> cells_;
};

struct TableFunction {
  const char* name;         // "loci_nearest"
  const char* declaration;  // CREATE TABLE x(answer columns, then HIDDEN argument columns)
  int columns;              // answer columns
  int required;             // arguments that must be given
  int optional;             // arguments that may follow them
  const char* usage;        // "('table', x, y, k)", for errors
  int sorted_by;            // the answer column the rows ascend in (-1: none)
  // Fills `rows`; `args` holds the arguments given, in order. Throws SqlError.
  void (*answer)(sqlite3* db, const Registry& registry, std::span<sqlite3_value* const> args,
                 FunctionRows& rows);
};

int register_table_function(sqlite3* db, const TableFunction& f,
                            const std::shared_ptr<Registry>& registry);

// A numeric argument of `function`: an SQL error naming `what` unless it is a finite number.
inline double number_argument(sqlite3_value* v, const char* function, const char* what) {
  double x = 0;
  if (const char* problem = read_number(v, x))
    throw SqlError{SQLITE_MISMATCH, format_sql("%s: %s is %s", function, what, problem)};
  return x;
}

// A coordinate argument: a number as number_argument gives, within +-1e150 (squared distances
// of larger ones overflow a double).
inline double coordinate_argument(sqlite3_value* v, const char* function, const char* what) {
  const double x = number_argument(v, function, what);
  if (!(std::abs(x) <= kMaxCoordinate))
    throw SqlError{SQLITE_MISMATCH, format_sql("%s: %s is beyond 1e150", function, what)};
  return x;
}

// A count argument (k of the nearest-k functions): a whole number >= 0.
inline std::size_t count_argument(sqlite3_value* v, const char* function) {
  const double k = number_argument(v, function, "k");
  if (k < 0 || k != std::floor(k))
    throw SqlError{SQLITE_MISMATCH, format_sql("%s: k must be a whole number >= 0", function)};
  return k > 1e18 ? std::size_t(1e18) : std::size_t(k);
}

}  // namespace loci::sqlite
