// The size limits of GDAL's shapefile reader kept by the direct reader (read_shapefile_boxes,
// read_shapefile_segments): a record of more than 10,000,000 parts is corrupt to GDAL, so the
// direct reader hands the file to GDAL (which refuses it) instead of indexing it; a record at
// the limit is read directly. The files are 200 MB each, written and read in about a second.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "loci/io/shapefile_boxes.hpp"

namespace {

namespace fs = std::filesystem;

void put_be32(std::vector<char>& b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i)
    b[at + std::size_t(i)] = char(v >> (24 - 8 * i));
}
template <class T>
void put_le(std::vector<char>& b, std::size_t at, T v) {
  std::memcpy(b.data() + at, &v, sizeof v);
}

// The 100-byte header of a polyline .shp or .shx of `bytes` bytes over the box (0,0)-(1,1).
std::vector<char> header(std::uint64_t bytes) {
  std::vector<char> h(100, 0);
  put_be32(h, 0, 9994);
  put_be32(h, 24, std::uint32_t(bytes / 2));
  put_le<std::int32_t>(h, 28, 1000);
  put_le<std::int32_t>(h, 32, 3);
  put_le<double>(h, 44, 1.0);
  put_le<double>(h, 52, 1.0);
  return h;
}

// A shapefile of one polyline record of `parts` parts over parts + 1 points, the points on the
// diagonal of the unit square, with a .dbf of one integer field.
std::string write_polyline(const fs::path& dir, const std::string& name, std::uint32_t parts) {
  const std::uint32_t points = parts + 1;
  const std::uint64_t content = 44 + 4 * std::uint64_t(parts) + 16 * std::uint64_t(points);
  std::vector<char> record(8 + content, 0);
  put_be32(record, 0, 1);
  put_be32(record, 4, std::uint32_t(content / 2));
  put_le<std::int32_t>(record, 8, 3);
  put_le<double>(record, 8 + 20, 1.0);
  put_le<double>(record, 8 + 28, 1.0);
  put_le<std::uint32_t>(record, 8 + 36, parts);
  put_le<std::uint32_t>(record, 8 + 40, points);
  for (std::uint32_t i = 0; i < parts; ++i)
    put_le<std::uint32_t>(record, 8 + 44 + 4 * i, i);
  const std::size_t xy = 8 + 44 + 4 * std::size_t(parts);
  for (std::uint32_t i = 0; i < points; ++i) {
    const double v = double(i) / double(parts);
    put_le<double>(record, xy + 16 * std::size_t(i), v);
    put_le<double>(record, xy + 16 * std::size_t(i) + 8, v);
  }
  const std::string stem = (dir / name).string();
  {
    std::ofstream shp(stem + ".shp", std::ios::binary | std::ios::trunc);
    const auto h = header(100 + record.size());
    shp.write(h.data(), std::streamsize(h.size()));
    shp.write(record.data(), std::streamsize(record.size()));
  }
  {
    std::ofstream shx(stem + ".shx", std::ios::binary | std::ios::trunc);
    auto h = header(108);
    h.resize(108);
    put_be32(h, 100, 50);
    put_be32(h, 104, std::uint32_t(content / 2));
    shx.write(h.data(), std::streamsize(h.size()));
  }
  {
    // dBASE III: one record of one numeric field "n" of 10 characters.
    std::vector<char> dbf(32 + 32 + 1, 0);
    dbf[0] = 3;
    dbf[1] = 126, dbf[2] = 1, dbf[3] = 1;
    put_le<std::uint32_t>(dbf, 4, 1);
    put_le<std::uint16_t>(dbf, 8, 65);
    put_le<std::uint16_t>(dbf, 10, 11);
    dbf[32] = 'n';
    dbf[32 + 11] = 'N';
    dbf[32 + 16] = 10;
    dbf[64] = '\r';
    const std::string row = "          1";
    dbf.insert(dbf.end(), row.begin(), row.end());
    dbf.push_back('\x1a');
    std::ofstream(stem + ".dbf", std::ios::binary | std::ios::trunc)
        .write(dbf.data(), std::streamsize(dbf.size()));
  }
  return stem + ".shp";
}

TEST(ShapefileLimits, ARecordOfMorePartsThanGdalTakesGoesToGdal) {
  const fs::path dir =
      fs::temp_directory_path() / ("loci-shp-limits-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);

  // At the limit: read directly, one feature over the unit square, one segment per part.
  const std::string at = write_polyline(dir, "at_limit", 10'000'000);
  const auto boxes = loci::io::read_shapefile_boxes(at);
  ASSERT_TRUE(boxes);
  ASSERT_EQ(boxes->items.boxes.size(), 1u);
  EXPECT_EQ(boxes->items.boxes[0].min[0], 0.0);
  EXPECT_EQ(boxes->items.boxes[0].max[1], 1.0);
  fs::remove(at);

  // One part more: corrupt to GDAL, so not read directly (GDAL then refuses the file).
  const std::string over = write_polyline(dir, "over_limit", 10'000'001);
  EXPECT_FALSE(loci::io::read_shapefile_boxes(over));
  EXPECT_FALSE(loci::io::read_shapefile_segments(over));
  fs::remove_all(dir);
}

}  // namespace
