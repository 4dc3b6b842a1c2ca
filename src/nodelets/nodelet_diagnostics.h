// The diagnostics both nodelets publish: the input rate and one task of the nodelet's
// own counts, once a second. Both run on wall time: under simulated time (a bag replay)
// /clock may come late, jump or stop, and diagnostic_updater's FrequencyStatus, which
// reads ros::Time, then reported 0.03 Hz for a 30 Hz replay. The rate is counted over
// the last few wall seconds, so a pause shows as "no input" and is forgotten within that
// window once input comes again.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "callback_guard.h"

namespace mono_plane_detection {

// Messages per wall second over a sliding window (a DiagnosticTask).
class WallRateStatus : public diagnostic_updater::DiagnosticTask {
 public:
  WallRateStatus(double min_hz, double max_hz, double window_s = 5.0)
      : DiagnosticTask("input rate"),
        min_hz_(min_hz),
        max_hz_(max_hz),
        window_s_(window_s),
        waiting_since_(ros::WallTime::now()) {}

  void tick(const ros::WallTime& now = ros::WallTime::now()) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (started_.isZero()) started_ = now;
    ticks_.push_back(now);
    ++total_;
    trim(now);
  }

  // A lazy nodelet nobody listens to subscribes to nothing: no input is then expected.
  // Once subscribed again, the rate counts afresh and a window passes before its absence
  // is a warning (a camera driver takes a moment to send its first image).
  void setIdle(bool idle, const ros::WallTime& now = ros::WallTime::now()) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (idle_ && !idle) {
      waiting_since_ = now;
      started_ = ros::WallTime();
      ticks_.clear();
    }
    idle_ = idle;
  }

  void run(diagnostic_updater::DiagnosticStatusWrapper& status) override {
    run(status, ros::WallTime::now());
  }

  void run(diagnostic_updater::DiagnosticStatusWrapper& status, const ros::WallTime& now) {
    std::lock_guard<std::mutex> lock(mutex_);
    trim(now);
    // Nothing yet since the start or the subscription, and that only for a moment.
    const bool waiting = started_.isZero() && (now - waiting_since_).toSec() <= window_s_;
    // Until a whole window has passed since the first message, rate over what there is,
    // but over a second at least: one message 4 ms after the first is no 265 Hz (it said
    // "frequency too high" at start; hostile try).
    const double span = started_.isZero()
                            ? window_s_
                            : std::min(window_s_, std::max((now - started_).toSec(), 1.0));
    const double hz = static_cast<double>(ticks_.size()) / span;
    if (idle_)
      status.summary(diagnostic_msgs::DiagnosticStatus::OK,
                     "idle: nobody listens, nothing subscribed (lazy)");
    else if (waiting)
      status.summary(diagnostic_msgs::DiagnosticStatus::OK, "waiting for the first input");
    else if (started_.isZero())
      status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no input yet");
    else if (ticks_.empty())
      status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no input for the last window");
    else if (hz < min_hz_ && span >= window_s_)
      status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "frequency too low");
    else if (hz > max_hz_)
      status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "frequency too high");
    else
      status.summary(diagnostic_msgs::DiagnosticStatus::OK, "desired frequency met");
    status.add("events in window", ticks_.size());
    status.add("events since startup", total_);
    status.add("duration of window (s), wall time", span);
    status.add("actual frequency (Hz)", hz);
    status.add("minimum acceptable frequency (Hz)", min_hz_);
    status.add("maximum acceptable frequency (Hz)", max_hz_);
  }

 private:
  void trim(const ros::WallTime& now) {
    while (!ticks_.empty() && (now - ticks_.front()).toSec() > window_s_) ticks_.pop_front();
  }

  std::mutex mutex_;
  double min_hz_, max_hz_, window_s_;
  std::deque<ros::WallTime> ticks_;
  ros::WallTime waiting_since_;  // the start or the last subscription
  ros::WallTime started_;        // the first input since then; zero: none yet
  long total_ = 0;
  bool idle_ = false;
};

// Every problem a status has now, each under a key of its own ("problem: <key>": none
// hides another); the summary is the most severe, the first added of equal ones (callers
// add the present state before what happened lately).
class StatusProblems {
 public:
  void add(unsigned char level, const std::string& key, const std::string& text) {
    problems_.push_back({level, key, text});
  }
  // (key, text) pairs as WARNs, each key after `prefix` (StreamHealth::problems,
  // RecentEvents::recent: both nodelets list them alike).
  void addWarnings(const std::vector<std::pair<std::string, std::string>>& warnings,
                   const std::string& prefix = "") {
    for (const auto& [key, text] : warnings)
      add(diagnostic_msgs::DiagnosticStatus::WARN, prefix + key, text);
  }

  void report(diagnostic_updater::DiagnosticStatusWrapper& status,
              const std::string& ok_text) const {
    const Problem* worst = nullptr;
    for (const Problem& p : problems_)
      if (!worst || p.level > worst->level) worst = &p;
    if (worst)
      status.summary(worst->level, worst->text);
    else
      status.summary(diagnostic_msgs::DiagnosticStatus::OK, ok_text);
    status.add("problems now", problems_.size());
    for (const Problem& p : problems_)
      status.add(
          "problem: " + p.key,
          (p.level == diagnostic_msgs::DiagnosticStatus::ERROR ? "ERROR: " : "WARN: ") + p.text);
  }

 private:
  struct Problem {
    unsigned char level;
    std::string key, text;
  };
  std::vector<Problem> problems_;
};

class NodeletDiagnostics {
 public:
  template <class Owner>
  void start(ros::NodeHandle& nh, ros::NodeHandle& pnh, const std::string& name,
             const std::string& task, Owner* owner,
             void (Owner::*diagnose)(diagnostic_updater::DiagnosticStatusWrapper&),
             CallbackGuard& guard, double min_rate_hz, double max_rate_hz) {
    updater_ = std::make_unique<diagnostic_updater::Updater>(nh, pnh, name);
    // The camera's namespace: two cameras' nodelets are told apart by aggregators.
    updater_->setHardwareID(nh.getNamespace());
    rate_ = std::make_unique<WallRateStatus>(min_rate_hz, max_rate_hz);
    updater_->add(*rate_);
    updater_->add(task, owner, diagnose);
    // force_update: update() compares ros::Time, which a paused or late /clock holds still.
    timer_ = nh.createWallTimer(ros::WallDuration(1.0),
                                guard.wrap("diagnostics timer", [this](const ros::WallTimerEvent&) {
                                  updater_->force_update();
                                }));
  }

  void tick() {
    if (rate_) rate_->tick();
  }

  void setIdle(bool idle) {
    if (rate_) rate_->setIdle(idle);
  }

  // Stops the timer and drops the updater now, while the nodelet's callback queue lives
  // (a nodelet whose onInit throws is deleted after its queue: initOrAbandon, callback_guard.h).
  void stop() {
    timer_.stop();
    timer_ = ros::WallTimer();
    updater_.reset();
  }

  ~NodeletDiagnostics() {
    timer_.stop();
    if (updater_) updater_->broadcast(diagnostic_msgs::DiagnosticStatus::OK, "shutting down");
  }

 private:
  std::unique_ptr<diagnostic_updater::Updater> updater_;
  std::unique_ptr<WallRateStatus> rate_;
  ros::WallTimer timer_;
};

}  // namespace mono_plane_detection
