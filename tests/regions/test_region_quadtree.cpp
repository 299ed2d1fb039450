// RegionQuadtree against brute force on the finest grid: random and blob-shaped rasters,
// discs and half-planes described by classifiers (exact and deliberately conservative), window
// queries, point location on grid lines, overlays, and degenerate grids.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "loci/index/region_quadtree.hpp"

using namespace loci;

namespace {

struct Raster {
  std::size_t width, height;
  std::vector<std::uint8_t> pixels;
  bool at(std::size_t c, std::size_t r) const {
    return c < width && r < height && pixels[r * width + c];
  }
};

enum class Picture { noise, blobs, all_set, none_set, one_pixel };

Raster make_raster(Picture p, std::size_t width, std::size_t height, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Raster r{width, height, std::vector<std::uint8_t>(width * height, 0)};
  switch (p) {
    case Picture::noise:
      for (auto& v : r.pixels)
        v = rng() % 3 == 0;
      break;
    case Picture::blobs:
      for (int b = 0; b < 6; ++b) {
        const double cx = double(rng() % width), cy = double(rng() % height);
        const double rad = 2 + double(rng() % (width / 3 + 1));
        for (std::size_t y = 0; y < height; ++y)
          for (std::size_t x = 0; x < width; ++x)
            if (std::hypot(x - cx, y - cy) <= rad) r.pixels[y * width + x] = 1;
      }
      break;
    case Picture::all_set:
      std::fill(r.pixels.begin(), r.pixels.end(), 1);
      break;
    case Picture::one_pixel:
      r.pixels[(rng() % height) * width + rng() % width] = 1;
      break;
    default:
      break;
  }
  return r;
}

// The cover of a closed box against a closed disc, decided on exact corner distances.
Cover disc_cover(const Box2& b, const Point2& c, double r) {
  const double near = squared_distance(c, b);
  double far = 0;
  for (int a = 0; a < 2; ++a) {
    const double d = std::max(std::abs(c[a] - b.min[a]), std::abs(c[a] - b.max[a]));
    far += d * d;
  }
  if (near > r * r) return Cover::outside;
  return far <= r * r ? Cover::inside : Cover::boundary;
}

// Every finest cell's cover, read at its centre, must be what `truth` says of its block.
template <class Truth>
void expect_cells(const RegionQuadtree& t, Truth truth) {
  const std::uint32_t cells = 1u << t.levels();
  for (std::uint32_t y = 0; y < cells; ++y)
    for (std::uint32_t x = 0; x < cells; ++x) {
      const Box2 b = t.cell_box(x, y, t.levels());
      ASSERT_EQ(t.cover_at(b.center()), truth(x, y, b)) << "cell " << x << "," << y;
    }
}

std::vector<QuadCell> leaves(const RegionQuadtree& t) {
  std::vector<QuadCell> out;
  t.visit_cells([&](const QuadCell& c) { out.push_back(c); });
  return out;
}

bool same_cells(const std::vector<QuadCell>& a, const std::vector<QuadCell>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].box != b[i].box || a[i].cover != b[i].cover || a[i].level != b[i].level ||
        a[i].x != b[i].x || a[i].y != b[i].y)
      return false;
  return true;
}

const Box2 kRegion{{-3.5, 10.25}, {60.5, 74.25}};  // side 64

}  // namespace

class RasterTest : public ::testing::TestWithParam<Picture> {};

TEST_P(RasterTest, EveryPixelAndTheAreaMatchTheRaster) {
  for (const auto& [w, h, levels] : {std::tuple{64, 64, 6}, {50, 37, 6}, {1, 1, 0}, {9, 16, 5}}) {
    const Raster r = make_raster(GetParam(), w, h, 17 + w);
    const auto t = RegionQuadtree::from_raster(kRegion, levels, r.pixels, r.width, r.height);
    t.validate();
    EXPECT_EQ(t.count(Cover::boundary), 0u);
    expect_cells(t, [&](std::uint32_t x, std::uint32_t y, const Box2&) {
      return r.at(x, y) ? Cover::inside : Cover::outside;
    });
    const double step = 64.0 / double(1u << levels);
    const auto set = std::count(r.pixels.begin(), r.pixels.end(), 1);
    EXPECT_DOUBLE_EQ(t.area(Cover::inside), double(set) * step * step);
    EXPECT_DOUBLE_EQ(t.area(Cover::inside) + t.area(Cover::outside), 64.0 * 64.0);
  }
}

TEST_P(RasterTest, ClassifierBuildGivesTheSameTree) {
  const Raster r = make_raster(GetParam(), 32, 32, 5);
  const auto t = RegionQuadtree::from_raster(kRegion, 5, r.pixels, r.width, r.height);
  const double step = 2.0;
  // brute force: count the pixels under each block
  const auto u = RegionQuadtree::build(kRegion, 5, [&](const Box2& b) {
    std::size_t in = 0, all = 0;
    for (std::size_t y = 0; y < 32; ++y)
      for (std::size_t x = 0; x < 32; ++x) {
        const Point2 c{kRegion.min[0] + (x + 0.5) * step, kRegion.min[1] + (y + 0.5) * step};
        if (!intersects(b, c)) continue;
        ++all;
        in += r.at(x, y);
      }
    return in == 0 ? Cover::outside : in == all ? Cover::inside : Cover::boundary;
  });
  u.validate();
  EXPECT_TRUE(same_cells(leaves(t), leaves(u)));
  EXPECT_EQ(t.node_count(), u.node_count());
}

std::string picture_name(const ::testing::TestParamInfo<Picture>& info) {
  static const char* const names[] = {"noise", "blobs", "all_set", "none_set", "one_pixel"};
  return names[int(info.param)];
}

INSTANTIATE_TEST_SUITE_P(Pictures, RasterTest,
                         ::testing::Values(Picture::noise, Picture::blobs, Picture::all_set,
                                           Picture::none_set, Picture::one_pixel),
                         picture_name);

TEST(RegionQuadtree, DiscHasMxBoundaryCellsExactlyWhereTheCircleRuns) {
  const Point2 c{20.0, 40.0};
  for (const double r : {0.0, 0.7, 9.0, 30.0, 200.0}) {
    const auto t =
        RegionQuadtree::build(kRegion, 7, [&](const Box2& b) { return disc_cover(b, c, r); });
    t.validate();
    expect_cells(t,
                 [&](std::uint32_t, std::uint32_t, const Box2& b) { return disc_cover(b, c, r); });
    // every boundary cell really is crossed by the circle, and only finest cells are
    t.visit_cells([&](const QuadCell& cell) {
      EXPECT_EQ(cell.cover, disc_cover(cell.box, c, r));
      if (cell.cover == Cover::boundary) EXPECT_EQ(cell.level, 7);
    });
  }
}

TEST(RegionQuadtree, ConservativeClassifierMergesBackToTheSameTree) {
  const Point2 c{33.0, 41.0};
  const double r = 17.5;
  const int levels = 6;
  const auto exact =
      RegionQuadtree::build(kRegion, levels, [&](const Box2& b) { return disc_cover(b, c, r); });
  // says boundary for every block coarser than 4 finest cells across
  const auto lazy = RegionQuadtree::build(kRegion, levels, [&](const Box2& b) {
    return b.extent(0) > 4.0 ? Cover::boundary : disc_cover(b, c, r);
  });
  lazy.validate();
  EXPECT_TRUE(same_cells(leaves(exact), leaves(lazy)));
}

TEST(RegionQuadtree, WindowQueryMatchesBruteForceOverLeaves) {
  const Raster r = make_raster(Picture::blobs, 64, 64, 9);
  const auto a = RegionQuadtree::from_raster(kRegion, 6, r.pixels, r.width, r.height);
  const auto b = RegionQuadtree::build(kRegion, 6, [&](const Box2& box) {
    return disc_cover(box, {10.0, 30.0}, 12.0);
  });
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-10, 70), side(0, 30);
  for (const RegionQuadtree* t : {&a, &b}) {
    const auto all = leaves(*t);
    for (int q = 0; q < 300; ++q) {
      Box2 w{{u(rng) + kRegion.min[0], u(rng) + kRegion.min[1]}, {0, 0}};
      w.max = {w.min[0] + side(rng), w.min[1] + (q % 10 == 0 ? 0 : side(rng))};
      if (q % 7 == 0) w = t->cell_box(rng() % 8, rng() % 8, 3);  // touching along grid lines
      std::vector<QuadCell> want;
      for (const auto& cell : all)
        if (cell.cover != Cover::outside && intersects(cell.box, w)) want.push_back(cell);
      const auto got = t->query(w);
      ASSERT_TRUE(same_cells(got, want)) << "window " << to_string(w);
      const auto s = t->query(w, [](const QuadCell&) { return true; });
      EXPECT_EQ(s.results, want.size());
    }
  }
  std::size_t seen = 0;
  a.query(kRegion, [&](const QuadCell&) { return ++seen, false; });
  EXPECT_EQ(seen, 1u);
}

TEST(RegionQuadtree, PointLocationOnGridLinesAndOutside) {
  const Raster r = make_raster(Picture::noise, 16, 16, 4);
  const auto t = RegionQuadtree::from_raster(kRegion, 4, r.pixels, r.width, r.height);
  // a point on a grid line belongs to the cell above / right of it; the top edge to the last
  for (std::uint32_t y = 0; y <= 16; ++y)
    for (std::uint32_t x = 0; x <= 16; ++x) {
      const Point2 p{kRegion.min[0] + 4.0 * x, kRegion.min[1] + 4.0 * y};
      EXPECT_EQ(t.cover_at(p),
                r.at(std::min(x, 15u), std::min(y, 15u)) ? Cover::inside : Cover::outside);
    }
  EXPECT_EQ(t.cover_at({kRegion.min[0] - 1, kRegion.min[1]}), Cover::outside);
  EXPECT_EQ(t.cover_at({kRegion.max[0], kRegion.max[1] + 1e-9}), Cover::outside);
  EXPECT_THROW(t.cover_at({std::nan(""), 0.0}), InvalidGeometry);
  EXPECT_THROW(t.query(Box2{{1, 1}, {0, 0}}), InvalidGeometry);
}

TEST(RegionQuadtree, OverlayMatchesCellWiseCombination) {
  const int levels = 6;
  const Raster r = make_raster(Picture::blobs, 64, 64, 21);
  const auto img = RegionQuadtree::from_raster(kRegion, levels, r.pixels, r.width, r.height);
  const auto disc = RegionQuadtree::build(kRegion, levels, [&](const Box2& b) {
    return disc_cover(b, {40.0, 50.0}, 20.0);
  });
  const auto disc2 = RegionQuadtree::build(kRegion, levels, [&](const Box2& b) {
    return disc_cover(b, {25.0, 45.0}, 14.0);
  });
  auto unite = [](Cover x, Cover y) {
    if (x == Cover::inside || y == Cover::inside) return Cover::inside;
    return x == Cover::boundary || y == Cover::boundary ? Cover::boundary : Cover::outside;
  };
  auto meet = [](Cover x, Cover y) {
    if (x == Cover::outside || y == Cover::outside) return Cover::outside;
    return x == Cover::inside && y == Cover::inside ? Cover::inside : Cover::boundary;
  };
  for (const auto& [first, second] : {std::pair{&img, &disc}, {&disc, &disc2}, {&disc, &disc}}) {
    const RegionQuadtree* a = first;  // named, not bound, for the lambdas below
    const RegionQuadtree* b = second;
    const auto u = RegionQuadtree::unite(*a, *b);
    const auto m = RegionQuadtree::intersect(*a, *b);
    u.validate();
    m.validate();
    expect_cells(u, [&](std::uint32_t, std::uint32_t, const Box2& box) {
      return unite(a->cover_at(box.center()), b->cover_at(box.center()));
    });
    expect_cells(m, [&](std::uint32_t, std::uint32_t, const Box2& box) {
      return meet(a->cover_at(box.center()), b->cover_at(box.center()));
    });
  }
  EXPECT_TRUE(same_cells(leaves(RegionQuadtree::unite(disc, disc)), leaves(disc)));
  const auto other =
      RegionQuadtree::build(kRegion, levels - 1, [](const Box2&) { return Cover::inside; });
  EXPECT_THROW(RegionQuadtree::unite(disc, other), InvalidArgument);
}

TEST(RegionQuadtree, DegenerateGridsAndBadInput) {
  // no cuts: one leaf, boundary if the classifier says so
  const auto one = RegionQuadtree::build(kRegion, 0, [](const Box2&) { return Cover::boundary; });
  one.validate();
  EXPECT_EQ(one.node_count(), 1u);
  EXPECT_EQ(one.count(Cover::boundary), 1u);
  // all boundary: the full grid of finest cells
  const auto full = RegionQuadtree::build(kRegion, 4, [](const Box2&) { return Cover::boundary; });
  full.validate();
  EXPECT_EQ(full.count(Cover::boundary), 256u);
  EXPECT_EQ(full.query(kRegion).size(), 256u);
  // a thin region is extended to a square from its min corner
  const auto thin =
      RegionQuadtree::build(Box2{{0, 0}, {8, 1}}, 3, [](const Box2&) { return Cover::inside; });
  EXPECT_EQ(thin.region(), (Box2{{0, 0}, {8, 8}}));
  EXPECT_EQ(thin.node_count(), 1u);

  auto any = [](const Box2&) { return Cover::inside; };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(RegionQuadtree::build(Box2{{nan, 0}, {1, 1}}, 3, any), InvalidGeometry);
  EXPECT_THROW(RegionQuadtree::build(Box2{{0, 0}, {0, 0}}, 3, any), InvalidGeometry);
  EXPECT_THROW(RegionQuadtree::build(kRegion, 31, any), InvalidArgument);
  EXPECT_THROW(RegionQuadtree::build(kRegion, -1, any), InvalidArgument);
  // A cell the tree does not have (a level below its finest shifted by a negative count, an
  // x beyond the grid gave an inverted box).
  const auto two = RegionQuadtree::build(kRegion, 2, any);
  EXPECT_THROW(two.cell_box(0, 0, 5), InvalidArgument);
  EXPECT_THROW(two.cell_box(0, 0, -1), InvalidArgument);
  EXPECT_THROW(two.cell_box(4, 0, 2), InvalidArgument);
  EXPECT_THROW(two.cell_box(0, 2, 1), InvalidArgument);
  EXPECT_THROW(two.cell_box(~0u, 0, 0), InvalidArgument);
  EXPECT_EQ(two.cell_box(3, 3, 2).max, two.region().max);
  EXPECT_THROW(RegionQuadtree::build(Box2{{1e9, 1e9}, {1e9 + 1e-3, 1e9 + 1e-3}}, 30, any),
               InvalidArgument);
  const std::vector<std::uint8_t> px(100, 1);
  EXPECT_THROW(RegionQuadtree::from_raster(kRegion, 3, px, 10, 10), InvalidArgument);
  EXPECT_THROW(RegionQuadtree::from_raster(kRegion, 4, px, 11, 10), InvalidArgument);
}
