// The loci_rtree module: CREATE VIRTUAL TABLE t USING loci_rtree(id, minx, maxx, miny, maxy
// [, +aux ...]), SQLite rtree's argument shape with exact double coordinates.
#include "rtree_table.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <optional>

namespace loci::sqlite {

namespace {

constexpr std::size_t kChunkBytes = 1 << 20;
constexpr int kCoordinates = 4;
const char* const kShadowSuffixes[] = {"node", "delta", "dead", "meta", "aux"};

// ---- Values -------------------------------------------------------------------------------

// A coordinate from SQL: integers and real numbers, and text that reads as one, within
// +-1e150 (as in layers: squared distances of larger ones overflow a double); anything else
// is an error naming the column.
double coordinate(sqlite3_value* v, const char* column, const RTreeTable& t) {
  double x = 0;
  const char* problem = read_number(v, x);
  if (!problem && !(std::abs(x) <= kMaxCoordinate)) problem = "beyond 1e150";
  if (problem)
    throw SqlError{SQLITE_CONSTRAINT,
                   format_sql("loci_rtree %s: %s is %s", t.name.c_str(), column, problem)};
  return x;
}

// The largest double <= i and the smallest double >= i.
double double_below(sqlite3_int64 i) {
  double d = double(i);
  if (d > -9223372036854775808.0 && d < 9223372036854775808.0 && sqlite3_int64(d) <= i) return d;
  if (d >= 9223372036854775808.0) return std::nextafter(d, 0.0);
  return sqlite3_int64(d) > i ? std::nextafter(d, -INFINITY) : d;
}
double double_above(sqlite3_int64 i) {
  double d = double(i);
  if (d >= 9223372036854775808.0) return d;  // 2^63 > every int64
  return sqlite3_int64(d) < i ? std::nextafter(d, INFINITY) : d;
}

// Adds "column op value" to the window with SQL's comparison rules for a REAL column: an
// integer operand compares exactly, NULL matches nothing, text that reads as a number is that
// number, other text and blobs sort above every number.
void add_constraint(Window& w, int column, Op op, sqlite3_value* v) {
  switch (sqlite3_value_type(v)) {
    case SQLITE_NULL:
      w.make_empty();
      return;
    case SQLITE_TEXT:
      // The coordinate columns are REAL: text that reads as a number compares as one.
      if (sqlite3_value_numeric_type(v) != SQLITE_TEXT) return add_constraint(w, column, op, v);
      [[fallthrough]];
    case SQLITE_BLOB:
      if (op == Op::eq || op == Op::gt || op == Op::ge) w.make_empty();
      return;
    case SQLITE_INTEGER: {
      const sqlite3_int64 i = sqlite3_value_int64(v);
      const double below = double_below(i), above = double_above(i);
      switch (op) {
        case Op::eq:
          if (below != above) w.make_empty();
          w.add(column, op, below);
          return;
        case Op::le:
        case Op::gt:
          w.add(column, op, below);
          return;
        case Op::lt:
        case Op::ge:
          w.add(column, op, above);
          return;
      }
      return;
    }
    default:
      w.add(column, op, sqlite3_value_double(v));
  }
}

// ---- Plans --------------------------------------------------------------------------------

enum Plan : int { plan_scan = 0, plan_rowid = 1, plan_window = 2 };

char op_code(unsigned char op) {
  switch (op) {
    case SQLITE_INDEX_CONSTRAINT_EQ:
      return '=';
    case SQLITE_INDEX_CONSTRAINT_LT:
      return '<';
    case SQLITE_INDEX_CONSTRAINT_LE:
      return 'l';
    case SQLITE_INDEX_CONSTRAINT_GT:
      return '>';
    case SQLITE_INDEX_CONSTRAINT_GE:
      return 'g';
    default:
      return 0;
  }
}
Op op_of(char c) {
  switch (c) {
    case '=':
      return Op::eq;
    case '<':
      return Op::lt;
    case 'l':
      return Op::le;
    case '>':
      return Op::gt;
    default:
      return Op::ge;
  }
}

// The rows a query matched, taken at xFilter. Should the same connection write to the table
// (or roll back) while the cursor is still being stepped, the rows not yet returned are looked
// up again as xNext reaches them: a row deleted since, or no longer in the window, is skipped,
// and one updated is returned as it is now (never its old box beside its new aux values).
struct Cursor : sqlite3_vtab_cursor {
  std::vector<Hit> hits;
  std::size_t at = 0;
  std::uint64_t changes = 0;  // the table's count of changes when the hits were taken
  bool windowed = false;      // the hits answer `window`
  Window window;
};

RTreeTable& table_of(sqlite3_vtab* v) {
  return *static_cast<RTreeTable*>(v);
}

// ---- Creating and connecting --------------------------------------------------------------

int connect(sqlite3* db, void* aux, int argc, const char* const* argv, sqlite3_vtab** out,
            char** err, bool create) {
  auto table = std::make_unique<RTreeTable>();
  try {
    std::vector<std::string> names, aux_names;
    for (std::string& a : column_arguments(argc, argv, "loci_rtree")) {
      if (a[0] == '+') {
        if (names.size() < 1 + kCoordinates)
          throw SqlError{SQLITE_ERROR,
                         "loci_rtree: +aux columns come after id, minx, maxx, "
                         "miny, maxy"};
        aux_names.push_back(a.substr(1));
      } else {
        if (!aux_names.empty()) throw SqlError{SQLITE_ERROR, "loci_rtree: +aux columns come last"};
        names.push_back(std::move(a));
      }
    }
    if (names.size() != 1 + kCoordinates)
      throw SqlError{SQLITE_ERROR,
                     format_sql("loci_rtree: expected (id, minx, maxx, miny, maxy [, +aux ...]), "
                                "got %d column%s before the +aux ones (2-dimensional boxes only)",
                                int(names.size()), names.size() == 1 ? "" : "s")};
    table->aux_count = int(aux_names.size());
    table->db = db;
    table->schema = argv[1];
    table->name = argv[2];

    // Typed like the values they hold, so SQL's comparison rules are those of REAL columns.
    std::string decl = "CREATE TABLE x(";
    for (std::size_t i = 0; i < names.size(); ++i)
      decl += (i ? ", " : "") + names[i] + (i ? " REAL" : " INTEGER");
    for (const auto& a : aux_names)
      decl += ", " + a;
    decl += ")";
    if (sqlite3_declare_vtab(db, decl.c_str()) != SQLITE_OK)
      throw SqlError{SQLITE_ERROR, std::string("loci_rtree: ") + sqlite3_errmsg(db)};
    sqlite3_vtab_config(db, SQLITE_VTAB_CONSTRAINT_SUPPORT, 1);

    if (create) {
      RTreeTable& t = *table;
      exec(db,
           format_sql("CREATE TABLE %s(n INTEGER PRIMARY KEY, data BLOB);"
                      "CREATE TABLE %s(id INTEGER PRIMARY KEY, minx REAL, maxx REAL, "
                      "miny REAL, maxy REAL);"
                      "CREATE TABLE %s(id INTEGER PRIMARY KEY);"
                      "CREATE TABLE %s(k TEXT PRIMARY KEY, v);"
                      "INSERT INTO %s VALUES('format', %d), ('generation', %lld);",
                      t.shadow("node").c_str(), t.shadow("delta").c_str(), t.shadow("dead").c_str(),
                      t.shadow("meta").c_str(), t.shadow("meta").c_str(), int(RTreeIndex::kFormat),
                      ShadowTable::first_generation()));
      if (t.aux_count) {
        std::string sql = "CREATE TABLE " + t.shadow("aux") + "(id INTEGER PRIMARY KEY";
        for (int i = 0; i < t.aux_count; ++i)
          sql += format_sql(", a%d", i);
        exec(db, sql + ")");
      }
    }
    if (create || !table->find_missing_shadow()) table->prepare_statements();
    table->attach(db, argv[1], argv[2], registry_of(aux));
    *out = table.release();
    return SQLITE_OK;
  } catch (const SqlError& e) {
    *err = sqlite3_mprintf("%s", e.message.c_str());
    return e.code;
  } catch (const std::bad_alloc&) {
    return SQLITE_NOMEM;
  } catch (const std::exception& e) {
    *err = sqlite3_mprintf("loci_rtree: %s", e.what());
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
  RTreeTable& t = table_of(v);
  const int rc = guarded(v, [&] { return t.drop_shadows(), SQLITE_OK; });
  if (rc != SQLITE_OK) return rc;
  return x_disconnect(v);
}

// ---- Planning -----------------------------------------------------------------------------

int x_best_index(sqlite3_vtab* v, sqlite3_index_info* info) {
  return guarded(v, [&] {
    // A lookup by id beats any window.
    for (int i = 0; i < info->nConstraint; ++i) {
      const auto& c = info->aConstraint[i];
      if (c.usable && c.op == SQLITE_INDEX_CONSTRAINT_EQ && c.iColumn <= col_id) {
        info->aConstraintUsage[i].argvIndex = 1;
        info->aConstraintUsage[i].omit = 0;  // SQLite checks the id's type rules again
        info->idxNum = plan_rowid;
        info->estimatedCost = 10.0;
        info->estimatedRows = 1;
        info->idxFlags = SQLITE_INDEX_SCAN_UNIQUE;
        return SQLITE_OK;
      }
    }
    std::string codes;
    int arg = 0;
    for (int i = 0; i < info->nConstraint; ++i) {
      const auto& c = info->aConstraint[i];
      const char code = op_code(c.op);
      if (!c.usable || !code || c.iColumn < col_minx || c.iColumn > col_maxy) continue;
      if (arg == 30) break;
      codes += code;
      codes += char('0' + c.iColumn);
      info->aConstraintUsage[i].argvIndex = ++arg;
      info->aConstraintUsage[i].omit = 1;
    }
    const RTreeTable& t = table_of(v);
    const double rows = t.index ? double(std::max<std::size_t>(t.index->size(), 1)) : 1e6;
    if (arg == 0) {
      // A scan comes in ascending id order, as a rowid table's does.
      if (info->nOrderBy == 1 && info->aOrderBy[0].iColumn <= col_id && !info->aOrderBy[0].desc)
        info->orderByConsumed = 1;
      info->idxNum = plan_scan;
      info->estimatedCost = 2.0 * rows + 1e5;
      info->estimatedRows = sqlite3_int64(rows);
      return SQLITE_OK;
    }
    info->idxNum = plan_window;
    info->idxStr = sqlite3_mprintf("%s", codes.c_str());
    if (!info->idxStr) return SQLITE_NOMEM;
    info->needToFreeIdxStr = 1;
    // Each constraint on another column narrows the window: the more, the cheaper.
    info->estimatedCost = 20.0 + rows / double(1 << std::min(2 * arg, 20));
    info->estimatedRows = sqlite3_int64(std::max(1.0, rows / double(1 << std::min(2 * arg, 20))));
    return SQLITE_OK;
  });
}

// ---- Reading ------------------------------------------------------------------------------

// A cursor takes the table's spare hit buffer, so a run of queries allocates nothing.
int x_open(sqlite3_vtab* v, sqlite3_vtab_cursor** out) {
  auto* c = new (std::nothrow) Cursor();
  if (!c) return SQLITE_NOMEM;
  c->hits.swap(table_of(v).spare_hits);
  *out = c;
  return SQLITE_OK;
}
int x_close(sqlite3_vtab_cursor* cur) {
  auto* c = static_cast<Cursor*>(cur);
  auto& spare = table_of(cur->pVtab).spare_hits;
  if (c->hits.capacity() > spare.capacity() && c->hits.capacity() <= (1u << 16)) {
    c->hits.clear();
    spare.swap(c->hits);
  }
  delete c;
  return SQLITE_OK;
}

int x_filter(sqlite3_vtab_cursor* cur, int plan, const char* codes, int argc,
             sqlite3_value** argv) {
  Cursor& c = *static_cast<Cursor*>(cur);
  return guarded(cur->pVtab, [&] {
    RTreeTable& t = table_of(cur->pVtab);
    RTreeIndex& index = t.current();
    c.hits.clear();
    c.at = 0;
    c.changes = t.changes;
    c.windowed = false;
    if (plan == plan_rowid) {
      RowId id;
      if (argc == 1 && row_id(argv[0], id)) {
        if (auto b = index.find(id)) c.hits.push_back({id, *b});
      } else if (argc == 1 && sqlite3_value_type(argv[0]) != SQLITE_NULL) {
        index.scan_by_id(c.hits);  // not an integer: SQLite's own comparison decides
      }
    } else if (plan == plan_window) {
      Window w;
      for (int i = 0; i < argc && codes && codes[2 * i]; ++i)
        add_constraint(w, codes[2 * i + 1] - '0', op_of(codes[2 * i]), argv[i]);
      if (w.unbounded() && !w.empty()) {
        index.scan_by_id(c.hits);
      } else {
        index.window(w, c.hits);
        c.windowed = true;
        c.window = w;
      }
    } else {
      index.scan_by_id(c.hits);
    }
    return SQLITE_OK;
  });
}

int x_next(sqlite3_vtab_cursor* cur) {
  Cursor& c = *static_cast<Cursor*>(cur);
  ++c.at;
  RTreeTable& t = table_of(cur->pVtab);
  if (c.changes == t.changes || c.at >= c.hits.size()) return SQLITE_OK;
  return guarded(cur->pVtab, [&] {  // written to since the hits were taken
    RTreeIndex& index = t.current();
    for (; c.at < c.hits.size(); ++c.at) {
      Hit& h = c.hits[c.at];
      const std::optional<Box2> now = index.find(h.id);
      if (!now || (c.windowed && !c.window.matches(*now))) continue;
      h.box = *now;
      break;
    }
    return SQLITE_OK;
  });
}
int x_eof(sqlite3_vtab_cursor* cur) {
  const Cursor& c = *static_cast<Cursor*>(cur);
  return c.at >= c.hits.size();
}

int x_column(sqlite3_vtab_cursor* cur, sqlite3_context* ctx, int column) {
  const Cursor& c = *static_cast<Cursor*>(cur);
  const Hit& h = c.hits[c.at];
  if (column == col_id) {
    sqlite3_result_int64(ctx, h.id);
    return SQLITE_OK;
  }
  if (column <= col_maxy) {
    sqlite3_result_double(ctx, column_of(h.box, column));
    return SQLITE_OK;
  }
  return guarded(cur->pVtab, [&] {
    RTreeTable& t = table_of(cur->pVtab);
    Statement& s = t.get_aux;
    s.bind(1, sqlite3_int64(h.id));
    if (s.step()) sqlite3_result_value(ctx, sqlite3_column_value(s.get(), column - col_maxy));
    s.reset();
    return SQLITE_OK;
  });
}

int x_rowid(sqlite3_vtab_cursor* cur, sqlite_int64* id) {
  const Cursor& c = *static_cast<Cursor*>(cur);
  *id = c.hits[c.at].id;
  return SQLITE_OK;
}

// ---- Writing ------------------------------------------------------------------------------

int x_update(sqlite3_vtab* v, int argc, sqlite3_value** argv, sqlite_int64* new_rowid) {
  RTreeTable& t = table_of(v);
  ++t.changes;
  return guarded(v, [&] {
    RTreeIndex& index = t.current();
    RowId old_id = 0;
    const bool has_old = sqlite3_value_type(argv[0]) != SQLITE_NULL;
    if (has_old) old_id = sqlite3_value_int64(argv[0]);
    if (argc == 1) {
      if (index.erase(old_id) && t.aux_count) {
        t.drop_aux.bind(1, sqlite3_int64(old_id));
        t.drop_aux.run();
      }
      return SQLITE_OK;
    }
    // argv[1] the new rowid, argv[2] the id column, argv[3..6] the box, then the aux values.
    // The id column is the rowid, as in an INTEGER PRIMARY KEY: a NULL id inserted takes a new
    // one, and an UPDATE to a NULL id (or rowid) is refused as a rowid table refuses it.
    RowId id = 0;
    sqlite3_value* const given = given_id(argv, has_old, old_id, "loci_rtree", t.name);
    if (sqlite3_value_type(given) != SQLITE_NULL) {
      if (!row_id(given, id))
        throw SqlError{SQLITE_MISMATCH,
                       format_sql("loci_rtree %s: the id must be an integer", t.name.c_str())};
    } else {
      const std::optional<RowId> top = index.max_id();
      if (top == std::numeric_limits<RowId>::max()) {
        // As a rowid table does once its largest rowid is taken: an unused one at random, or
        // SQLITE_FULL when a hundred tries find none.
        id = 0;
        for (int attempt = 0; attempt < 100 && id == 0; ++attempt) {
          RowId r = 0;
          sqlite3_randomness(int(sizeof r), &r);
          r &= std::numeric_limits<RowId>::max();
          if (r != 0 && !index.find(r)) id = r;
        }
        if (id == 0)
          throw SqlError{SQLITE_FULL, format_sql("loci_rtree %s: no id left", t.name.c_str())};
      } else {
        id = top ? *top + 1 : 1;
      }
    }
    Box2 b;
    b.min[0] = coordinate(argv[3], "minx", t);
    b.max[0] = coordinate(argv[4], "maxx", t);
    b.min[1] = coordinate(argv[5], "miny", t);
    b.max[1] = coordinate(argv[6], "maxy", t);
    for (int a = 0; a < 2; ++a)
      if (b.min[a] > b.max[a])
        throw SqlError{SQLITE_CONSTRAINT,
                       format_sql("loci_rtree %s: %s > %s for id %lld", t.name.c_str(),
                                  a ? "miny" : "minx", a ? "maxy" : "maxx", (long long)id)};
    if ((!has_old || id != old_id) && index.find(id)) {
      if (sqlite3_vtab_on_conflict(t.db) != SQLITE_REPLACE)
        throw SqlError{SQLITE_CONSTRAINT, format_sql("UNIQUE constraint failed: %s.id (%lld)",
                                                     t.name.c_str(), (long long)id)};
      index.erase(id);
    }
    if (has_old && id != old_id) {
      index.erase(old_id);
      if (t.aux_count) {
        t.drop_aux.bind(1, sqlite3_int64(old_id));
        t.drop_aux.run();
      }
    }
    index.put(id, b);
    if (t.aux_count) {
      t.put_aux.bind(1, sqlite3_int64(id));
      for (int i = 0; i < t.aux_count; ++i)
        sqlite3_bind_value(t.put_aux.get(), 2 + i, argv[7 + i]);
      t.put_aux.run();
    }
    if (!has_old) *new_rowid = id;
    return SQLITE_OK;
  });
}

// ---- Transactions -------------------------------------------------------------------------

int x_sync(sqlite3_vtab* v) {
  return guarded(v, [&] { return table_of(v).flush(true), SQLITE_OK; });
}
int x_rollback(sqlite3_vtab* v) {
  table_of(v).forget();
  return SQLITE_OK;
}
int x_savepoint(sqlite3_vtab* v, int) {
  return guarded(v, [&] { return table_of(v).flush(false), SQLITE_OK; });
}
int x_rollback_to(sqlite3_vtab* v, int) {
  table_of(v).forget();
  return SQLITE_OK;
}

int x_rename(sqlite3_vtab* v, const char* new_name) {
  RTreeTable& t = table_of(v);
  return guarded(v, [&] {
    t.flush(false);
    t.rename_shadows(new_name);
    return SQLITE_OK;
  });
}

int x_shadow_name(const char* suffix) {
  return is_shadow_suffix(suffix, kShadowSuffixes);
}

sqlite3_module rtree_module() {
  sqlite3_module m{};
  m.iVersion = 3;
  m.xCreate = x_create;
  m.xConnect = x_connect;
  m.xBestIndex = x_best_index;
  m.xDisconnect = x_disconnect;
  m.xDestroy = x_destroy;
  m.xOpen = x_open;
  m.xClose = x_close;
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
  m.xSavepoint = x_savepoint;
  m.xRelease = no_op_savepoint;
  m.xRollbackTo = x_rollback_to;
  m.xShadowName = x_shadow_name;
  return m;
}

const sqlite3_module kRTreeModule = rtree_module();

}  // namespace

// ---- RTreeTable ---------------------------------------------------------------------------

std::vector<const char*> RTreeTable::shadow_suffixes() const {
  std::vector<const char*> out(std::begin(kShadowSuffixes), std::end(kShadowSuffixes));
  if (!aux_count) out.pop_back();
  return out;
}

void RTreeTable::finalize_statements() {
  for (Statement* s : {&get_generation, &set_generation, &read_node, &write_node, &clear_node,
                       &read_delta, &put_delta, &drop_delta, &clear_delta, &read_dead, &put_dead,
                       &clear_dead, &get_aux, &put_aux, &drop_aux})
    s->finalize();
}

void RTreeTable::prepare_statements() {
  const auto sql = [&](const char* fmt, const char* suffix) {
    return format_sql(fmt, shadow(suffix).c_str());
  };
  prepare_generation();
  read_node.prepare(db, sql("SELECT n, data FROM %s ORDER BY n", "node"));
  write_node.prepare(db, sql("INSERT INTO %s(n, data) VALUES(?1, ?2)", "node"));
  clear_node.prepare(db, sql("DELETE FROM %s", "node"));
  read_delta.prepare(db, sql("SELECT id, minx, maxx, miny, maxy FROM %s", "delta"));
  put_delta.prepare(db, sql("INSERT OR REPLACE INTO %s VALUES(?1, ?2, ?3, ?4, ?5)", "delta"));
  drop_delta.prepare(db, sql("DELETE FROM %s WHERE id = ?1", "delta"));
  clear_delta.prepare(db, sql("DELETE FROM %s", "delta"));
  read_dead.prepare(db, sql("SELECT id FROM %s", "dead"));
  put_dead.prepare(db, sql("INSERT OR IGNORE INTO %s VALUES(?1)", "dead"));
  clear_dead.prepare(db, sql("DELETE FROM %s", "dead"));
  if (aux_count) {
    get_aux.prepare(db, sql("SELECT * FROM %s WHERE id = ?1", "aux"));
    std::string values = "?1";
    for (int i = 0; i < aux_count; ++i)
      values += format_sql(", ?%d", i + 2);
    put_aux.prepare(db, format_sql("INSERT OR REPLACE INTO %s VALUES(%s)", shadow("aux").c_str(),
                                   values.c_str()));
    drop_aux.prepare(db, sql("DELETE FROM %s WHERE id = ?1", "aux"));
  }
}

RTreeIndex RTreeTable::load_stored() {
  RTreeIndex::Header h{};
  std::memcpy(h.magic, RTreeIndex::kMagic, sizeof h.magic);
  h.format = RTreeIndex::kFormat;
  h.node_size = RTreeIndex::Packed::node_size;
  h.payload_bytes = 0;

  struct Reader {
    Statement& s;
    sqlite3_int64 next = 1;
    const std::byte* data = nullptr;
    std::size_t left = 0;
    bool done = false;
    bool more() {
      while (left == 0 && !done) {
        if (!s.step()) {
          done = true;
          break;
        }
        if (sqlite3_column_int64(s.get(), 0) != next++)
          throw Error("the %_node chunks are not numbered 1, 2, 3, ...");
        data = static_cast<const std::byte*>(sqlite3_column_blob(s.get(), 1));
        left = std::size_t(sqlite3_column_bytes(s.get(), 1));
      }
      return left != 0;
    }
  } reader{read_node};

  const ResetOnExit reset_node{read_node};
  if (read_node.step()) {
    if (sqlite3_column_int64(read_node.get(), 0) != 0 ||
        sqlite3_column_bytes(read_node.get(), 1) != int(sizeof h))
      throw Error("the %_node header is missing or has the wrong size");
    std::memcpy(&h, sqlite3_column_blob(read_node.get(), 1), sizeof h);
  } else {
    reader.done = true;  // never written: empty
  }
  const auto read = [&](std::span<std::byte> dst) {
    while (!dst.empty()) {
      if (!reader.more()) return false;
      const std::size_t n = std::min(dst.size(), reader.left);
      std::memcpy(dst.data(), reader.data, n);
      reader.data += n;
      reader.left -= n;
      dst = dst.subspan(n);
    }
    return true;
  };

  std::vector<Hit> delta;
  {
    const ResetOnExit reset_delta{read_delta};
    while (read_delta.step()) {
      sqlite3_stmt* s = read_delta.get();
      for (int i = 1; i <= 4; ++i)
        if (sqlite3_column_type(s, i) != SQLITE_FLOAT &&
            sqlite3_column_type(s, i) != SQLITE_INTEGER)
          throw Error("%_delta holds a coordinate that is not a number");
      const Box2 b{{{sqlite3_column_double(s, 1), sqlite3_column_double(s, 3)}},
                   {{sqlite3_column_double(s, 2), sqlite3_column_double(s, 4)}}};
      // As a write would have taken it: within +-1e150, min <= max.
      for (int a = 0; a < 2; ++a)
        if (!(std::abs(b.min[a]) <= kMaxCoordinate && std::abs(b.max[a]) <= kMaxCoordinate &&
              b.min[a] <= b.max[a]))
          throw Error("%_delta holds a box no write would store (id " +
                      std::to_string(sqlite3_column_int64(s, 0)) + ")");
      delta.push_back({sqlite3_column_int64(s, 0), b});
    }
  }
  std::vector<RowId> dead;
  {
    const ResetOnExit reset_dead{read_dead};
    while (read_dead.step())
      dead.push_back(sqlite3_column_int64(read_dead.get(), 0));
  }
  return RTreeIndex::load(h, read, std::move(delta), std::move(dead));
}

namespace {
// A message about the shadow tables ("%_node ...") with the table's own names ("t_node ...").
std::string naming_shadows(std::string message, const std::string& table) {
  for (std::size_t p = 0; (p = message.find("%_", p)) != std::string::npos; p += table.size())
    message.replace(p, 1, table);
  return message;
}
}  // namespace

RTreeIndex& RTreeTable::current() {
  if (index && !index->has_touched() && changed_elsewhere()) index.reset();
  if (!index) {
    const sqlite3_int64 g = stored_generation();
    try {
      index = std::make_unique<RTreeIndex>(load_stored());
    } catch (const Error& e) {
      throw SqlError{SQLITE_CORRUPT_VTAB,
                     format_sql("loci_rtree %s: the stored index is corrupt: %s", name.c_str(),
                                naming_shadows(e.what(), name).c_str())};
    }
    generation = g;
    ++changes;
  }
  return *index;
}

void RTreeTable::write_base() {
  clear_node.run();
  const RTreeIndex::Header h = index->header();
  write_node.bind(1, sqlite3_int64(0));
  sqlite3_bind_blob(write_node.get(), 2, &h, int(sizeof h), SQLITE_STATIC);
  write_node.run();
  std::vector<std::byte> chunk;
  chunk.reserve(kChunkBytes);
  sqlite3_int64 n = 1;
  const auto emit = [&] {
    write_node.bind(1, n++);
    sqlite3_bind_blob(write_node.get(), 2, chunk.data(), int(chunk.size()), SQLITE_STATIC);
    write_node.run();
    chunk.clear();
  };
  for (std::span<const std::byte> part : index->payload()) {
    while (!part.empty()) {
      const std::size_t take = std::min(part.size(), kChunkBytes - chunk.size());
      chunk.insert(chunk.end(), part.begin(), part.begin() + std::ptrdiff_t(take));
      part = part.subspan(take);
      if (chunk.size() == kChunkBytes) emit();
    }
  }
  if (!chunk.empty()) emit();
  clear_delta.run();
  clear_dead.run();
}

void RTreeTable::flush(bool may_repack) {
  if (!index || !index->has_touched()) return;
  if (may_repack && index->wants_repack()) {
    index->repack();
    write_base();
  } else {
    for (RowId id : index->take_touched()) {
      if (auto b = index->delta_box(id)) {
        put_delta.bind(1, sqlite3_int64(id));
        put_delta.bind(2, b->min[0]);
        put_delta.bind(3, b->max[0]);
        put_delta.bind(4, b->min[1]);
        put_delta.bind(5, b->max[1]);
        put_delta.run();
      } else {
        drop_delta.bind(1, sqlite3_int64(id));
        drop_delta.run();
      }
      if (index->is_dead(id)) {
        put_dead.bind(1, sqlite3_int64(id));
        put_dead.run();
      }
    }
  }
  bump_generation();
}

std::string RTreeTable::check() {
  try {
    if (std::string meta = check_meta(int(RTreeIndex::kFormat)); !meta.empty()) return meta;
    RTreeIndex stored = load_stored();
    stored.validate();
    RTreeIndex& live = current();
    live.validate();
    if (!live.has_touched() && !live.same_rows(stored))
      return "the index in memory differs from the stored one";
    if (aux_count) {
      Statement ids;
      ids.prepare(db, format_sql("SELECT id FROM %s", shadow("aux").c_str()));
      std::size_t count = 0;
      while (ids.step()) {
        ++count;
        const RowId id = sqlite3_column_int64(ids.get(), 0);
        if (!live.find(id))
          return format_sql("%s_aux holds id %lld, which has no box", name.c_str(), (long long)id);
      }
      if (count != live.size())
        return format_sql("%s_aux holds %lld rows for %lld boxes", name.c_str(), (long long)count,
                          (long long)live.size());
    }
    return "ok";
  } catch (const SqlError& e) {
    return e.message;
  } catch (const std::exception& e) {
    return naming_shadows(e.what(), name);
  }
}

int register_rtree(sqlite3* db, const std::shared_ptr<Registry>& registry) {
  return sqlite3_create_module_v2(db, "loci_rtree", &kRTreeModule, new_registry_handle(registry),
                                  free_registry_handle);
}

}  // namespace loci::sqlite
