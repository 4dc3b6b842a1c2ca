// The one place per nodelet where "no exception leaves a callback" is enforced: every
// subscription, timer and connect callback is wrapped; an exception (std::exception or
// anything else) is caught, logged throttled with its reason, counted for diagnostics,
// and the nodelet keeps its state and goes on with the next message.
#pragma once

#include <ros/console.h>
#include <ros/time.h>

#include <atomic>
#include <boost/function.hpp>
#include <boost/shared_ptr.hpp>
#include <exception>
#include <mutex>
#include <string>
#include <utility>

namespace mono_plane_detection {

class CallbackGuard {
 public:
  explicit CallbackGuard(std::string logger = "") : logger_(std::move(logger)) {}
  void setLogger(const std::string& logger) { logger_ = logger; }

  // Runs f; never throws.
  template <class F>
  void run(const char* callback, F&& f) noexcept {
    try {
      f();
    } catch (const std::exception& e) {
      caught(callback, e.what());
    } catch (...) {
      caught(callback, "an exception of unknown type");
    }
  }

  // A guarded callable with f's arguments (timer, connect and message callbacks).
  template <class F>
  auto wrap(const char* callback, F f) {
    return [this, callback, f](const auto&... args) { run(callback, [&] { f(args...); }); };
  }

  // A guarded message callback of the type roscpp and image_transport subscribe with.
  template <class M, class Owner>
  boost::function<void(const boost::shared_ptr<const M>&)> message(
      const char* callback, Owner* owner, void (Owner::*method)(const boost::shared_ptr<const M>&)) {
    return wrap(callback, [owner, method](const boost::shared_ptr<const M>& msg) {
      (owner->*method)(msg);
    });
  }

  long count() const { return count_; }
  std::string lastReason() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_;
  }

 private:
  void caught(const char* callback, const char* what) noexcept {
    try {
      ++count_;
      bool log = false;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        last_ = std::string(callback) + ": " + what;
        // At most one line per 5 s of wall time (ROS time stands or goes back in a replay).
        const ros::WallTime now = ros::WallTime::now();
        log = last_logged_.isZero() || (now - last_logged_).toSec() >= 5.0;
        if (log) last_logged_ = now;
      }
      if (log)
        ROS_ERROR_STREAM_NAMED(logger_, "exception in the " << callback << " callback (" << what
                                                            << "): this call dropped, state kept");
    } catch (...) {  // logging itself failed (out of memory): nothing more to do
    }
  }

  std::string logger_;
  std::atomic<long> count_{0};
  mutable std::mutex mutex_;
  std::string last_;
  ros::WallTime last_logged_;
};

// A nodelet's onInit: nodelet's Loader deletes a nodelet whose onInit threw only after
// it has deleted the nodelet's callback queues, so every timer, publisher (with connect
// callbacks), subscriber and service made so far must go first (`abandon`), or their
// destructors use the freed queue and the whole manager dies (e.g. an image_transport
// plugin that is not installed, with lazy: false). The exception is then passed on: the
// Loader refuses the nodelet with an ERROR, the manager and its other nodelets go on.
template <class Init, class Abandon>
void initOrAbandon(const std::string& logger, Init&& init, Abandon&& abandon) {
  try {
    init();
  } catch (const std::exception& e) {
    ROS_ERROR_STREAM_NAMED(logger, logger << ": could not start (" << e.what() << "): not loaded");
    abandon();
    throw;
  } catch (...) {
    abandon();
    throw;
  }
}

}  // namespace mono_plane_detection
