#pragma once
// A file name in a folder of this test process's own under gtest's temporary folder: /tmp is
// shared by parallel test runs (two workspaces, CI next to a developer), and fixed names
// there made one run read the other's bag. The folder goes, with all in it, when the process
// exits: the accuracy rostests' bags are up to 90 MB each, and every `make test` left about
// 1 GB in /tmp. MPD_KEEP_TEST_FILES=1 keeps it (the path is <TempDir>mpd_<pid>/).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <system_error>

namespace mono_plane_detection {

class TestTempFolder {
 public:
  TestTempFolder()
      : pid_(::getpid()),
        path_(std::string(::testing::TempDir()) + "mpd_" + std::to_string(pid_)) {
    std::error_code ignored;
    std::filesystem::create_directories(path_, ignored);
  }
  ~TestTempFolder() {
    if (ownedByThisProcess() && !keep()) {
      std::error_code ignored;
      std::filesystem::remove_all(path_, ignored);
    }
  }
  TestTempFolder(const TestTempFolder&) = delete;
  TestTempFolder& operator=(const TestTempFolder&) = delete;

  const std::string& path() const { return path_; }
  // False in a forked child (a death test), which holds a copy of its parent's folder.
  bool ownedByThisProcess() const { return ::getpid() == pid_; }
  static bool keep() {
    const char* value = std::getenv("MPD_KEEP_TEST_FILES");
    return value && std::string(value) != "" && std::string(value) != "0";
  }

 private:
  pid_t pid_;
  std::string path_;
};

inline std::string tempPath(const std::string& name) {
  static std::mutex mutex;
  static std::unique_ptr<TestTempFolder> folder;  // removed at exit by its own process only
  // A forked child's copy of its parent's folder, kept until its exit, whose destructor
  // leaves the folder alone (released into nothing, LeakSanitizer failed the child).
  static std::unique_ptr<TestTempFolder> inherited;
  std::lock_guard<std::mutex> lock(mutex);
  if (!folder || !folder->ownedByThisProcess()) {
    if (folder) inherited = std::move(folder);
    folder = std::make_unique<TestTempFolder>();
  }
  return folder->path() + "/" + name;
}

}  // namespace mono_plane_detection
