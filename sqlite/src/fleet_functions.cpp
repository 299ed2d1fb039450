// The table-valued functions over loci_fleet tables (fleet_table.hpp), each answering from the
// reports in force at its time:
//   loci_fleet_window('f', xmin, ymin, xmax, ymax, t)   id, x, y: the objects whose position at
//                                                       t lies in the closed window, by id
//   loci_fleet_nearest('f', x, y, k [, t])              id, distance: the k objects nearest
//                                                       (x, y) at t (default: now), nearest first
//   loci_conflicts('f', D, H [, now])                   id_a, id_b, tcpa, dcpa, t_enter, t_exit:
//                                                       every pair within D at some time of
//                                                       [now, now + H], id_a < id_b, by (id_a,
//                                                       id_b)
// "now" is the latest report time in f unless given.
#include <algorithm>
#include <cmath>

#include "fleet_table.hpp"
#include "loci/index/moving/conflicts.hpp"
#include "table_function.hpp"

namespace loci::sqlite {

namespace {

const char* table_argument(sqlite3_value* v) {
  return reinterpret_cast<const char*>(sqlite3_value_text(v));
}

void fleet_window(sqlite3* db, const Registry& registry, std::span<sqlite3_value* const> args,
                  FunctionRows& rows) {
  const char* f = "loci_fleet_window";
  const Box<2> box{
      {{coordinate_argument(args[1], f, "xmin"), coordinate_argument(args[2], f, "ymin")}},
      {{coordinate_argument(args[3], f, "xmax"), coordinate_argument(args[4], f, "ymax")}}};
  const double t = number_argument(args[5], f, "t");
  if (box.min[0] > box.max[0] || box.min[1] > box.max[1])
    throw SqlError{SQLITE_MISMATCH, format_sql("%s: the window is inverted (%s > %s)", f,
                                               box.min[0] > box.max[0] ? "xmin" : "ymin",
                                               box.min[0] > box.max[0] ? "xmax" : "ymax")};
  ReadHold hold;
  FleetTable& fleet = table_named<FleetTable>(db, registry, table_argument(args[0]), f, hold);
  FleetState& state = fleet.current();
  const auto window = MovingWindow<2>::at(box, t);
  std::vector<FleetReport> hits;
  if (t >= state.latest()) {
    state.tree().query(window, [&](Id id, const Motion2& m) {
      hits.push_back({FleetState::id_of(id), m});
      return true;
    });
    std::sort(hits.begin(), hits.end(),
              [](const FleetReport& a, const FleetReport& b) { return a.first < b.first; });
  } else {
    for (const FleetReport& r : fleet.in_force_at(t))
      if (inside(r.second, window)) hits.push_back(r);
  }
  for (const auto& [id, m] : hits) {
    const Point2 p = position(m, t);
    rows.add(sqlite3_int64(id));
    rows.add(p[0]);
    rows.add(p[1]);
  }
}

void fleet_nearest(sqlite3* db, const Registry& registry, std::span<sqlite3_value* const> args,
                   FunctionRows& rows) {
  const char* f = "loci_fleet_nearest";
  const Point2 q{{coordinate_argument(args[1], f, "x"), coordinate_argument(args[2], f, "y")}};
  const std::size_t k = count_argument(args[3], f);
  ReadHold hold;
  FleetTable& fleet = table_named<FleetTable>(db, registry, table_argument(args[0]), f, hold);
  FleetState& state = fleet.current();
  const double t = args.size() > 4 ? number_argument(args[4], f, "t") : state.latest();
  if (state.size() == 0 || k == 0) return;
  std::vector<Neighbor> found;
  if (t >= state.latest()) {
    found = state.tree().nearest(q, t, k);
    for (Neighbor& n : found)
      n.id = Id(FleetState::id_of(n.id));
  } else {
    loci::detail::check_nearest_time(t);
    for (const auto& [id, m] : fleet.in_force_at(t))
      found.push_back({Id(id), std::sqrt(squared_distance(position(m, t), q))});
    const auto by_distance = [](const Neighbor& a, const Neighbor& b) {
      return a.distance < b.distance;
    };
    const std::size_t n = std::min(k, found.size());
    std::partial_sort(found.begin(), found.begin() + std::ptrdiff_t(n), found.end(), by_distance);
    found.resize(n);
    for (const Neighbor& near : found)
      loci::detail::check_nearest_distance(near.distance);
  }
  for (const Neighbor& n : found) {
    rows.add(sqlite3_int64(n.id));
    rows.add(n.distance);
  }
}

// find_conflicts orders pairs by unsigned id: SQL ids go in with their sign bit flipped, so
// that the order is SQL's.
Id ordered_key(FleetId id) {
  return Id(id) ^ (Id(1) << 63);
}
FleetId id_of_ordered(Id key) {
  return FleetId(key ^ (Id(1) << 63));
}

void conflicts(sqlite3* db, const Registry& registry, std::span<sqlite3_value* const> args,
               FunctionRows& rows) {
  const char* f = "loci_conflicts";
  const double within = number_argument(args[1], f, "D");
  const double horizon = number_argument(args[2], f, "H");
  if (within < 0) throw SqlError{SQLITE_MISMATCH, format_sql("%s: D must be >= 0", f)};
  if (horizon < 0) throw SqlError{SQLITE_MISMATCH, format_sql("%s: H must be >= 0", f)};
  ReadHold hold;
  FleetTable& fleet = table_named<FleetTable>(db, registry, table_argument(args[0]), f, hold);
  FleetState& state = fleet.current();
  const double now = args.size() > 3 ? number_argument(args[3], f, "now") : state.latest();
  if (state.size() == 0) return;  // no report: no latest time (and no pair)
  try {
    check_conflict_query(within, now, horizon);
  } catch (const InvalidArgument& e) {
    throw SqlError{SQLITE_MISMATCH, format_sql("%s: %s", f, e.what())};
  }
  const std::vector<FleetReport> reports = fleet.in_force_at(now);
  std::vector<Id> ids;
  std::vector<Motion2> motions;
  ids.reserve(reports.size());
  motions.reserve(reports.size());
  for (const auto& [id, m] : reports) {
    ids.push_back(ordered_key(id));
    motions.push_back(m);
  }
  // Named by their SQL ids (the keys passed below are not).
  check_conflict_objects<2>(std::span<const Motion2>(motions), now, horizon, [&](std::size_t i) {
    return "id " + std::to_string(reports[i].first);
  });
  for (const Conflict& c : find_conflicts<2>(ids, motions, within, now, horizon)) {
    rows.add(sqlite3_int64(id_of_ordered(c.a)));
    rows.add(sqlite3_int64(id_of_ordered(c.b)));
    rows.add(c.approach.tcpa);
    rows.add(c.approach.dcpa);
    rows.add(c.approach.t_enter);
    rows.add(c.approach.t_exit);
  }
}

const TableFunction kFleetWindow{"loci_fleet_window",
                                 "CREATE TABLE x(id, x, y, arg_table HIDDEN, arg_xmin HIDDEN, "
                                 "arg_ymin HIDDEN, arg_xmax HIDDEN, arg_ymax HIDDEN, arg_t HIDDEN)",
                                 3,
                                 6,
                                 0,
                                 "six arguments: ('fleet', xmin, ymin, xmax, ymax, t)",
                                 0,
                                 fleet_window};
const TableFunction kFleetNearest{
    "loci_fleet_nearest",
    "CREATE TABLE x(id, distance, arg_table HIDDEN, arg_x HIDDEN, arg_y HIDDEN, arg_k HIDDEN, "
    "arg_t HIDDEN)",
    2,
    4,
    1,
    "('fleet', x, y, k [, t])",
    1,
    fleet_nearest};
const TableFunction kConflicts{"loci_conflicts",
                               "CREATE TABLE x(id_a, id_b, tcpa, dcpa, t_enter, t_exit, "
                               "arg_table HIDDEN, arg_d HIDDEN, arg_h HIDDEN, arg_now HIDDEN)",
                               6,
                               3,
                               1,
                               "('fleet', D, H [, now])",
                               0,
                               conflicts};

}  // namespace

int register_fleet_functions(sqlite3* db, const std::shared_ptr<Registry>& registry) {
  int rc = register_table_function(db, kFleetWindow, registry);
  if (rc == SQLITE_OK) rc = register_table_function(db, kFleetNearest, registry);
  if (rc == SQLITE_OK) rc = register_table_function(db, kConflicts, registry);
  return rc;
}

}  // namespace loci::sqlite
