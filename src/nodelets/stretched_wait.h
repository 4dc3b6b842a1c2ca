// Time waited, in message stamps, over the stretches of a stream: a pause or a jump of
// the stamps (a bag loop, another bag, a driver's clock) closes a stretch, and its length
// is no waiting (the nodelets said "not seen for 100000011 s" after stamps jumped
// forward). Used by both nodelets for the start-up target's wait. Not thread-safe: the
// owners hold their lock.
#pragma once

namespace mono_plane_detection {

class StretchedWait {
 public:
  // A message of the stretch, stamped stamp_s.
  void seen(double stamp_s) {
    if (!open_) start_s_ = stamp_s;
    open_ = true;
    last_s_ = stamp_s;
  }
  // The stream paused or jumped: what follows is a new stretch.
  void closeStretch() {
    before_s_ = seconds();
    open_ = false;
  }
  void reset() {
    open_ = false;
    before_s_ = 0;
  }
  double seconds() const { return before_s_ + (open_ ? last_s_ - start_s_ : 0.0); }

 private:
  bool open_ = false;
  double start_s_ = 0, last_s_ = 0;  // of the open stretch
  double before_s_ = 0;              // of the closed ones
};

}  // namespace mono_plane_detection
