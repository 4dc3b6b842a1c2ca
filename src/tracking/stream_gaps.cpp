#include "mono_plane_detection/tracking/stream_gaps.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace mono_plane_detection {
namespace {

constexpr size_t kRemembered = 64;
// A pause's "images counted": more than any interval can hold, so never counted.
constexpr long kNeverCounted = std::numeric_limits<long>::max();

}  // namespace

int64_t GapCounter::periodNs() const {
  if (recent_.size() < 3) return 0;
  std::vector<int64_t> sorted;
  sorted.reserve(recent_.size());
  for (const auto& r : recent_) sorted.push_back(r.first);
  std::sort(sorted.begin(), sorted.end());
  // Start from the second smallest (one short outlier does not set it; a saturated
  // consumer sees few images in a row), then take the median of the intervals within
  // half a period of it, again until it settles: stamps with jitter (a camera stamped on
  // arrival, +-5 ms at 30 Hz) spread the single intervals around the period, and their
  // smallest alone counted 86 images missing where none were (hostile try).
  int64_t period = sorted[1];
  for (int round = 0; round < 4; ++round) {
    const auto low = std::lower_bound(sorted.begin(), sorted.end(), period / 2);
    const auto high = std::upper_bound(sorted.begin(), sorted.end(), period + period / 2);
    const int64_t median = *(low + (high - low) / 2);
    if (median == period) break;
    period = median;
  }
  return period;
}

bool GapCounter::isPause(int64_t interval_ns, double max_gap_s) const {
  const double seconds = static_cast<double>(interval_ns) * 1e-9;
  if (seconds <= max_gap_s) return false;
  const int64_t period = periodNs();
  // (A 1 Hz bag's first second was a "tracking lost" WARN at every start.)
  if (period <= 0) return seconds > kPausePeriods * max_gap_s;
  return static_cast<double>(interval_ns) > kPausePeriods * period;
}

void GapCounter::addPause(int64_t interval_ns) {
  if (interval_ns <= 0) return;
  recent_.push_back({interval_ns, kNeverCounted});
  while (recent_.size() > kRemembered) recent_.pop_front();
}

long GapCounter::add(int64_t interval_ns) {
  if (interval_ns <= 0) return 0;
  recent_.push_back({interval_ns, 0});
  while (recent_.size() > kRemembered) recent_.pop_front();
  if (recent_.size() < 4) return 0;
  // A consumer slower than the stream sees consecutive images only now and then (when
  // its queue catches up), so earlier intervals are counted again against the newest
  // period; what was counted before is never taken back.
  const double period = static_cast<double>(periodNs());
  long added = 0;
  for (auto& [interval, counted] : recent_) {
    const double periods = static_cast<double>(interval) / period;
    const long missing = periods > 1.5 ? std::lround(periods) - 1 : 0;
    if (missing > counted) {
      added += missing - counted;
      counted = missing;
    }
  }
  return added;
}

}  // namespace mono_plane_detection
