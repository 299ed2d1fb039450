// What the fuzz targets share: a scratch file of this process for inputs that the code under
// test reads by path, and the rule that loci may fail only by throwing loci::Error (anything
// else escaping, a crash, a leak or a sanitizer report is a finding).
#pragma once

#include <unistd.h>

#include <cctype>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

namespace loci::fuzz {

namespace detail {

// Removes this process's scratch files (those of every suffix) when it exits.
struct ScratchCleanup {
  ScratchCleanup() = default;
  ScratchCleanup(const ScratchCleanup&) = delete;
  ScratchCleanup& operator=(const ScratchCleanup&) = delete;
  ~ScratchCleanup() {
    const std::string mine = "loci-fuzz-" + std::to_string(::getpid());
    std::error_code ec;
    std::vector<std::filesystem::path> found;
    for (const auto& e : std::filesystem::directory_iterator("/tmp", ec)) {
      const std::string name = e.path().filename().string();
      // Not another process's whose id starts with the same digits.
      if (name.compare(0, mine.size(), mine) == 0 &&
          (name.size() == mine.size() ||
           !std::isdigit(static_cast<unsigned char>(name[mine.size()]))))
        found.push_back(e.path());
    }
    for (const auto& p : found)
      std::filesystem::remove(p, ec);
  }
};

}  // namespace detail

// A path under /tmp unique to this process, ending in `suffix`; removed when the process exits
// (with any other file made from it by appending to it).
inline std::string scratch_path(const char* suffix) {
  static detail::ScratchCleanup cleanup;
  return "/tmp/loci-fuzz-" + std::to_string(::getpid()) + suffix;
}

inline void write_file(const std::string& path, const std::uint8_t* data, std::size_t size) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
}

}  // namespace loci::fuzz
