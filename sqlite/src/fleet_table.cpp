// The loci_fleet module: CREATE VIRTUAL TABLE f USING loci_fleet(id, t, x, y, vx, vy).
#include "fleet_table.hpp"

#include <strings.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace loci::sqlite {

// ---- FleetState ---------------------------------------------------------------------------

double FleetState::latest() const {
  double t = -std::numeric_limits<double>::infinity();
  for (const auto& [id, m] : current_)
    t = std::max(t, m.t);
  return t;
}

std::vector<FleetReport> FleetState::reports() const {
  std::vector<FleetReport> out(current_.begin(), current_.end());
  std::sort(out.begin(), out.end(),
            [](const FleetReport& a, const FleetReport& b) { return a.first < b.first; });
  return out;
}

const TprTree<2>& FleetState::tree() {
  if (!built_ || pending_.size() > current_.size() / 8 + 64) {
    std::vector<Id> ids;
    std::vector<Motion2> motions;
    ids.reserve(current_.size());
    motions.reserve(current_.size());
    for (const auto& [id, m] : current_) {
      ids.push_back(key(id));
      motions.push_back(m);
    }
    tree_.build(ids, motions);
    built_ = true;
  } else {
    for (const FleetId id : pending_) {
      if (const Motion2* m = find(id))
        tree_.update(key(id), *m);
      else
        tree_.erase(key(id));
    }
  }
  pending_.clear();
  return tree_;
}

void FleetState::validate() {
  const TprTree<2>& t = tree();
  t.validate();
  if (t.size() != current_.size())
    throw Error("the tree holds " + std::to_string(t.size()) + " objects for " +
                std::to_string(current_.size()) + " current reports");
  for (const auto& [id, m] : current_)
    if (!t.contains(key(id)) || !(t.at(key(id)) == m))
      throw Error("the tree's report of id " + std::to_string(id) + " is not the current one");
}

namespace {

constexpr int kFormat = 1;
const char* const kShadowSuffixes[] = {"report", "current", "meta"};
const char* const kColumns[] = {"id", "t", "x", "y", "vx", "vy"};
enum Column : int { col_id = 0, col_t = 1 };
enum Plan : int { plan_scan = 0, plan_id = 1 };

FleetTable& table_of(sqlite3_vtab* v) {
  return *static_cast<FleetTable*>(v);
}

// A report from SQL values (t, x, y, vx, vy), each checked with a message naming it.
Motion2 motion_of(sqlite3_value* const* v, const FleetTable& t, FleetId id) {
  double value[5];
  for (int i = 0; i < 5; ++i) {
    const char* problem = read_number(v[i], value[i]);
    if (!problem && !(std::abs(value[i]) <= kMaxCoordinate)) problem = "beyond 1e150";
    if (problem)
      throw SqlError{SQLITE_CONSTRAINT,
                     format_sql("loci_fleet %s: %s is %s (id %lld)", t.name.c_str(),
                                kColumns[1 + i], problem, (long long)id)};
  }
  return Motion2{value[0], {{value[1], value[2]}}, {{value[3], value[4]}}};
}

// ---- Creating and connecting --------------------------------------------------------------

int connect(sqlite3* db, void* aux, int argc, const char* const* argv, sqlite3_vtab** out,
            char** err, bool create) {
  auto table = std::make_unique<FleetTable>();
  try {
    const std::vector<std::string> names = column_arguments(argc, argv, "loci_fleet");
    bool same = names.size() == std::size(kColumns);
    for (std::size_t i = 0; same && i < names.size(); ++i)
      same = strcasecmp(names[i].c_str(), kColumns[i]) == 0;
    if (!same) {
      std::string got;
      for (const auto& n : names)
        got += (got.empty() ? "" : ", ") + n;
      throw SqlError{SQLITE_ERROR,
                     "loci_fleet: expected the columns (id, t, x, y, vx, vy), got (" + got + ")"};
    }
    if (sqlite3_declare_vtab(db,
                             "CREATE TABLE x(id INTEGER, t REAL, x REAL, y REAL, vx REAL, "
                             "vy REAL)") != SQLITE_OK)
      throw SqlError{SQLITE_ERROR, std::string("loci_fleet: ") + sqlite3_errmsg(db)};
    sqlite3_vtab_config(db, SQLITE_VTAB_CONSTRAINT_SUPPORT, 1);
    FleetTable& t = *table;
    t.db = db;
    t.schema = argv[1];
    t.name = argv[2];
    if (create)
      exec(db, format_sql("CREATE TABLE %s(id INTEGER, t REAL, x REAL, y REAL, vx REAL, vy REAL, "
                          "PRIMARY KEY(id, t)) WITHOUT ROWID;"
                          "CREATE TABLE %s(id INTEGER PRIMARY KEY, t REAL, x REAL, y REAL, "
                          "vx REAL, vy REAL);"
                          "CREATE TABLE %s(k TEXT PRIMARY KEY, v);"
                          "INSERT INTO %s VALUES('format', %d), ('generation', %lld);",
                          t.shadow("report").c_str(), t.shadow("current").c_str(),
                          t.shadow("meta").c_str(), t.shadow("meta").c_str(), kFormat,
                          ShadowTable::first_generation()));
    if (create || !t.find_missing_shadow()) t.prepare_statements();
    t.attach(db, argv[1], argv[2], registry_of(aux));
    *out = table.release();
    return SQLITE_OK;
  } catch (const SqlError& e) {
    *err = sqlite3_mprintf("%s", e.message.c_str());
    return e.code;
  } catch (const std::bad_alloc&) {
    return SQLITE_NOMEM;
  } catch (const std::exception& e) {
    *err = sqlite3_mprintf("loci_fleet: %s", e.what());
    return SQLITE_ERROR;
  }
}

int x_create(sqlite3* db, void* aux, int argc, const char* const* argv, sqlite3_vtab** out,
             char** err) {
  return connect(db, aux, argc, argv, out, err, true);
}
int x_connect(sqlite3* db, void* aux, int argc, const char* const* argv, sqlite3_vtab** out,
              char** err) {
  return connect(db, aux, argc, argv, out, err, false);
}
int x_disconnect(sqlite3_vtab* v) {
  delete &table_of(v);
  return SQLITE_OK;
}
int x_destroy(sqlite3_vtab* v) {
  const int rc = guarded(v, [&] { return table_of(v).drop_shadows(), SQLITE_OK; });
  if (rc != SQLITE_OK) return rc;
  return x_disconnect(v);
}

// ---- Reading: the current reports, all or by id ------------------------------------------

struct Cursor : sqlite3_vtab_cursor {
  std::vector<FleetReport> rows;
  std::size_t at = 0;
  std::uint64_t changes = 0;  // the table's count of changes when the rows were taken
};

int x_best_index(sqlite3_vtab* v, sqlite3_index_info* info) {
  return guarded(v, [&] {
    for (int i = 0; i < info->nConstraint; ++i) {
      const auto& c = info->aConstraint[i];
      if (c.usable && c.op == SQLITE_INDEX_CONSTRAINT_EQ && c.iColumn <= col_id) {
        info->aConstraintUsage[i].argvIndex = 1;
        info->aConstraintUsage[i].omit = 0;  // SQLite checks the id's type rules again
        info->idxNum = plan_id;
        info->estimatedCost = 10.0;
        info->estimatedRows = 1;
        info->idxFlags = SQLITE_INDEX_SCAN_UNIQUE;
        return SQLITE_OK;
      }
    }
    const FleetTable& t = table_of(v);
    const double rows = t.state ? double(std::max<std::size_t>(t.state->size(), 1)) : 1e6;
    info->idxNum = plan_scan;
    info->estimatedCost = 2.0 * rows + 1e5;
    info->estimatedRows = sqlite3_int64(rows);
    if (info->nOrderBy == 1 && info->aOrderBy[0].iColumn <= col_id && !info->aOrderBy[0].desc)
      info->orderByConsumed = 1;  // rows come by id
    return SQLITE_OK;
  });
}

int x_filter(sqlite3_vtab_cursor* cur, int plan, const char*, int argc, sqlite3_value** argv) {
  Cursor& c = *static_cast<Cursor*>(cur);
  return guarded(cur->pVtab, [&] {
    FleetTable& t = table_of(cur->pVtab);
    FleetState& state = t.current();
    c.rows.clear();
    c.at = 0;
    c.changes = t.changes;
    FleetId id = 0;
    if (plan == plan_id && argc == 1 && row_id(argv[0], id)) {
      if (const Motion2* m = state.find(id)) c.rows.push_back({id, *m});
    } else if (plan != plan_id || (argc == 1 && sqlite3_value_type(argv[0]) != SQLITE_NULL)) {
      c.rows = state.reports();  // not an integer id: SQLite's own comparison decides
    }
    return SQLITE_OK;
  });
}

int x_next(sqlite3_vtab_cursor* cur) {
  Cursor& c = *static_cast<Cursor*>(cur);
  ++c.at;
  FleetTable& t = table_of(cur->pVtab);
  if (c.changes == t.changes || c.at >= c.rows.size()) return SQLITE_OK;
  // Written to since the rows were taken (a loop over the table writing to it): the rows
  // still to come are read as they are now, those removed skipped, as a rowid table does.
  return guarded(cur->pVtab, [&] {
    FleetState& state = t.current();
    for (; c.at < c.rows.size(); ++c.at)
      if (const Motion2* m = state.find(c.rows[c.at].first)) {
        c.rows[c.at].second = *m;
        break;
      }
    return SQLITE_OK;
  });
}
int x_eof(sqlite3_vtab_cursor* cur) {
  const Cursor& c = *static_cast<Cursor*>(cur);
  return c.at >= c.rows.size();
}
int x_column(sqlite3_vtab_cursor* cur, sqlite3_context* ctx, int column) {
  const Cursor& c = *static_cast<Cursor*>(cur);
  const auto& [id, m] = c.rows[c.at];
  const double values[] = {0, m.t, m.p[0], m.p[1], m.v[0], m.v[1]};
  if (column == col_id)
    sqlite3_result_int64(ctx, id);
  else
    sqlite3_result_double(ctx, values[column]);
  return SQLITE_OK;
}
int x_rowid(sqlite3_vtab_cursor* cur, sqlite_int64* id) {
  const Cursor& c = *static_cast<Cursor*>(cur);
  *id = c.rows[c.at].first;
  return SQLITE_OK;
}

// ---- Writing ------------------------------------------------------------------------------

int x_update(sqlite3_vtab* v, int argc, sqlite3_value** argv, sqlite_int64* new_rowid) {
  FleetTable& t = table_of(v);
  ++t.changes;
  return guarded(v, [&] {
    t.current();
    const bool has_old = sqlite3_value_type(argv[0]) != SQLITE_NULL;
    const FleetId old_id = has_old ? sqlite3_value_int64(argv[0]) : 0;
    if (argc == 1) {
      t.erase_object(old_id);
      return SQLITE_OK;
    }
    // argv[1] the new rowid, argv[2] the id column, argv[3..7] t, x, y, vx, vy.
    sqlite3_value* const given = given_id(argv, has_old, old_id, "loci_fleet", t.name);
    FleetId id = 0;
    if (sqlite3_value_type(given) == SQLITE_NULL)
      throw SqlError{
          SQLITE_CONSTRAINT,
          format_sql("loci_fleet %s: id is NULL (a report names its object)", t.name.c_str())};
    if (!row_id(given, id))
      throw SqlError{SQLITE_MISMATCH,
                     format_sql("loci_fleet %s: the id must be an integer", t.name.c_str())};
    const Motion2 m = motion_of(argv + 3, t, id);
    // A report at a time the object already has one replaces it, unless OR IGNORE asks to
    // keep what is there (an UPDATE rewriting the report in place is no such conflict).
    if (sqlite3_vtab_on_conflict(t.db) == SQLITE_IGNORE && t.has_report(id, m.t)) {
      const Motion2* at = has_old ? t.current().find(old_id) : nullptr;
      if (!(has_old && old_id == id && at && at->t == m.t)) return SQLITE_OK;
    }
    if (has_old) t.drop_current_report(old_id);
    t.add_report(id, m);
    if (!has_old) *new_rowid = id;
    return SQLITE_OK;
  });
}

// ---- Transactions -------------------------------------------------------------------------

int x_sync(sqlite3_vtab* v) {
  FleetTable& t = table_of(v);
  return guarded(v, [&] {
    if (t.wrote) t.bump_generation();
    t.wrote = false;
    return SQLITE_OK;
  });
}
int x_rollback(sqlite3_vtab* v) {
  table_of(v).forget();
  table_of(v).wrote = false;
  return SQLITE_OK;
}
int x_rollback_to(sqlite3_vtab* v, int) {
  table_of(v).forget();  // `wrote` stays: what came before the savepoint still commits
  return SQLITE_OK;
}

int x_rename(sqlite3_vtab* v, const char* new_name) {
  return guarded(v, [&] { return table_of(v).rename_shadows(new_name), SQLITE_OK; });
}

int x_shadow_name(const char* suffix) {
  return is_shadow_suffix(suffix, kShadowSuffixes);
}

sqlite3_module fleet_module() {
  sqlite3_module m{};
  m.iVersion = 3;
  m.xCreate = x_create;
  m.xConnect = x_connect;
  m.xBestIndex = x_best_index;
  m.xDisconnect = x_disconnect;
  m.xDestroy = x_destroy;
  m.xOpen = open_cursor<Cursor>;
  m.xClose = close_cursor<Cursor>;
  m.xFilter = x_filter;
  m.xNext = x_next;
  m.xEof = x_eof;
  m.xColumn = x_column;
  m.xRowid = x_rowid;
  m.xUpdate = x_update;
  m.xBegin = no_op_transaction;
  m.xSync = x_sync;
  m.xCommit = no_op_transaction;
  m.xRollback = x_rollback;
  m.xRename = x_rename;
  m.xSavepoint = no_op_savepoint;
  m.xRelease = no_op_savepoint;
  m.xRollbackTo = x_rollback_to;
  m.xShadowName = x_shadow_name;
  return m;
}

const sqlite3_module kFleetModule = fleet_module();

}  // namespace

// ---- FleetTable ---------------------------------------------------------------------------

std::vector<const char*> FleetTable::shadow_suffixes() const {
  return {std::begin(kShadowSuffixes), std::end(kShadowSuffixes)};
}

void FleetTable::finalize_statements() {
  for (Statement* s :
       {&get_generation, &set_generation, &put_report, &drop_report, &drop_history, &latest_report,
        &read_history, &put_current, &drop_current, &read_current, &find_report})
    s->finalize();
}

void FleetTable::prepare_statements() {
  const auto sql = [&](const char* fmt, const char* suffix) {
    return format_sql(fmt, shadow(suffix).c_str());
  };
  prepare_generation();
  put_report.prepare(db, sql("INSERT OR REPLACE INTO %s VALUES(?1, ?2, ?3, ?4, ?5, ?6)", "report"));
  drop_report.prepare(db, sql("DELETE FROM %s WHERE id = ?1 AND t = ?2", "report"));
  find_report.prepare(db, sql("SELECT 1 FROM %s WHERE id = ?1 AND t = ?2", "report"));
  drop_history.prepare(db, sql("DELETE FROM %s WHERE id = ?1", "report"));
  latest_report.prepare(
      db,
      sql("SELECT id, t, x, y, vx, vy FROM %s WHERE id = ?1 ORDER BY t DESC LIMIT 1", "report"));
  read_history.prepare(
      db, sql("SELECT id, t, x, y, vx, vy FROM %s WHERE t <= ?1 ORDER BY id, t", "report"));
  put_current.prepare(db,
                      sql("INSERT OR REPLACE INTO %s VALUES(?1, ?2, ?3, ?4, ?5, ?6)", "current"));
  drop_current.prepare(db, sql("DELETE FROM %s WHERE id = ?1", "current"));
  read_current.prepare(db, sql("SELECT id, t, x, y, vx, vy FROM %s", "current"));
}

Motion2 FleetTable::read_motion(sqlite3_stmt* s, int first, const char* table) const {
  for (int i = first; i < first + 5; ++i)
    if (sqlite3_column_type(s, i) != SQLITE_FLOAT && sqlite3_column_type(s, i) != SQLITE_INTEGER)
      throw SqlError{SQLITE_CORRUPT_VTAB,
                     format_sql("loci_fleet %s: %s_%s holds a value that is not a number",
                                name.c_str(), name.c_str(), table)};
  const auto d = [&](int i) { return sqlite3_column_double(s, first + i); };
  const Motion2 m{d(0), {{d(1), d(2)}}, {{d(3), d(4)}}};
  try {
    check_motion(m);
  } catch (const Error& e) {
    throw SqlError{SQLITE_CORRUPT_VTAB, format_sql("loci_fleet %s: %s_%s: %s", name.c_str(),
                                                   name.c_str(), table, e.what())};
  }
  return m;
}

FleetState& FleetTable::current() {
  if (state && !wrote && changed_elsewhere()) state.reset();
  if (!state) {
    const sqlite3_int64 g = stored_generation();
    FleetState fresh;
    const ResetOnExit reset{read_current};
    while (read_current.step())
      fresh.put(sqlite3_column_int64(read_current.get(), 0),
                read_motion(read_current.get(), 1, "current"));
    state = std::move(fresh);
    generation = g;
  }
  return *state;
}

void FleetTable::store_current(FleetId id, const Motion2& m) {
  put_current.bind(1, sqlite3_int64(id));
  put_current.bind(2, m.t);
  put_current.bind(3, m.p[0]);
  put_current.bind(4, m.p[1]);
  put_current.bind(5, m.v[0]);
  put_current.bind(6, m.v[1]);
  put_current.run();
  state->put(id, m);
}

void FleetTable::add_report(FleetId id, const Motion2& m) {
  FleetState& s = current();
  put_report.bind(1, sqlite3_int64(id));
  put_report.bind(2, m.t);
  put_report.bind(3, m.p[0]);
  put_report.bind(4, m.p[1]);
  put_report.bind(5, m.v[0]);
  put_report.bind(6, m.v[1]);
  put_report.run();
  wrote = true;
  const Motion2* now = s.find(id);
  if (!now || m.t >= now->t) store_current(id, m);
}

bool FleetTable::has_report(FleetId id, double t) {
  find_report.bind(1, sqlite3_int64(id));
  find_report.bind(2, t);
  const ResetOnExit reset{find_report};
  return find_report.step();
}

void FleetTable::drop_current_report(FleetId id) {
  FleetState& s = current();
  const Motion2* now = s.find(id);
  if (!now) return;
  drop_report.bind(1, sqlite3_int64(id));
  drop_report.bind(2, now->t);
  drop_report.run();
  wrote = true;
  latest_report.bind(1, sqlite3_int64(id));
  const ResetOnExit reset{latest_report};
  if (latest_report.step()) {
    store_current(id, read_motion(latest_report.get(), 1, "report"));
  } else {
    drop_current.bind(1, sqlite3_int64(id));
    drop_current.run();
    s.erase(id);
  }
}

void FleetTable::erase_object(FleetId id) {
  FleetState& s = current();
  for (Statement* st : {&drop_history, &drop_current}) {
    st->bind(1, sqlite3_int64(id));
    st->run();
  }
  wrote = true;
  s.erase(id);
}

std::vector<FleetReport> FleetTable::in_force_at(double t) {
  FleetState& s = current();
  if (t >= s.latest()) return s.reports();
  std::vector<FleetReport> out;
  read_history.bind(1, t);
  const ResetOnExit reset{read_history};
  while (read_history.step()) {
    const FleetId id = sqlite3_column_int64(read_history.get(), 0);
    const Motion2 m = read_motion(read_history.get(), 1, "report");
    if (!out.empty() && out.back().first == id)
      out.back().second = m;  // rows come by (id, t): the last one of an id is in force
    else
      out.push_back({id, m});
  }
  return out;
}

std::string FleetTable::check() {
  try {
    if (std::string meta = check_meta(kFormat); !meta.empty()) return meta;
    // %_current against the latest report of each id in %_report.
    Statement latest, count;
    latest.prepare(db, format_sql("SELECT r.id, r.t, r.x, r.y, r.vx, r.vy FROM %s r WHERE r.t = "
                                  "(SELECT max(t) FROM %s WHERE id = r.id) ORDER BY r.id",
                                  shadow("report").c_str(), shadow("report").c_str()));
    std::vector<FleetReport> stored;
    while (latest.step())
      stored.push_back(
          {sqlite3_column_int64(latest.get(), 0), read_motion(latest.get(), 1, "report")});
    std::vector<FleetReport> current_rows;
    {
      const ResetOnExit reset{read_current};
      while (read_current.step())
        current_rows.push_back({sqlite3_column_int64(read_current.get(), 0),
                                read_motion(read_current.get(), 1, "current")});
    }
    std::sort(current_rows.begin(), current_rows.end(),
              [](const FleetReport& a, const FleetReport& b) { return a.first < b.first; });
    if (current_rows != stored)
      return format_sql("%s_current is not the latest report of each id in %s_report", name.c_str(),
                        name.c_str());
    FleetState& s = current();
    if (s.reports() != stored) return "the reports in memory differ from the stored ones";
    s.validate();
    return "ok";
  } catch (const SqlError& e) {
    return e.message;
  } catch (const std::exception& e) {
    return e.what();
  }
}

int register_fleet(sqlite3* db, const std::shared_ptr<Registry>& registry) {
  return sqlite3_create_module_v2(db, "loci_fleet", &kFleetModule, new_registry_handle(registry),
                                  free_registry_handle);
}

}  // namespace loci::sqlite
