// Layer nearest-n per segment (LayerQuery on a LayerIndex built in memory and on a mapped
// sidecar) against brute force over every segment of every feature, on layers whose features
// interleave: long random walks crossing one region, so that tree nodes hold segments of many
// features and the walk must not drop a subtree while one of its features can still be nearer.
// Duplicated features give ties; a feature of one zero-length segment and points far outside
// the layer are included.
#include <gtest/gtest.h>

#include <unistd.h>
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <functional>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "loci/geom/predicates.hpp"
#include "loci/io/commands.hpp"
#include "loci/io/exact.hpp"
#include "loci/io/layer_query.hpp"
#include "loci/io/sidecar.hpp"

namespace loci::io {
namespace {

struct Layer {
  LayerItems items;
  std::vector<std::pair<std::int64_t, Segment2>> segments;  // (fid, segment), brute force
};

void add_segment(Layer& l, std::int64_t fid, const Point2& a, const Point2& b) {
  const Segment2 s{a, b};
  l.items.boxes.push_back(s.box());
  l.items.records.push_back({fid, 0, segment_flags(a, b, false)});
  l.segments.emplace_back(fid, s);
}

// `features` random walks of `steps` segments over [0, 100]^2; every fifth feature repeats the
// one before it (same geometry, another FID).
Layer interleaved(int features, int steps, std::uint64_t seed) {
  Layer l;
  l.items.per = Per::segment;
  l.items.layer_name = "walks";
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> pos(0, 100), step(-6, 6);
  std::vector<Segment2> previous;
  for (int f = 0; f < features; ++f) {
    const std::int64_t fid = 10 * f + 3;
    if (f % 5 == 4) {
      for (const Segment2& s : previous)
        add_segment(l, fid, s.a, s.b);
      continue;
    }
    previous.clear();
    Point2 p{pos(rng), pos(rng)};
    for (int i = 0; i < steps; ++i) {
      Point2 q{std::clamp(p[0] + step(rng), 0.0, 100.0), std::clamp(p[1] + step(rng), 0.0, 100.0)};
      if (i % 7 == 3) q[1] = p[1];   // horizontal
      if (i % 11 == 5) q[0] = p[0];  // vertical
      add_segment(l, fid, p, q);
      previous.push_back({p, q});
      p = q;
    }
  }
  add_segment(l, 7777, {50.5, 50.5}, {50.5, 50.5});  // a point
  return l;
}

std::vector<std::pair<double, std::int64_t>> brute(const Layer& l, const Point2& p) {
  std::map<std::int64_t, double> best;
  for (const auto& [fid, s] : l.segments) {
    const double d = std::sqrt(squared_distance(p, s));
    const auto [it, fresh] = best.try_emplace(fid, d);
    if (!fresh) it->second = std::min(it->second, d);
  }
  std::vector<std::pair<double, std::int64_t>> out;
  for (const auto& [fid, d] : best)
    out.emplace_back(d, fid);
  std::sort(out.begin(), out.end());
  return out;
}

// Every answer of k-nearest at each point: distances in rank order equal to brute force's,
// each feature reported once with its own distance.
void check(const LayerIndex& index, const Layer& l, std::uint64_t seed) {
  LayerQuery query(index, "", "");
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> near(-5, 105), far(-400, 400);
  std::size_t compared = 0;
  for (int i = 0; i < 300; ++i) {
    const Point2 p = i % 10 == 9 ? Point2{far(rng), far(rng)} : Point2{near(rng), near(rng)};
    const auto expected = brute(l, p);
    std::map<std::int64_t, double> of;
    for (const auto& [d, fid] : expected)
      of[fid] = d;
    // The answers of the largest k first: each smaller k's is its first rows (features at
    // equal distances rank by FID, duplicated features' among them).
    std::vector<Answer> all;
    for (const std::size_t k : {of.size() + 3, std::size_t(1), std::size_t(4), std::size_t(17)}) {
      std::vector<Answer> got;
      Query q;
      q.kind = Query::Kind::nearest;
      q.point = p;
      q.k = k;
      query.run(q, 1, false, got);
      ASSERT_EQ(got.size(), std::min(k, expected.size())) << "k " << k;
      if (all.empty()) all = got;
      std::vector<std::int64_t> seen;
      for (std::size_t r = 0; r < got.size(); ++r) {
        EXPECT_EQ(got[r].fid, all[r].fid) << "point " << p[0] << ',' << p[1] << " k " << k;
        EXPECT_EQ(got[r].distance, all[r].distance);
        if (r > 0 && got[r].distance == got[r - 1].distance)
          EXPECT_LT(got[r - 1].fid, got[r].fid) << "a tie out of FID order";
        // A segment comes back from its box in canonical direction: the last bit may differ.
        const double tol = 1e-13 * (1 + expected[r].first);
        EXPECT_NEAR(got[r].distance, expected[r].first, tol)
            << "point " << p[0] << ',' << p[1] << " k " << k << " rank " << r;
        ASSERT_TRUE(of.count(got[r].fid));
        EXPECT_NEAR(got[r].distance, of[got[r].fid], tol);
        seen.push_back(got[r].fid);
        ++compared;
      }
      std::sort(seen.begin(), seen.end());
      EXPECT_EQ(std::adjacent_find(seen.begin(), seen.end()), seen.end()) << "a feature twice";
    }
  }
  EXPECT_GT(compared, 3000u);
}

TEST(LayerNearest, InterleavedFeaturesInMemory) {
  for (const Structure s : {Structure::packed_hilbert, Structure::packed_str, Structure::rstar}) {
    Layer l = interleaved(60, 120, 5);
    Layer copy = l;
    const LayerIndex index = LayerIndex::build(std::move(copy.items), s);
    check(index, l, 11);
  }
}

TEST(LayerNearest, ManySmallFeatures) {
  Layer l = interleaved(2000, 3, 8);
  Layer copy = l;
  const LayerIndex index = LayerIndex::build(std::move(copy.items), Structure::packed_hilbert);
  check(index, l, 12);
}

// A tree of one leaf (13 segments of 4 features): the features' boxes come from the leaf itself.
TEST(LayerNearest, OneLeaf) {
  for (const Structure s : {Structure::packed_hilbert, Structure::packed_str}) {
    Layer l = interleaved(3, 4, 9);
    ASSERT_LE(l.items.boxes.size(), 16u);
    Layer copy = l;
    const LayerIndex index = LayerIndex::build(std::move(copy.items), s);
    check(index, l, 14);
  }
}

TEST(LayerNearest, InterleavedFeaturesFromASidecar) {
  Layer l = interleaved(40, 200, 6);
  const PackedRTree2 tree = PackedRTree2::build(l.items.boxes);
  SidecarInfo info;
  info.per = Per::segment;
  info.layer_name = "walks";
  info.items = l.items.boxes.size();
  info.bounds = tree.bounds();
  const std::string path = "/tmp/loci-nearest-" + std::to_string(::getpid()) + ".loci";
  write_sidecar(path, tree, l.items.records, info);
  LayerIndex index = LayerIndex::adopt(Sidecar::open(path));
  ::unlink(path.c_str());
  check(index, l, 13);
}

using Levels = std::vector<std::vector<HierarchyNode>>;
using Tamper = std::function<void(Levels&, std::vector<HierarchyRoot>&)>;
using HullTamper = std::function<void(std::vector<std::uint32_t>&, std::vector<Point2>&)>;

// Writes a per-segment sidecar of `items` at `path` with the features' hierarchies stored, as
// loci index writes it; `tamper` may change a copy of their nodes and roots first (the file's
// checksums then hold for what it wrote: a forged file).
void write_with_hierarchies(const LayerItems& items, const std::string& path,
                            const Tamper& tamper = {}, const HullTamper& hull_tamper = {}) {
  const PackedRTree2 tree = PackedRTree2::build(items.boxes);
  const LayerIndex::Features f = LayerIndex::build_features(&tree, Per::segment, items.records);
  ASSERT_TRUE(f.hierarchical);
  Levels levels;
  for (const auto& l : f.levels)
    levels.emplace_back(l.begin(), l.end());
  std::vector<HierarchyRoot> roots(f.roots.begin(), f.roots.end());
  if (tamper) tamper(levels, roots);
  std::vector<std::uint32_t> hull_first(f.hull_first.begin(), f.hull_first.end());
  std::vector<Point2> hull_points(f.hull_points.begin(), f.hull_points.end());
  if (hull_tamper) hull_tamper(hull_first, hull_points);
  Hierarchies h{f.fid, {}, roots, &f.root_tree, hull_first, hull_points};
  for (const auto& l : levels)
    h.levels.emplace_back(l);
  SidecarInfo info;
  info.per = Per::segment;
  info.layer_name = items.layer_name;
  info.has_polygons = items.has_polygons;
  info.items = items.boxes.size();
  info.bounds = tree.bounds();
  write_sidecar(path, tree, items.records, info, &h);
}

std::string scratch(const char* name) {
  return "/tmp/loci-" + std::string(name) + "-" + std::to_string(::getpid()) + ".loci";
}

// The hierarchies stored by loci index are read in place (nothing is built) and answer as
// those built in memory do.
TEST(LayerNearest, StoredHierarchiesAnswerAsBuiltOnes) {
  for (const auto& [features, steps] : {std::pair{40, 200}, std::pair{2000, 3}}) {
    const Layer l = interleaved(features, steps, 6);
    const std::string path = scratch("stored");
    write_with_hierarchies(l.items, path);
    const LayerIndex index = LayerIndex::adopt(Sidecar::open(path));
    ::unlink(path.c_str());
    const LayerIndex::Features& f = index.features();
    ASSERT_TRUE(f.hierarchical);
    EXPECT_NE(f.check, nullptr) << "built instead of read from the file";
    EXPECT_TRUE(f.own_levels.empty());
    check(index, l, 13);
  }
}

// A file whose hierarchies are forged with valid checksums (indices out of range, a node of
// more than 16 children, a feature beyond the FIDs) is refused when a query reads the bad
// node, with a message naming the file, and never followed outside the arrays.
TEST(LayerNearest, ForgedHierarchiesAreRefusedWhenRead) {
  const Layer l = interleaved(40, 200, 16);
  const std::vector<std::pair<const char*, Tamper>> forgeries = {
      {"leaf out of range",
       [](Levels& levels, std::vector<HierarchyRoot>&) {
         for (auto& n : levels[0])
           n.first = n.last = 1u << 30;
       }},
      {"feature out of range",
       [](Levels& levels, std::vector<HierarchyRoot>&) {
         for (auto& n : levels[0])
           n.feature = 1u << 20;
       }},
      {"children beyond the level below",
       [](Levels& levels, std::vector<HierarchyRoot>&) {
         for (auto& n : levels[1])
           n.last = std::uint32_t(levels[0].size()) + 1;
       }},
      {"seventeen children",
       [](Levels& levels, std::vector<HierarchyRoot>&) {
         for (auto& n : levels[1])
           n.last = std::min(n.first + 17, std::uint32_t(levels[0].size()));
       }},
      {"root out of range",
       [](Levels&, std::vector<HierarchyRoot>& roots) {
         for (auto& r : roots)
           r.node = 1u << 30;
       }},
      {"root of no level",
       [](Levels&, std::vector<HierarchyRoot>& roots) {
         for (auto& r : roots)
           r.level = 70;
       }},
      {"nodes sharing their children",
       [](Levels& levels, std::vector<HierarchyRoot>& roots) {
         // 63 levels of 16 nodes above level 0, each over the first 16 nodes below it, every
         // box holding the layer: a walk of 16^63 paths, each node within the arrays.
         levels.resize(1);
         Box2 all = Box2::empty();
         for (const auto& n : levels[0])
           all.expand(n.box);
         for (int l = 1; l < 64; ++l)
           levels.emplace_back(16, HierarchyNode{all, 0, 0, 16, 0});
         for (auto& r : roots)
           r = {63, 0};
       }},
  };
  // The queries, and their answers from the sound file.
  std::vector<Query> queries;
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> near(-5, 105);
  for (int i = 0; i < 40; ++i) {
    Query q;
    q.kind = Query::Kind::nearest;
    q.point = {near(rng), near(rng)};
    q.k = 1 + i % 5;
    queries.push_back(q);
  }
  std::vector<std::vector<Answer>> sound(queries.size());
  {
    const std::string path = scratch("sound");
    write_with_hierarchies(l.items, path, {});
    const LayerIndex index = LayerIndex::adopt(Sidecar::open(path));
    LayerQuery query(index, "", "");
    for (std::size_t i = 0; i < queries.size(); ++i)
      query.run(queries[i], 1, false, sound[i]);
    ::unlink(path.c_str());
  }
  for (const auto& [what, tamper] : forgeries) {
    const std::string path = scratch("forged");
    write_with_hierarchies(l.items, path, tamper);
    const LayerIndex index = LayerIndex::adopt(Sidecar::open(path));
    LayerQuery query(index, "", "");
    // Each query is refused, or answers from what it read of the file, all sound (a feature
    // measured from its hull alone does not read its nodes).
    std::size_t refused = 0;
    for (std::size_t i = 0; i < queries.size(); ++i) {
      std::vector<Answer> answers;
      try {
        query.run(queries[i], 1, false, answers);
      } catch (const Error& e) {
        ++refused;
        EXPECT_NE(std::string(e.what()).find(path + ": corrupt index file (feature hierarchies)"),
                  std::string::npos)
            << what << ": " << e.what();
        continue;
      }
      ASSERT_EQ(answers.size(), sound[i].size()) << what;
      for (std::size_t r = 0; r < answers.size(); ++r) {
        EXPECT_EQ(answers[r].fid, sound[i][r].fid) << what;
        EXPECT_EQ(answers[r].distance, sound[i][r].distance) << what;
      }
    }
    EXPECT_GE(refused, 20u) << what;
    // loci check finds it too.
    EXPECT_THROW(check_sidecar(path), Error) << what;
    ::unlink(path.c_str());
  }
}

// Hierarchies that stay within their arrays but are not those of the segments (two nodes'
// boxes swapped, a leaf's slot given to the wrong feature or the wrong diagonal) may answer
// wrongly; loci check compares them with the segments' and says so.
TEST(LayerNearest, CheckComparesTheStoredHierarchiesWithTheSegments) {
  const Layer l = interleaved(40, 200, 18);
  const std::string path = scratch("check");
  write_with_hierarchies(l.items, path);
  EXPECT_NE(check_sidecar(path).find(": ok,"), std::string::npos);
  const std::vector<std::pair<const char*, Tamper>> tampers = {
      {"boxes swapped",
       [](Levels& levels, std::vector<HierarchyRoot>&) {
         std::swap(levels[0][3].box, levels[0][levels[0].size() - 4].box);
       }},
      {"a slot dropped",
       [](Levels& levels, std::vector<HierarchyRoot>&) {
         std::uint32_t& slots = levels[0][5].slots;
         slots &= ~(1u << std::countr_zero(slots));
       }},
      {"a diagonal turned",
       [](Levels& levels, std::vector<HierarchyRoot>&) {
         std::uint32_t& slots = levels[0][7].slots;
         slots ^= 1u << (16 + std::countr_zero(slots));
       }},
  };
  const std::vector<std::pair<const char*, HullTamper>> hull_tampers = {
      {"a hull vertex moved",
       [](std::vector<std::uint32_t>&, std::vector<Point2>& points) { points[4][0] += 1e-9; }},
      {"a hull's vertex given to the next hull",
       [](std::vector<std::uint32_t>& first, std::vector<Point2>&) { --first[2]; }},
  };
  auto refused = [&](const char* what) {
    try {
      check_sidecar(path);
      ADD_FAILURE() << what << ": a hierarchy unlike the segments' passed loci check";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("do not match the segments"), std::string::npos)
          << what << ": " << e.what();
    }
  };
  for (const auto& [what, tamper] : tampers) {
    write_with_hierarchies(l.items, path, tamper);
    refused(what);
  }
  for (const auto& [what, tamper] : hull_tampers) {
    write_with_hierarchies(l.items, path, {}, tamper);
    refused(what);
  }
  ::unlink(path.c_str());
}

// Features far from the query are measured from their hulls alone: with every level-0 node of
// the file forged out of range, a query far from all features still answers, exactly (brute
// force), since a vertex of each hull is certainly nearest; a query inside a feature's hull,
// which has to read its segments, is refused. Hull starts beyond the vertices are refused too.
TEST(LayerNearest, FarFeaturesAreMeasuredFromTheirHullsAlone) {
  // 100 jagged rings of 40 segments (more than a leaf, so that each root is above level 0),
  // radius 1 to 3, on a grid 10 apart.
  Layer l;
  l.items.per = Per::segment;
  l.items.layer_name = "rings";
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> radius(1, 3);
  for (int f = 0; f < 100; ++f) {
    const Point2 c{10.0 * (f % 10) + 5, 10.0 * (f / 10) + 5};
    std::vector<Point2> ring;
    for (int i = 0; i < 40; ++i) {
      const double a = 2 * std::numbers::pi * i / 40, r = radius(rng);
      ring.push_back({c[0] + r * std::cos(a), c[1] + r * std::sin(a)});
    }
    for (int i = 0; i < 40; ++i)
      add_segment(l, 100 + f, ring[std::size_t(i)], ring[std::size_t((i + 1) % 40)]);
  }
  const Tamper leaves_out_of_range = [](Levels& levels, std::vector<HierarchyRoot>& roots) {
    for (auto& n : levels[0])
      n.first = n.last = 1u << 30;
    for (const HierarchyRoot& r : roots)
      ASSERT_GT(r.level, 0u);
  };
  const std::string path = scratch("hulls");
  write_with_hierarchies(l.items, path, leaves_out_of_range);
  const LayerIndex index = LayerIndex::adopt(Sidecar::open(path));
  LayerQuery query(index, "", "");
  std::size_t answered = 0;
  for (const Point2 p : {Point2{-3000.3, 1234.5}, Point2{777.7, -2500.1}, Point2{4000.2, 4100.9}}) {
    Query q;
    q.kind = Query::Kind::nearest;
    q.point = p;
    q.k = 7;
    std::vector<Answer> got;
    query.run(q, 1, false, got);
    const auto expected = brute(l, p);
    ASSERT_EQ(got.size(), 7u);
    for (std::size_t r = 0; r < got.size(); ++r) {
      EXPECT_NEAR(got[r].distance, expected[r].first, 1e-12 * expected[r].first) << r;
      EXPECT_EQ(got[r].fid, expected[r].second) << r;
    }
    ++answered;
  }
  EXPECT_EQ(answered, 3u);
  Query inside;
  inside.kind = Query::Kind::nearest;
  inside.point = {55.2, 54.9};
  inside.k = 2;
  std::vector<Answer> got;
  EXPECT_THROW(query.run(inside, 1, false, got), Error);
  ::unlink(path.c_str());

  // A hull emptied (every feature has one of at least one vertex): refused when read, not
  // taken for a feature too far to rank.
  write_with_hierarchies(
      l.items, path, {},
      [](std::vector<std::uint32_t>& first, std::vector<Point2>&) { first[7] = first[6]; });
  {
    const LayerIndex emptied = LayerIndex::adopt(Sidecar::open(path));
    LayerQuery q_emptied(emptied, "", "");
    Query all;
    all.kind = Query::Kind::nearest;
    all.point = {50.5, 50.5};
    all.k = 100;
    EXPECT_THROW(q_emptied.run(all, 1, false, got), Error);
  }
  // Hull vertices that are not numbers: the feature is measured from its segments (and loci
  // check refuses the file).
  write_with_hierarchies(l.items, path, {},
                         [](std::vector<std::uint32_t>& first, std::vector<Point2>& points) {
                           for (std::uint32_t v = first[3]; v < first[4]; ++v)
                             points[v] = {NAN, NAN};
                         });
  {
    const LayerIndex nan_hull = LayerIndex::adopt(Sidecar::open(path));
    LayerQuery q_nan(nan_hull, "", "");
    Query all;
    all.kind = Query::Kind::nearest;
    all.point = {-3000.3, 1234.5};
    all.k = 100;
    got.clear();
    q_nan.run(all, 1, false, got);
    ASSERT_EQ(got.size(), 100u);
    const auto expected = brute(l, all.point);
    for (std::size_t r = 0; r < got.size(); ++r)
      EXPECT_NEAR(got[r].distance, expected[r].first, 1e-12 * expected[r].first) << r;
    EXPECT_THROW(check_sidecar(path), Error);
  }
  write_with_hierarchies(
      l.items, path, {},
      [](std::vector<std::uint32_t>& first, std::vector<Point2>&) { first[50] = 1u << 30; });
  const LayerIndex forged = LayerIndex::adopt(Sidecar::open(path));
  LayerQuery near_forged(forged, "", "");
  std::size_t refused = 0;
  for (int i = 0; i < 100; ++i) {
    Query q;
    q.kind = Query::Kind::nearest;
    q.point = {10.0 * (i % 10) + 5.5, 10.0 * (i / 10) + 1};
    q.k = 100;
    try {
      near_forged.run(q, 1, false, got);
    } catch (const Error& e) {
      ++refused;
      EXPECT_NE(std::string(e.what()).find("corrupt index file (feature hierarchies)"),
                std::string::npos)
          << e.what();
    }
  }
  EXPECT_EQ(refused, 100u) << "every query meets every feature's hull (k = 100)";
  ::unlink(path.c_str());
}

// A level-0 node says which of its leaf's slots hold the feature's segments and which of those
// run antidiagonally: exactly what the records give.
TEST(LayerNearest, LeafSlotsAreTheFeaturesSegments) {
  const Layer l = interleaved(40, 200, 19);
  const PackedRTree2 tree = PackedRTree2::build(l.items.boxes);
  const LayerIndex::Features f = LayerIndex::build_features(&tree, Per::segment, l.items.records);
  ASSERT_TRUE(f.hierarchical);
  const auto items = tree.item_indices();
  std::size_t anti = 0, seen = 0;
  for (const HierarchyNode& node : f.levels[0]) {
    std::uint32_t expect = 0;
    for (std::size_t e = 0; e < PackedRTree2::node_size; ++e) {
      const std::size_t pos = std::size_t(node.first) * PackedRTree2::node_size + e;
      if (pos >= tree.size()) break;
      const ItemRecord& r = l.items.records[items[pos]];
      if (r.fid != f.fid[node.feature]) continue;
      expect |= 1u << e;
      if (r.flags & item_antidiagonal) expect |= 1u << (16 + e), ++anti;
      ++seen;
    }
    EXPECT_EQ(node.slots, expect);
  }
  EXPECT_EQ(seen, tree.size()) << "every segment in exactly one node";
  EXPECT_GT(anti, 0u);
  EXPECT_LT(anti, seen);
  for (std::size_t level = 1; level < f.levels.size(); ++level)
    for (const HierarchyNode& node : f.levels[level])
      EXPECT_EQ(node.slots, 0u);
}

// Opening costs the same whatever the file's size for nearest-n too: one query verifies the
// few chunks it reads (the hierarchies of the features near it, their leaves and records).
TEST(LayerNearest, OneQueryReadsAFewChunksOfTheStoredHierarchies) {
  // 400 features, each a walk of 300 segments within its own cell of a 20 x 20 grid.
  Layer l;
  l.items.per = Per::segment;
  l.items.layer_name = "cells";
  std::mt19937_64 rng(19);
  std::uniform_real_distribution<double> step(-1, 1);
  for (int f = 0; f < 400; ++f) {
    const double x0 = 10.0 * (f % 20), y0 = 10.0 * (f / 20);
    Point2 p{x0 + 5, y0 + 5};
    for (int i = 0; i < 300; ++i) {
      const Point2 q{std::clamp(p[0] + step(rng), x0, x0 + 9),
                     std::clamp(p[1] + step(rng), y0, y0 + 9)};
      add_segment(l, f, p, q);
      p = q;
    }
  }
  const std::string path = scratch("chunks");
  write_with_hierarchies(l.items, path);
  const LayerIndex index = LayerIndex::adopt(Sidecar::open(path));
  ::unlink(path.c_str());
  LayerQuery query(index, "", "");
  Query q;
  q.kind = Query::Kind::nearest;
  q.point = {50, 50};
  q.k = 3;
  std::vector<Answer> answers;
  query.run(q, 1, false, answers);
  ASSERT_EQ(answers.size(), 3u);
  const loci::detail::LazyCheck* chunks = index.features().check;
  ASSERT_NE(chunks, nullptr);
  EXPECT_GT(chunks->chunks(), 100u);
  EXPECT_LE(chunks->verified(), chunks->chunks() / 5) << "of " << chunks->chunks();
}

// Polygons per segment: features of one to three rings (star-shaped, vertices on an integer
// grid so that rays from grid points run through vertices and along edges; the second ring a
// hole in the first, the third another polygon, which may overlap the first), overlapping each
// other; rings run either way, their records carrying their polygon's number.
struct Polygons {
  LayerItems items;
  struct Edge {
    std::int64_t fid;
    int polygon;  // of the feature
    Segment2 s;
  };
  std::vector<Edge> rings;
};

Polygons star_polygons(int features, std::uint64_t seed) {
  Polygons l;
  l.items.per = Per::segment;
  l.items.layer_name = "stars";
  l.items.has_polygons = true;
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> centre(10, 90), radius(3, 25), corners(3, 12);
  for (int f = 0; f < features; ++f) {
    const std::int64_t fid = 5 * f + 1;
    const int cx = centre(rng), cy = centre(rng);
    const int rings = 1 + f % 3;
    for (int r = 0; r < rings; ++r) {
      // A hole inside the first ring when r = 1; another island for r = 2.
      const int ox = r == 2 ? centre(rng) : cx, oy = r == 2 ? centre(rng) : cy;
      const int size = r == 1 ? 2 : radius(rng);
      const int n = corners(rng);
      std::vector<Point2> ring;
      for (int i = 0; i < n; ++i) {
        const double a = 2 * std::numbers::pi * i / n;
        const double len = r == 1 ? size : size * (0.5 + 0.5 * ((i * 7 + f) % 3) / 2.0);
        ring.push_back({double(ox + int(std::lround(len * std::cos(a)))),
                        double(oy + int(std::lround(len * std::sin(a))))});
      }
      if ((f + r) % 2) std::reverse(ring.begin(), ring.end());
      const int polygon = r == 2 ? 1 : 0;
      for (int i = 0; i < n; ++i) {
        const Point2 a = ring[i], b = ring[(i + 1) % n];
        const Segment2 s{a, b};
        l.items.boxes.push_back(s.box());
        l.items.records.push_back({fid, 0, segment_flags(a, b, true, std::uint32_t(polygon))});
        l.rings.push_back({fid, polygon, s});
      }
    }
  }
  return l;
}

void check_polygons(const LayerIndex& index, const Polygons& l);

TEST(LayerNearest, PolygonsHoldingThePointAreAtDistanceZero) {
  const Polygons l = star_polygons(120, 21);
  Polygons copy = l;
  const LayerIndex memory = LayerIndex::build(std::move(copy.items), Structure::packed_hilbert);
  // And the same through hierarchies stored in a sidecar.
  const std::string path = scratch("stars");
  write_with_hierarchies(l.items, path);
  const LayerIndex stored = LayerIndex::adopt(Sidecar::open(path));
  ::unlink(path.c_str());
  ASSERT_NE(stored.features().check, nullptr);
  for (const LayerIndex* from : {&memory, &stored})
    check_polygons(*from, l);
}

void check_polygons(const LayerIndex& index, const Polygons& l) {
  const LayerIndex::Features& features = index.features();
  LayerQuery query(index, "", "");
  std::mt19937_64 rng(22);
  std::uniform_int_distribution<int> grid(0, 200);
  std::uniform_real_distribution<double> any(-5, 105);
  std::size_t inside = 0, compared = 0;
  for (int i = 0; i < 3000; ++i) {
    // Grid points and half-grid points (rays through vertices and along edges), and others.
    const Point2 p = i % 3 == 2 ? Point2{any(rng), any(rng)}
                                : Point2{grid(rng) / 2.0, grid(rng) / 2.0 + (i % 3) * 0.25};
    std::map<std::int64_t, double> best;
    std::map<std::pair<std::int64_t, int>, bool> odd;  // per polygon of each feature
    for (const auto& [fid, polygon, s] : l.rings) {
      const double d = std::sqrt(squared_distance(p, s));
      const auto [it, fresh] = best.try_emplace(fid, d);
      if (!fresh) it->second = std::min(it->second, d);
      odd[{fid, polygon}] ^= ray_crosses(s.a, s.b, p);
    }
    bool on_a_ring = false;
    for (const auto& [fid, d] : best)
      on_a_ring |= d == 0;
    if (on_a_ring) continue;  // on a ring a point may or may not count: distance 0 either way
    std::vector<std::int64_t> expected;
    for (auto& [fid, d] : best)
      if (odd[{fid, 0}] || odd[{fid, 1}]) {
        expected.push_back(fid);
        d = 0;
      }
    std::vector<std::int64_t> got = containing_polygons(index, p, features);
    std::vector<std::int64_t> along_x = containing_polygons(index, p);
    std::sort(got.begin(), got.end());
    std::sort(along_x.begin(), along_x.end());
    ASSERT_EQ(got, expected) << "point " << p[0] << ',' << p[1];
    ASSERT_EQ(along_x, expected) << "point " << p[0] << ',' << p[1];
    inside += !expected.empty();

    std::vector<double> distances;
    for (const auto& [fid, d] : best)
      distances.push_back(d);
    std::sort(distances.begin(), distances.end());
    std::vector<Answer> answers;
    Query q;
    q.kind = Query::Kind::nearest;
    q.point = p;
    q.k = 6;
    query.run(q, 1, false, answers);
    ASSERT_EQ(answers.size(), 6u);
    for (std::size_t r = 0; r < answers.size(); ++r) {
      EXPECT_NEAR(answers[r].distance, distances[r], 1e-13 * (1 + distances[r]))
          << "point " << p[0] << ',' << p[1] << " rank " << r;
      EXPECT_NEAR(answers[r].distance, best[answers[r].fid], 1e-13 * (1 + distances[r]));
      ++compared;
    }
  }
  EXPECT_GT(inside, 300u);
  EXPECT_GT(compared, 10000u);
}

// A feature whose root box is at a finite squared distance while every box below it
// overflows (coordinates near 1e154, which the command line refuses but the library takes):
// it is left out, as the walks over the shared tree leave it, and never given the distance of
// another feature's leaf.
TEST(LayerNearest, FeatureBeyondTheSquaredRangeIsLeftOut) {
  for (const Structure s : {Structure::packed_hilbert, Structure::rstar}) {
    LayerItems items;
    items.per = Per::segment;
    items.layer_name = "far";
    auto add = [&](std::int64_t fid, const Point2& a, const Point2& b) {
      items.boxes.push_back(Segment2{a, b}.box());
      items.records.push_back({fid, 0, segment_flags(a, b, false)});
    };
    const double e = 1e154;
    for (int i = 0; i < 32; ++i)
      add(0, {double(i), 0}, {double(i + 1), 0});
    for (int i = 0; i < 16; ++i)
      add(1, {0.9 * e + i * 1e150, 1.3 * e}, {0.9 * e + (i + 1) * 1e150, 1.3 * e});
    for (int i = 0; i < 16; ++i)
      add(1, {1.3 * e, 0.9 * e + i * 1e150}, {1.3 * e, 0.9 * e + (i + 1) * 1e150});
    const LayerIndex index = LayerIndex::build(std::move(items), s);
    LayerQuery query(index, "", "");
    Query q;
    q.kind = Query::Kind::nearest;
    q.point = {-5, 0};
    q.k = 2;
    std::vector<Answer> answers;
    query.run(q, 1, false, answers);
    ASSERT_EQ(answers.size(), 1u) << to_string(s);
    EXPECT_EQ(answers[0].fid, 0);
    EXPECT_EQ(answers[0].distance, 5.0);
  }
}

// --candidates: each feature at the distance of its nearest segment box (no exact distance),
// a polygon holding the point at 0 (its boxes need not reach the point), against brute force
// over the boxes and the rings, for every structure.
TEST(LayerNearest, CandidatesRankFeaturesByTheirBoxes) {
  const Polygons l = star_polygons(150, 31);
  for (const Structure s : {Structure::packed_hilbert, Structure::packed_str, Structure::rstar}) {
    Polygons copy = l;
    const LayerIndex index = LayerIndex::build(std::move(copy.items), s);
    LayerQuery query(index, "", "");
    std::mt19937_64 rng(32);
    std::uniform_real_distribution<double> any(-20, 120);
    std::size_t compared = 0, inside = 0;
    for (int i = 0; i < 400; ++i) {
      const Point2 p{any(rng), any(rng)};
      std::map<std::int64_t, double> best;
      std::map<std::pair<std::int64_t, int>, bool> odd;  // per polygon of each feature
      for (const auto& [fid, polygon, seg] : l.rings) {
        const double d = std::sqrt(squared_distance(p, seg.box()));
        const auto [it, fresh] = best.try_emplace(fid, d);
        if (!fresh) it->second = std::min(it->second, d);
        odd[{fid, polygon}] ^= ray_crosses(seg.a, seg.b, p);
      }
      for (auto& [fid, d] : best)
        if (odd[{fid, 0}] || odd[{fid, 1}]) d = 0, ++inside;
      std::vector<double> distances;
      for (const auto& [fid, d] : best)
        distances.push_back(d);
      std::sort(distances.begin(), distances.end());
      Query q;
      q.kind = Query::Kind::nearest;
      q.point = p;
      q.k = 1 + i % 12;
      std::vector<Answer> answers;
      query.run(q, 1, true, answers);
      ASSERT_EQ(answers.size(), q.k);
      for (std::size_t r = 0; r < answers.size(); ++r) {
        EXPECT_EQ(answers[r].distance, distances[r]) << "point " << p[0] << ',' << p[1];
        EXPECT_EQ(answers[r].distance, best[answers[r].fid]);
        ++compared;
      }
    }
    EXPECT_GT(compared, 2000u);
    EXPECT_GT(inside, 200u);
  }
}

// --candidates per segment holds the exact answer of every kind of query: a window, a point
// or a segment inside a polygon meets none of its segments' boxes, and the polygon is among
// the candidates all the same (it was left out), for every structure.
TEST(LayerNearest, CandidatesPerSegmentHoldTheExactAnswer) {
  const Polygons l = star_polygons(150, 33);
  for (const Structure s : {Structure::packed_hilbert, Structure::packed_str, Structure::rstar}) {
    Polygons copy = l;
    const LayerIndex index = LayerIndex::build(std::move(copy.items), s);
    LayerQuery query(index, "", "");
    std::mt19937_64 rng(34);
    std::uniform_real_distribution<double> any(-5, 105), size(0, 1.5);
    std::size_t exact_total = 0, without_boxes = 0, holding = 0;
    for (int i = 0; i < 1500; ++i) {
      Query q;
      const Point2 p{any(rng), any(rng)};
      q.kind = std::array{Query::Kind::bbox, Query::Kind::point, Query::Kind::segment,
                          Query::Kind::within, Query::Kind::nearest}[std::size_t(i % 5)];
      q.box = {p, {p[0] + size(rng), p[1] + size(rng)}};
      q.point = p;
      q.segment = {p, {p[0] + size(rng), p[1] - size(rng)}};
      q.radius = size(rng);
      q.k = 3;
      q.first = i % 10 == 2;
      std::vector<Answer> exact, candidates;
      query.run(q, 1, false, exact);
      query.run(q, 1, true, candidates);
      std::set<std::int64_t> c;
      for (const Answer& a : candidates)
        c.insert(a.fid);
      for (const Answer& a : exact) {
        if (q.kind == Query::Kind::nearest || q.first) break;  // ranks may differ
        EXPECT_TRUE(c.count(a.fid)) << "query " << i << " feature " << a.fid;
        ++exact_total;
        // Whether a box of its segments met the query's box.
        const Box2 reach =
            q.kind == Query::Kind::segment ? q.segment.box()
            : q.kind == Query::Kind::within
                ? Box2{{p[0] - q.radius, p[1] - q.radius}, {p[0] + q.radius, p[1] + q.radius}}
            : q.kind == Query::Kind::point ? Box2::of_point(p)
                                           : q.box;
        bool met = false;
        for (const auto& [fid, polygon, seg] : l.rings)
          met |= fid == a.fid && intersects(seg.box(), reach);
        without_boxes += !met;
      }
      // Nearest: a polygon holding the point ranks at 0 among the candidates too.
      if (q.kind == Query::Kind::nearest) {
        const auto at_zero = [](const std::vector<Answer>& answers) {
          return std::count_if(answers.begin(), answers.end(),
                               [](const Answer& a) { return a.distance == 0; });
        };
        EXPECT_GE(at_zero(candidates), at_zero(exact)) << "query " << i;
        holding += at_zero(exact) > 0;
      }
    }
    EXPECT_GT(exact_total, 1000u);
    EXPECT_GT(without_boxes, 100u);
    EXPECT_GT(holding, 100u);
  }
}

}  // namespace
}  // namespace loci::io
