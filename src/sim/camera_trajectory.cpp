#include "mono_plane_detection/sim/camera_trajectory.h"

#include <cmath>
#include <random>

namespace mono_plane_detection {
namespace {

double radians(double deg) { return deg * CV_PI / 180.0; }

// Heading and position of a robot that drives at constant speed while its heading
// turns smoothly by `turn` over `duration` (cosine ramp), integrated numerically.
void drive(const TrajectoryParams& p, double t, double& yaw, cv::Vec3d& position) {
  const double turn = radians(p.turn_deg);
  auto heading = [&](double s) {
    const double u = std::min(std::max(s / p.duration_s, 0.0), 1.0);
    return turn * (1 - std::cos(CV_PI * u)) / 2;
  };
  const int steps = std::max(1, static_cast<int>(t * 200));
  const double dt = t / steps;
  position = cv::Vec3d(0, 0, 0);
  for (int i = 0; i < steps; ++i) {
    const double h = heading((i + 0.5) * dt);
    position += p.speed_mps * dt * cv::Vec3d(-std::sin(h), std::cos(h), 0);
  }
  yaw = heading(t);
}

}  // namespace

cv::Matx33d cameraOrientation(double yaw, double pitch_down, double roll) {
  const cv::Vec3d heading(-std::sin(yaw), std::cos(yaw), 0), up(0, 0, 1);
  const cv::Vec3d forward = std::cos(pitch_down) * heading - std::sin(pitch_down) * up;
  cv::Vec3d right = forward.cross(up);
  right /= cv::norm(right);
  cv::Vec3d down = forward.cross(right);
  const cv::Vec3d x = std::cos(roll) * right + std::sin(roll) * down;
  const cv::Vec3d y = -std::sin(roll) * right + std::cos(roll) * down;
  return {x[0], y[0], forward[0], x[1], y[1], forward[1], x[2], y[2], forward[2]};
}

bool knownTrajectory(const std::string& name) {
  return name == "wheeled" || name == "humanoid" || name == "rotation" ||
         name == "turn_in_place" || name == "look_around";
}

Pose trajectoryPose(const TrajectoryParams& params, double t) {
  TrajectoryParams p = params;
  if (p.name == "turn_in_place") {
    // On the spot: heading as the wheeled path's, no driving; the camera is ahead of the
    // turning axis.
    TrajectoryParams still = p;
    still.speed_mps = 0;
    double yaw;
    cv::Vec3d position;
    drive(still, t, yaw, position);
    Pose pose;
    pose.R = cameraOrientation(yaw, radians(p.pitch_down_deg), 0);
    pose.t = cv::Vec3d(-std::sin(yaw), std::cos(yaw), 0) * p.camera_forward_m +
             cv::Vec3d(0, 0, p.camera_height_m);
    return pose;
  }
  double look = 0;
  if (p.name == "look_around") {
    look = radians(p.look_amplitude_deg) * std::sin(2 * CV_PI * t / p.look_period_s);
    p.speed_mps /= 3;
    p.name = "humanoid";
  }
  const double pitch = radians(p.pitch_down_deg);
  Pose pose;
  if (p.name == "rotation") {
    // Pure rotation in place: the heading swings left and right, no translation.
    const double yaw = radians(p.rotation_amplitude_deg) * std::sin(2 * CV_PI * t / p.duration_s);
    pose.R = cameraOrientation(yaw, pitch, 0);
    pose.t = cv::Vec3d(0, 0, p.camera_height_m);
    return pose;
  }
  double yaw;
  cv::Vec3d position;
  drive(p, t, yaw, position);
  position[2] = p.camera_height_m;
  double roll = 0, extra_pitch = 0;
  if (p.name == "humanoid") {
    // A walking robot's head: 2 steps/s bob, sway at the stride frequency, roll and
    // pitch wobble, and a jerk (a sharp 1.5 deg nod decaying in 0.1 s) every ~1.5 s.
    const double step_hz = 2.0;
    position[2] += 0.4 + 0.02 * std::sin(2 * CV_PI * step_hz * t);
    const cv::Vec3d lateral(std::cos(yaw), std::sin(yaw), 0);
    position += 0.015 * std::sin(CV_PI * step_hz * t) * lateral;
    roll = radians(2.0) * std::sin(CV_PI * step_hz * t);
    extra_pitch = radians(1.5) * std::sin(2 * CV_PI * step_hz * t + 0.7);
    std::mt19937 rng(p.seed);
    std::uniform_real_distribution<double> gap(1.0, 2.0), sign(-1.0, 1.0);
    for (double jerk = gap(rng); jerk < t; jerk += gap(rng)) {
      const double since = t - jerk, amplitude = radians(1.5) * (sign(rng) < 0 ? -1 : 1);
      extra_pitch += amplitude * std::exp(-since / 0.1);
    }
  }
  pose.R = cameraOrientation(yaw + look, pitch + extra_pitch, roll);
  pose.t = position;
  return pose;
}

}  // namespace mono_plane_detection
