// loci_nearest('t', x, y, k): the k rows of loci_rtree table t nearest (x, y), nearest first,
// as a table-valued function with columns id and distance (Euclidean, to the box; 0 inside).
#include <cmath>
#include <cstring>

#include "rtree_table.hpp"

namespace loci::sqlite {

namespace {

enum : int { col_id_out = 0, col_distance = 1, arg_table = 2, arg_x = 3, arg_y = 4, arg_k = 5 };

struct NearestTable : sqlite3_vtab {
  sqlite3* db = nullptr;
  std::shared_ptr<Registry> registry;
};

struct NearestCursor : sqlite3_vtab_cursor {
  std::vector<Near> rows;
  std::size_t at = 0;
};

int x_connect(sqlite3* db, void* aux, int, const char* const*, sqlite3_vtab** out, char** err) {
  const int rc = sqlite3_declare_vtab(
      db, "CREATE TABLE x(id, distance, tab HIDDEN, x HIDDEN, y HIDDEN, k HIDDEN)");
  if (rc != SQLITE_OK) {
    *err = sqlite3_mprintf("loci_nearest: %s", sqlite3_errmsg(db));
    return rc;
  }
  auto* t = new (std::nothrow) NearestTable();
  if (!t) return SQLITE_NOMEM;
  t->db = db;
  t->registry = registry_of(aux);
  sqlite3_vtab_config(db, SQLITE_VTAB_INNOCUOUS);
  *out = t;
  return SQLITE_OK;
}

int x_disconnect(sqlite3_vtab* v) {
  delete static_cast<NearestTable*>(v);
  return SQLITE_OK;
}

int x_best_index(sqlite3_vtab* v, sqlite3_index_info* info) {
  int slot[4] = {-1, -1, -1, -1};
  for (int i = 0; i < info->nConstraint; ++i) {
    const auto& c = info->aConstraint[i];
    if (c.iColumn < arg_table || c.op != SQLITE_INDEX_CONSTRAINT_EQ) continue;
    if (!c.usable) return SQLITE_CONSTRAINT;  // wait for a plan where the argument is known
    slot[c.iColumn - arg_table] = i;
  }
  for (int a = 0; a < 4; ++a) {
    if (slot[a] < 0) {
      set_error(v, "loci_nearest takes four arguments: ('table', x, y, k)");
      return SQLITE_ERROR;
    }
    info->aConstraintUsage[slot[a]].argvIndex = a + 1;
    info->aConstraintUsage[slot[a]].omit = 1;
  }
  // Rows come nearest first.
  if (info->nOrderBy == 1 && info->aOrderBy[0].iColumn == col_distance && !info->aOrderBy[0].desc)
    info->orderByConsumed = 1;
  info->estimatedCost = 100;
  info->estimatedRows = 10;
  return SQLITE_OK;
}

int x_open(sqlite3_vtab*, sqlite3_vtab_cursor** out) {
  auto* c = new (std::nothrow) NearestCursor();
  if (!c) return SQLITE_NOMEM;
  *out = c;
  return SQLITE_OK;
}
int x_close(sqlite3_vtab_cursor* c) {
  delete static_cast<NearestCursor*>(c);
  return SQLITE_OK;
}

double number(sqlite3_value* v, const char* what) {
  int type = sqlite3_value_type(v);
  if (type == SQLITE_TEXT) type = sqlite3_value_numeric_type(v);
  if (type != SQLITE_INTEGER && type != SQLITE_FLOAT)
    throw SqlError{SQLITE_MISMATCH, format_sql("loci_nearest: %s is %s", what,
                                               type == SQLITE_NULL ? "NULL" : "not a number")};
  const double x = sqlite3_value_double(v);
  if (!std::isfinite(x))
    throw SqlError{SQLITE_MISMATCH, format_sql("loci_nearest: %s is not finite", what)};
  return x;
}

int x_filter(sqlite3_vtab_cursor* cur, int, const char*, int argc, sqlite3_value** argv) {
  NearestCursor& c = *static_cast<NearestCursor*>(cur);
  const NearestTable& nt = *static_cast<NearestTable*>(cur->pVtab);
  return guarded(cur->pVtab, [&] {
    c.rows.clear();
    c.at = 0;
    if (argc != 4) throw SqlError{SQLITE_ERROR, "loci_nearest takes ('table', x, y, k)"};
    const char* name = reinterpret_cast<const char*>(sqlite3_value_text(argv[0]));
    const Point2 p{{number(argv[1], "x"), number(argv[2], "y")}};
    RowId k = 0;
    const double kd = number(argv[3], "k");
    if (kd < 0 || kd != std::floor(kd))
      throw SqlError{SQLITE_MISMATCH, "loci_nearest: k must be a whole number >= 0"};
    k = kd > 1e18 ? RowId(1e18) : RowId(kd);
    RTreeTable& t = table_named(nt.db, *nt.registry, name, "loci_nearest");
    t.current().nearest(p, std::size_t(k), c.rows);
    return SQLITE_OK;
  });
}

int x_next(sqlite3_vtab_cursor* cur) {
  ++static_cast<NearestCursor*>(cur)->at;
  return SQLITE_OK;
}
int x_eof(sqlite3_vtab_cursor* cur) {
  const NearestCursor& c = *static_cast<NearestCursor*>(cur);
  return c.at >= c.rows.size();
}
int x_column(sqlite3_vtab_cursor* cur, sqlite3_context* ctx, int column) {
  const NearestCursor& c = *static_cast<NearestCursor*>(cur);
  const Near& r = c.rows[c.at];
  if (column == col_id_out)
    sqlite3_result_int64(ctx, r.id);
  else if (column == col_distance)
    sqlite3_result_double(ctx, r.distance);
  else
    sqlite3_result_null(ctx);  // the hidden arguments are not read back
  return SQLITE_OK;
}
int x_rowid(sqlite3_vtab_cursor* cur, sqlite_int64* id) {
  *id = sqlite_int64(static_cast<NearestCursor*>(cur)->at);
  return SQLITE_OK;
}

sqlite3_module nearest_module() {
  sqlite3_module m{};
  m.iVersion = 1;
  m.xConnect = x_connect;  // no xCreate: eponymous only
  m.xBestIndex = x_best_index;
  m.xDisconnect = x_disconnect;
  m.xDestroy = x_disconnect;
  m.xOpen = x_open;
  m.xClose = x_close;
  m.xFilter = x_filter;
  m.xNext = x_next;
  m.xEof = x_eof;
  m.xColumn = x_column;
  m.xRowid = x_rowid;
  return m;
}

const sqlite3_module kNearestModule = nearest_module();

}  // namespace

int register_nearest(sqlite3* db, const std::shared_ptr<Registry>& registry) {
  return sqlite3_create_module_v2(db, "loci_nearest", &kNearestModule,
                                  new_registry_handle(registry), free_registry_handle);
}

}  // namespace loci::sqlite
