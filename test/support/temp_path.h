#pragma once
// A file name in gtest's temporary folder that no other test process uses: /tmp is shared
// by parallel test runs (two workspaces, CI next to a developer), and fixed names there made
// one run read the other's bag.
#include <gtest/gtest.h>
#include <unistd.h>

#include <string>

namespace mono_plane_detection {

inline std::string tempPath(const std::string& name) {
  return std::string(::testing::TempDir()) + "mpd_" + std::to_string(::getpid()) + "_" + name;
}

}  // namespace mono_plane_detection
