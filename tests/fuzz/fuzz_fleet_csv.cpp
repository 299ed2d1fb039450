// Fuzz target: the planar fleet CSV reader (id,t,x,y[,vx,vy]) on arbitrary text, from memory.
// Bad text must be refused with a loci::Error; whatever is read must be sorted by (id, t),
// finite and within the coordinate range.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "loci/geom/error.hpp"
#include "loci/io/fleet.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const loci::io::FleetData d = loci::io::read_fleet_csv(text, "fuzz.csv");
    for (std::size_t i = 0; i < d.reports.size(); ++i) {
      const auto& r = d.reports[i];
      if (!loci::within_coordinate_range(r.m.p) || !loci::within_coordinate_range(r.m.v) ||
          !std::isfinite(r.m.t))
        std::abort();
      if (i > 0 && (d.reports[i - 1].id > r.id ||
                    (d.reports[i - 1].id == r.id && !(d.reports[i - 1].m.t < r.m.t))))
        std::abort();
    }
    loci::io::in_force(d.reports, d.latest());
  } catch (const loci::Error&) {
  }
  return 0;
}
