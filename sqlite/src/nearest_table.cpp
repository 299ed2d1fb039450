// loci_nearest('t', x, y, k): the k rows of loci_rtree table t nearest (x, y), nearest first,
// as a table-valued function with columns id and distance (Euclidean, to the box; 0 inside).
#include "rtree_table.hpp"
#include "table_function.hpp"

namespace loci::sqlite {

namespace {

void nearest(sqlite3* db, const Registry& registry, std::span<sqlite3_value* const> args,
             FunctionRows& rows) {
  const char* f = "loci_nearest";
  const char* name = reinterpret_cast<const char*>(sqlite3_value_text(args[0]));
  const Point2 p{{coordinate_argument(args[1], f, "x"), coordinate_argument(args[2], f, "y")}};
  const std::size_t k = count_argument(args[3], f);
  ReadHold hold;
  RTreeTable& t = table_named<RTreeTable>(db, registry, name, f, hold);
  std::vector<Near> found;
  t.current().nearest(p, k, found);
  for (const Near& n : found) {
    rows.add(sqlite3_int64(n.id));
    rows.add(n.distance);
  }
}

const TableFunction kNearest{
    "loci_nearest",
    "CREATE TABLE x(id, distance, arg_table HIDDEN, arg_x HIDDEN, arg_y HIDDEN, arg_k HIDDEN)",
    2,
    4,
    0,
    "four arguments: ('table', x, y, k)",
    1,
    nearest};

}  // namespace

int register_nearest(sqlite3* db, const std::shared_ptr<Registry>& registry) {
  return register_table_function(db, kNearest, registry);
}

}  // namespace loci::sqlite
