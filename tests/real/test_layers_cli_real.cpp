// The `loci` executable on Natural Earth layers (labelled large;real): countries' coastlines
// (1 m) and land (10 m), converted once to shapefiles in the build tree, queried by windows
// and nearest-n through a sidecar, and compared with a brute force over every feature through
// OGR's geometry. Skipped with a message when datasets/fetch.sh has not filled the cache.
#include <gdal_utils.h>
#include <gtest/gtest.h>

#include <array>
#include <filesystem>

#include "layers/cli_support.hpp"

namespace fs = std::filesystem;
using namespace loci::test;

namespace {

const std::string kCache = std::string(LOCI_DATASETS_DIR) + "/cache/";

// The shapefile made from cache/NAME/map.geo.json, made on first use and kept.
std::string shapefile(const std::string& name) {
  const fs::path dir = fs::path(LOCI_REAL_CACHE);
  const fs::path shp = dir / (name + ".shp");
  if (fs::exists(shp)) return shp.string();
  fs::create_directories(dir);
  GDALAllRegister();
  CPLSetConfigOption("OGR_GEOJSON_MAX_OBJ_SIZE", "0");
  GDALDatasetH src = GDALOpenEx((kCache + name + "/map.geo.json").c_str(), GDAL_OF_VECTOR, nullptr,
                                nullptr, nullptr);
  if (!src) return {};
  const char* argv[] = {"-f", "ESRI Shapefile", "-nln", name.c_str(), nullptr};
  GDALVectorTranslateOptions* opts =
      GDALVectorTranslateOptionsNew(const_cast<char**>(argv), nullptr);
  const std::string tmp = (dir / ("tmp-" + name)).string();
  fs::remove_all(tmp);
  fs::create_directories(tmp);
  GDALDatasetH out =
      GDALVectorTranslate((tmp + "/" + name + ".shp").c_str(), nullptr, 1, &src, opts, nullptr);
  GDALVectorTranslateOptionsFree(opts);
  GDALClose(src);
  if (!out) return {};
  GDALClose(out);
  for (const auto& e : fs::directory_iterator(tmp))
    fs::rename(e.path(), dir / e.path().filename());
  fs::remove_all(tmp);
  return shp.string();
}

class RealLayersCli : public ::testing::TestWithParam<std::tuple<const char*, const char*>> {
 protected:
  void SetUp() override {
    const std::string name = std::get<0>(GetParam());
    if (!fs::exists(kCache + name + "/map.geo.json"))
      GTEST_SKIP() << "no " << kCache << name << ": run datasets/fetch.sh to fetch the real layers";
    layer_ = shapefile(name);
    ASSERT_FALSE(layer_.empty()) << "cannot convert " << name;
  }
  std::string layer_;
};

}  // namespace

TEST_P(RealLayersCli, WindowsAndNearestMatchOgr) {
  const std::string per = std::get<1>(GetParam());
  const std::string sidecar = layer_ + "." + per + ".loci";
  CliRun r = run_loci("index -q " + layer_ + " --per " + per + " -o " + sidecar);
  ASSERT_EQ(r.status, 0) << r.err;
  const OgrFeatureSet s = read_with_ogr(layer_);
  // every feature of the layer, as GDAL counts them and as `loci info` reports them
  GDALDatasetUniquePtr ds(GDALDataset::Open(layer_.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY));
  ASSERT_TRUE(ds);
  const auto count = ds->GetLayer(0)->GetFeatureCount(TRUE);
  ASSERT_GT(count, 0);
  ASSERT_EQ(std::int64_t(s.fids.size()), count);
  const CliRun info = run_loci("info " + layer_);
  EXPECT_NE(info.out.find("features:  " + std::to_string(count)), std::string::npos) << info.out;

  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> lon(-170, 170), lat(-60, 75), size(0.2, 12);
  const std::string windows = layer_ + ".windows", points = layer_ + ".points";
  std::vector<std::array<double, 4>> w;
  {
    std::ofstream out(windows);
    out.precision(17);
    for (int i = 0; i < 25; ++i) {
      const double x = lon(rng), y = lat(rng);
      w.push_back({x, y, x + size(rng), y + size(rng) / 2});
      out << w.back()[0] << ',' << w.back()[1] << ',' << w.back()[2] << ',' << w.back()[3] << '\n';
    }
  }
  r = run_loci("query " + layer_ + " --index " + sidecar + " --bbox-file " + windows);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto got = parse_ids(r.out, w.size());
  std::size_t hits = 0;
  for (std::size_t i = 0; i < w.size(); ++i) {
    const auto expected = brute_intersects(s, *ogr_box(w[i][0], w[i][1], w[i][2], w[i][3]));
    EXPECT_EQ(got[i + 1], expected) << "window " << i + 1;
    hits += expected.size();
  }
  EXPECT_GT(hits, 5u);

  std::vector<std::pair<double, double>> p;
  {
    std::ofstream out(points);
    out.precision(17);
    for (int i = 0; i < 5; ++i) {
      p.emplace_back(lon(rng), lat(rng));
      out << p.back().first << ',' << p.back().second << '\n';
    }
  }
  r = run_loci("query " + layer_ + " --index " + sidecar + " --nearest-file " + points +
               " -k 3 -f csv");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = lines(r.out);
  ASSERT_EQ(rows.size(), 1 + 3 * p.size());
  for (std::size_t q = 0; q < p.size(); ++q) {
    const auto brute = brute_distances(s, p[q].first, p[q].second);
    for (std::size_t i = 0; i < 3; ++i) {
      std::istringstream in(rows[1 + q * 3 + i]);
      std::string number, fid, dist;
      std::getline(in, number, ',');
      std::getline(in, fid, ',');
      std::getline(in, dist, ',');
      EXPECT_NEAR(std::stod(dist), brute[i].first, 1e-9) << "point " << q + 1 << " rank " << i;
    }
  }
  fs::remove(sidecar);
}

INSTANTIATE_TEST_SUITE_P(NaturalEarth, RealLayersCli,
                         ::testing::Values(std::make_tuple("countries-coastline-1m", "segment"),
                                           std::make_tuple("countries-land-10m", "feature")),
                         [](const auto& info) {
                           std::string n = std::get<0>(info.param);
                           std::replace(n.begin(), n.end(), '-', '_');
                           return n + "_" + std::get<1>(info.param);
                         });
