#include "mono_plane_detection/geometry/stats.h"

#include <algorithm>

namespace mono_plane_detection {
namespace {

template <typename T>
T rankValue(std::vector<T>& values, double q) {
  if (values.empty()) return T(0);
  q = std::min(std::max(q, 0.0), 1.0);
  const size_t k = std::min(values.size() - 1, static_cast<size_t>(q * values.size()));
  std::nth_element(values.begin(), values.begin() + static_cast<long>(k), values.end());
  return values[k];
}

}  // namespace

double percentile(std::vector<double> values, double q) { return rankValue(values, q); }
double median(std::vector<double> values) { return rankValue(values, 0.5); }
float median(std::vector<float> values) { return rankValue(values, 0.5); }

}  // namespace mono_plane_detection
