// All-or-nothing output files: see atomic_file.hpp.
#include "loci/io/atomic_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <system_error>
#include <vector>

#include "loci/geom/error.hpp"
#include "shapefile_names.hpp"

namespace fs = std::filesystem;

namespace loci::io {
namespace {

Error cannot_write(const std::string& path, int err) {
  return Error("cannot write " + path + " (" + std::strerror(err) + ")");
}

// ---- Temporaries removed on SIGINT, SIGTERM and SIGHUP ----------------------------------
// A fixed table, so that the handler touches no allocator: a slot holds a path.
struct TempSlot {
  std::atomic<bool> used{false};
  char path[PATH_MAX];
};
std::array<TempSlot, 16> g_temps;
std::atomic<bool> g_handlers{false};

extern "C" void remove_temps_and_die(int sig) {
  for (auto& slot : g_temps) {
    if (!slot.used.load()) continue;
    ::unlink(slot.path);
  }
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

void install_handlers() {
  if (g_handlers.exchange(true)) return;
  // Past a file size limit a write fails with EFBIG, which the error path cleans up after,
  // instead of the process dying with the temporary left behind.
  ::signal(SIGXFSZ, SIG_IGN);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction old {};
    ::sigaction(sig, nullptr, &old);
    if (old.sa_handler == SIG_IGN) continue;  // e.g. nohup: keep ignoring
    struct sigaction sa {};
    sa.sa_handler = remove_temps_and_die;
    sigemptyset(&sa.sa_mask);
    ::sigaction(sig, &sa, nullptr);
  }
}

int register_temp(const std::string& path) {
  install_handlers();
  if (path.size() >= PATH_MAX) return -1;
  for (std::size_t i = 0; i < g_temps.size(); ++i) {
    TempSlot& slot = g_temps[i];
    bool expected = false;
    if (slot.used.load()) continue;
    std::memcpy(slot.path, path.c_str(), path.size() + 1);
    if (slot.used.compare_exchange_strong(expected, true)) return int(i);
  }
  return -1;  // more than 16 at once: still removed on every normal path
}

void unregister_temp(int slot) {
  if (slot >= 0) g_temps[std::size_t(slot)].used.store(false);
}

// ---- Temporary names ----------------------------------------------------------------------

// The hidden prefix of every temporary for `name` in `dir`: ".NAME." with NAME cut so that the
// whole temporary name fits the directory's limit.
std::string temp_prefix(const std::string& dir, const std::string& name) {
  long limit = ::pathconf(dir.c_str(), _PC_NAME_MAX);
  if (limit <= 0) limit = 255;
  // "." + name + "." + pid (up to 10) + ".tmp" + 6 random characters
  const std::size_t room = std::size_t(limit) - 1 - 1 - 10 - 4 - 6;
  return "." + name.substr(0, std::min(name.size(), room)) + ".";
}

// Removes temporaries for the same target left by a process that no longer exists.
void remove_stale(const std::string& dir, const std::string& prefix) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string n = e.path().filename().string();
    if (n.size() <= prefix.size() + 10 || n.compare(0, prefix.size(), prefix) != 0) continue;
    const std::size_t dot = n.find(".tmp", prefix.size());
    if (dot == std::string::npos || dot + 10 != n.size()) continue;
    const std::string pid_text = n.substr(prefix.size(), dot - prefix.size());
    if (pid_text.empty() || !std::all_of(pid_text.begin(), pid_text.end(), ::isdigit)) continue;
    const long pid = std::strtol(pid_text.c_str(), nullptr, 10);
    if (pid <= 0 || (::kill(pid_t(pid), 0) == -1 && errno == ESRCH)) fs::remove_all(e.path(), ec);
  }
}

std::string temp_template(const std::string& dir, const std::string& name) {
  const std::string prefix = temp_prefix(dir, name);
  remove_stale(dir, prefix);
  return dir + "/" + prefix + std::to_string(::getpid()) + ".tmpXXXXXX";
}

std::string directory_of(const fs::path& p) {
  const fs::path parent = p.parent_path();
  return parent.empty() ? "." : parent.string();
}

mode_t new_file_mode() {
  const mode_t mask = ::umask(0);
  ::umask(mask);
  return 0666 & ~mask;
}

bool is_special_path(const std::string& path) {
  return path.rfind("/dev/", 0) == 0 || path.rfind("/proc/", 0) == 0;
}

// The descriptor of this process a path names (/dev/stdout, /dev/stderr, /dev/fd/N,
// /proc/self/fd/N), -1 for any other path.
int named_descriptor(const std::string& path) {
  if (path == "/dev/stdout") return 1;
  if (path == "/dev/stderr") return 2;
  for (const char* prefix : {"/dev/fd/", "/proc/self/fd/"}) {
    const std::size_t n = std::strlen(prefix);
    if (path.size() <= n || path.compare(0, n, prefix) != 0 || path.size() - n > 9) continue;
    int fd = 0;
    for (std::size_t i = n; i < path.size(); ++i) {
      if (path[i] < '0' || path[i] > '9') return -1;
      fd = fd * 10 + (path[i] - '0');
    }
    return fd;
  }
  return -1;
}

// A file whose first bytes are those of an SQLite database (a GeoPackage) or a TIFF: one that
// may hold several layers or raster data, which an output written over it would lose. Other
// files are replaced without asking GDAL (a sidecar index being rewritten, a text output).
bool may_hold_layers(const std::string& path) {
  unsigned char head[16] = {};
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  const std::size_t n = std::fread(head, 1, sizeof head, f);
  std::fclose(f);
  const bool sqlite = n == 16 && std::memcmp(head, "SQLite format 3", 16) == 0;
  const bool tiff =
      n >= 4 && (std::memcmp(head, "II*", 4) == 0 || std::memcmp(head, "MM\0*", 4) == 0 ||
                 std::memcmp(head, "II+", 4) == 0 || std::memcmp(head, "MM\0+", 4) == 0);
  return sqlite || tiff;
}

}  // namespace

AtomicFile::AtomicFile(const std::string& path) : path_(path) {
  // Written through the descriptor it names, where it names one of this process's: opened
  // again, the file behind it (`> out.txt`) would be truncated and written from its start,
  // over what others wrote into it before; closed, there is nothing to write to (and no file
  // is made in its place).
  if (const int named = named_descriptor(path); named >= 0) {
    fd_ = ::fcntl(named, F_DUPFD_CLOEXEC, 0);
    if (fd_ < 0) throw cannot_write(path, errno == EINVAL ? EBADF : errno);
    return;
  }
  std::error_code ec;
  fs::path target = path;
  if (fs::is_symlink(fs::symlink_status(target, ec)) && !is_special_path(path)) {
    // Followed link by link, as open() would: a link to a file not there yet is written
    // through too (weakly_canonical leaves a dangling last link unresolved).
    for (int hops = 0; fs::is_symlink(fs::symlink_status(target, ec)); ++hops) {
      if (hops == 40) throw cannot_write(path, ELOOP);
      const fs::path link = fs::read_symlink(target, ec);
      if (ec) throw cannot_write(path, ec.value());
      target = link.is_absolute() ? link : target.parent_path() / link;
    }
    target = fs::weakly_canonical(target, ec);
    if (ec) throw cannot_write(path, ec.value());
    path_ = target.string();
  }
  const fs::file_status st = fs::status(target, ec);
  if (fs::is_directory(st)) throw Error("cannot write " + path + " (it is a directory)");
  if (fs::is_block_file(st)) throw Error("cannot write " + path + " (it is a block device)");
  const bool in_place = fs::is_character_file(st) || fs::is_fifo(st) || fs::is_socket(st) ||
                        (is_special_path(path) && fs::exists(st));
  if (in_place) {
    fd_ = ::open(path.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
    if (fd_ < 0) throw cannot_write(path, errno);
    return;
  }
  if (fs::is_regular_file(st) && may_hold_layers(path_)) refuse_replacing_layers(path_);
  mode_t mode = new_file_mode();
  struct stat old {};
  if (::stat(path_.c_str(), &old) == 0) mode = old.st_mode & 07777;
  tmp_ = temp_template(directory_of(target), target.filename().string());
  fd_ = ::mkostemp(tmp_.data(), O_CLOEXEC);
  if (fd_ < 0) throw cannot_write(path, errno);
  register_slot_ = register_temp(tmp_);
  if (::fchmod(fd_, mode) != 0) {
    const int e = errno;
    ::close(fd_);
    ::unlink(tmp_.c_str());
    unregister_temp(register_slot_);
    throw cannot_write(path, e);
  }
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  if (stream_)
    std::fclose(stream_);
  else if (fd_ >= 0)
    ::close(fd_);
  if (!tmp_.empty()) {
    ::unlink(tmp_.c_str());
    unregister_temp(register_slot_);
  }
}

std::FILE* AtomicFile::stream() {
  if (!stream_) {
    stream_ = ::fdopen(fd_, "w");
    if (!stream_) throw cannot_write(path_, errno);
  }
  return stream_;
}

void AtomicFile::commit() {
  committed_ = true;
  int err = 0;
  if (stream_) {
    if (std::fflush(stream_) != 0 || std::ferror(stream_)) err = errno ? errno : EIO;
    if (!tmp_.empty() && !err && ::fsync(fd_) != 0 && errno != EINVAL) err = errno;
    if (std::fclose(stream_) != 0 && !err) err = errno;
  } else {
    if (!tmp_.empty() && ::fsync(fd_) != 0 && errno != EINVAL) err = errno;
    if (::close(fd_) != 0 && !err) err = errno;
  }
  stream_ = nullptr;
  fd_ = -1;
  if (tmp_.empty()) {
    if (err) throw cannot_write(path_, err);
    return;
  }
  if (!err && ::rename(tmp_.c_str(), path_.c_str()) != 0) err = errno;
  if (err) ::unlink(tmp_.c_str());
  unregister_temp(register_slot_);
  if (err) throw cannot_write(path_, err);
}

namespace detail {

bool shapefile_companion(const std::string& ext) {
  static const char* kinds[] = {".shp", ".shx", ".dbf", ".prj", ".cpg",    ".qix",
                                ".sbn", ".sbx", ".qpj", ".fbn", ".fbx",    ".ain",
                                ".aih", ".atx", ".ixs", ".mxs", ".shp.xml"};
  std::string e = ext;
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return std::find(std::begin(kinds), std::end(kinds), e) != std::end(kinds);
}

std::string extension_after(const std::string& name, const std::string& stem) {
  return name.size() > stem.size() && name.compare(0, stem.size(), stem) == 0 &&
                 name[stem.size()] == '.'
             ? name.substr(stem.size())
             : std::string();
}

}  // namespace detail

bool same_file(const std::string& a, const std::string& b) {
  if (a == b) return true;
  std::error_code ec;
  return fs::exists(a, ec) && fs::exists(b, ec) && fs::equivalent(a, b, ec);
}

void refuse_replacing_binary_dataset(const std::string& out) {
  std::error_code ec;
  if (!fs::is_regular_file(fs::status(out, ec))) return;
  unsigned char head[16] = {};
  std::FILE* f = std::fopen(out.c_str(), "rb");
  if (!f) return;
  const std::size_t n = std::fread(head, 1, sizeof head, f);
  std::fclose(f);
  if (n == 0) return;
  // The name of the file itself, a link followed.
  std::string ext = fs::weakly_canonical(out, ec).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  // A dBase table by its header: a version byte dBase and GDAL write, a month and a day, and a
  // header of 32 bytes per field plus 33.
  const auto dbase = [&] {
    const unsigned char versions[] = {0x02, 0x03, 0x30, 0x31, 0x32, 0x43,
                                      0x63, 0x83, 0x8b, 0xcb, 0xf5, 0xfb};
    const unsigned header = head[8] | unsigned(head[9]) << 8;
    return n == 16 &&
           std::find(std::begin(versions), std::end(versions), head[0]) != std::end(versions) &&
           head[2] <= 12 && head[3] <= 31 && header >= 33;
  };
  const char* kind = nullptr;
  if (may_hold_layers(out))
    kind = head[0] == 'S' ? "an SQLite database (a GeoPackage, say)" : "a TIFF image";
  else if (n >= 4 && std::memcmp(head, "\0\0\x27\x0a", 4) == 0)
    kind = "a shapefile's geometry or index (.shp, .shx)";
  else if (ext == ".dbf" && dbase())
    kind = "a dBase table (a shapefile's attributes)";
  if (kind)
    throw Error("refusing to write " + out + ": it is " + kind +
                ", which this text output would replace; name another file");
}

void refuse_overwriting(const std::string& out, const std::string& input, const char* what) {
  if (out.empty() || input.empty()) return;
  std::error_code ec;
  const fs::path o = fs::weakly_canonical(out, ec), i = fs::weakly_canonical(input, ec);
  bool same = fs::exists(o, ec) && fs::exists(i, ec) && fs::equivalent(o, i, ec);
  if (!same && o.parent_path() == i.parent_path()) {
    const std::string stem = i.stem().string();
    const std::string x = detail::extension_after(o.filename().string(), stem);
    same = detail::shapefile_companion(i.extension().string()) && !x.empty() &&
           detail::shapefile_companion(x);
  }
  if (same) throw Error("refusing to write " + out + ": it is the " + what + " " + input);
}

}  // namespace loci::io
