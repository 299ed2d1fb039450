// loci::Error and its family: every failure the library reports is one of these.
//
// Messages say what was wrong and where (which coordinate, which feature, which file) so that
// a command-line user can act on the one line they see. Hot-path preconditions are assertions,
// not exceptions; these are for input that comes from outside the program.
#pragma once

#include <stdexcept>
#include <string>

namespace loci {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A coordinate is NaN or infinite, a box is inverted, a geometry is empty.
class InvalidGeometry : public Error {
 public:
  using Error::Error;
};

// A query or build parameter is out of its range (k = 0, node size 1, ...).
class InvalidArgument : public Error {
 public:
  using Error::Error;
};

}  // namespace loci
