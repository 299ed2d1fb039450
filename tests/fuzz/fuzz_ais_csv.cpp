// Fuzz target: the AIS CSV reader (MarineCadastre columns) on arbitrary text, from memory,
// projection to the local frame included. Bad text must be refused with a loci::Error; every
// row is either kept or counted as skipped, and what is kept is finite.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "loci/geom/error.hpp"
#include "loci/io/fleet.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const loci::io::FleetData d = loci::io::read_ais_csv(text, "fuzz.csv");
    if (d.reports.size() + d.skipped.total() != d.rows) std::abort();
    for (const auto& r : d.reports)
      if (!loci::is_finite(r.m.p) || !loci::is_finite(r.m.v) || !std::isfinite(r.m.t)) std::abort();
    d.summary();
  } catch (const loci::Error&) {
  }
  return 0;
}
