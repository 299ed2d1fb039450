// loci: the command users run. A query its sidecar answers (per segment, or --candidates; FIDs
// on stdout or into a new file) runs here, without GDAL: loading GDAL's libraries takes about
// 30 ms, several times such a query; so does `loci check`, which reads only the sidecar and the
// layer's files. So does a query per feature of a shapefile, whose records are read directly
// (shapefile_records.hpp): a record only GDAL reads hands the command over then, before
// anything is written, and loci-full reads the queries again (from a pipe, a copy in memory the
// front made). Every other command, and a query that needs the layer or
// GDAL (a stale or missing sidecar, one per feature of another format, csv or GeoJSON output,
// -o onto a file that is there), is handed to loci-full with the same arguments (exec): it has
// every command and GDAL, and says what is wrong with a command.
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdint>
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
// feature (features_here), where loci-full reads the queries again: from the command line, a
// regular file, or a copy in memory of a file read once.
std::optional<loci::io::LoadedIndex> g_loaded;

// The arguments run with: those given, where a query file read once (a pipe, a terminal, a
// FIFO, a file named as a descriptor such as /dev/stdin) may be replaced by the copy made of
// it; and the name given for each copy's.
std::vector<std::string> g_args;
std::vector<char*> g_argv;
std::vector<std::pair<std::string, std::string>> g_copies;

const char* const kQueryFiles[] = {"--bbox-file", "--nearest-file", "--point-file"};

// Reading a query file failed after some of it was read: the command cannot be handed over.
struct CopyFailed : loci::Error {
  using loci::Error::Error;
};

// A copy of the file `name` in memory, named so that a program this process becomes (exec)
// opens it afresh: /proc/self/fd/N, the descriptor left open across exec. nullopt where that
// cannot be made, decided before `name` is opened (opening a FIFO takes its writer's lines):
// no memory files or no /proc; `name` missing or a directory (loci-full says so). Throws
// CopyFailed when reading or copying fails midway (what was read is gone).
std::optional<std::string> copy_in_memory(const std::string& name) {
#if defined(__linux__)
  struct stat st {};
  if (::stat(name.c_str(), &st) != 0 || S_ISDIR(st.st_mode)) return std::nullopt;
  const int copy = ::memfd_create("loci-queries", 0);  // not MFD_CLOEXEC: loci-full opens it
  if (copy < 0) return std::nullopt;
  const std::string copy_name = "/proc/self/fd/" + std::to_string(copy);
  const int in =
      ::access(copy_name.c_str(), R_OK) == 0 ? ::open(name.c_str(), O_RDONLY | O_CLOEXEC) : -1;
  if (in < 0) {  // no /proc, or `name` gone meanwhile: nothing was read
    ::close(copy);
    return std::nullopt;
  }
  const auto fail = [&](const char* what, int error) {
    ::close(in);
    ::close(copy);
    throw CopyFailed(name + ": " + what + " (" + std::strerror(error) + ")");
  };
  char buf[1 << 16];
  // A line longer than read_query_file takes is refused here already: memory files are
  // outside the process's address-space limit, and an endless stream without a newline would
  // fill the machine's memory.
  std::size_t line = 1, length = 0;
  // Nor does the copy grow past the process's address-space limit (ulimit -v), which loci-full
  // reading it again would meet: an endless stream of good lines stops there, said so.
  struct rlimit limit {};
  const std::uint64_t most = ::getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY
                                 ? std::uint64_t(limit.rlim_cur)
                                 : UINT64_MAX;
  std::uint64_t total = 0;
  for (;;) {
    const ssize_t n = ::read(in, buf, sizeof buf);
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("cannot read the query file", errno);
    }
    total += std::uint64_t(n);
    if (total > most) {
      ::close(in);
      ::close(copy);
      throw CopyFailed(name + ": larger than the memory this process may use (ulimit -v)");
    }
    for (const char* at = buf; at < buf + n;) {
      const char* nl = static_cast<const char*>(std::memchr(at, '\n', std::size_t(buf + n - at)));
      length += std::size_t((nl ? nl : buf + n) - at);
      if (length > loci::io::kQueryLineLimit) {
        ::close(in);
        ::close(copy);
        throw CopyFailed(loci::io::query_line_too_long(name, line));
      }
      if (!nl) break;
      ++line, length = 0, at = nl + 1;
    }
    for (ssize_t at = 0; at < n;) {
      const ssize_t w = ::write(copy, buf + at, std::size_t(n - at));
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) fail("cannot copy the query file into memory", w < 0 ? errno : EIO);
      at += w;
    }
  }
  ::close(in);
  return copy_name;
#else
  (void)name;
  return std::nullopt;
#endif
}

// Replaces the value of every query-file option named in `once` in g_args by a copy in memory
// of that file, walking the arguments as parse() does (`--bbox-file F`, `--bbox-file=F`).
// False when a copy cannot be made (the arguments are then left as given).
bool copy_query_files(const Command& c, const std::vector<std::string>& once) {
  bool copied = true;
  for (std::size_t i = 2; copied && i < g_args.size(); ++i) {
    const std::string arg = g_args[i];
    if (arg.size() < 2 || arg[0] != '-') continue;
    const std::size_t eq = arg.rfind("--", 0) == 0 ? arg.find('=') : std::string::npos;
    const std::string name = arg.substr(0, eq);
    const Flag* flag = nullptr;
    for (const Flag& f : c.flags)
      if (name == f.name || (f.alias && name == f.alias)) flag = &f;
    if (!flag || !flag->value) continue;
    const std::size_t at = eq == std::string::npos ? i + 1 : i;
    if (eq == std::string::npos) ++i;  // the value that follows is no option
    if (at >= g_args.size() ||
        std::find(once.begin(), once.end(), std::string(flag->name)) == once.end())
      continue;
    const std::string file = eq == std::string::npos ? g_args[at] : arg.substr(eq + 1);
    // `-` is stdin, named as loci-full names it (parse() reads it as /dev/stdin).
    const std::string named = file == "-" ? "/dev/stdin" : file;
    const std::optional<std::string> copy = copy_in_memory(named);
    copied = copy.has_value();
    if (!copied) break;
    g_copies.emplace_back(*copy, named);
    g_args[at] = eq == std::string::npos ? *copy : name + "=" + *copy;
  }
  for (std::size_t i = 0; i < g_args.size(); ++i)
    g_argv[i] = g_args[i].data();
  return copied;
}

// Whether this process answers: a `loci query` its sidecar answers without GDAL (g_loaded set).
// Parses the arguments and opens the sidecar, but reads no query file (unless copied, above)
// and writes nothing, so that a command handed over starts afresh.
bool answered_here() {
  const int argc = int(g_args.size());
  char** argv = g_argv.data();
  if (argc < 3 || std::strcmp(argv[1], "query") != 0) return false;
  for (int i = 2; i < argc; ++i)
    if (!std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h")) return false;
  try {
    const Command c = query_command();
    const Args a = parse(c, 2, argc, argv);
    // The query files loci-full could not read again as they are: other than regular files (a
    // pipe, a terminal, a FIFO is read once), or named as one of this process's descriptors
    // (/dev/stdin, /dev/fd/N, /proc/self/fd/N: outside Linux, opening those shares the offset
    // this process's read left at the end).
    std::vector<std::string> once;
    for (const char* file : kQueryFiles) {
      if (!a.has(file)) continue;
      const std::string name = a.get(file);
      struct stat st {};
      if (::stat(name.c_str(), &st) != 0 || !S_ISREG(st.st_mode) || name.rfind("/dev/", 0) == 0 ||
          name.rfind("/proc/", 0) == 0)
        once.push_back(file);
    }
    g_loaded = loci::io::answers_without_gdal(query_options(a, false));
    // Per feature, those are copied first, for loci-full to read again (or it is handed over
    // before any is read, where they cannot be).
    if (g_loaded && g_loaded->features_here && !once.empty() && !copy_query_files(c, once))
      g_loaded.reset();
    return g_loaded.has_value();
  } catch (const CopyFailed&) {  // what was read is gone: said here
    throw;
  } catch (...) {  // loci-full says what is wrong
    return false;
  }
}

[[noreturn]] void hand_over(char** argv);

int run_query_here(const Args& a) {
  loci::io::QueryOptions o;
  try {
    o = query_options(a, true);
  } catch (const loci::Error& e) {
    // A copy in memory is named as the file it copies.
    std::string what = e.what();
    for (const auto& [copy, given] : g_copies)
      if (what.rfind(copy + ":", 0) == 0) throw loci::Error(given + what.substr(copy.size()));
    throw;
  }
  o.loaded = g_loaded;
  try {
    loci::io::query_layer(o, stdout);
  } catch (const loci::io::NeedsGdal&) {
    // A feature only GDAL reads: nothing was written, and loci-full reads the queries again.
    if (g_loaded->features_here) hand_over(g_argv.data());
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
  g_args.assign(argv, argv + argc);
  for (std::string& arg : g_args)
    g_argv.push_back(arg.data());
  g_argv.push_back(nullptr);
  try {
    if (answered_here()) {
      Command here = query_command();
      here.run = run_query_here;
      return run_command(here, 2, argc, g_argv.data());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "loci: error: %s\n", loci::io::printable(e.what()).c_str());
    return 1;
  }
  hand_over(g_argv.data());
}
