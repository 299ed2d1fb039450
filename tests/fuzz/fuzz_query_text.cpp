// Fuzz target: the text a user types or puts in a query file. The first byte picks the parser
// (bbox, point, segment, within, or a --bbox-file / --nearest-file); the rest is its input.
// Bad text must be refused with a loci::Error.
#include <cstdint>
#include <string>

#include "fuzz_support.hpp"
#include "loci/io/commands.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    switch (data[0] % 6) {
      case 0:
        loci::io::parse_bbox(text);
        break;
      case 1:
        loci::io::parse_point(text);
        break;
      case 2:
        loci::io::parse_segment(text);
        break;
      case 3:
        loci::io::parse_within(text);
        break;
      default: {
        static const std::string path = loci::fuzz::scratch_path(".queries");
        loci::fuzz::write_file(path, data + 1, size - 1);
        const auto kind =
            data[0] % 6 == 4 ? loci::io::Query::Kind::bbox : loci::io::Query::Kind::nearest;
        loci::io::read_query_file(path, kind, 3);
      }
    }
  } catch (const loci::Error&) {
  }
  return 0;
}
