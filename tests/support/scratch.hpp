// A file or directory of one test process in the system's temporary directory, removed with
// whatever it holds when the object goes away (also after a failed assertion left the test
// early), so that running the suite again and again leaves nothing behind.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>
#include <utility>

namespace loci::test {

class Scratch {
 public:
  // `<temp>/<stem>-<pid><suffix>`, removed first if an earlier process of the same id left it.
  explicit Scratch(const std::string& stem, const std::string& suffix = "")
      : path_(std::filesystem::temp_directory_path() /
              (stem + "-" + std::to_string(::getpid()) + suffix)) {
    remove();
  }
  Scratch(Scratch&& other) noexcept : path_(std::exchange(other.path_, {})) {}
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
  Scratch& operator=(Scratch&&) = delete;
  ~Scratch() { remove(); }

  const std::filesystem::path& path() const { return path_; }
  std::string str() const { return path_.string(); }

 private:
  void remove() const {
    std::error_code ignored;
    if (!path_.empty()) std::filesystem::remove_all(path_, ignored);
  }
  std::filesystem::path path_;
};

}  // namespace loci::test
