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

TEST(Statistics, SpearmanOfRanksWithTiesAtTheirMeanRank) {
  // Monotone relations are ±1 whatever their shape.
  EXPECT_DOUBLE_EQ(spearman({1, 2, 3, 4}, {10, 100, 1000, 1e6}), 1.0);
  EXPECT_DOUBLE_EQ(spearman({1, 2, 3, 4}, {4, 3, 2, 1}), -1.0);
  // The textbook formula 1 − 6Σd²/(n(n²−1)) holds without ties: ranks (1..5) and (2,1,4,3,5), Σd² = 4.
  EXPECT_NEAR(spearman({1, 2, 3, 4, 5}, {20, 10, 40, 30, 50}), 1.0 - 6.0 * 4.0 / (5.0 * 24.0), 1e-12);
  // Ties: x ranks (1.5, 1.5, 3), y ranks (1, 2, 3); Pearson of those by hand is 0.8660254.
  EXPECT_NEAR(spearman({7, 7, 9}, {1, 2, 3}), std::sqrt(3.0) / 2.0, 1e-12);
  // Non-finite pairs are left out; too few pairs, or a constant side, give NaN.
  EXPECT_DOUBLE_EQ(spearman({1, NAN, 2, 3}, {1, 5, 2, 3}), 1.0);
  EXPECT_TRUE(std::isnan(spearman({1}, {1})));
  EXPECT_TRUE(std::isnan(spearman({1, 1, 1}, {1, 2, 3})));
  EXPECT_TRUE(std::isnan(spearman({1, 2}, {1, 2, 3})));
}

}  // namespace
}  // namespace shapedb::core
