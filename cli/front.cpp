// loci: the command users run. A query its sidecar answers (per segment, or --candidates; FIDs
// on stdout) runs here, without GDAL: loading GDAL's libraries takes about 30 ms, several times
// such a query. Every other command, and a query that needs the layer (a stale or missing
// sidecar, one per feature, csv or GeoJSON output, -o), is handed to loci-full with the same
// arguments (exec): it has every command and GDAL, and says what is wrong with a command.
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <string>

#include "command_line.hpp"

namespace {

using namespace loci::cli;

// Whether this process answers: a `loci query` its sidecar answers without GDAL. Parses the
// arguments and opens the sidecar, but reads no query file and writes nothing, so that a
// command handed over starts afresh (a query file on a pipe is read once).
bool answered_here(int argc, char** argv) {
  if (argc < 3 || std::strcmp(argv[1], "query") != 0) return false;
  for (int i = 2; i < argc; ++i)
    if (!std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h")) return false;
  try {
    const Args a = parse(query_command(), 2, argc, argv);
    return loci::io::answers_without_gdal(query_options(a, false));
  } catch (...) {  // loci-full says what is wrong
    return false;
  }
}

// The directory this program is in, with its trailing '/'.
std::string own_directory() {
  char buf[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return "./";
  const std::string path(buf, std::size_t(n));
  return path.substr(0, path.rfind('/') + 1);
}

// Runs loci-full in place of this process: beside this program (the build tree), or where it
// is installed (LOCI_FULL_FROM_BIN, relative to the directory of programs).
[[noreturn]] void hand_over(char** argv) {
  const std::string dir = own_directory();
  const std::string places[] = {dir + "loci-full", dir + LOCI_FULL_FROM_BIN + "/loci-full"};
  int error = 0;
  for (const std::string& full : places) {
    ::execv(full.c_str(), argv);
    if (!error || errno != ENOENT) error = errno;
  }
  std::fprintf(stderr, "loci: error: cannot run %s (%s): loci is not installed whole\n",
               places[1].c_str(), std::strerror(error));
  std::exit(1);
}

}  // namespace

int main(int argc, char** argv) {
  if (answered_here(argc, argv)) return run_command(query_command(), 2, argc, argv);
  hand_over(argv);
}
