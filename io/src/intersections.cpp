// `loci intersections` (see intersections.hpp).
#include "loci/io/intersections.hpp"

#include <algorithm>
#include <span>

#include "block_writer.hpp"
#include "gdal_layer.hpp"
#include "loci/geom/error.hpp"
#include "loci/index/detail/large_alloc.hpp"
#include "loci/index/segment_intersections.hpp"
#include "loci/io/atomic_file.hpp"
#include "loci/io/layer_reader.hpp"

namespace loci::io {

Linework::Linework(const std::vector<SegmentRecord>& recs) {
  segs.reserve(recs.size());
  fid.reserve(recs.size());
  // A repeated vertex (a segment of length zero) is left out of its line when the line has
  // segments of some length: it lies on both of its neighbours, so it meets nothing they do
  // not, and kept it would part them, and their shared vertex would read as the line crossing
  // itself. A line that is one point repeated keeps one such segment.
  for (std::size_t i = 0; i < recs.size();) {
    std::size_t j = i;
    bool any_length = recs[i].segment.a != recs[i].segment.b;
    while (j + 1 < recs.size() && recs[j + 1].fid == recs[i].fid &&
           recs[j + 1].part == recs[i].part) {
      ++j;
      any_length = any_length || recs[j].segment.a != recs[j].segment.b;
    }
    const auto begin = std::uint32_t(segs.size());
    for (std::size_t k = i; k <= j; ++k) {
      if (any_length && recs[k].segment.a == recs[k].segment.b) continue;
      segs.push_back(recs[k].segment);
      fid.push_back(recs[k].fid);
      if (!any_length) break;
    }
    const auto end = std::uint32_t(segs.size());
    for (std::uint32_t k = begin; k < end; ++k) {
      first.push_back(begin);
      last.push_back(end - 1);
    }
    i = j + 1;
  }
}

namespace {

// A layer whose features are all points has no linework to intersect: answering "no
// intersections" would read as if its lines did not cross, so it is refused. (A layer
// without features has nothing to intersect either way and answers nothing.)
void check_has_linework(const Linework& l, const std::string& path, const std::string& name) {
  if (!l.segs.empty()) return;
  const std::size_t features = read_envelopes(path, name).size();
  if (features > 0)
    throw InvalidArgument(path + ": no lines or polygon rings to intersect (its " +
                          std::to_string(features) +
                          (features == 1 ? " feature is a point" : " features are points") + ")");
}

}  // namespace

std::vector<IntersectionRow> find_intersections(const IntersectionsOptions& o,
                                                std::string* system) {
  std::string left_system;
  const Linework left(read_segments(o.layer_path, o.layer_name, o.progress, &left_system));
  check_has_linework(left, o.layer_path, o.layer_name);
  if (system) *system = left_system;
  // The layer given twice (however its path is spelled, and by name or as the default first
  // layer) is the layer against itself.
  if (o.other_path.empty() ||
      detail::same_layer(o.layer_path, o.layer_name, o.other_path, o.other_name))
    return intersection_rows(left, nullptr, o.pairs_only, o.jobs);
  std::string right_system;
  const Linework right(read_segments(o.other_path, o.other_name, o.progress, &right_system));
  check_has_linework(right, o.other_path, o.other_name);
  detail::check_same_system(detail::layer_label(o.layer_path, o.layer_name), left_system,
                            detail::layer_label(o.other_path, o.other_name), right_system);
  return intersection_rows(left, &right, o.pairs_only, o.jobs);
}

std::vector<IntersectionRow> intersection_rows(const Linework& left, const Linework* other,
                                               bool pairs_only, unsigned jobs) {
  // Each thread keeps its own rows, sorted and made unique on that thread, then merged.
  using Rows = loci::detail::LargeVector<IntersectionRow>;
  const unsigned threads = loci::detail::thread_count(jobs);
  std::vector<Rows> parts(threads);
  auto add = [&parts, pairs_only](unsigned k, std::int64_t a, std::int64_t b,
                                  const SegmentIntersection& x) {
    Rows& rows = parts[k];
    if (pairs_only) {
      rows.push_back({a, b, {0, 0}});
      return;
    }
    rows.push_back({a, b, x.a});
    if (x.kind == SegmentMeet::overlap) rows.push_back({a, b, x.b});
  };
  if (!other) {
    segment_intersections_parallel(
        std::span<const Segment2>(left.segs), [&](Id i, Id j) { return left.adjacent(i, j); },
        threads,
        [&](unsigned k) {
          return [&, k](Id i, Id j, const SegmentIntersection& x) {
            add(k, std::min(left.fid[i], left.fid[j]), std::max(left.fid[i], left.fid[j]), x);
            return true;
          };
        });
  } else {
    const Linework& right = *other;
    segment_intersections_parallel(std::span<const Segment2>(left.segs),
                                   std::span<const Segment2>(right.segs), threads, [&](unsigned k) {
                                     return [&, k](Id i, Id j, const SegmentIntersection& x) {
                                       add(k, left.fid[i], right.fid[j], x);
                                       return true;
                                     };
                                   });
  }
  loci::detail::for_rows(threads, threads, [&](std::uint32_t k, unsigned) {
    std::sort(parts[k].begin(), parts[k].end());
    parts[k].erase(std::unique(parts[k].begin(), parts[k].end()), parts[k].end());
    return true;
  });
  std::vector<IntersectionRow> rows(parts[0].begin(), parts[0].end());
  for (unsigned k = 1; k < threads; ++k) {
    std::vector<IntersectionRow> merged(rows.size() + parts[k].size());
    std::merge(rows.begin(), rows.end(), parts[k].begin(), parts[k].end(), merged.begin());
    merged.erase(std::unique(merged.begin(), merged.end()), merged.end());
    rows.swap(merged);
  }
  return rows;
}

std::size_t write_intersections(const IntersectionsOptions& o, std::FILE* fallback) {
  if (o.format == Format::ids)
    throw InvalidArgument("loci intersections writes csv or geojson, not ids");
  refuse_overwriting(o.out_path, o.layer_path);
  refuse_overwriting(o.out_path, o.other_path);
  std::string system;
  const std::vector<IntersectionRow> rows = find_intersections(o, &system);
  OutputFile out(o.out_path, fallback);
  std::FILE* f = out.stream();
  if (o.format == Format::csv) {
    std::fputs(o.pairs_only ? "fid_a,fid_b\n" : "fid_a,fid_b,x,y\n", f);
    for (const auto& r : rows) {
      if (o.pairs_only)
        std::fprintf(f, "%lld,%lld\n", (long long)r.fid_a, (long long)r.fid_b);
      else
        std::fprintf(f, "%lld,%lld,%s\n", (long long)r.fid_a, (long long)r.fid_b,
                     detail::shortest_pair(r.p[0], r.p[1]).c_str());
    }
  } else {
    // The points are in the (first) layer's coordinates: a reader must know which.
    const std::string crs = detail::geojson_crs_member(system);
    std::fprintf(f, "{\"type\":\"FeatureCollection\",%s\"features\":[", crs.c_str());
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const auto& r = rows[k];
      std::fprintf(f, "%s\n{\"type\":\"Feature\",\"properties\":{\"fid_a\":%lld,\"fid_b\":%lld},",
                   k ? "," : "", (long long)r.fid_a, (long long)r.fid_b);
      if (o.pairs_only)
        std::fputs("\"geometry\":null}", f);
      else
        std::fprintf(f, "\"geometry\":{\"type\":\"Point\",\"coordinates\":[%s]}}",
                     detail::shortest_pair(r.p[0], r.p[1]).c_str());
    }
    std::fputs("\n]}\n", f);
  }
  out.commit();
  return rows.size();
}

}  // namespace loci::io
