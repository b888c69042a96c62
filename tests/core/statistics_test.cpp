// Percentile and median: one definition each, checked against values worked out by hand.

#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include <shapedb/core/statistics.h>

namespace shapedb::core {
namespace {

TEST(Statistics, PercentileIsTheNearestRank) {
  std::vector<double> hundred;
  for (int i = 100; i >= 1; --i)  // any order
    hundred.push_back(i);
  EXPECT_EQ(percentile(hundred, 0.99), 99.0);  // not the maximum
  EXPECT_EQ(percentile(hundred, 0.5), 50.0);
  EXPECT_EQ(percentile(hundred, 0.9), 90.0);
  EXPECT_EQ(percentile(hundred, 1.0), 100.0);
  EXPECT_EQ(percentile(hundred, 0.001), 1.0);
  EXPECT_EQ(percentile({3.0, 1.0, 2.0}, 0.5), 2.0);
  EXPECT_EQ(percentile({7.0}, 0.99), 7.0);
}

TEST(Statistics, MedianAveragesTheTwoMiddleValues) {
  EXPECT_EQ(median({4.0, 1.0, 3.0, 2.0}), 2.5);
  EXPECT_EQ(median({5.0, 1.0, 3.0}), 3.0);
}

TEST(Statistics, NonFiniteValuesAreLeftOut) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(median({nan, 1.0, inf, 3.0}), 2.0);
  EXPECT_EQ(percentile({nan, 1.0, 2.0, -inf}, 1.0), 2.0);
  EXPECT_TRUE(std::isnan(median({})));
  EXPECT_TRUE(std::isnan(percentile({nan}, 0.5)));
}

}  // namespace
}  // namespace shapedb::core
