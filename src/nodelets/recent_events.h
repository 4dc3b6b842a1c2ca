// What went wrong lately, per kind: a log throttle per kind (one kind never hides
// another: a 32FC1 image right after a 16UC1 one is logged too), the last text of each
// kind for diagnostics, and whether it happened within a window (a diagnostics WARN ends
// a while after its cause, as the input rate's does). Wall time: it must hold under a
// paused or looping /clock. Thread-safe.
#pragma once

#include <ros/time.h>

#include <map>
#include <mutex>
#include <string>

namespace mono_plane_detection {

class RecentEvents {
 public:
  // Records an event; true when its kind was not logged in the last period_s (log it).
  bool note(const std::string& kind, const std::string& text, double period_s = 5.0) {
    std::lock_guard<std::mutex> lock(mutex_);
    const ros::WallTime now = ros::WallTime::now();
    Event& e = events_[kind];
    e.last = now;
    e.text = text;
    if (!e.logged.isZero() && (now - e.logged).toSec() < period_s) return false;
    e.logged = now;
    return true;
  }

  // Whether an event of this kind was noted within window_s.
  bool happened(const std::string& kind, double window_s) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = events_.find(kind);
    return it != events_.end() && (ros::WallTime::now() - it->second.last).toSec() <= window_s;
  }

  // The last text of any kind noted within window_s, "" when none.
  std::string recent(double window_s) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const ros::WallTime now = ros::WallTime::now();
    const Event* newest = nullptr;
    for (const auto& [kind, e] : events_)
      if ((now - e.last).toSec() <= window_s && (!newest || e.last > newest->last)) newest = &e;
    return newest ? newest->text : std::string();
  }

 private:
  struct Event {
    ros::WallTime last, logged;
    std::string text;
  };
  mutable std::mutex mutex_;
  std::map<std::string, Event> events_;
};

// The kind of a reason text, for RecentEvents: up to its first ':' or '(' (and a quoted
// name in it: "unsupported encoding '32FC1'" and "... '16UC1'" are two kinds).
inline std::string reasonKind(const std::string& reason) {
  const size_t quote = reason.find('\'');
  const size_t stop = reason.find_first_of(":(");
  if (quote != std::string::npos && (stop == std::string::npos || quote < stop)) {
    const size_t close = reason.find('\'', quote + 1);
    return reason.substr(0, close == std::string::npos ? reason.size() : close + 1);
  }
  return reason.substr(0, stop == std::string::npos ? reason.size() : stop);
}

}  // namespace mono_plane_detection
