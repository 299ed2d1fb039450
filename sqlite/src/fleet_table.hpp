// The loci_fleet virtual table: a fleet of moving points as SQL rows (DESIGN.md sections 5 and
// 8). CREATE VIRTUAL TABLE f USING loci_fleet(id, t, x, y, vx, vy).
//
// Rows are reports: object `id` is at (x, y) at time t and moves with velocity (vx, vy) until
// its next report. The table keeps every report; what SELECT * FROM f shows is each object's
// current state, its report with the latest t (one row per id, rowid = id).
//   INSERT   adds a report. One later than the object's current state (or its first) becomes
//            the current state; an older one joins the history only, where windows at earlier
//            times find it. A report at a time the object already has a report for replaces it.
//   UPDATE   rewrites the current report: the shown row leaves the history and the new values
//            are inserted as a report (so changing t may make an older report current again).
//   DELETE   removes the object with its whole history.
// NULL, text that is not a number, NaN, infinities and values beyond 1e150 are SQL errors.
//
// Shadow tables (in the table's schema, named after it):
//   %_report(id, t, x, y, vx, vy, PRIMARY KEY(id, t)) WITHOUT ROWID   every report
//   %_current(id INTEGER PRIMARY KEY, t, x, y, vx, vy)   each object's latest report
//   %_meta(k TEXT PRIMARY KEY, v)                       'format' and 'generation'
//
// Transactions. Writes go straight to the shadow tables (so the journal undoes them with the
// statement, the savepoint or the transaction) and to the in-memory state: the current reports
// by id and a TPR*-tree over them (index/moving/tpr_tree.hpp). The tree follows writes lazily:
// the ids written since it was last brought up to date wait in a list, and the next query
// either applies them or, when they are many, packs a new tree (TprTree::build). ROLLBACK and
// ROLLBACK TO drop the in-memory state and it is read again from %_current. A transaction that
// wrote bumps 'generation' at commit (xSync), so other connections notice (shadow_table.hpp).
//
// Queries. At a time t at or after the latest report, every object's current report is in
// force and the tree answers exactly. Before it, the report in force for an object is its
// latest with time <= t (objects with none are absent), read from %_report in one pass.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "loci/geom/motion.hpp"
#include "loci/index/moving/tpr_tree.hpp"
#include "shadow_table.hpp"

namespace loci::sqlite {

using FleetId = std::int64_t;
using FleetReport = std::pair<FleetId, Motion2>;

// The current reports of a fleet and the TPR*-tree over them, kept in step on demand. Knows
// nothing of SQLite.
class FleetState {
 public:
  const Motion2* find(FleetId id) const {
    const auto it = current_.find(id);
    return it == current_.end() ? nullptr : &it->second;
  }
  void put(FleetId id, const Motion2& m) {
    current_[id] = m;
    pending_.push_back(id);
  }
  void erase(FleetId id) {
    if (current_.erase(id)) pending_.push_back(id);
  }
  std::size_t size() const { return current_.size(); }
  // The latest report time over the current reports; -infinity when there are none.
  double latest() const;
  // The current reports, by id.
  std::vector<FleetReport> reports() const;
  // The tree over the current reports, brought up to date.
  const TprTree<2>& tree();
  // Throws loci::Error when the tree does not hold exactly the current reports.
  void validate();

  // TprTree ids are unsigned: SQL ids are stored as their bits.
  static Id key(FleetId id) { return Id(id); }
  static FleetId id_of(Id key) { return FleetId(key); }

 private:
  std::unordered_map<FleetId, Motion2> current_;
  TprTree<2> tree_;
  bool built_ = false;
  std::vector<FleetId> pending_;  // ids written since the tree was brought up to date
};

struct FleetTable : ShadowTable {
  static constexpr const char* kModule = "loci_fleet";

  std::optional<FleetState> state;  // empty until read
  bool wrote = false;               // this transaction wrote: bump 'generation' at commit
  // Writes through the table and rollbacks, counted: an open cursor compares it with the
  // count it started at.
  std::uint64_t changes = 0;

  Statement put_report, drop_report, drop_history, latest_report, read_history, put_current,
      drop_current, read_current, find_report;

  // The in-memory state, read from %_current if needed and checked against changes made by
  // other connections. Throws SqlError.
  FleetState& current();
  void forget() {
    state.reset();
    ++changes;
    forget_version();
  }

  // Adds a report (INSERT; see the header for what becomes current).
  void add_report(FleetId id, const Motion2& m);
  // Whether `id` has a report at time t.
  bool has_report(FleetId id, double t);
  // Removes the current report of `id` from the history; the latest remaining one becomes
  // current (UPDATE's first half).
  void drop_current_report(FleetId id);
  // Removes the object and its history (DELETE).
  void erase_object(FleetId id);
  // The report in force at time t for every object that has one (latest with time <= t), by
  // id. Exact for every t: from the tree's objects when t is at or after the latest report,
  // from %_report otherwise.
  std::vector<FleetReport> in_force_at(double t);

  std::string check() override;
  const char* module_name() const override { return kModule; }
  std::vector<const char*> shadow_suffixes() const override;
  void prepare_statements() override;
  void finalize_statements() override;

 private:
  void store_current(FleetId id, const Motion2& m);
  // A report read from a shadow table row (columns first.. first + 4: t, x, y, vx, vy);
  // throws SqlError when the row does not hold one.
  Motion2 read_motion(sqlite3_stmt* s, int first, const char* table) const;
};

}  // namespace loci::sqlite
