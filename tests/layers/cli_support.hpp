// What the layer suites share: running the real `loci` executable, making small layers with
// GDAL, and brute-force answers computed through OGR's own geometry (GEOS), independent of
// loci's index and of its exact tests.
#pragma once

#include <gdal_priv.h>
#include <ogrsf_frmts.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace loci::test {

struct CliRun {
  int status = -1;  // exit code, or 128 + signal
  std::string out;
  std::string err;
};

inline std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s)
    q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Runs the shell command `command` (quoted as needed) and captures everything.
inline CliRun run_command(const std::string& command) {
  static int counter = 0;
  const std::string err =
      (std::filesystem::temp_directory_path() /
       ("loci-test-err-" + std::to_string(::getpid()) + "-" + std::to_string(counter++)))
          .string();
  const std::string cmd = command + " 2>" + shell_quote(err);
  CliRun r;
  std::FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[65536];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0)
    r.out.append(buf, n);
  const int st = ::pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + (WIFSIGNALED(st) ? WTERMSIG(st) : 0);
  r.err = read_text(err);
  std::filesystem::remove(err);
  return r;
}

// Runs `loci ARGS` (ARGS already quoted as needed) and captures everything.
inline CliRun run_loci(const std::string& args) {
  return run_command(std::string(LOCI_EXE) + " " + args);
}

inline std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);)
    if (!l.empty()) out.push_back(l);
  return out;
}

// "QUERY FID" rows into a list per query (1-based), or "FID" rows into list 1.
inline std::vector<std::vector<long long>> parse_ids(const std::string& text, std::size_t queries) {
  std::vector<std::vector<long long>> out(queries + 1);
  for (const auto& l : lines(text)) {
    std::istringstream in(l);
    long long a = 0, b = 0;
    in >> a;
    if (in >> b)
      out.at(std::size_t(a)).push_back(b);
    else
      out.at(1).push_back(a);
  }
  return out;
}

struct OgrFeatureSet {
  std::vector<long long> fids;
  std::vector<std::unique_ptr<OGRGeometry>> geoms;
  std::vector<OGREnvelope> envelopes;
};

inline OgrFeatureSet read_with_ogr(const std::string& path) {
  GDALAllRegister();
  CPLSetConfigOption("OGR_GEOJSON_MAX_OBJ_SIZE", "0");
  OgrFeatureSet s;
  GDALDatasetUniquePtr ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY));
  if (!ds) return s;
  for (auto& f : *ds->GetLayer(0)) {
    if (!f->GetGeometryRef() || f->GetGeometryRef()->IsEmpty()) continue;
    s.fids.push_back(f->GetFID());
    s.geoms.emplace_back(f->StealGeometry());
    OGREnvelope e;
    s.geoms.back()->getEnvelope(&e);
    s.envelopes.push_back(e);
  }
  return s;
}

inline std::unique_ptr<OGRGeometry> ogr_box(double x0, double y0, double x1, double y1) {
  if (x0 == x1 && y0 == y1) return std::make_unique<OGRPoint>(x0, y0);
  if (x0 == x1 || y0 == y1) {
    auto l = std::make_unique<OGRLineString>();
    l->addPoint(x0, y0);
    l->addPoint(x1, y1);
    return l;
  }
  auto poly = std::make_unique<OGRPolygon>();
  OGRLinearRing r;
  r.addPoint(x0, y0);
  r.addPoint(x1, y0);
  r.addPoint(x1, y1);
  r.addPoint(x0, y1);
  r.addPoint(x0, y0);
  poly->addRing(&r);
  return poly;
}

// FIDs whose geometry intersects `q` (GEOS through OGR), ascending.
inline std::vector<long long> brute_intersects(const OgrFeatureSet& s, const OGRGeometry& q) {
  OGREnvelope qe;
  q.getEnvelope(&qe);
  std::vector<long long> out;
  for (std::size_t i = 0; i < s.fids.size(); ++i)
    if (s.envelopes[i].Intersects(qe) && s.geoms[i]->Intersects(&q)) out.push_back(s.fids[i]);
  std::sort(out.begin(), out.end());
  return out;
}

// (distance, fid) of every feature, nearest first.
inline std::vector<std::pair<double, long long>> brute_distances(const OgrFeatureSet& s, double x,
                                                                 double y) {
  OGRPoint p(x, y);
  std::vector<std::pair<double, long long>> out;
  for (std::size_t i = 0; i < s.fids.size(); ++i)
    out.emplace_back(s.geoms[i]->Distance(&p), s.fids[i]);
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace loci::test
