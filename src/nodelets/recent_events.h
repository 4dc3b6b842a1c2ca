// What went wrong lately, per kind: a log throttle per kind (one kind never hides
// another: a 32FC1 image right after a 16UC1 one is logged too), the last text of each
// kind for diagnostics while it is recent (a diagnostics WARN ends a while after its
// cause, as the input rate's does). Wall time: it must hold under a
// paused or looping /clock. Thread-safe.
#pragma once

#include <ros/time.h>

#include <algorithm>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace mono_plane_detection {

// Lines per 5 s for rare events each worth its own line (a bag loop's reset): every loop
// of a bag looping at most once a second is told; a flood (stamps going back and forth)
// still gets 5 lines per 5 s, and the diagnostics count every one.
constexpr size_t kRareEventBurst = 5;

class RecentEvents {
 public:
  // Records an event; true when its kind was logged fewer than `burst` times in the last
  // period_s (log it). A burst above 1 is for rare events each worth a line (a bag loop's
  // reset), still limited when they come as a flood.
  bool note(const std::string& kind, const std::string& text, double period_s = 5.0,
            size_t burst = 1) {
    std::lock_guard<std::mutex> lock(mutex_);
    const ros::WallTime now = ros::WallTime::now();
    Event& e = events_[kind];
    e.last = now;
    e.text = text;
    while (!e.logged.empty() && (now - e.logged.front()).toSec() >= period_s)
      e.logged.erase(e.logged.begin());
    if (e.logged.size() >= std::max<size_t>(1, burst)) return false;
    e.logged.push_back(now);
    return true;
  }

  // Every kind noted within window_s with its last text, newest first: diagnostics show
  // each as a key of its own, so one never hides another.
  std::vector<std::pair<std::string, std::string>> recent(double window_s) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const ros::WallTime now = ros::WallTime::now();
    std::vector<std::pair<ros::WallTime, const std::pair<const std::string, Event>*>> found;
    for (const auto& entry : events_)
      if ((now - entry.second.last).toSec() <= window_s)
        found.push_back({entry.second.last, &entry});
    std::sort(found.begin(), found.end(),
              [](const auto& a, const auto& b) { return a.first > b.first; });
    std::vector<std::pair<std::string, std::string>> out;
    for (const auto& f : found) out.emplace_back(f.second->first, f.second->second.text);
    return out;
  }

 private:
  struct Event {
    ros::WallTime last;
    std::vector<ros::WallTime> logged;  // within the last period, oldest first
    std::string text;
  };
  mutable std::mutex mutex_;
  std::map<std::string, Event> events_;
};

// Counts over the last window of wall time (images received and found missing, resets):
// what diagnostics judge a stream by now, not since the start. Thread-safe.
class WindowCounts {
 public:
  explicit WindowCounts(double window_s = 10.0) : window_s_(window_s) {}
  void add(long a, long b = 0) {
    std::lock_guard<std::mutex> lock(mutex_);
    const ros::WallTime now = ros::WallTime::now();
    forget(now);
    entries_.push_back({now, a, b});
  }
  void clear() {
    std::lock_guard<std::mutex> lock(mutex_);
    entries_.clear();
  }
  // The sums of a and of b over the window.
  std::pair<long, long> sums() const {
    std::lock_guard<std::mutex> lock(mutex_);
    const ros::WallTime now = ros::WallTime::now();
    std::pair<long, long> out{0, 0};
    for (const Entry& e : entries_)
      if ((now - e.at).toSec() <= window_s_) {
        out.first += e.a;
        out.second += e.b;
      }
    return out;
  }

 private:
  struct Entry {
    ros::WallTime at;
    long a, b;
  };
  void forget(const ros::WallTime& now) {
    while (!entries_.empty() && (now - entries_.front().at).toSec() > window_s_)
      entries_.pop_front();
  }
  double window_s_;
  mutable std::mutex mutex_;
  std::deque<Entry> entries_;  // oldest first
};

// "N of M images missing in the last 10 s ..." when over a tenth of a stream's images
// (and at least 3) went missing in the window, "" otherwise: a stray drop is no problem,
// a queue that overflows is (a tracker or map slower than the stream under load).
inline std::string missingShareText(long received, long missing, const std::string& what,
                                    const std::string& why) {
  if (missing < 3 || 10 * missing <= received + missing) return {};
  return std::to_string(missing) + " of " + std::to_string(received + missing) + " " + what +
         " missing in the last 10 s (" + why + ")";
}

// A stream's health lately, for diagnostics (both nodelets): messages lost before they
// reached us (gaps in the stamps: a queue that overflows shows only there) and time going
// back again and again (two sources on one topic). Thread-safe.
class StreamHealth {
 public:
  // A bag loop goes back once; this many times in 10 s is a flood.
  static constexpr long kBackwardsFlood = 3;
  void received(long missing_found) { stream_.add(1, missing_found); }
  void wentBackwards() { backwards_.add(1); }
  // The stream is gone (a lazy nodelet's last listener left): its lately is no problem now.
  void forget() {
    stream_.clear();
    backwards_.clear();
  }
  // (key, text) of each problem now; what: "images" / "tracks"; why_missing: the likely
  // causes; restarting: what starts over each time the stamps go back; topic: "image".
  std::vector<std::pair<std::string, std::string>> problems(const std::string& what,
                                                            const std::string& why_missing,
                                                            const std::string& restarting,
                                                            const std::string& topic) const {
    std::vector<std::pair<std::string, std::string>> out;
    const auto [received, missing] = stream_.sums();
    const std::string text = missingShareText(received, missing, what, why_missing);
    if (!text.empty()) out.emplace_back(what + " missing", text);
    if (const long back = backwards_.sums().first; back >= kBackwardsFlood)
      out.emplace_back("time", "time went backwards " + std::to_string(back) +
                                   " times in the last 10 s, " + restarting +
                                   " each time: two publishers on one " + topic +
                                   " topic, or two /clock sources?");
    return out;
  }

 private:
  WindowCounts stream_;     // messages received, messages found missing
  WindowCounts backwards_;  // times the stamps went back
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
