// loci: the command users run. A query its sidecar answers (per segment, or --candidates; FIDs
// on stdout or into a new file) runs here, without GDAL: loading GDAL's libraries takes about
// 30 ms, several times such a query; so does `loci check`, which reads only the sidecar and the
// layer's files. So does a query per feature of a shapefile, whose records are read directly
// (shapefile_records.hpp), when its queries come from the command line or a regular file: a
// record only GDAL reads hands the command over then, before anything is written, and
// loci-full reads the queries again. Every other command, and a query that needs the layer or
// GDAL (a stale or missing sidecar, one per feature of another format, csv or GeoJSON output,
// -o onto a file that is there), is handed to loci-full with the same arguments (exec): it has
// every command and GDAL, and says what is wrong with a command.
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "command_line.hpp"

namespace {

using namespace loci::cli;

// The sidecar this process answers from (answers_without_gdal's), loaded once: the query
// file is read after it was chosen, and nothing can be handed over from then on, except per
// feature (features_here), where the queries came from the command line or a regular file
// that loci-full reads again.
std::optional<loci::io::LoadedIndex> g_loaded;

// Whether this process answers: a `loci query` its sidecar answers without GDAL (g_loaded set).
// Parses the arguments and opens the sidecar, but reads no query file and writes nothing, so
// that a command handed over starts afresh (a query file on a pipe is read once).
bool answered_here(int argc, char** argv) {
  if (argc < 3 || std::strcmp(argv[1], "query") != 0) return false;
  for (int i = 2; i < argc; ++i)
    if (!std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h")) return false;
  try {
    const Args a = parse(query_command(), 2, argc, argv);
    // The queries can be read again by loci-full when none comes from a file other than a
    // regular one (a pipe, a terminal, a FIFO is read once), named otherwise than as one of
    // this process's descriptors (/dev/stdin, /dev/fd/N, /proc/self/fd/N: outside Linux,
    // opening those shares the offset this process's read left at the end).
    bool rereadable = true;
    for (const char* file : {"--bbox-file", "--nearest-file", "--point-file"}) {
      if (!a.has(file)) continue;
      const std::string name = a.get(file);
      struct stat st {};
      rereadable &= ::stat(name.c_str(), &st) == 0 && S_ISREG(st.st_mode) &&
                    name.rfind("/dev/", 0) != 0 && name.rfind("/proc/", 0) != 0;
    }
    g_loaded = loci::io::answers_without_gdal(query_options(a, false), rereadable);
    return g_loaded.has_value();
  } catch (...) {  // loci-full says what is wrong
    return false;
  }
}

[[noreturn]] void hand_over(char** argv);
char** g_argv = nullptr;

int run_query_here(const Args& a) {
  loci::io::QueryOptions o = query_options(a, true);
  o.loaded = g_loaded;
  try {
    loci::io::query_layer(o, stdout);
  } catch (const loci::io::NeedsGdal&) {
    // A feature only GDAL reads: nothing was written, and loci-full reads the queries again.
    if (g_loaded->features_here) hand_over(g_argv);
    throw;
  }
  return 0;
}

// Runs loci-full in place of this process: beside this program (the build tree), or where it
// is installed (LOCI_FULL_FROM_BIN, relative to the directory of programs). Without
// /proc/self/exe to say where this program is, only the path of the install prefix configured
// (LOCI_FULL_INSTALLED) is tried, never a file the current directory happens to hold.
[[noreturn]] void hand_over(char** argv) {
  std::vector<std::string> places;
  char buf[PATH_MAX];
  if (const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1); n > 0) {
    std::string dir(buf, std::size_t(n));
    dir.resize(dir.rfind('/') + 1);
    places = {dir + "loci-full", dir + LOCI_FULL_FROM_BIN + "/loci-full"};
  } else {
    places = {LOCI_FULL_INSTALLED};
  }
  // The failure told is the first that is not a missing file, else the last place's.
  std::string failed;
  int error = 0;
  for (const std::string& full : places) {
    ::execv(full.c_str(), argv);
    if (failed.empty() || error == ENOENT) failed = full, error = errno;
  }
  std::fprintf(stderr, "loci: error: cannot run %s (%s): loci is not installed whole\n",
               failed.c_str(), std::strerror(error));
  std::exit(1);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 2 && !std::strcmp(argv[1], "check"))
    return run_command(check_command(), 2, argc, argv);
  g_argv = argv;
  if (answered_here(argc, argv)) {
    Command here = query_command();
    here.run = run_query_here;
    return run_command(here, 2, argc, argv);
  }
  hand_over(argv);
}
