// `navbus latency`'s statistics: nearest-rank percentiles and a sink's gap and order counts.
#include <gtest/gtest.h>

#include "navbus/tool/latency.hpp"

TEST(Latency, NearestRankStatistics) {
  std::vector<std::int64_t> v;
  for (int i = 1000; i >= 1; --i) v.push_back(i);
  const auto s = navbus::tool::latencyStats(v);
  EXPECT_EQ(s.count, 1000u);
  EXPECT_EQ(s.median_ns, 500);
  EXPECT_EQ(s.p90_ns, 900);
  EXPECT_EQ(s.p99_ns, 990);
  EXPECT_EQ(s.p999_ns, 999);
  EXPECT_EQ(s.max_ns, 1000);
  EXPECT_EQ(navbus::tool::latencyStats({}).count, 0u);
}

TEST(Latency, SinkCountsGapsAndOutOfOrderSamples) {
  navbus::tool::SinkCount c;
  for (std::uint64_t seq : {1, 2, 3, 6, 7, 5, 10})
    c.take(seq, static_cast<std::int64_t>(seq) * 100);
  EXPECT_EQ(c.taken, 7u);
  EXPECT_EQ(c.missing, 2u + 2u);  // 4 and 5 before 6 (5 came late), 8 and 9
  EXPECT_EQ(c.out_of_order, 1u);  // 5 after 7
  EXPECT_EQ(c.last_seq, 10u);
  EXPECT_EQ(c.first_ns, 100);
  EXPECT_EQ(c.last_ns, 1000);
}
