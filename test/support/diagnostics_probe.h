// The latest diagnostics status of one nodelet task ("/tracker: tracking"), for the
// rostest nodes: its level and values by key.
#pragma once

#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <string>

#include "support/test_timeouts.h"

class DiagnosticsProbe {
 public:
  DiagnosticsProbe(ros::NodeHandle& nh, std::string name) : name_(std::move(name)) {
    sub_ = nh.subscribe("/diagnostics", 50, &DiagnosticsProbe::onDiagnostics, this);
  }

  // Waits for a status published after this call (they come once a second).
  bool waitFresh(double seconds = 5.0) {
    received_ = false;
    return spinUntil([&] { return received_; }, seconds);
  }

  // The value of `key`, "" when absent.
  std::string value(const std::string& key) const {
    for (const auto& kv : status_.values)
      if (kv.key == key) return kv.value;
    return "";
  }
  // -1 when absent; a status that came without the key fails the test (a renamed key
  // would make before/after comparisons of -1 with -1 pass).
  long number(const std::string& key) const {
    const std::string v = value(key);
    if (v.empty() && !status_.values.empty())
      ADD_FAILURE() << "no diagnostics key '" << key << "' in " << status_.name;
    return v.empty() ? -1 : std::stol(v);
  }
  int level() const { return status_.level; }
  const std::string& message() const { return status_.message; }
  const std::string& hardwareId() const { return status_.hardware_id; }

 private:
  void onDiagnostics(const diagnostic_msgs::DiagnosticArrayConstPtr& msg) {
    for (const auto& s : msg->status)
      if (s.name.size() >= name_.size() &&
          s.name.compare(s.name.size() - name_.size(), name_.size(), name_) == 0 &&
          (s.name.size() == name_.size() || s.name[s.name.size() - name_.size() - 1] == '/' ||
           s.name[s.name.size() - name_.size() - 1] == ' ')) {
        status_ = s;
        received_ = true;
      }
  }

  std::string name_;
  ros::Subscriber sub_;
  diagnostic_msgs::DiagnosticStatus status_;
  bool received_ = false;
};
