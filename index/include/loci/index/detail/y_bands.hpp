// YBands: items with closed ranges of y bucketed into equal horizontal bands, so that the
// items whose range may contain a given y come from one lookup: the band holding y lists every
// item whose range overlaps the band (a superset of those containing y). Point location by
// crossing parity uses it to find the edges a horizontal ray may cross (BspTree's build, the
// layer queries' prepared polygons). An item spanning many bands is listed in each, so the
// band count is chosen from the item count; memory O(items + listings).
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace loci::detail {

class YBands {
 public:
  YBands() = default;

  // range(i) gives item i's {ylo, yhi}, ylo <= yhi, for i < count; bands over [y0, y1].
  template <class Range>
  YBands(std::size_t count, Range&& range, double y0, double y1, std::size_t bands)
      : y0_(y0), start_(std::max<std::size_t>(bands, 1) + 1, 0) {
    const std::size_t n = start_.size() - 1;
    scale_ = y1 > y0 ? static_cast<double>(n) / (y1 - y0) : 0;
    for (std::size_t i = 0; i < count; ++i) {
      const auto [lo, hi] = range(i);
      for (std::size_t b = band(lo), e = band(hi); b <= e; ++b)
        ++start_[b + 1];
    }
    for (std::size_t b = 0; b < n; ++b)
      start_[b + 1] += start_[b];
    items_.resize(start_[n]);
    std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
    for (std::size_t i = 0; i < count; ++i) {
      const auto [lo, hi] = range(i);
      for (std::size_t b = band(lo), e = band(hi); b <= e; ++b)
        items_[fill[b]++] = static_cast<std::uint32_t>(i);
    }
  }

  // The items whose range may contain y.
  std::span<const std::uint32_t> at(double y) const {
    if (start_.size() < 2) return {};
    const std::size_t b = band(y);
    return {items_.data() + start_[b], items_.data() + start_[b + 1]};
  }

  // The items whose range may meet [lo, hi], lo <= hi: the listings of the bands from lo's to
  // hi's, in which an item spanning several of them appears in each.
  std::span<const std::uint32_t> at(double lo, double hi) const {
    if (start_.size() < 2) return {};
    return {items_.data() + start_[band(lo)], items_.data() + start_[band(hi) + 1]};
  }
  // The band holding y.
  std::size_t band_of(double y) const { return start_.size() < 2 ? 0 : band(y); }

  std::size_t memory_bytes() const {
    return (start_.capacity() + items_.capacity()) * sizeof(std::uint32_t);
  }

 private:
  std::size_t band(double y) const {
    const double f = (y - y0_) * scale_;
    if (!(f > 0)) return 0;
    return std::min(start_.size() - 2, static_cast<std::size_t>(f));
  }

  double y0_ = 0, scale_ = 0;
  std::vector<std::uint32_t> start_, items_;
};

}  // namespace loci::detail
