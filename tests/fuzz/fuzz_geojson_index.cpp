// Fuzz target: a layer GDAL reads from bytes (GeoJSON through GDAL's in-memory /vsimem/),
// indexed as `loci index` does, per feature or per segment by the first byte; the sidecar it
// writes is then opened and queried. Bad layers must be refused with a loci::Error.
#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_vsi.h>

#include <cstdint>
#include <string>

#include "fuzz_support.hpp"
#include "loci/io/commands.hpp"
#include "loci/io/sidecar.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  CPLSetErrorHandler(CPLQuietErrorHandler);
  static const std::string out = loci::fuzz::scratch_path(".geojson.loci");
  const std::string layer = "/vsimem/fuzz.geojson";
  VSILFILE* f = VSIFileFromMemBuffer(layer.c_str(), const_cast<GByte*>(data + 1), size - 1, FALSE);
  if (!f) return 0;
  VSIFCloseL(f);
  try {
    loci::io::IndexOptions options;
    options.layer_path = layer;
    options.out_path = out;
    options.per = data[0] & 1 ? loci::io::Per::segment : loci::io::Per::feature;
    loci::io::index_layer(options);
    const auto sidecar = loci::io::Sidecar::open(out);
    sidecar.tree().validate();
    sidecar.tree().query(sidecar.info().bounds);
  } catch (const loci::Error&) {
  }
  VSIUnlink(layer.c_str());
  return 0;
}
