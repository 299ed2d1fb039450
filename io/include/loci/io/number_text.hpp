// Numbers in text as every reader of loci's input takes them: std::from_chars in the C
// locale's format (whatever the process locale), which takes no leading plus. One plus is
// allowed before a number, not a sign after it ("+-5" is no number, nor "++5").
#pragma once

#include <string_view>

namespace loci::io::detail {

// Drops a leading '+' from s; false when another sign follows it.
inline bool drop_plus(std::string_view& s) {
  if (s.empty() || s[0] != '+') return true;
  s.remove_prefix(1);
  return s.empty() || (s[0] != '-' && s[0] != '+');
}

}  // namespace loci::io::detail
