// BlockWriter: the rows of a big answer gathered into one buffer and written in blocks of
// about 64 KB, numbers appended in place (std::to_chars: integers, and doubles in their
// shortest round-trip form) rather than formatted into strings of their own or by printf.
// Write errors are the stream's, reported where the stream is committed (OutputFile).
#pragma once

#include <charconv>
#include <cstdio>
#include <initializer_list>
#include <string>

namespace loci::io::detail {

inline void append_num(std::string& out, double d) {
  char buf[32];
  out.append(buf, std::to_chars(buf, buf + sizeof buf, d).ptr);
}

// The numbers joined by commas.
inline void append_nums(std::string& out, std::initializer_list<double> values) {
  const char* sep = "";
  for (const double v : values) {
    out += sep;
    append_num(out, v);
    sep = ",";
  }
}

// The shortest text that reads back as d; two of them joined by a comma.
inline std::string shortest(double d) {
  std::string s;
  append_num(s, d);
  return s;
}
inline std::string shortest_pair(double a, double b) {
  std::string s;
  append_nums(s, {a, b});
  return s;
}

template <class Int>
void append_int(std::string& out, Int v) {
  char buf[24];
  out.append(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
}

class BlockWriter {
 public:
  explicit BlockWriter(std::FILE* f) : f_(f) { buf_.reserve(kBlock + 1024); }
  // The text not yet written; rows are appended to it.
  std::string& buf() { return buf_; }
  // After each row: writes the block once it is full.
  void row_done() {
    if (buf_.size() >= kBlock) flush();
  }
  // Writes what is left; the last call before the stream is committed.
  void flush() {
    std::fwrite(buf_.data(), 1, buf_.size(), f_);
    buf_.clear();
  }

 private:
  static constexpr std::size_t kBlock = std::size_t(1) << 16;
  std::FILE* f_;
  std::string buf_;
};

}  // namespace loci::io::detail
