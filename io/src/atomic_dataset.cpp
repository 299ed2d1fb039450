// Datasets written through GDAL whole or not at all (AtomicDataset), and the guard against
// replacing a file of several layers: see atomic_file.hpp.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <system_error>
#include <vector>

#include <cpl_error.h>
#include <cpl_string.h>
#include <cpl_vsi.h>
#include <gdal.h>
#include <ogr_api.h>

#include "loci/geom/error.hpp"
#include "loci/io/atomic_file.hpp"
#include "shapefile_names.hpp"

namespace fs = std::filesystem;

namespace loci::io {

AtomicDataset::AtomicDataset(const std::string& path) : path_(path) {
  static std::atomic<unsigned> counter{0};
  std::error_code ec;
  if (fs::is_directory(fs::status(path, ec)))
    throw Error("cannot write " + path + " (it is a directory)");
  refuse_replacing_layers(path);
  // GDAL writes into memory: its drivers do not report every failed write to disk, so the files
  // go to disk afterwards through AtomicFile, every write checked.
  dir_ = "/vsimem/loci-dataset-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
  VSIMkdir(dir_.c_str(), 0755);
  staging_ = dir_ + "/" + fs::path(path).filename().string();
}

AtomicDataset::~AtomicDataset() {
  VSIRmdirRecursive(dir_.c_str());
}

void AtomicDataset::commit() {
  std::vector<std::string> names;
  if (char** list = VSIReadDir(dir_.c_str())) {
    for (char** n = list; *n; ++n)
      if (std::strcmp(*n, ".") != 0 && std::strcmp(*n, "..") != 0) names.emplace_back(*n);
    CSLDestroy(list);
  }
  std::sort(names.begin(), names.end());
  const fs::path target = path_;
  std::string main_name = target.filename().string();
  if (std::find(names.begin(), names.end(), main_name) == names.end()) {
    // The shapefile driver writes X.shp for X.SHP: its file goes to the name asked for (the
    // companions keep the driver's names, which readers look for in either case).
    const auto same_but_case = std::find_if(names.begin(), names.end(), [&](const std::string& n) {
      return n.size() == main_name.size() && EQUAL(n.c_str(), main_name.c_str());
    });
    if (same_but_case == names.end())
      throw Error("cannot write " + path_ + " (the driver wrote no file of that name)");
    main_name = *same_but_case;
  }
  std::error_code ec;
  const fs::file_status st = fs::status(target, ec);
  const bool device = fs::is_character_file(st) || fs::is_fifo(st) || fs::is_socket(st);
  if (device && names.size() > 1)
    throw Error("cannot write " + path_ + " (the format writes " + std::to_string(names.size()) +
                " files, a device or pipe takes one)");
  // Every file whole under its temporary name first, then all renamed.
  std::vector<std::unique_ptr<AtomicFile>> files;
  for (const auto& name : names) {
    files.push_back(std::make_unique<AtomicFile>(
        name == main_name ? path_ : (target.parent_path() / name).string()));
    vsi_l_offset size = 0;
    const GByte* data = VSIGetMemFileBuffer((dir_ + "/" + name).c_str(), &size, FALSE);
    std::FILE* f = files.back()->stream();
    if (size && std::fwrite(data, 1, std::size_t(size), f) != std::size_t(size))
      throw Error("cannot write " + path_ + " (" + std::strerror(errno ? errno : EIO) + ")");
  }
  for (auto& f : files)
    f->commit();
  if (!device && detail::shapefile_companion(target.extension().string())) {
    const std::string stem = target.stem().string();
    for (const auto& e :
         fs::directory_iterator(target.parent_path().empty() ? "." : target.parent_path(), ec)) {
      const std::string n = e.path().filename().string();
      const std::string x = detail::extension_after(n, stem);
      // The driver's name for the main file (x.shp for X.SHP) was written under the target's.
      const bool written =
          n == target.filename().string() ||
          (n != main_name && std::find(names.begin(), names.end(), n) != names.end());
      if (!x.empty() && detail::shapefile_companion(x) && !written) fs::remove(e.path(), ec);
    }
  }
}

void refuse_replacing_layers(const std::string& out) {
  std::error_code ec;
  if (!fs::is_regular_file(fs::status(out, ec))) return;
  GDALAllRegister();  // also where the command has read nothing through GDAL
  CPLPushErrorHandler(CPLQuietErrorHandler);
  // A format of one layer (GeoJSON, a shapefile, CSV) is replaced without being read: opening
  // a big GeoJSON would parse all of it.
  GDALDriverH driver =
      GDALIdentifyDriverEx(out.c_str(), GDAL_OF_VECTOR | GDAL_OF_RASTER, nullptr, nullptr);
  if (!driver || (!GDALGetMetadataItem(driver, GDAL_DCAP_MULTIPLE_VECTOR_LAYERS, nullptr) &&
                  !GDALGetMetadataItem(driver, GDAL_DCAP_RASTER, nullptr))) {
    CPLPopErrorHandler();
    return;
  }
  GDALDatasetH ds = GDALOpenEx(out.c_str(), GDAL_OF_VECTOR | GDAL_OF_RASTER | GDAL_OF_READONLY,
                               nullptr, nullptr, nullptr);
  CPLPopErrorHandler();
  if (!ds) return;  // not a dataset GDAL reads: replaced as any file is
  const int layers = GDALDatasetGetLayerCount(ds);
  const bool rasters =
      GDALGetRasterCount(ds) > 0 || CSLCount(GDALGetMetadata(ds, "SUBDATASETS")) > 0;
  std::string names;
  for (int i = 0; i < layers && i < 4; ++i)
    names += std::string(i ? ", " : "") + OGR_L_GetName(GDALDatasetGetLayer(ds, i));
  if (layers > 4) names += ", ...";
  GDALClose(ds);
  if (layers <= 1 && !rasters) return;
  std::string held = layers > 1 ? std::to_string(layers) + " layers (" + names + ")" : "";
  if (rasters) held += std::string(held.empty() ? "" : " and ") + "raster data";
  throw Error("refusing to write " + out + ": it holds " + held +
              ", which writing the whole file would lose; name another file");
}

}  // namespace loci::io
