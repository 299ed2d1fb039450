// Files that appear whole or not at all: every file loci writes (sidecars, query answers,
// clipped layers, drawings) goes through AtomicFile or AtomicDataset.
//
// A target that is a regular file, or does not exist yet, is written under a temporary name in
// its own directory and renamed over it by commit(), so a reader sees the old file or the whole
// new one, and a failure (a full disk, an error, a signal) leaves the old file intact:
// - the temporary name is hidden and says whose it is: `.NAME.PID.tmpXXXXXX`, with NAME
//   shortened so that the name never exceeds what the final name's directory allows;
// - its mode is the existing target's, or 0666 less the umask for a new file;
// - SIGINT, SIGTERM and SIGHUP remove the temporaries of the process before it dies; a leftover
//   of a process killed harder (SIGKILL) is removed by the next write to the same target once
//   its PID is gone.
// A symbolic link is followed: the file it points to is replaced and the link stays. A
// character device, FIFO or socket (/dev/null, /dev/stdout, a pipe) is written in place and
// never replaced. A directory is refused.
//
// AtomicDataset does the same for GDAL outputs that are several files (a shapefile's .shp,
// .shx, .dbf, .prj): GDAL writes them in memory (/vsimem/, since its drivers do not report every
// failed write to disk), and commit() writes each through an AtomicFile, every write checked,
// renames them all into place, then removes the target's old shapefile companions (.prj, .qix,
// ...) that the new dataset does not have. GDAL never sees the real target: a device or FIFO
// receives the one file of a one-file format.
#pragma once

#include <cstdio>
#include <string>

namespace loci::io {

class AtomicFile {
 public:
  // Throws loci::Error naming the target when it cannot be written.
  explicit AtomicFile(const std::string& path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  int fd() const { return fd_; }
  // A stdio stream over fd(), made on first use; commit() flushes and closes it.
  std::FILE* stream();
  // Flushes, checks every write, syncs and renames into place. Throws loci::Error naming the
  // target (the old file stays) when anything failed.
  void commit();

 private:
  std::string path_;  // the file finally written (a symbolic link resolved)
  std::string tmp_;   // empty when writing in place
  int fd_ = -1;
  std::FILE* stream_ = nullptr;
  int register_slot_ = -1;  // in the table of temporaries removed on a signal
  bool committed_ = false;
};

class AtomicDataset {
 public:
  // Throws loci::Error naming the target when its directory cannot hold the dataset.
  explicit AtomicDataset(const std::string& path);
  ~AtomicDataset();
  AtomicDataset(const AtomicDataset&) = delete;
  AtomicDataset& operator=(const AtomicDataset&) = delete;

  // Where GDAL should create the dataset.
  const std::string& staging_path() const { return staging_; }
  // Moves every file GDAL wrote into place. Call after closing the dataset.
  void commit();

 private:
  std::string path_;
  std::string dir_;  // the staging directory, in GDAL's /vsimem/
  std::string staging_;
};

// Throws loci::Error when `out` is an existing dataset holding more than one layer, or raster
// data (a GeoPackage with other tables, a KML with several folders): writing a dataset
// replaces the whole file, and would lose what loci was not asked to write. AtomicDataset's
// constructor calls it (a command constructs its output before its work, to fail early).
void refuse_replacing_layers(const std::string& out);

// Throws loci::Error when `out` is an existing file of a binary dataset (an SQLite database or
// GeoPackage, a TIFF, a shapefile's .shp, .shx or .dbf), which a text output (an answer, a
// drawing) written over it would destroy; text datasets (a GeoJSON, a CSV) are replaced, as a
// command run again replaces its answer.
void refuse_replacing_binary_dataset(const std::string& out);

// True when the two paths name one file (spelled alike, or the same file through another
// spelling, a link or a relative path).
bool same_file(const std::string& a, const std::string& b);

// Throws loci::Error when writing `out` would overwrite the layer `input` or one of its
// companion files (a shapefile's .shp, .shx, .dbf, ...): the same file, or the same stem in
// the same directory for a shapefile. The message calls `input` `what`.
void refuse_overwriting(const std::string& out, const std::string& input,
                        const char* what = "input layer");

}  // namespace loci::io
