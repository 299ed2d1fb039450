// ConflictMonitor cases too long for the default run (labelled large).
#include <gtest/gtest.h>

#include <cstdint>

#include "loci/index/moving/conflicts.hpp"

namespace loci {
namespace {

// A slot counts its reports in 32 bits; after 2^32 of them (without a full computation in
// between) its count comes round to the one a kept pair was found with. The pair must not
// look current again: the object has moved far away since.
TEST(ConflictMonitorLarge, ReportCountWrappingRoundDoesNotReviveAPair) {
  ConflictMonitor<2> monitor(100, 60, 60);
  monitor.report(1, Motion<2>{0, {{0, 0}}, {{0, 0}}});
  monitor.report(2, Motion<2>{0, {{10, 0}}, {{0, 0}}});
  monitor.refresh(0);
  ASSERT_EQ(monitor.conflicts().size(), 1u);
  const Motion<2> far{0, {{1e6, 0}}, {{0, 0}}};
  // 2^32 reports of object 1 (its count back where it was when the pair was kept).
  for (std::uint64_t k = 0; k < (std::uint64_t(1) << 32); ++k)
    monitor.report(1, far);
  monitor.refresh(0);
  EXPECT_EQ(monitor.full_computations(), 1u);  // an incremental refresh
  EXPECT_TRUE(monitor.conflicts().empty());
  // And back near: found again.
  monitor.report(1, Motion<2>{0, {{0, 5}}, {{0, 0}}});
  monitor.refresh(0);
  EXPECT_EQ(monitor.conflicts().size(), 1u);
}

}  // namespace
}  // namespace loci
