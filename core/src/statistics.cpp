#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include <shapedb/core/statistics.h>

namespace shapedb::core {

namespace {

void keepFinite(std::vector<double>& values) {
  std::erase_if(values, [](double x) { return !std::isfinite(x); });
}

}  // namespace

double percentile(std::vector<double> values, double q) {
  keepFinite(values);
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const double rank = std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size()));
  const std::size_t i = std::max<std::size_t>(static_cast<std::size_t>(rank), 1) - 1;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(i), values.end());
  return values[i];
}

double median(std::vector<double> values) {
  keepFinite(values);
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const std::size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid), values.end());
  const double upper = values[mid];
  if (values.size() % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid)));
}

}  // namespace shapedb::core
