// The shared machinery of the `loci` command line: see command_line.hpp.
#include "command_line.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <optional>
#include <set>
#include <string_view>

#include "loci/io/atomic_file.hpp"
#include "loci/io/number_text.hpp"

namespace loci::cli {

using namespace loci::io;

// Progress on stderr, only on a terminal and without -q.
Progress progress_bar(const Args& a, const char* what) {
  if (a.has("--quiet") || !::isatty(STDERR_FILENO)) return {};
  return [what](double f) {
    const int width = 30, filled = int(f * width + 0.5);
    std::fprintf(stderr, "\r%s [%.*s%*s] %3d%%", what, filled,
                 "==============================", width - filled, "", int(f * 100 + 0.5));
    if (f >= 1.0) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  };
}

const std::string& layer_arg(const Args& a, const char* command, const char* what) {
  if (a.positional.size() != 1)
    throw UsageError(std::string("loci ") + command + " needs exactly one " + what + " (see loci " +
                     command + " --help)");
  return a.positional[0];
}

std::size_t parse_count(const char* flag, const std::string& text, std::size_t lo, std::size_t hi) {
  long long v = 0;  // signed, so that "-3" is out of range rather than not a number
  std::string_view digits = text;
  const bool plus_ok = io::detail::drop_plus(digits);  // "+3" as every number is read
  const auto r = std::from_chars(digits.data(), digits.data() + digits.size(), v);
  const std::string shown = "'" + text.substr(0, 40) + "'";
  if (!plus_ok || digits.empty() || r.ptr != digits.data() + digits.size() ||
      (r.ec != std::errc() && r.ec != std::errc::result_out_of_range))
    throw UsageError(std::string("bad ") + flag + " " + shown + ": expected a whole number from " +
                     std::to_string(lo) + " to " + std::to_string(hi));
  if (r.ec != std::errc() || v < 0 || std::size_t(v) < lo || std::size_t(v) > hi)
    throw UsageError(std::string(flag) + " must be >= " + std::to_string(lo) +
                     " and <= " + std::to_string(hi) + " (got " + shown + ")");
  return v;
}

LoadOptions load_options(const Args& a, const std::string& layer) {
  LoadOptions o;
  o.layer_path = layer;
  o.layer_name = a.get("--layer");
  o.index_path = a.get("--index");
  if (a.has("--structure"))
    o.structure = parse_flag("--structure", a.get("--structure"), parse_structure);
  if (a.has("--per")) o.per = parse_flag("--per", a.get("--per"), parse_per);
  o.progress = progress_bar(a, "indexing");
  return o;
}

std::string format_named_by(const std::string& out) {
  const std::size_t slash = out.rfind('/');
  const std::size_t dot = out.rfind('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = out.substr(dot + 1);
  for (char& c : ext)
    c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext == "csv") return "csv";
  if (ext == "geojson" || ext == "json") return "geojson";
  if (ext == "svg") return "svg";
  if (ext == "loci") return "loci";
  static const char* const kOthers[] = {
      "shp",      "shx",      "dbf",      "prj",     "cpg",   "qix",  "gpkg", "fgb",
      "kml",      "kmz",      "gml",      "gpx",     "tab",   "mif",  "gdb",  "sqlite",
      "topojson", "geojsonl", "geojsons", "parquet", "arrow", "xlsx", "ods",  "tif",
      "tiff",     "png",      "jpg",      "jpeg",    "gif",   "webp", "pdf"};
  for (const char* other : kOthers)
    if (ext == other) return "." + ext;
  return "";
}

namespace {

std::string described(const std::string& format) {
  if (format == "ids") return "feature ids";
  if (format == "csv") return "CSV";
  if (format == "geojson") return "GeoJSON";
  if (format == "svg") return "an SVG drawing";
  if (format == "loci") return "a sidecar index";
  return "a " + format + " file";
}

const char* format_name(Format f) {
  return f == Format::ids ? "ids" : f == Format::csv ? "csv" : "geojson";
}

[[noreturn]] void refuse_named_other(const std::string& out, const std::string& named,
                                     const std::string& written, bool choice) {
  throw UsageError("-o " + out + ": its name says " + described(named) + " but the output is " +
                   described(written) +
                   (choice ? " (name the file for what it holds, or choose -f)"
                           : " (name the file for what it holds)"));
}

}  // namespace

Format output_format(const Args& a, std::initializer_list<Format> choices, Format fallback) {
  const std::string out = a.get("--output");
  const std::string named = out.empty() ? "" : format_named_by(out);
  bool offered = false;  // -f could choose what the name says
  for (const Format f : choices)
    offered = offered || named == format_name(f);
  if (!a.has("--format")) {
    for (const Format f : choices)
      if (named == format_name(f)) return f;
    if (!named.empty()) refuse_named_other(out, named, format_name(fallback), offered);
    return fallback;
  }
  const std::string given = a.get("--format");
  std::optional<Format> chosen;
  std::string listed;  // "ids, csv or geojson"
  std::size_t i = 0;
  for (const Format c : choices) {
    if (given == format_name(c)) chosen = c;
    listed += std::string(i == 0 ? "" : i + 1 == choices.size() ? " or " : ", ") + format_name(c);
    ++i;
  }
  if (!chosen)
    throw UsageError("--format: '" + printable_prefix(given, 40) +
                     "' is not a format this command writes (choose " + listed + ")");
  const Format f = *chosen;
  if (!named.empty() && named != format_name(f))
    refuse_named_other(out, named, format_name(f), offered);
  return f;
}

void check_output_name(const Args& a, const char* format) {
  const std::string out = a.get("--output");
  if (out.empty()) return;
  const std::string named = format_named_by(out);
  if (!named.empty() && named != format) refuse_named_other(out, named, format, false);
}

const Flag kLayer{"--layer", nullptr, "NAME",
                  "layer of a multi-layer dataset (default: the first)"};
const Flag kQuiet{"--quiet", "-q", nullptr, "no progress bar and no summary line"};
const Flag kStructure{
    "--structure", nullptr, "S",
    "packed-hilbert (default), packed-str, rstar or rtree (the last two in memory)"};
const Flag kPer{"--per", nullptr, "feature|segment",
                "one box per feature or one per segment of the linework (loci index: per "
                "segment when features average 64 segments or more; queries without a "
                "sidecar: per feature)"};
const Flag kIndex{"--index", nullptr, "FILE", "sidecar to use (default: LAYER.loci when present)"};

void print_command_help(const Command& c) {
  std::printf("usage: %s\n\n%s\n\noptions:\n", c.usage, c.summary);
  for (const Flag& f : c.flags) {
    std::string left =
        f.alias ? std::string(f.alias) + ", " + f.name : std::string("    ") + f.name;
    if (f.value) left += std::string(" ") + f.value;
    std::printf("  %-34s %s\n", left.c_str(), f.help);
  }
  std::printf("  %-34s %s\n\nexamples:\n%s", "    --help", "this text", c.examples);
}

Args parse(const Command& c, int first, int argc, char** argv) {
  Args a;
  std::set<std::string> given;  // options with a value seen so far, by long name
  const auto find = [&](std::string_view name) -> const Flag* {
    for (const Flag& f : c.flags)
      if (name == f.name || (f.alias && name == f.alias)) return &f;
    return nullptr;
  };
  for (int i = first; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg.size() < 2 || arg[0] != '-') {
      a.positional.push_back(arg);
      continue;
    }
    const Flag* flag = find(arg);
    // A value joined to its option: --name=VALUE, or -kVALUE for a one-letter option.
    std::optional<std::string> joined;
    if (!flag) {
      const std::size_t eq = arg.find('=');
      const std::size_t at = arg.rfind("--", 0) == 0 ? eq : arg[1] != '-' ? 2 : std::string::npos;
      if (at != std::string::npos && at < arg.size()) {
        if (const Flag* f = find(std::string_view(arg).substr(0, at)); f && f->value) {
          flag = f;
          joined = arg.substr(at + (at == eq ? 1 : 0));
          arg.resize(at);
        }
      }
    }
    if (!flag)
      throw UsageError("unknown option " + arg + " for loci " + c.name + " (see loci " + c.name +
                       " --help)");
    if (!flag->value) {
      a.values[flag->name] = "";
      continue;
    }
    if (!joined && i + 1 >= argc) throw UsageError(arg + " needs a value: " + flag->value);
    const std::string value = joined ? *joined : argv[i + 1];
    if (!joined) ++i;
    // An option's value is taken once: a second one would silently replace the first (two
    // --bbox are not two windows).
    if (!given.insert(flag->name).second)
      throw UsageError(arg + " is given twice; loci " + c.name + " takes one " + flag->name);
    if (value.empty())  // `-o ""` would otherwise mean stdout or a default
      throw UsageError(arg + " needs a value: " + flag->value + ", not an empty one");
    // `-o -` is stdout, as usual, where the output is text that may go there; a command that
    // writes a file says so (a file named "-" is ./-).
    if (!std::strcmp(flag->name, "--output") && value == "-") {
      if (flag->stdout_allowed) {
        a.values.erase(flag->name);
        continue;
      }
      throw UsageError(arg + " -: loci " + c.name +
                       " writes a file, not stdout; name it (./- for a file named -)");
    }
    // A query file `-` is stdin, as usual (a file named "-" is ./-).
    const std::string_view long_name = flag->name;
    if (value == "-" && long_name.size() > 5 && long_name.ends_with("-file")) {
      a.values[flag->name] = "/dev/stdin";
      continue;
    }
    a.values[flag->name] = value;
  }
  return a;
}

int help_status() {
  if (std::fflush(stdout) == 0 && !std::ferror(stdout)) return 0;
  std::fprintf(stderr, "loci: error: cannot write the help (%s)\n",
               std::strerror(errno ? errno : EIO));
  return 1;
}

int run_command(const Command& c, int first, int argc, char** argv,
                void (*before)(const Command&, const Args&)) {
  for (int i = first; i < argc; ++i)
    if (!std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h")) {
      print_command_help(c);
      return help_status();
    }
  try {
    const Args args = parse(c, first, argc, argv);
    if (before) before(c, args);
    const int status = c.run(args);
    // Output that did not reach its destination (a full disk, a closed pipe) is a failure.
    if (std::fflush(stdout) != 0 || std::ferror(stdout))
      throw loci::Error(std::string("cannot write output (") + std::strerror(errno ? errno : EIO) +
                        ")");
    return status;
  } catch (const std::bad_alloc&) {  // its what() names no cause a user knows
    std::fflush(stdout);
    std::fprintf(stderr, "loci: error: out of memory\n");
    return 1;
  } catch (const std::exception& e) {
    std::fflush(stdout);
    std::fprintf(stderr, "loci: error: %s\n", printable(e.what()).c_str());
    return 1;
  }
}

}  // namespace loci::cli
