// The machinery of the `loci` command line shared by its two programs: flags declared once
// per command (the table that `--help` prints, so the help cannot drift from what is accepted),
// their parsing, progress bars, and running a command with its one-line failure and exit 1.
//
// `loci` (front.cpp) runs the queries a sidecar answers and `loci check` without loading GDAL,
// and hands every other command to `loci-full` (loci.cpp), the whole table, which loads it.
#pragma once

#include <cstddef>
#include <initializer_list>
#include <map>
#include <string>
#include <vector>

#include "loci/geom/error.hpp"
#include "loci/io/commands.hpp"
#include "loci/io/output.hpp"

namespace loci::cli {

struct Flag {
  const char* name;   // "--bbox"
  const char* alias;  // "-b" or nullptr
  const char* value;  // "XMIN,YMIN,XMAX,YMAX", nullptr for a switch
  const char* help;
  // For --output: the output is text that may go to stdout, so `-o -` means stdout (commands
  // that write a file refuse it).
  bool stdout_allowed = false;
};

struct Args {
  std::vector<std::string> positional;
  std::map<std::string, std::string> values;  // by long name
  bool has(const char* name) const { return values.count(name) != 0; }
  std::string get(const char* name, const std::string& fallback = {}) const {
    auto it = values.find(name);
    return it == values.end() ? fallback : it->second;
  }
};

struct Command {
  const char* name;
  const char* usage;
  const char* summary;
  std::vector<Flag> flags;
  const char* examples;
  int (*run)(const Args&);
};

class UsageError : public loci::Error {
 public:
  using Error::Error;
};

// The largest -k.
inline constexpr std::size_t kMaxK = 1000000;

// Flags several commands share.
extern const Flag kLayer, kQuiet, kStructure, kPer, kIndex;

// Progress on stderr, only on a terminal and without -q.
io::Progress progress_bar(const Args& a, const char* what);

const std::string& layer_arg(const Args& a, const char* command, const char* what = "LAYER");

// A whole number in [lo, hi] given to `flag`; the error names the flag and the range.
std::size_t parse_count(const char* flag, const std::string& text, std::size_t lo, std::size_t hi);

// A flag's value run through the io parser that owns its vocabulary, the message prefixed
// with the flag's name.
template <class Parse>
auto parse_flag(const char* flag, const std::string& text, Parse parse) {
  try {
    return parse(text);
  } catch (const loci::Error& e) {
    throw UsageError(std::string(flag) + ": " + e.what());
  }
}

io::LoadOptions load_options(const Args& a, const std::string& layer);

// What the name of an output file says it holds, by its extension: "csv" (.csv), "geojson"
// (.geojson, .json), "svg" (.svg), "loci" (a sidecar), the extension itself (".shp") for a
// dataset or image format the command line writes only through `loci clip`, or "" where it
// says nothing (.txt, no extension, a device).
std::string format_named_by(const std::string& out);

// The answer format of a text output: -f where given, else the one -o's name says when
// `choices` holds it (`loci query -o near.geojson` writes GeoJSON), else `fallback`. A -f
// outside `choices` is refused, and so is a name saying another format than the one chosen
// (ids rows are not CSV), so that no file says it is what it is not (`-o pairs.shp` of CSV).
io::Format output_format(const Args& a, std::initializer_list<io::Format> choices,
                         io::Format fallback);

// For an output of one format ("svg", "csv", "loci"): refused when -o's name says another.
void check_output_name(const Args& a, const char* format);

void print_command_help(const Command& c);

// The exit status after help was printed: 0, or 1 (said in one line) when it did not reach
// stdout (a full disk, a closed pipe).
int help_status();

// The arguments argv[first, argc) of command c; throws UsageError naming what is wrong.
Args parse(const Command& c, int first, int argc, char** argv);

// Runs command c on argv[first, argc): its help for -h or --help; else parsed, `before` called
// (when given) and run, a failure said as one line `loci: error: ...` on stderr with status 1,
// as is output that did not reach stdout. Returns the exit status.
int run_command(const Command& c, int first, int argc, char** argv,
                void (*before)(const Command&, const Args&) = nullptr);

// `loci check` (check_command.cpp), which needs no GDAL.
const Command& check_command();

// `loci query`: the command, and its options (the query file read when `read_queries`).
const Command& query_command();
io::QueryOptions query_options(const Args& a, bool read_queries);

}  // namespace loci::cli
