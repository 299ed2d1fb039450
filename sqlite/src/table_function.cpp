// The virtual-table machinery of the extension's table-valued functions.
#include "table_function.hpp"

#include <string>
#include <string_view>

namespace loci::sqlite {

namespace {

// What SQLite carries as the module's client data.
struct Handle {
  const TableFunction* function;
  std::shared_ptr<Registry> registry;
};

struct FunctionTable : sqlite3_vtab {
  sqlite3* db = nullptr;
  const Handle* handle = nullptr;
};

struct FunctionCursor : sqlite3_vtab_cursor {
  FunctionRows rows;
  std::size_t at = 0;
  std::size_t count = 0;
  std::vector<sqlite3_value*> args;  // copies of the arguments, read back as hidden columns

  FunctionCursor() = default;
  FunctionCursor(const FunctionCursor&) = delete;
  FunctionCursor& operator=(const FunctionCursor&) = delete;
  ~FunctionCursor() { forget_args(); }
  void forget_args() {
    for (sqlite3_value* v : args)
      sqlite3_value_free(v);
    args.clear();
  }
};

const TableFunction& function_of(sqlite3_vtab* v) {
  return *static_cast<FunctionTable*>(v)->handle->function;
}

int x_connect(sqlite3* db, void* aux, int, const char* const*, sqlite3_vtab** out, char** err) {
  const auto* handle = static_cast<const Handle*>(aux);
  const int rc = sqlite3_declare_vtab(db, handle->function->declaration);
  if (rc != SQLITE_OK) {
    *err = sqlite3_mprintf("%s: %s", handle->function->name, sqlite3_errmsg(db));
    return rc;
  }
  auto* t = new (std::nothrow) FunctionTable();
  if (!t) return SQLITE_NOMEM;
  t->db = db;
  t->handle = handle;
  sqlite3_vtab_config(db, SQLITE_VTAB_INNOCUOUS);
  *out = t;
  return SQLITE_OK;
}

int x_disconnect(sqlite3_vtab* v) {
  delete static_cast<FunctionTable*>(v);
  return SQLITE_OK;
}

// The plan's number is the count of arguments given: the required ones and a prefix of the
// optional ones.
int x_best_index(sqlite3_vtab* v, sqlite3_index_info* info) {
  const TableFunction& f = function_of(v);
  const int arguments = f.required + f.optional;
  std::vector<int> slot(std::size_t(arguments), -1);
  bool compared = false;  // an argument's column under another operator than =
  for (int i = 0; i < info->nConstraint; ++i) {
    const auto& c = info->aConstraint[i];
    if (c.iColumn < f.columns) continue;
    if (c.op != SQLITE_INDEX_CONSTRAINT_EQ) {
      compared = true;
      continue;
    }
    if (!c.usable) return SQLITE_CONSTRAINT;  // wait for a plan where the argument is known
    slot[std::size_t(c.iColumn - f.columns)] = i;
  }
  int given = 0;
  while (given < arguments && slot[std::size_t(given)] >= 0)
    ++given;
  bool gap = false;
  for (int a = given; a < arguments; ++a)
    gap |= slot[std::size_t(a)] >= 0;
  if (given < f.required || gap) {
    set_error(v, format_sql("%s takes %s%s", f.name, f.usage,
                            compared ? " (an argument given as a column takes = or IN only)" : ""));
    return SQLITE_ERROR;
  }
  for (int a = 0; a < given; ++a) {
    info->aConstraintUsage[slot[std::size_t(a)]].argvIndex = a + 1;
    info->aConstraintUsage[slot[std::size_t(a)]].omit = 1;
  }
  info->idxNum = given;
  if (f.sorted_by >= 0 && info->nOrderBy == 1 && info->aOrderBy[0].iColumn == f.sorted_by &&
      !info->aOrderBy[0].desc)
    info->orderByConsumed = 1;
  info->estimatedCost = 100;
  info->estimatedRows = 10;
  return SQLITE_OK;
}

int x_filter(sqlite3_vtab_cursor* cur, int, const char*, int argc, sqlite3_value** argv) {
  FunctionCursor& c = *static_cast<FunctionCursor*>(cur);
  const auto& t = *static_cast<FunctionTable*>(cur->pVtab);
  return guarded(cur->pVtab, [&] {
    c.rows.clear();
    c.at = c.count = 0;
    c.forget_args();
    c.args.reserve(std::size_t(argc));  // so that no copy is lost to a failed push_back
    for (int i = 0; i < argc; ++i) {
      sqlite3_value* copy = sqlite3_value_dup(argv[i]);
      if (!copy) throw std::bad_alloc();
      c.args.push_back(copy);
    }
    const TableFunction& f = *t.handle->function;
    try {
      f.answer(t.db, *t.handle->registry, std::span<sqlite3_value* const>(argv, std::size_t(argc)),
               c.rows);
    } catch (const SqlError&) {
      throw;  // worded by the function already
    } catch (const std::bad_alloc&) {
      throw;
    } catch (const std::exception& e) {
      // The library's refusals ("nearest time is beyond 1e150") name the function asked; one
      // that names its operation first ("conflicts: ...") has it in the function's name
      // already (loci_conflicts).
      std::string_view what = e.what();
      const std::string_view name = f.name;
      if (const std::size_t colon = what.find(": ");
          colon != std::string_view::npos && colon > 0 &&
          name.ends_with(std::string("_") + std::string(what.substr(0, colon))))
        what.remove_prefix(colon + 2);
      throw SqlError{SQLITE_ERROR, std::string(f.name) + ": " + std::string(what)};
    }
    c.count = c.rows.rows(f.columns);
    return SQLITE_OK;
  });
}

int x_next(sqlite3_vtab_cursor* cur) {
  ++static_cast<FunctionCursor*>(cur)->at;
  return SQLITE_OK;
}
int x_eof(sqlite3_vtab_cursor* cur) {
  const FunctionCursor& c = *static_cast<FunctionCursor*>(cur);
  return c.at >= c.count;
}
int x_column(sqlite3_vtab_cursor* cur, sqlite3_context* ctx, int column) {
  const FunctionCursor& c = *static_cast<FunctionCursor*>(cur);
  const TableFunction& f = function_of(cur->pVtab);
  if (column >= f.columns) {
    // An argument column reads back the argument given (NULL for an optional one left out),
    // as SQLite's own table-valued functions do, so that a condition on it holds.
    const std::size_t a = std::size_t(column - f.columns);
    if (a < c.args.size())
      sqlite3_result_value(ctx, c.args[a]);
    else
      sqlite3_result_null(ctx);
    return SQLITE_OK;
  }
  const FunctionRows::Cell& cell = c.rows.at(c.at, column, f.columns);
  if (cell.integer)
    sqlite3_result_int64(ctx, cell.i);
  else
    sqlite3_result_double(ctx, cell.d);
  return SQLITE_OK;
}
int x_rowid(sqlite3_vtab_cursor* cur, sqlite_int64* id) {
  *id = sqlite_int64(static_cast<FunctionCursor*>(cur)->at);
  return SQLITE_OK;
}

sqlite3_module function_module() {
  sqlite3_module m{};
  m.iVersion = 1;
  m.xConnect = x_connect;  // no xCreate: eponymous only
  m.xBestIndex = x_best_index;
  m.xDisconnect = x_disconnect;
  m.xDestroy = x_disconnect;
  m.xOpen = open_cursor<FunctionCursor>;
  m.xClose = close_cursor<FunctionCursor>;
  m.xFilter = x_filter;
  m.xNext = x_next;
  m.xEof = x_eof;
  m.xColumn = x_column;
  m.xRowid = x_rowid;
  return m;
}

const sqlite3_module kFunctionModule = function_module();

void free_handle(void* h) {
  delete static_cast<Handle*>(h);
}

}  // namespace

int register_table_function(sqlite3* db, const TableFunction& f,
                            const std::shared_ptr<Registry>& registry) {
  auto* handle = new Handle{&f, registry};
  return sqlite3_create_module_v2(db, f.name, &kFunctionModule, handle, free_handle);
}

}  // namespace loci::sqlite
