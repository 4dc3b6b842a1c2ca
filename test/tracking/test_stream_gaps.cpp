// The stream's rhythm from its stamps: images missing, and what is a pause.
#include <gtest/gtest.h>

#include "mono_plane_detection/tracking/stream_gaps.h"

using namespace mono_plane_detection;

namespace {
constexpr int64_t kHz30 = 33333333;
constexpr int64_t kSecond = 1000000000;
}  // namespace

TEST(GapCounter, RegularStreamHasNoGaps) {
  GapCounter gaps;
  long missing = 0;
  for (int k = 0; k < 100; ++k) missing += gaps.add(kHz30 + (k % 3) * 1000000);
  EXPECT_EQ(missing, 0);
  EXPECT_EQ(gaps.add(4 * kHz30), 3);
}

// A camera stamped on arrival: +-5 ms of jitter at 30 Hz (intervals 23-43 ms) is no
// missing image (the second smallest interval as the period counted 86 of 600); dropped
// images are still counted.
TEST(GapCounter, JitteryStampsAreNoGaps) {
  auto stamp = [](int k) {  // deterministic jitter in [-5, 5] ms
    const int64_t jitter = static_cast<int64_t>((k * 7919) % 11) - 5;
    return k * kHz30 + jitter * 1000000;
  };
  GapCounter gaps;
  long missing = 0;
  for (int k = 1; k < 600; ++k) missing += gaps.add(stamp(k) - stamp(k - 1));
  EXPECT_EQ(missing, 0);
  EXPECT_NEAR(static_cast<double>(gaps.periodNs()), kHz30, 3e6);
  GapCounter dropping;  // every 7th image lost
  missing = 0;
  int previous = 0, dropped = 0;
  for (int k = 1; k < 600; ++k) {
    if (k % 7 == 0) {
      ++dropped;
      continue;
    }
    missing += dropping.add(stamp(k) - stamp(previous));
    previous = k;
  }
  EXPECT_EQ(missing, dropped);
}

TEST(GapCounter, PeriodStartsFromTheSecondSmallestInterval) {
  GapCounter gaps;
  EXPECT_EQ(gaps.periodNs(), 0);
  gaps.add(kHz30);
  gaps.add(kHz30 / 10);           // one short outlier (a duplicate-ish stamp) does not set it
  EXPECT_EQ(gaps.periodNs(), 0);  // three intervals needed
  gaps.add(2 * kHz30);
  EXPECT_EQ(gaps.periodNs(), kHz30);
  gaps.reset();
  EXPECT_EQ(gaps.periodNs(), 0);
}

// A 30 Hz camera one second apart is a pause; a 1 Hz bag's second is its rhythm.
TEST(GapCounter, PauseFollowsTheStreamsOwnPeriod) {
  GapCounter fast;
  for (int k = 0; k < 10; ++k) fast.add(kHz30);
  EXPECT_FALSE(fast.isPause(kSecond / 2, 1.0));  // under max_gap_s: never a pause
  EXPECT_TRUE(fast.isPause(kSecond + kSecond / 10, 1.0));

  GapCounter slow;  // before its period is known: over 3 x max_gap_s
  EXPECT_FALSE(slow.isPause(kSecond + kSecond / 50, 1.0));  // a 1 Hz bag's first second
  EXPECT_FALSE(slow.isPause(3 * kSecond, 1.0));
  EXPECT_TRUE(slow.isPause(3 * kSecond + kSecond / 10, 1.0));
  for (int k = 0; k < 3; ++k) slow.addPause(kSecond + k * kSecond / 50);
  EXPECT_FALSE(slow.isPause(kSecond + kSecond / 20, 1.0));
  EXPECT_FALSE(slow.isPause(3 * kSecond, 1.0));
  EXPECT_TRUE(slow.isPause(4 * kSecond, 1.0));  // more than 3 periods
}

// Pauses set the period but are never counted as missing images.
TEST(GapCounter, PausesAreNotMissingImages) {
  GapCounter gaps;
  long missing = 0;
  for (int k = 0; k < 10; ++k) missing += gaps.add(kHz30);
  gaps.addPause(60 * kHz30);
  for (int k = 0; k < 10; ++k) missing += gaps.add(kHz30);
  EXPECT_EQ(missing, 0);
  EXPECT_EQ(gaps.add(3 * kHz30), 2);
}
