// The rhythm of an image stream, from its stamps: images missing from it, and pauses long
// enough to be a tracking loss.
#pragma once

#include <cstdint>
#include <deque>
#include <utility>

namespace mono_plane_detection {

// Counts images missing from a stream by its stamps: the stream's period is the median of
// the last 64 intervals within half a period of it (starting from the second smallest:
// images that came in a row; jittery stamps spread those), and an interval of k
// periods (rounded, above 1.5) means k - 1 images never reached us: our subscriber queue
// dropped them, or the driver did. When the period estimate falls, the remembered
// intervals are counted again (a saturated tracker sees images in a row only when its
// queue catches up). Integer nanoseconds, so no stamp overflows. Chosen over header.seq
// because publishers inside a nodelet manager need not fill seq, and roscpp does not
// report what a subscriber queue drops. A stream that slows down for good counts as
// missing images for up to 64 images.
class GapCounter {
 public:
  // A pause is this many of the stream's own periods at least: a 1 Hz camera's (or bag's)
  // one second between images is its rhythm, not a pause; 30 Hz images one second apart
  // are a pause.
  static constexpr double kPausePeriods = 3.0;

  // Returns the number of images newly found missing.
  long add(int64_t interval_ns);
  // Remembered for the period only, never counted as missing images (a pause: what was
  // not sent is not "missing").
  void addPause(int64_t interval_ns);
  void reset() { recent_.clear(); }

  // The stream's period: the median of the remembered intervals within half a period of
  // it, from the second smallest on; 0 before three intervals.
  int64_t periodNs() const;
  // An interval after which tracking starts over: longer than max_gap_s and, once the
  // period is known, than kPausePeriods periods; before it is known (the stream's first
  // intervals are all the rhythm there is), longer than kPausePeriods x max_gap_s.
  bool isPause(int64_t interval_ns, double max_gap_s) const;

 private:
  std::deque<std::pair<int64_t, long>> recent_;  // interval, images counted in it
};

}  // namespace mono_plane_detection
