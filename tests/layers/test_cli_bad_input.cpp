// The command line on input and output that would crash it, lose data or answer silently
// wrongly: each case gives a clear one-line error and exit code 1 (or a correct answer where the
// input is merely unusual), and leaves nothing half-written. Regression tests of the
// reliability rows: empty layers, NaN coordinates, a full disk or stdout, devices, FIFOs and
// symbolic links as outputs, the input layer as output, temporaries and modes.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "layers/cli_support.hpp"
#include "loci/io/atomic_file.hpp"

namespace fs = std::filesystem;
using namespace loci::test;

namespace {

class BadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("loci-bad-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path(name)) << text;
    return path(name);
  }
  std::string lines_layer() const {
    return write("lines.geojson", R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{"n":1},"geometry":{"type":"LineString","coordinates":[[0,0],[1,1]]}},
{"type":"Feature","properties":{"n":2},"geometry":{"type":"LineString","coordinates":[[2,0],[3,1]]}}]})");
  }
  // Files in the directory whose name says they are temporaries.
  std::vector<std::string> temporaries() const {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(dir_))
      if (e.path().filename().string().find(".tmp") != std::string::npos)
        out.push_back(e.path().filename().string());
    return out;
  }

  fs::path dir_;
};

void expect_one_line_error(const CliRun& r) {
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(lines(r.err).size(), 1u) << r.err;
  EXPECT_EQ(r.err.rfind("loci: error: ", 0), 0u) << r.err;
}

TEST_F(BadInput, EmptyLayerGivesAnEmptyIndexAndEmptyAnswers) {
  for (const char* text : {R"({"type":"FeatureCollection","features":[]})",
                           R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":null}]})"}) {
    const std::string l = write("empty.geojson", text);
    fs::remove(l + ".loci");
    for (const char* per : {"feature", "segment"}) {
      const CliRun ix = run_loci("index " + shell_quote(l) + " --per " + per + " -q");
      ASSERT_EQ(ix.status, 0) << ix.err;
      const CliRun info = run_loci("info " + shell_quote(l));
      EXPECT_EQ(info.status, 0) << info.err;
      EXPECT_NE(info.out.find("0 entries"), std::string::npos) << info.out;
      const bool none = std::string(text).find("null") == std::string::npos;
      EXPECT_NE(info.out.find(none ? "geometry:  (no features)\n" : "geometry:  (none) x1\n"),
                std::string::npos)
          << info.out;
      for (const char* q : {"--bbox 0,0,1,1", "--nearest 0,0 -k 3", "--point 0,0", "--within 0,0,5",
                            "--segment 0,0,1,1"}) {
        const CliRun r = run_loci("query " + shell_quote(l) + " " + q);
        EXPECT_EQ(r.status, 0) << q << ": " << r.err;
        EXPECT_EQ(r.out, "") << q;
      }
      const CliRun d = run_loci("draw " + shell_quote(l) + " -o " + shell_quote(path("e.svg")));
      EXPECT_LE(d.status, 1);  // no crash: an empty drawing or a clear refusal
      if (d.status == 1) expect_one_line_error(d);
    }
  }
}

TEST_F(BadInput, NaNCoordinatesAreRefusedNamingTheFeature) {
  const std::string l = write("nan.geojson", R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[0,0],[1,1]]}},
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[0,0],[NaN,1],[2,2]]}}]})");
  for (const std::string per : {" --per feature", " --per segment", ""}) {  // "": chosen
    const CliRun r = run_loci("index " + shell_quote(l) + per);
    expect_one_line_error(r);
    EXPECT_NE(r.err.find("feature 1"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(l + ".loci"));
  }
  // info too (its extent said inf, or left a NaN out).
  const CliRun info = run_loci("info " + shell_quote(l));
  expect_one_line_error(info);
  EXPECT_NE(info.err.find("feature 1 has a NaN or infinite coordinate"), std::string::npos)
      << info.err;
  EXPECT_TRUE(info.out.empty()) << info.out;
  const CliRun clip =
      run_loci("clip " + shell_quote(l) + " --bbox -1,-1,3,3 -o " + shell_quote(path("c.geojson")));
  expect_one_line_error(clip);
  EXPECT_FALSE(fs::exists(path("c.geojson")));
  EXPECT_TRUE(temporaries().empty());
}

// GDAL reads a point with a NaN coordinate as an empty point that keeps the NaN (and drops it
// from a multipoint's text): it is refused like any NaN, not skipped as an empty geometry.
TEST_F(BadInput, NaNPointsGdalReadsAsEmptyAreRefusedToo) {
  for (const char* geometry :
       {R"({"type":"Point","coordinates":[NaN,3]})", R"({"type":"Point","coordinates":[3,NaN]})",
        R"({"type":"MultiPoint","coordinates":[[1,1],[NaN,3]]})",
        R"({"type":"GeometryCollection","geometries":[{"type":"Point","coordinates":[NaN,3]}]})"}) {
    const std::string l =
        write("nanpoint.geojson", std::string(R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":{"type":"Point","coordinates":[1,1]}},
{"type":"Feature","properties":{},"geometry":)") +
                                      geometry + "}]}");
    fs::remove(l + ".loci");
    for (const std::string per : {" --per feature", " --per segment"}) {
      const CliRun r = run_loci("index " + shell_quote(l) + per);
      expect_one_line_error(r);
      EXPECT_NE(r.err.find("feature 1 has a NaN"), std::string::npos) << geometry << r.err;
      EXPECT_FALSE(fs::exists(l + ".loci"));
    }
    const CliRun join = run_loci("join " + shell_quote(l) + " " + shell_quote(l));
    expect_one_line_error(join);
    expect_one_line_error(run_loci("info " + shell_quote(l)));
    // intersections reads linework only, and refuses such a point all the same
    const CliRun crossings = run_loci("intersections " + shell_quote(l));
    expect_one_line_error(crossings);
    EXPECT_NE(crossings.err.find("feature 1 has a NaN"), std::string::npos) << crossings.err;
  }
}

// POINT EMPTY in a GeoPackage (stored with both coordinates NaN, as in WKB) is an empty
// geometry like any other: skipped, not refused as a NaN coordinate (which made the whole
// layer unusable).
TEST_F(BadInput, EmptyPointsOfAGeoPackageAreSkipped) {
  const std::string csv = write("pe.csv", "id,WKT\n1,\"POINT EMPTY\"\n2,\"POINT (1 1)\"\n");
  const std::string gpkg = path("pe.gpkg");
  GDALAllRegister();
  {
    GDALDatasetUniquePtr src(GDALDataset::Open(csv.c_str(), GDAL_OF_VECTOR));
    ASSERT_TRUE(src);
    GDALDriver* drv = GetGDALDriverManager()->GetDriverByName("GPKG");
    ASSERT_NE(drv, nullptr);
    GDALDatasetUniquePtr out(drv->Create(gpkg.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
    ASSERT_TRUE(out);
    OGRLayer* l = out->CreateLayer("pe", nullptr, wkbPoint, nullptr);
    ASSERT_NE(l, nullptr);
    for (const char* wkt : {"POINT EMPTY", "POINT (1 1)"}) {
      OGRFeature f(l->GetLayerDefn());
      OGRGeometry* g = nullptr;
      ASSERT_EQ(OGRGeometryFactory::createFromWkt(wkt, nullptr, &g), OGRERR_NONE);
      f.SetGeometryDirectly(g);
      ASSERT_EQ(l->CreateFeature(&f), OGRERR_NONE);
    }
  }
  for (const std::string& layer : {csv, gpkg}) {
    SCOPED_TRACE(layer);
    const CliRun q = run_loci("query " + shell_quote(layer) + " --bbox 0,0,2,2");
    ASSERT_EQ(q.status, 0) << q.err;
    EXPECT_EQ(q.out, "2\n");  // both drivers number features from 1
    const CliRun i = run_loci("index -q " + shell_quote(layer));
    ASSERT_EQ(i.status, 0) << i.err;
    EXPECT_EQ(run_loci("query " + shell_quote(layer) + " --nearest 0,0 -k 5").out, q.out);
  }
}

// A geometry GDAL cannot parse (a CSV's WKT with an infinite coordinate, or not WKT at all)
// is refused in one line naming its feature, by every command that reads the layer.
TEST_F(BadInput, UnreadableGeometriesAreRefusedNamingTheFeature) {
  for (const char* wkt : {"LINESTRING (0 0,inf 1)", "garbage"}) {
    SCOPED_TRACE(wkt);
    const std::string l = write("badwkt.csv", std::string("id,WKT\n1,\"POINT (1 2)\"\n2,\"") + wkt +
                                                  "\"\n3,\"POINT (2 2)\"\n");
    fs::remove(l + ".loci");
    for (const std::string& command : std::vector<std::string>{
             "query " + shell_quote(l) + " --bbox 0,0,5,5", "info " + shell_quote(l),
             "index " + shell_quote(l), "index --per segment " + shell_quote(l),
             "join " + shell_quote(l) + " " + shell_quote(l) + " --closest",
             "intersections " + shell_quote(l)}) {
      const CliRun r = run_loci(command);
      expect_one_line_error(r);
      EXPECT_NE(r.err.find("badwkt.csv: cannot read the layer whole (feature 2: "),
                std::string::npos)
          << command << ": " << r.err;
      EXPECT_EQ(r.out, "") << command;
    }
    EXPECT_FALSE(fs::exists(l + ".loci"));
  }
}

// Features without points are skipped by `loci index`, which says how many.
TEST_F(BadInput, IndexCountsTheFeaturesItSkips) {
  const std::string l = write("skips.csv", "id,wkt\n1,POINT EMPTY\n2,\n3,POINT (1 2)\n");
  fs::remove(l + ".loci");
  CliRun r = run_loci("index " + shell_quote(l) + " --per feature");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("indexed 1 feature of layer"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("; skipped 2 features without a geometry or with an empty one\n"),
            std::string::npos)
      << r.err;
  r = run_loci("index " + shell_quote(l) + " --per segment");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("indexed 1 segment of 1 feature of layer"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("; skipped 2 features"), std::string::npos) << r.err;
  const std::string full = write("full.csv", "id,wkt\n1,POINT (1 2)\n2,POINT (3 4)\n");
  r = run_loci("index " + shell_quote(full));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("indexed 2 features of layer"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("skipped"), std::string::npos) << r.err;
}

TEST_F(BadInput, DevicesFifosAndLinksAreWrittenThroughNeverReplaced) {
  const std::string l = lines_layer();
  const std::string dev = path("null");
  ASSERT_EQ(::mknod(dev.c_str(), S_IFCHR | 0666, makedev(1, 3)), 0) << "needs root";
  for (const char* f : {"ids", "csv", "geojson"}) {
    const CliRun r =
        run_loci("query " + shell_quote(l) + " --bbox 0,0,9,9 -f " + f + " -o " + shell_quote(dev));
    EXPECT_EQ(r.status, 0) << r.err;
    struct stat st {};
    ASSERT_EQ(::stat(dev.c_str(), &st), 0);
    EXPECT_TRUE(S_ISCHR(st.st_mode)) << "the device was replaced (" << f << ")";
  }
  // a symbolic link: the file it points to gets the answer, the link stays
  write("target.txt", "old\n");
  fs::create_symlink("target.txt", path("link.txt"));
  const CliRun r =
      run_loci("query " + shell_quote(l) + " --bbox 0,0,9,9 -o " + shell_quote(path("link.txt")));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::is_symlink(path("link.txt")));
  EXPECT_EQ(read_text(path("target.txt")), "0\n1\n");
  // a link to a file not there yet (through a second, relative link into a subdirectory):
  // the file is created where the links lead, the links stay
  fs::create_directory(path("sub"));
  fs::create_symlink("new.txt", path("sub/inner.txt"));
  fs::create_symlink("sub/inner.txt", path("dangling.txt"));
  const CliRun d = run_loci("query " + shell_quote(l) + " --bbox 0,0,9,9 -o " +
                            shell_quote(path("dangling.txt")));
  ASSERT_EQ(d.status, 0) << d.err;
  EXPECT_TRUE(fs::is_symlink(path("dangling.txt")));
  EXPECT_TRUE(fs::is_symlink(path("sub/inner.txt")));
  EXPECT_EQ(read_text(path("sub/new.txt")), "0\n1\n");
  // a loop of links is refused in one line
  fs::create_symlink("loop_b.txt", path("loop_a.txt"));
  fs::create_symlink("loop_a.txt", path("loop_b.txt"));
  expect_one_line_error(run_loci("query " + shell_quote(l) + " --bbox 0,0,9,9 -o " +
                                 shell_quote(path("loop_a.txt"))));
  EXPECT_TRUE(fs::is_symlink(path("loop_a.txt")));
  // a FIFO as sidecar or layer is refused at once, not waited on
  const std::string fifo = path("fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto t0 = std::chrono::steady_clock::now();
  expect_one_line_error(
      run_loci("query " + shell_quote(l) + " --index " + shell_quote(fifo) + " --bbox 0,0,1,1"));
  expect_one_line_error(run_loci("info " + shell_quote(fifo)));
  {
    // ... by every command that reads a layer. A guard opens it for writing after 20 s, so
    // that a command waiting on it ends (and the test fails) instead of hanging.
    std::atomic<bool> done{false};
    std::thread guard([&] {
      for (int i = 0; !done; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        if (i < 200) continue;
        const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
        if (fd >= 0) ::close(fd);
      }
    });
    for (const std::string& command : std::vector<std::string>{
             "index", "index --per feature", "check", "query --bbox 0,0,1,1", "intersections",
             "draw -o " + shell_quote(path("fifo.svg")),
             "clip --bbox 0,0,1,1 -o " + shell_quote(path("fifo_clip.geojson"))}) {
      const auto space = command.find(' ');
      const std::string verb = command.substr(0, space),
                        rest = space == std::string::npos ? "" : command.substr(space);
      const CliRun r = run_loci(verb + " " + shell_quote(fifo) + rest);
      expect_one_line_error(r);
      EXPECT_NE(r.err.find("not a regular file"), std::string::npos) << command << ": " << r.err;
    }
    done = true;
    guard.join();
  }
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(20));
  // a directory as output
  expect_one_line_error(
      run_loci("query " + shell_quote(l) + " --bbox 0,0,9,9 -o " + shell_quote(dir_.string())));
  // an empty output name (not stdout, nor the default sidecar)
  expect_one_line_error(run_loci("query " + shell_quote(l) + " --bbox 0,0,9,9 -o ''"));
  expect_one_line_error(run_loci("index " + shell_quote(l) + " -o ''"));
  expect_one_line_error(run_loci("fleet generate --count 3 -o ''"));
  // `-o -` is stdout where the output may go there; a command writing a file refuses it
  const std::string cwd = fs::current_path().string();
  fs::current_path(dir_);
  const CliRun dash = run_loci("query " + shell_quote(l) + " --bbox 0,0,9,9 -o -");
  EXPECT_EQ(dash.status, 0) << dash.err;
  EXPECT_EQ(dash.out, run_loci("query " + shell_quote(l) + " --bbox 0,0,9,9").out);
  EXPECT_FALSE(dash.out.empty());
  for (const std::string& command :
       {"index " + shell_quote(l) + " -o -", "clip " + shell_quote(l) + " --bbox 0,0,9,9 -o -"})
    expect_one_line_error(run_loci(command));
  const CliRun generated = run_loci("fleet generate --count 3 -q -o -");  // text: stdout
  EXPECT_EQ(generated.status, 0) << generated.err;
  EXPECT_EQ(lines(generated.out).size(), 10u);
  EXPECT_FALSE(fs::exists(dir_ / "-"));
  fs::current_path(cwd);
}

TEST_F(BadInput, TheInputLayerIsNeverOverwritten) {
  const std::string l = lines_layer();
  const std::string before = read_text(l);
  expect_one_line_error(run_loci("index " + shell_quote(l) + " -o " + shell_quote(l)));
  expect_one_line_error(
      run_loci("query " + shell_quote(l) + " --bbox 0,0,9,9 -o " + shell_quote(l)));
  expect_one_line_error(
      run_loci("clip " + shell_quote(l) + " --bbox 0,0,9,9 -o " + shell_quote(l)));
  expect_one_line_error(run_loci("intersections " + shell_quote(l) + " -o " + shell_quote(l)));
  EXPECT_EQ(read_text(l), before);
  // a shapefile's companion files count as the layer
  const CliRun shp =
      run_loci("clip " + shell_quote(l) + " --bbox -1,-1,9,9 -o " + shell_quote(path("roads.shp")));
  ASSERT_EQ(shp.status, 0) << shp.err;
  const std::string dbf = read_text(path("roads.dbf"));
  expect_one_line_error(run_loci("query " + shell_quote(path("roads.shp")) + " --bbox 0,0,9,9 -o " +
                                 shell_quote(path("roads.dbf"))));
  EXPECT_EQ(read_text(path("roads.dbf")), dbf);
  // nor the index the command reads, the layer's own or one given with --index
  ASSERT_EQ(run_loci("index -q " + shell_quote(l)).status, 0);
  ASSERT_EQ(
      run_loci("index -q " + shell_quote(l) + " -o " + shell_quote(path("other.loci"))).status, 0);
  const std::string sidecar = read_text(l + ".loci"), other = read_text(path("other.loci"));
  for (const std::string& command : {"query " + shell_quote(l) + " --bbox 0,0,9,9",
                                     "clip " + shell_quote(l) + " --bbox 0,0,9,9"}) {
    // (a text answer is refused sooner, by the name: a .loci file is no text)
    const std::string why = command.rfind("clip", 0) == 0 ? "it is the index" : "says a sidecar";
    const CliRun own = run_loci(command + " -o " + shell_quote(l + ".loci"));
    expect_one_line_error(own);
    EXPECT_NE(own.err.find(why), std::string::npos) << own.err;
    const CliRun given = run_loci(command + " --index " + shell_quote(path("other.loci")) + " -o " +
                                  shell_quote(path("other.loci")));
    expect_one_line_error(given);
    EXPECT_NE(given.err.find(why), std::string::npos) << given.err;
  }
  EXPECT_EQ(read_text(l + ".loci"), sidecar);
  EXPECT_EQ(read_text(path("other.loci")), other);
}

// loci-quickstart, beside loci, gives its usage for --help (it took it for a layer's name).
TEST_F(BadInput, QuickstartHelpIsHelp) {
  const std::string exe = std::string(LOCI_EXE) + "-quickstart";
  const CliRun h = run_command(exe + " --help");
  EXPECT_EQ(h.status, 0) << h.err;
  EXPECT_EQ(h.out.rfind("usage: loci-quickstart LAYER", 0), 0u) << h.out;
  EXPECT_TRUE(h.err.empty()) << h.err;
  const CliRun full = run_command(exe + " --help > /dev/full");
  EXPECT_EQ(full.status, 1);
  EXPECT_NE(full.err.find("cannot write the help"), std::string::npos) << full.err;
  for (const char* bad : {"", " -x", " a b c"}) {
    const CliRun r = run_command(exe + bad);
    EXPECT_EQ(r.status, 1) << bad;
    EXPECT_EQ(r.err.rfind("usage: loci-quickstart LAYER", 0), 0u) << bad << ": " << r.err;
  }
}

TEST_F(BadInput, FullDiskAndFullStdoutFailAndKeepTheOldFile) {
  const std::string l = lines_layer();
  for (const char* f : {"ids", "csv", "geojson"}) {
    const CliRun r = run_loci("query " + shell_quote(l) + " --bbox 0,0,9,9 -f " + std::string(f) +
                              " > /dev/full");
    expect_one_line_error(r);
  }
  expect_one_line_error(run_loci("info " + shell_quote(l) + " > /dev/full"));
  // the help and the version too (the help said nothing and exited 0)
  const CliRun version = run_loci("--version");
  EXPECT_EQ(version.status, 0) << version.err;
  EXPECT_EQ(version.out.rfind("loci 0.", 0), 0u) << version.out;
  expect_one_line_error(run_loci("--version > /dev/full"));
  for (const char* help : {"--help", "fleet --help", "query --help", "fleet query -h"}) {
    const CliRun r = run_loci(std::string(help) + " > /dev/full");
    expect_one_line_error(r);
    EXPECT_NE(r.err.find("cannot write the help"), std::string::npos) << help << ": " << r.err;
  }
  // a file size limit stands in for a full disk: the old output must stay whole
  write("old.csv", "the old answer\n");
  const std::string cmd = "ulimit -f 0; " + std::string(LOCI_EXE) + " query " + shell_quote(l) +
                          " --bbox 0,0,9,9 -f csv -o " + shell_quote(path("old.csv")) +
                          " 2>/dev/null";
  const int st = std::system(("bash -c " + shell_quote(cmd)).c_str());
  EXPECT_NE(st, 0);
  EXPECT_EQ(read_text(path("old.csv")), "the old answer\n");
  // clip writes through GDAL, whose drivers do not report every failed write
  const std::string sample = std::string(LOCI_DATASETS_DIR) + "/samples/coastline-denmark.geojson";
  write("old.geojson", "the old layer\n");
  const std::string clip = "ulimit -f 8; " + std::string(LOCI_EXE) + " clip " +
                           shell_quote(sample) + " --bbox 8,54,13,58 -o " +
                           shell_quote(path("old.geojson")) + " 2>/dev/null";
  EXPECT_NE(std::system(("bash -c " + shell_quote(clip)).c_str()), 0);
  EXPECT_EQ(read_text(path("old.geojson")), "the old layer\n");
  EXPECT_TRUE(temporaries().empty());
}

TEST_F(BadInput, TemporariesAreHiddenModesKeptAndLeftoversRemoved) {
  const std::string l = lines_layer();
  // a leftover of a process killed with SIGKILL (its PID no longer exists) goes away
  const std::string stale = path(".lines.geojson.loci.2147483646.tmpAbCdEf");
  write(".lines.geojson.loci.2147483646.tmpAbCdEf", "half a sidecar");
  ::umask(077);
  const CliRun ix = run_loci("index " + shell_quote(l) + " -q");
  ::umask(022);
  ASSERT_EQ(ix.status, 0) << ix.err;
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_EQ(fs::status(l + ".loci").permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write);
  // an existing output keeps its mode
  write("out.txt", "x");
  fs::permissions(path("out.txt"),
                  fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  ASSERT_EQ(
      run_loci("query " + shell_quote(l) + " --bbox 0,0,9,9 -o " + shell_quote(path("out.txt")))
          .status,
      0);
  EXPECT_EQ(fs::status(path("out.txt")).permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  // a long layer name: the temporary's name must still fit
  const std::string long_name(237, 'x');
  fs::copy_file(l, path(long_name));
  const CliRun lng = run_loci("index " + shell_quote(path(long_name)) + " -q");
  EXPECT_EQ(lng.status, 0) << lng.err;
  EXPECT_TRUE(temporaries().empty());
}

TEST_F(BadInput, TruncatedAndForeignFilesAreRefusedInOneLine) {
  const std::string l = lines_layer();
  ASSERT_EQ(
      run_loci("clip " + shell_quote(l) + " --bbox -1,-1,9,9 -o " + shell_quote(path("roads.shp")))
          .status,
      0);
  const std::string shp = path("roads.shp");
  const std::string whole = read_text(shp);
  std::ofstream(shp, std::ios::binary) << whole.substr(0, whole.size() - 20);
  for (const char* cmd : {"index ", "info ", "query --bbox 0,0,9,9 "}) {
    std::string c = cmd;
    const std::size_t sp = c.find(' ');
    const CliRun r = run_loci(c.substr(0, sp) + " " + shell_quote(shp) + c.substr(sp));
    expect_one_line_error(r);  // GDAL's own ERROR lines must not leak either
  }
  EXPECT_FALSE(fs::exists(shp + ".loci"));
  static constexpr char kForeign[] =
      "\x89"
      "garbage\0"
      "bytes and more";
  write("random.shp", std::string(kForeign, sizeof kForeign - 1));
  expect_one_line_error(run_loci("index " + shell_quote(path("random.shp"))));
  write("empty.geojson", "");
  expect_one_line_error(run_loci("index " + shell_quote(path("empty.geojson"))));
}

TEST_F(BadInput, SignalsRemoveTheTemporaries) {
  // A writer killed by SIGTERM, SIGINT or SIGHUP in the middle of a write: the old file stays
  // and no temporary is left (the handler of atomic_file.cpp runs, then the signal kills).
  write("out.txt", "the old answer\n");
  for (int sig : {SIGTERM, SIGINT, SIGHUP}) {
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      loci::io::AtomicFile f(path("out.txt"));
      std::fputs("half of a new answer", f.stream());
      std::fflush(f.stream());
      ::raise(sig);
      ::_exit(0);  // not reached
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << "signal " << sig;
    EXPECT_TRUE(temporaries().empty()) << "signal " << sig;
    EXPECT_EQ(read_text(path("out.txt")), "the old answer\n");
  }
}

}  // namespace

namespace {

// A sidecar given where a layer is expected is named as one, and a sidecar drawn after its layer
// was renamed away names the missing layer.
TEST_F(BadInput, ASidecarGivenAsALayerIsNamed) {
  const std::string l = lines_layer();
  ASSERT_EQ(run_loci("index -q " + shell_quote(l)).status, 0);
  const std::string sidecar = l + ".loci";
  for (const std::string& args :
       {"info " + shell_quote(sidecar), "index -q " + shell_quote(sidecar),
        "query " + shell_quote(sidecar) + " --bbox 0,0,9,9"}) {
    const CliRun r = run_loci(args);
    expect_one_line_error(r);
    EXPECT_NE(r.err.find("a loci index, not a layer"), std::string::npos) << args << r.err;
  }
  const std::string moved = path("moved.geojson.loci");
  fs::rename(sidecar, moved);
  const CliRun d = run_loci("draw " + shell_quote(moved) + " -o " + shell_quote(path("d.svg")));
  expect_one_line_error(d);
  EXPECT_NE(d.err.find("its layer " + path("moved.geojson") + " is missing"), std::string::npos)
      << d.err;
  EXPECT_FALSE(fs::exists(path("d.svg")));
}

// A GeoPackage with layers a and b: the sidecar says which layer it indexes, and a query of the
// default (first) layer does not use a sidecar of b.
TEST_F(BadInput, ASidecarAnswersOnlyForTheLayerItIndexes) {
  const std::string a = write("a.geojson", R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[0,0],[1,1]]}}]})");
  const std::string b = write("b.geojson", R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[5,5],[6,6]]}},
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[7,5],[8,6]]}}]})");
  const std::string gpkg = path("multi.gpkg");
  ASSERT_EQ(std::system(("ogr2ogr -f GPKG " + shell_quote(gpkg) + " " + shell_quote(a) +
                         " -nln a >/dev/null 2>&1 && ogr2ogr -update " + shell_quote(gpkg) + " " +
                         shell_quote(b) + " -nln b >/dev/null 2>&1")
                            .c_str()),
            0)
      << "ogr2ogr (gdal-bin, from scripts/install-deps.sh) could not make a two-layer GeoPackage";
  ASSERT_EQ(run_loci("index " + shell_quote(gpkg) + " --layer b -q").status, 0);
  // The default layer is a: the sidecar of b must not answer for it.
  const CliRun r = run_loci("query " + shell_quote(gpkg) + " --bbox -10,-10,10,10 -f ids");
  expect_one_line_error(r);
  EXPECT_NE(r.err.find("indexes layer 'b', not the default 'a'"), std::string::npos) << r.err;
  // Asked for b, it answers from the sidecar; an in-memory structure answers for a.
  EXPECT_EQ(
      lines(run_loci("query " + shell_quote(gpkg) + " --layer b --bbox -10,-10,10,10 -f ids").out)
          .size(),
      2u);
  EXPECT_EQ(lines(run_loci("query " + shell_quote(gpkg) +
                           " --structure rstar --bbox -10,-10,10,10 -f ids")
                      .out)
                .size(),
            1u);
}

}  // namespace

namespace {

// Clip writes a piece for every feature query reports: a bowtie polygon is made valid and cut,
// and a square the window touches at one corner leaves that corner, a point.
TEST_F(BadInput, ClipAgreesWithQueryOnBowtiesAndTouchingWindows) {
  const std::string l = write("shapes.geojson", R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{"n":1},"geometry":{"type":"Polygon","coordinates":[[[0,0],[2,2],[2,0],[0,2],[0,0]]]}},
{"type":"Feature","properties":{"n":2},"geometry":{"type":"Polygon","coordinates":[[[5,5],[6,5],[6,6],[5,6],[5,5]]]}}]})");
  for (const char* bbox : {"0.5,0.5,1.5,1.5", "6,6,7,7", "-1,-1,9,9"}) {
    const CliRun q = run_loci("query " + shell_quote(l) + " --bbox " + bbox + " -f ids");
    ASSERT_EQ(q.status, 0) << q.err;
    const std::string out = path("clip.geojson");
    const CliRun c =
        run_loci("clip " + shell_quote(l) + " --bbox " + bbox + " -o " + shell_quote(out));
    ASSERT_EQ(c.status, 0) << c.err;
    EXPECT_EQ(lines(c.err).size(), 1u) << "GEOS or GDAL messages leaked: " << c.err;
    EXPECT_NE(c.err.find("clipped into"), std::string::npos) << c.err;
    const std::string text = read_text(out);
    std::size_t features = 0;
    for (std::size_t p = 0; (p = text.find("\"Feature\"", p)) != std::string::npos; ++p)
      ++features;
    EXPECT_EQ(features, lines(q.out).size()) << bbox << "\n" << text;
    EXPECT_EQ(features > 0, text.find("\"coordinates\": [ ]") == std::string::npos);
  }
  const std::string corner = path("corner.geojson");
  ASSERT_EQ(run_loci("clip " + shell_quote(l) + " --bbox 6,6,7,7 -o " + shell_quote(corner)).status,
            0);
  EXPECT_NE(read_text(corner).find("\"Point\""), std::string::npos) << read_text(corner);
}

}  // namespace

namespace {

// Coordinates whose squared distances would overflow are refused, in layers and in queries,
// rather than answered with infinite distances and a wrong ranking.
// loci index -o replaces only an index or an empty file: it wrote its sidecar over a
// GeoJSON or any other file named, and wrote a whole index into a FIFO or /dev/null before
// failing on it as not a regular file. The default LAYER.loci is replaced whatever it holds.
TEST_F(BadInput, IndexWithOutputReplacesOnlyAnIndex) {
  const std::string l = lines_layer();
  // (a layer named as one is refused by its name; named otherwise, by what it holds)
  const std::string other = write("other.geojson", R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":{"type":"Point","coordinates":[1,2]}}]})");
  const std::string before = read_text(other);
  CliRun r = run_loci("index " + shell_quote(l) + " -o " + shell_quote(other));
  expect_one_line_error(r);
  EXPECT_NE(r.err.find("its name says GeoJSON"), std::string::npos) << r.err;
  EXPECT_EQ(read_text(other), before);
  const std::string unnamed = write("other-points", before);
  r = run_loci("index " + shell_quote(l) + " -o " + shell_quote(unnamed));
  expect_one_line_error(r);
  EXPECT_NE(r.err.find("is not a loci index file"), std::string::npos) << r.err;
  EXPECT_EQ(read_text(unnamed), before);
  const std::string fifo = path("index.fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const std::string& device : {fifo, std::string("/dev/null")}) {
    r = run_loci("index " + shell_quote(l) + " -o " + shell_quote(device));
    expect_one_line_error(r);
    EXPECT_NE(r.err.find("not a regular file"), std::string::npos) << r.err;
  }
  const std::string index = path("lines.idx");
  { std::ofstream(index).flush(); }  // empty: taken
  ASSERT_EQ(run_loci("index -q " + shell_quote(l) + " -o " + shell_quote(index)).status, 0);
  ASSERT_EQ(run_loci("index -q " + shell_quote(l) + " -o " + shell_quote(index)).status, 0);
  const std::string beside = l + ".loci";
  { std::ofstream(beside) << "not an index"; }
  ASSERT_EQ(run_loci("index -q " + shell_quote(l)).status, 0);
  EXPECT_EQ(run_loci("check " + shell_quote(beside)).status, 0);
  fs::remove(beside);
}

// -o naming one of the process's descriptors (/dev/stdout, /dev/fd/N, /proc/self/fd/N) writes
// through it: opened again, the file behind it was truncated and written from its start, over
// what the shell had written there before (and leaving NUL bytes before what came after).
TEST_F(BadInput, OutputNamedAsADescriptorWritesThroughIt) {
  const std::string l = lines_layer();
  const std::string fleet = write("one.csv", "id,t,x,y,vx,vy\n1,0,0,0,1,0\n");
  const std::string out = path("through.txt");
  const CliRun expected = run_loci("query " + shell_quote(l) + " --bbox -1000,-1000,1000,1000");
  ASSERT_EQ(expected.status, 0) << expected.err;
  for (const std::string& name : {"/dev/stdout", "/dev/fd/1", "/proc/self/fd/1"}) {
    for (const std::string& command :
         {"query " + shell_quote(l) + " --bbox -1000,-1000,1000,1000 -o " + name,
          "fleet query " + shell_quote(fleet) + " --bbox 0,0,1,1 -q -o " + name}) {
      const std::string shell = "( echo before; " + std::string(LOCI_EXE) + " " + command +
                                "; echo after ) > " + shell_quote(out);
      ASSERT_EQ(std::system(shell.c_str()), 0) << command;
      const std::string answer = command.rfind("fleet", 0) == 0 ? "1\n" : expected.out;
      EXPECT_EQ(read_text(out), "before\n" + answer + "after\n") << command;
    }
  }
  // Closed, the descriptor is no output: one line, exit 1 (no file is made in its place).
  const CliRun closed = run_loci("query " + shell_quote(l) + " --bbox 0,0,1,1 -o /dev/fd/1 1>&-");
  expect_one_line_error(closed);
  EXPECT_NE(closed.err.find("cannot write /dev/fd/1 (Bad file descriptor)"), std::string::npos)
      << closed.err;
}

// An output's name says what it holds: without -f the answer takes the format its name says
// (.csv, .geojson, .json, in any case), and a name saying another format than the output's is
// refused before anything is written (`join ... -o pairs.shp` wrote CSV named .shp, `draw -o
// map.png` an SVG named .png).
TEST_F(BadInput, OutputNamesSayWhatTheyHold) {
  const std::string l = lines_layer();
  const std::string fleet = write("two.csv", "id,t,x,y,vx,vy\n1,0,0,0,1,0\n2,0,1,0,-1,0\n");
  const std::string q = "query " + shell_quote(l) + " --bbox -10,-10,10,10 -q";
  ASSERT_EQ(run_loci(q + " -o " + shell_quote(path("a.csv"))).status, 0);
  EXPECT_EQ(read_text(path("a.csv")), "fid,n\n0,1\n1,2\n");
  ASSERT_EQ(run_loci(q + " -o " + shell_quote(path("a.GeoJSON"))).status, 0);
  EXPECT_NE(read_text(path("a.GeoJSON")).find("\"FeatureCollection\""), std::string::npos);
  ASSERT_EQ(run_loci(q + " -o " + shell_quote(path("a.txt"))).status, 0);
  EXPECT_EQ(read_text(path("a.txt")), "0\n1\n");
  ASSERT_EQ(run_loci("fleet query " + shell_quote(fleet) + " --bbox -1,-1,2,1 -q -o " +
                     shell_quote(path("f.json")))
                .status,
            0);
  EXPECT_NE(read_text(path("f.json")).find("\"FeatureCollection\""), std::string::npos);
  struct Refused {
    std::string command, out, says;
  };
  const std::string conflicts =
      "fleet conflicts " + shell_quote(fleet) + " --within 1 --horizon 10 -q";
  const std::vector<Refused> refused = {
      {q, "x.shp", "its name says a .shp file but the output is feature ids"},
      {q + " -f ids", "ids.csv", "its name says CSV but the output is feature ids"},
      {"join " + shell_quote(l) + " " + shell_quote(l) + " -p intersects -f ids -q", "j.csv",
       "its name says CSV but the output is feature ids"},
      {"join " + shell_quote(l) + " " + shell_quote(l) + " -p intersects -f geojson -q", "j.csv",
       "'geojson' is not a format this command writes (choose csv or ids)"},
      {q + " -f csv", "x.geojson", "its name says GeoJSON but the output is CSV"},
      {q + " -f geojson", "x.csv", "its name says CSV but the output is GeoJSON"},
      {q, "x.svg", "its name says an SVG drawing but the output is feature ids"},
      {q, "x.loci", "its name says a sidecar index but the output is feature ids"},
      {"join " + shell_quote(l) + " " + shell_quote(l) + " -p intersects -q", "pairs.geojson",
       "its name says GeoJSON but the output is CSV"},
      {"intersections " + shell_quote(l) + " -q", "x.gpkg", "its name says a .gpkg file"},
      {"draw " + shell_quote(l) + " -q", "map.png", "but the output is an SVG drawing"},
      {"index " + shell_quote(l) + " -q", "x.geojson", "but the output is a sidecar index"},
      {conflicts, "c.svg", "its name says an SVG drawing but the output is CSV"},
      {"fleet draw " + shell_quote(fleet) + " -q", "f.pdf", "its name says a .pdf file"},
      {"fleet generate --count 3 -q", "g.geojson", "its name says GeoJSON but the output is CSV"},
  };
  for (const Refused& r : refused) {
    const CliRun run = run_loci(r.command + " -o " + shell_quote(path(r.out)));
    expect_one_line_error(run);
    EXPECT_NE(run.err.find(r.says), std::string::npos) << r.command << "\n" << run.err;
    EXPECT_FALSE(fs::exists(path(r.out))) << r.command;
  }
  EXPECT_TRUE(temporaries().empty());
}

// A query file's line longer than 1 MiB (a binary file, a stream without newlines) is refused
// before it fills memory, in one line, the old output kept: std::getline took running out of
// memory for the end of the file and answered the queries before it, exit 0; /dev/zero grew
// without bound. So too where the front copies a pipe into memory for loci-full.
TEST_F(BadInput, AQueryFileLineLongerThanTheLimitIsRefused) {
  const std::string l = lines_layer();
  const std::string shp = path("lines.shp");
  ASSERT_EQ(std::system(("ogr2ogr -q " + shell_quote(shp) + " " + shell_quote(l)).c_str()), 0)
      << "ogr2ogr (gdal-bin, from scripts/install-deps.sh) could not make a shapefile";
  ASSERT_EQ(run_loci("index -q --per feature " + shell_quote(shp)).status, 0);
  const std::string q = path("long.txt");
  {
    std::ofstream out(q, std::ios::binary);
    out << "0,0,9,9\n" << std::string((std::size_t(1) << 20) + 1, '\0') << "\n";
  }
  write("old.csv", "the old answer\n");
  for (const std::string& layer : {l, shp}) {
    const CliRun r = run_loci("query " + shell_quote(layer) + " --bbox-file " + shell_quote(q) +
                              " -f csv -o " + shell_quote(path("old.csv")));
    expect_one_line_error(r);
    EXPECT_NE(r.err.find("long.txt: line 2: longer than 1 MiB"), std::string::npos) << r.err;
    EXPECT_EQ(read_text(path("old.csv")), "the old answer\n");
    // From a pipe (the front copies it for loci-full on the shapefile), and endless.
    const CliRun p = run_command("cat " + shell_quote(q) + " | " + std::string(LOCI_EXE) +
                                 " query " + shell_quote(layer) + " --bbox-file -");
    expect_one_line_error(p);
    // stdin named alike by the front and by loci-full (the front said `-`)
    EXPECT_NE(p.err.find("/dev/stdin: line 2: longer than 1 MiB"), std::string::npos) << p.err;
    EXPECT_EQ(p.out, "") << layer;
    const CliRun z = run_command("timeout 60 " + std::string(LOCI_EXE) + " query " +
                                 shell_quote(layer) + " --nearest-file /dev/zero");
    expect_one_line_error(z);
    EXPECT_NE(z.err.find("/dev/zero: line 1: longer than 1 MiB"), std::string::npos) << z.err;
  }
  // A read that fails names the file (it was the library's message alone).
  const CliRun unreadable = run_loci("query " + shell_quote(l) + " --bbox-file /proc/self/mem");
  expect_one_line_error(unreadable);
  EXPECT_NE(unreadable.err.find("/proc/self/mem: cannot read the query file"), std::string::npos)
      << unreadable.err;
  // A line of exactly 1 MiB is read (and refused as the query it is not).
  {
    std::ofstream out(q, std::ios::binary);
    out << "0,0,9,9\n" << std::string((std::size_t(1) << 20) - 1, ' ') << "1\n";
  }
  const CliRun edge = run_loci("query " + shell_quote(l) + " --bbox-file " + shell_quote(q));
  expect_one_line_error(edge);
  EXPECT_NE(edge.err.find("line 2: bad"), std::string::npos) << edge.err;
}

// A feature GDAL reads only in part (its record out of the file: the .shx rewritten in place
// with its time set back, as a file changed while a batch runs leaves it) is an error naming
// it, not a feature silently left out of the answer (exit 0 without it, before).
TEST_F(BadInput, AFeatureReadOnlyInPartIsAnErrorNotADrop) {
  const std::string l = write("two.geojson", R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{"n":0},"geometry":{"type":"Polygon","coordinates":[[[0,0],[1,0],[1,1],[0,1],[0,0]]]}},
{"type":"Feature","properties":{"n":1},"geometry":{"type":"Polygon","coordinates":[[[2,0],[4,0],[2,2],[2,0]]]}}]})");
  const std::string shp = path("two.shp"), shx = path("two.shx");
  ASSERT_EQ(std::system(("ogr2ogr -q " + shell_quote(shp) + " " + shell_quote(l)).c_str()), 0)
      << "ogr2ogr (gdal-bin, from scripts/install-deps.sh) could not make a shapefile";
  ASSERT_EQ(run_loci("index -q --per feature " + shell_quote(shp)).status, 0);
  const std::string window = " --bbox 2.5,0.5,3,1";  // inside the triangle, FID 1
  ASSERT_EQ(run_loci("query " + shell_quote(shp) + window).out, "1\n");
  {
    const auto time = fs::last_write_time(shx);
    std::string bytes = read_text(shx);
    ASSERT_GE(bytes.size(), 116u);
    // The second record's offset, in 16-bit words, big-endian: far beyond the .shp's end.
    const unsigned char far[4] = {0x7f, 0xff, 0xff, 0x00};
    std::copy(far, far + 4, bytes.begin() + 108);
    std::ofstream(shx, std::ios::binary | std::ios::in | std::ios::out) << bytes;
    fs::last_write_time(shx, time);
  }
  for (const char* format : {"ids", "csv", "geojson"}) {
    const CliRun r = run_loci("query " + shell_quote(shp) + window + " -f " + format);
    expect_one_line_error(r);
    EXPECT_NE(r.err.find("two.shp: cannot read feature 1 ("), std::string::npos) << r.err;
  }
  // Without the index, the layer read whole says so too.
  fs::remove(shp + ".loci");
  const CliRun r = run_loci("query " + shell_quote(shp) + window);
  expect_one_line_error(r);
  EXPECT_NE(r.err.find("feature 1"), std::string::npos) << r.err;
}

// An endless stream of good query lines on a pipe, copied into memory by the front for
// loci-full: the copy, outside the address-space limit, stops at it and says so (it grew until
// the machine's memory ran out).
TEST_F(BadInput, AQueryStreamLargerThanTheMemoryLimitIsRefused) {
  if (std::system(("bash -c " + shell_quote("ulimit -v 200000; " + std::string(LOCI_EXE) +
                                            " --version >/dev/null 2>&1"))
                      .c_str()) != 0)
    GTEST_SKIP() << "this build of loci does not start under ulimit -v (a sanitized build)";
  const std::string shp = path("lines.shp");
  ASSERT_EQ(
      std::system(("ogr2ogr -q " + shell_quote(shp) + " " + shell_quote(lines_layer())).c_str()), 0)
      << "ogr2ogr (gdal-bin, from scripts/install-deps.sh) could not make a shapefile";
  ASSERT_EQ(run_loci("index -q --per feature " + shell_quote(shp)).status, 0);
  const CliRun r =
      run_command("bash -c " + shell_quote("ulimit -v 200000; yes 0.5,0.5 | head -c 300000000 | " +
                                           std::string(LOCI_EXE) + " query " + shell_quote(shp) +
                                           " --nearest-file - >/dev/null"));
  expect_one_line_error(r);
  EXPECT_NE(r.err.find("/dev/stdin: larger than the memory this process may use"),
            std::string::npos)
      << r.err;
}

// A batch's CSV header is that of its kind of query, rows or none: an empty --nearest-file
// lost its distance column.
TEST_F(BadInput, EmptyQueryFilesGiveTheHeaderOfTheirKind) {
  const std::string l = lines_layer();
  const std::string empty = write("empty.txt", ""), one = write("one.txt", "0,0\n");
  const std::string head[] = {"query,fid,distance,n", "query,fid,n", "query,fid,n"};
  const char* files[] = {"--nearest-file", "--bbox-file", "--point-file"};
  for (int i = 0; i < 3; ++i) {
    const CliRun none =
        run_loci("query " + shell_quote(l) + " -f csv " + files[i] + " " + shell_quote(empty));
    ASSERT_EQ(none.status, 0) << none.err;
    EXPECT_EQ(none.out, head[i] + "\n") << files[i];
    if (i == 1) continue;  // (a point is no window)
    const CliRun some =
        run_loci("query " + shell_quote(l) + " -f csv " + files[i] + " " + shell_quote(one));
    ASSERT_EQ(some.status, 0) << some.err;
    EXPECT_EQ(lines(some.out).at(0), head[i]) << files[i];
  }
}

TEST_F(BadInput, CoordinatesTooLargeForDistancesAreRefused) {
  const std::string l = write("huge.geojson", R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[0,0],[1,1]]}},
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[0,0],[1e300,1],[2,2]]}}]})");
  for (const std::string per : {" --per feature", " --per segment", ""}) {  // "": chosen
    const CliRun r = run_loci("index " + shell_quote(l) + per);
    expect_one_line_error(r);
    EXPECT_NE(r.err.find("feature 1"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("1e150"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(l + ".loci"));
  }
  const std::string ok = lines_layer();
  // Beyond doubles too (std::from_chars finds them out of range), however written; a number
  // too small for a double is not said too large.
  const std::string huge_integer = "1" + std::string(400, '0');
  for (const std::string& q : std::vector<std::string>{
           "--bbox 0,0,1e301,1", "--nearest 1e200,0 -k 1", "--within 0,0,1e160",
           "--nearest 1e400,0 -k 1", "--point 0,-1E+400",
           "--bbox 0,0,1,0.00001e99999999999999999999", "--nearest " + huge_integer + ",0",
           "--within 0,0,1" + huge_integer + ".5"}) {
    const CliRun r = run_loci("query " + shell_quote(ok) + " " + q);
    expect_one_line_error(r);
    EXPECT_NE(r.err.find("1e150"), std::string::npos) << q << ": " << r.err;
  }
  for (const std::string& q : std::vector<std::string>{
           "--nearest 1e-400,0 -k 1", "--point 0.000" + std::string(400, '0') + "1,0",
           "--point 0,1e-99999999999999999999", "--bbox +-1,0,1,1", "--nearest 0,++1"}) {
    const CliRun r = run_loci("query " + shell_quote(ok) + " " + q);
    expect_one_line_error(r);
    EXPECT_EQ(r.err.find("1e150"), std::string::npos) << q << ": " << r.err;
  }
  // A plus before a number is read alike everywhere: in counts and single values too (-k +2
  // was refused while --nearest +0,+0 was taken), a sign after it nowhere.
  const CliRun plus = run_loci("query " + shell_quote(ok) + " --nearest +0,+0 -k +2");
  EXPECT_EQ(plus.status, 0) << plus.err;
  EXPECT_EQ(plus.out, run_loci("query " + shell_quote(ok) + " --nearest 0,0 -k 2").out);
  const std::string fleet = write("plus.csv", "id,t,x,y,vx,vy\n1,0,0,0,1,0\n2,0,3,0,-1,0\n");
  const CliRun conflicts =
      run_loci("fleet conflicts " + shell_quote(fleet) + " --within +1 --horizon +5 -q");
  EXPECT_EQ(conflicts.status, 0) << conflicts.err;
  EXPECT_EQ(lines(conflicts.out).size(), 2u) << conflicts.out;
  for (const std::string& bad :
       {"query " + shell_quote(ok) + " --nearest 0,0 -k +-2",
        "fleet conflicts " + shell_quote(fleet) + " --within +-1 --horizon 5",
        std::string("fleet generate --count ++2")})
    expect_one_line_error(run_loci(bad));
  // Large but carryable coordinates still answer exactly.
  const std::string big = write("big.geojson", R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":{"type":"Point","coordinates":[1e149,1e149]}},
{"type":"Feature","properties":{},"geometry":{"type":"Point","coordinates":[-1e149,-1e149]}},
{"type":"Feature","properties":{},"geometry":{"type":"Point","coordinates":[0,0]}}]})");
  const CliRun r = run_loci("query " + shell_quote(big) + " --nearest 9e148,9e148 -k 3 -f ids");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(lines(r.out), (std::vector<std::string>{"0", "2", "1"}));
}

}  // namespace

namespace {

// The sidecar of another layer given with --index is named as such, not called stale.
TEST_F(BadInput, AForeignSidecarIsNamedForTheLayerItIndexes) {
  const std::string lines = lines_layer();
  const std::string grid = write("grid.geojson", R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":{"type":"Point","coordinates":[0,0]}}]})");
  ASSERT_EQ(run_loci("index " + shell_quote(grid) + " -q").status, 0);
  const CliRun r = run_loci("query " + shell_quote(lines) + " --index " +
                            shell_quote(grid + ".loci") + " --bbox 0,0,9,9");
  expect_one_line_error(r);
  EXPECT_NE(r.err.find("indexes layer 'grid', not 'lines'"), std::string::npos) << r.err;
}

}  // namespace

namespace {

// Unusual but valid layers answer exactly; broken shapefiles fail in one line; two `loci index`
// runs on one layer at once leave one whole sidecar.
TEST_F(BadInput, UnusualLayersAnswerAndBrokenOnesFailInOneLine) {
  const std::string mixed = write("mixed.geojson", R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":{"type":"Point","coordinates":[1,1]}},
{"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[2,2],[2,2]]}},
{"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[[4,4],[5,4],[5,5],[4,5],[4,4]]]}},
{"type":"Feature","properties":{},"geometry":{"type":"GeometryCollection","geometries":[]}},
{"type":"Feature","properties":{},"geometry":{"type":"MultiPoint","coordinates":[[8,8],[9,9]]}}]})");
  for (const char* per : {"feature", "segment"}) {
    ASSERT_EQ(run_loci("index " + shell_quote(mixed) + " --per " + per + " -q").status, 0);
    const CliRun r = run_loci("query " + shell_quote(mixed) + " --bbox 0,0,4.5,4.5 -f ids");
    ASSERT_EQ(r.status, 0) << r.err;
    // the point, the zero-length line and the polygon's corner; not the empty collection
    EXPECT_EQ(lines(r.out), (std::vector<std::string>{"0", "1", "2"})) << per;
  }
  // A shapefile without its .shx or its .dbf.
  ASSERT_EQ(run_loci("clip " + shell_quote(lines_layer()) + " --bbox -1,-1,9,9 -o " +
                     shell_quote(path("roads.shp")))
                .status,
            0);
  for (const char* missing : {".shx", ".dbf"}) {
    for (const char* ext : {".shp", ".shx", ".dbf"})
      fs::copy_file(path(std::string("roads") + ext), path(std::string("cut") + ext),
                    fs::copy_options::overwrite_existing);
    fs::remove(path(std::string("cut") + missing));
    const CliRun r = run_loci("query " + shell_quote(path("cut.shp")) + " --bbox -1,-1,9,9 -f ids");
    if (r.status == 0)
      EXPECT_EQ(lines(r.out).size(), 2u) << missing;  // GDAL managed without it: exact answers
    else
      expect_one_line_error(r);
  }
  // Two index runs at once: both finish, and the sidecar left is whole and answers.
  const std::string l = lines_layer();
  pid_t pids[2];
  for (pid_t& pid : pids) {
    pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      const CliRun r = run_loci("index " + shell_quote(l) + " --per segment -q");
      ::_exit(r.status);
    }
  }
  for (pid_t pid : pids) {
    int status = 0;
    ::waitpid(pid, &status, 0);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  }
  const CliRun q = run_loci("query " + shell_quote(l) + " --bbox -1,-1,9,9 -f ids");
  ASSERT_EQ(q.status, 0) << q.err;
  EXPECT_EQ(lines(q.out).size(), 2u);
  EXPECT_TRUE(temporaries().empty());
}

}  // namespace

// A newline in a file, layer or field name keeps an error to one line and a summary to one
// line per item (they were printed raw).
TEST_F(BadInput, NamesWithNewlinesKeepMessagesToOneLine) {
  const CliRun missing =
      run_loci("query " + shell_quote(path("no\nfile.geojson")) + " --bbox 0,0,1,1");
  expect_one_line_error(missing);
  EXPECT_NE(missing.err.find("no?file.geojson"), std::string::npos) << missing.err;
  const std::string l = write("odd.geojson", R"({"type":"FeatureCollection","features":[
{"type":"Feature","properties":{"a\nb":1},"geometry":{"type":"Point","coordinates":[0,0]}}]})");
  expect_one_line_error(
      run_loci("query " + shell_quote(l) + " --layer " + shell_quote("x\ny") + " --bbox 0,0,1,1"));
  const CliRun info = run_loci("info " + shell_quote(l));
  ASSERT_EQ(info.status, 0) << info.err;
  EXPECT_NE(info.out.find("fields:    a?b:Integer\n"), std::string::npos) << info.out;
  // A path with a newline: info's index line, and a command's report of what it wrote.
  fs::create_directories(path("nl\ndir"));
  const std::string odd = path("nl\ndir/x.geojson");
  fs::copy_file(l, odd, fs::copy_options::overwrite_existing);
  const CliRun in_dir = run_loci("info " + shell_quote(odd));
  ASSERT_EQ(in_dir.status, 0) << in_dir.err;
  EXPECT_EQ(lines(in_dir.out).size(), 7u) << in_dir.out;
  // The command offered names it as a shell reads it back ($'\x0a' for the newline).
  EXPECT_NE(in_dir.out.find("index:     none (loci index '" + path("nl") +
                            "'$'\\x0a''dir/x.geojson' writes "),
            std::string::npos)
      << in_dir.out;
  const std::string offered = in_dir.out.substr(in_dir.out.find("loci index ") + 11);
  const std::string word = offered.substr(0, offered.find(" writes "));
  EXPECT_EQ(run_command("bash -c " + shell_quote("test -f " + word)).status, 0) << word;
  const CliRun wrote = run_loci("intersections " + shell_quote(lines_layer()) + " -o " +
                                shell_quote(path("a\nb.csv")));
  ASSERT_EQ(wrote.status, 0) << wrote.err;
  EXPECT_EQ(lines(wrote.err).size(), 1u) << wrote.err;
  // Bytes of a binary file are '?' too (a PNG's 0x89, a C1 control's UTF-8 form), and text in
  // UTF-8 stays as it is.
  write("binary.txt", "0,0,\x89PNG\xc2\x9b,1\n");
  const CliRun binary = run_loci("query " + shell_quote(lines_layer()) + " --bbox-file " +
                                 shell_quote(path("binary.txt")));
  expect_one_line_error(binary);
  EXPECT_NE(binary.err.find("'0,0,?PNG??,1'"), std::string::npos) << binary.err;
  const CliRun accented =
      run_loci("query " + shell_quote(path("caf\xc3\xa9.geojson")) + " --bbox 0,0,1,1");
  expect_one_line_error(accented);
  EXPECT_NE(accented.err.find("caf\xc3\xa9.geojson"), std::string::npos) << accented.err;
  // A line cut for the message is cut between characters; a mark turning the text's
  // direction (U+202E) or a line separator (U+2028) is '?'.
  std::string long_line = "a";
  for (int i = 0; i < 40; ++i)
    long_line += "\xc3\xa9";
  write("accents.txt", long_line + "\n");
  const CliRun cut = run_loci("query " + shell_quote(lines_layer()) + " --bbox-file " +
                              shell_quote(path("accents.txt")));
  expect_one_line_error(cut);
  EXPECT_NE(cut.err.find("a" + long_line.substr(1, 58) + "...'"), std::string::npos) << cut.err;
  write("marks.txt",
        "1,\xe2\x80\xae"
        "2,\xe2\x80\xa8"
        "3,4\n");
  const CliRun marks = run_loci("query " + shell_quote(lines_layer()) + " --bbox-file " +
                                shell_quote(path("marks.txt")));
  expect_one_line_error(marks);
  EXPECT_NE(marks.err.find("'1,???2,???3,4'"), std::string::npos) << marks.err;
  // A Latin-1 name (not UTF-8) is '?' in messages, and offered as the shell reads it back.
  const std::string latin = path("caf\xe9.geojson");
  fs::copy_file(lines_layer(), latin, fs::copy_options::overwrite_existing);
  const CliRun info_latin = run_loci("info " + shell_quote(latin));
  ASSERT_EQ(info_latin.status, 0) << info_latin.err;
  EXPECT_NE(info_latin.out.find("'$'\\xe9''.geojson' writes "), std::string::npos)
      << info_latin.out;
}
