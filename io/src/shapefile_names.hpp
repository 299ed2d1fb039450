// The names of a shapefile's files, shared by the writer that replaces them
// (AtomicDataset::commit, atomic_dataset.cpp) and the guard against overwriting an input
// (refuse_overwriting, atomic_file.cpp).
#pragma once

#include <string>

namespace loci::io::detail {

// Whether `ext` (".shp", ".SHX", ".shp.xml"...) is one of the files a shapefile keeps beside
// its .shp; a new dataset written over an old one must not leave the old ones (a stale .prj,
// a spatial index hiding features) behind.
bool shapefile_companion(const std::string& ext);

// ".shp" of "roads.shp", ".shp.xml" of "roads.shp.xml", relative to the stem "roads"; empty
// when `name` is not the stem and an extension.
std::string extension_after(const std::string& name, const std::string& stem);

}  // namespace loci::io::detail
