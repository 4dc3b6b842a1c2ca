// PipelineParams from the private parameter server namespace (config/planes*.yaml);
// values that would break the core are replaced by the defaults, loudly.
#pragma once

#include <ros/ros.h>

#include <string>

#include "mono_plane_detection/mapping/plane_pipeline.h"

namespace mono_plane_detection {

PipelineParams readPipelineParams(const ros::NodeHandle& pnh, const std::string& logger);

}  // namespace mono_plane_detection
