// Fuzz target: the sidecar loader. Any bytes handed to Sidecar::open must be refused with a
// loci::Error (at open, when a query first reads a corrupt chunk, or by verify()) or give an
// index whose queries stay inside the mapping; seeds are real sidecars.
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_support.hpp"
#include "loci/io/layer_query.hpp"
#include "loci/io/sidecar.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = loci::fuzz::scratch_path(".loci");
  loci::fuzz::write_file(path, data, size);
  try {
    const auto sidecar = loci::io::Sidecar::open(path);
    const auto& tree = sidecar.tree();
    const auto records = sidecar.records();
    std::size_t seen = 0;
    tree.query(sidecar.info().bounds, [&](loci::Id id, const loci::Box2&) {
      if (id < records.size()) seen += records[id].fid & 1;
      return true;
    });
    tree.nearest({0, 0}, 3);
    sidecar.verify();
  } catch (const loci::Error&) {
  }
  // Nearest-n through the layer query (per segment: the stored feature hierarchies), from a
  // mapping verified only where the walk reads it.
  try {
    const auto index = loci::io::LayerIndex::adopt(loci::io::Sidecar::open(path));
    loci::io::LayerQuery query(index, "", "");
    std::vector<loci::io::Answer> answers;
    loci::io::Query q;
    q.kind = loci::io::Query::Kind::nearest;
    q.k = 2;
    for (const loci::Point2& p : {loci::Point2{0, 0}, loci::Point2{5.5, 5.3}, loci::Point2{3, 2}})
      for (const bool candidates : {false, true}) {
        q.point = p;
        query.run(q, 1, candidates, answers);
      }
  } catch (const loci::Error&) {
  }
  return 0;
}
