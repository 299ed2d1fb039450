// `loci check`: its flags and its run (check_sidecar needs no GDAL: the front runs it too).
#include <cstdio>

#include "command_line.hpp"

namespace loci::cli {

namespace {

int run_check(const Args& a) {
  const std::string out = io::check_sidecar(layer_arg(a, "check", "FILE.loci | LAYER"));
  std::printf("%s\n", out.c_str());
  return 0;
}

}  // namespace

const Command& check_command() {
  static const Command command = {
      "check",
      "loci check FILE.loci | LAYER",
      "verifies a sidecar index completely: every checksum and the tree's invariants, and that "
      "the layer it is named after (FILE) has not changed since",
      {},
      "  loci check countries.shp.loci\n  loci check countries.shp      (its sidecar "
      "countries.shp.loci)\n",
      run_check};
  return command;
}

}  // namespace loci::cli
