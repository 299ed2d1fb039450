// loci-quickstart LAYER [LAYER_NAME]: indexes the segments of a layer in each R-tree and
// answers a few sample window and nearest-n queries, printing what each found.
#include <chrono>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "loci/index/packed_rtree.hpp"
#include "loci/index/rstar_tree.hpp"
#include "loci/io/layer_reader.hpp"

namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

int run(const std::string& path, const std::string& layer) {
  const auto segments = loci::io::read_segments(path, layer);
  if (segments.empty()) throw loci::Error(path + ": the layer has no linework");
  std::vector<loci::Box2> boxes;
  boxes.reserve(segments.size());
  for (const auto& s : segments)
    boxes.push_back(s.segment.box());
  std::printf("%s: %zu segments\n", path.c_str(), boxes.size());

  auto t0 = std::chrono::steady_clock::now();
  const auto hilbert = loci::PackedRTree2::build(boxes, loci::Packing::hilbert);
  std::printf("  packed R-tree (Hilbert): built in %.1f ms, %d levels, %.1f bytes/box\n",
              ms_since(t0), hilbert.levels(), double(hilbert.memory_bytes()) / boxes.size());
  t0 = std::chrono::steady_clock::now();
  const auto str = loci::PackedRTree2::build(boxes, loci::Packing::str);
  std::printf("  packed R-tree (STR):     built in %.1f ms\n", ms_since(t0));
  t0 = std::chrono::steady_clock::now();
  loci::RStarTree2 rstar;
  for (std::size_t i = 0; i < boxes.size(); ++i)
    rstar.insert(boxes[i], i);
  std::printf("  R*-tree (inserted):      built in %.1f ms, height %d\n", ms_since(t0),
              rstar.height());

  const loci::Box2 extent = hilbert.bounds();
  const loci::Point2 c = extent.center();
  const double w = extent.extent(0) / 20, h = extent.extent(1) / 20;
  const loci::Box2 windows[] = {
      {{c[0] - w, c[1] - h}, {c[0] + w, c[1] + h}},
      {{extent.min[0], extent.min[1]}, {extent.min[0] + 2 * w, extent.min[1] + 2 * h}},
      {{extent.max[0] - 2 * w, extent.max[1] - 2 * h}, {extent.max[0], extent.max[1]}}};
  for (const auto& win : windows) {
    const auto stats = hilbert.query(win, [](loci::Id, const loci::Box2&) { return true; });
    const auto same_str = str.query(win).size();
    const auto same_rstar = rstar.query(win).size();
    std::printf("  window %s: %zu segments (%zu nodes visited); STR %zu, R* %zu\n",
                loci::to_string(win).c_str(), stats.results, stats.nodes_visited, same_str,
                same_rstar);
  }
  for (const auto& p : {c, extent.min}) {
    std::printf("  nearest 3 to %s:", loci::to_string(p).c_str());
    for (const auto& n : hilbert.nearest(p, 3))
      std::printf(" feature %lld at %.6g;", static_cast<long long>(segments[n.id].fid), n.distance);
    std::printf("\n");
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  constexpr const char* kUsage =
      "usage: loci-quickstart LAYER [LAYER_NAME]\n"
      "Indexes the segments of a layer in a packed R-tree (Hilbert and STR) and an R*-tree,\n"
      "and prints what a few windows and nearest-3 queries find in each.\n";
  if (argc == 2 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h")) {
    std::fputs(kUsage, stdout);
    if (std::fflush(stdout) == 0 && !std::ferror(stdout)) return 0;
    std::fprintf(stderr, "loci-quickstart: error: cannot write the help\n");
    return 1;
  }
  if (argc < 2 || argc > 3 || argv[1][0] == '-') {
    std::fputs(kUsage, stderr);
    return 1;
  }
  try {
    return run(argv[1], argc == 3 ? argv[2] : "");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "loci: error: %s\n", e.what());
    return 1;
  }
}
