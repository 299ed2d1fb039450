// One window and one nearest-n on a packed R-tree of a small lattice of boxes, checked by hand.
#include <cstdio>
#include <vector>

#include "loci/index/packed_rtree.hpp"

int main() {
  std::vector<loci::Box2> boxes;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j)
      boxes.push_back({{double(i), double(j)}, {i + 0.5, j + 0.5}});
  const auto tree = loci::PackedRTree2::build(boxes);
  const std::size_t in_window = tree.query(loci::Box2{{2.2, 2.2}, {4.1, 4.1}}).size();
  const auto nearest = tree.nearest({7.25, 7.25}, 1);
  const bool ok = in_window == 9 && nearest.size() == 1 && nearest[0].id == 77;
  std::printf("%s: %zu boxes in the window\n", ok ? "ok" : "wrong", in_window);
  return ok ? 0 : 1;
}
