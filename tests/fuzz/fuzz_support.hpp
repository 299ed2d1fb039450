// What the fuzz targets share: a scratch file of this process for inputs that the code under
// test reads by path, and the rule that loci may fail only by throwing loci::Error (anything
// else escaping, a crash, a leak or a sanitizer report is a finding).
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

namespace loci::fuzz {

// A path under /tmp unique to this process, ending in `suffix`.
inline std::string scratch_path(const char* suffix) {
  return "/tmp/loci-fuzz-" + std::to_string(::getpid()) + suffix;
}

inline void write_file(const std::string& path, const std::uint8_t* data, std::size_t size) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
}

}  // namespace loci::fuzz
