// The diagnostics both nodelets publish: the input rate (FrequencyStatus, window set by
// the parameters expected_min_rate_hz / expected_max_rate_hz) and one task of the nodelet's own counts,
// updated once a second.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/update_functions.h>
#include <ros/ros.h>

#include <memory>
#include <string>

#include "callback_guard.h"

namespace mono_plane_detection {

class NodeletDiagnostics {
 public:
  template <class Owner>
  void start(ros::NodeHandle& nh, ros::NodeHandle& pnh, const std::string& name,
             const std::string& task, Owner* owner,
             void (Owner::*diagnose)(diagnostic_updater::DiagnosticStatusWrapper&),
             CallbackGuard& guard, double min_rate_hz, double max_rate_hz) {
    min_rate_ = min_rate_hz;
    max_rate_ = max_rate_hz;
    updater_ = std::make_unique<diagnostic_updater::Updater>(nh, pnh, name);
    updater_->setHardwareID("camera");
    rate_ = std::make_unique<diagnostic_updater::FrequencyStatus>(
        diagnostic_updater::FrequencyStatusParam(&min_rate_, &max_rate_, 0.1, 10));
    updater_->add(*rate_);
    updater_->add(task, owner, diagnose);
    timer_ = nh.createTimer(ros::Duration(1.0),
                            guard.wrap("diagnostics timer", [this](const ros::TimerEvent&) {
                              updater_->update();
                            }));
  }

  void tick() {
    if (rate_) rate_->tick();
  }

  ~NodeletDiagnostics() {
    if (updater_) updater_->broadcast(diagnostic_msgs::DiagnosticStatus::OK, "shutting down");
  }

 private:
  double min_rate_ = 5.0, max_rate_ = 100.0;
  std::unique_ptr<diagnostic_updater::Updater> updater_;
  std::unique_ptr<diagnostic_updater::FrequencyStatus> rate_;
  ros::Timer timer_;
};

}  // namespace mono_plane_detection
