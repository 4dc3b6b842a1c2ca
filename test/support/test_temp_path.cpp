// The tests' temporary folder: one per process, gone at its exit (test/support/temp_path.h).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "support/temp_path.h"

namespace mono_plane_detection {
namespace {

namespace fs = std::filesystem;

std::string folderOf(pid_t pid) { return std::string(::testing::TempDir()) + "mpd_" + std::to_string(pid); }

// Runs body in a child process that then exits normally (static destructors run, as at the
// end of a test program); returns the child's pid, or -1 when it did not exit with 0.
template <class Body>
pid_t inChild(Body body) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    body();
    std::exit(0);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) && WEXITSTATUS(status) == 0 ? pid : -1;
}

void writeFile(const std::string& path) { std::ofstream(path) << "bag"; }

TEST(TempPath, IsInAFolderOfThisProcessOwn) {
  const std::string path = tempPath("a.bag");
  EXPECT_EQ(fs::path(path).parent_path().string(), folderOf(::getpid()));
  EXPECT_EQ(fs::path(path).filename().string(), "a.bag");
  EXPECT_TRUE(fs::is_directory(fs::path(path).parent_path()));
}

TEST(TempPath, TheFolderGoesWithEverythingInItWhenTheProcessExits) {
  const pid_t child = inChild([] {
    ::unsetenv("MPD_KEEP_TEST_FILES");
    const std::string base = tempPath("accuracy");
    writeFile(base + ".bag");  // names made from one tempPath go too
    fs::create_directories(tempPath("results/images"));
    writeFile(tempPath("results/images/0.png"));
    if (!fs::exists(base + ".bag") || !fs::exists(tempPath("results/images/0.png"))) std::exit(3);
  });
  ASSERT_GT(child, 0);
  EXPECT_FALSE(fs::exists(folderOf(child)));
}

TEST(TempPath, MpdKeepTestFilesKeepsThem) {
  const pid_t child = inChild([] {
    ::setenv("MPD_KEEP_TEST_FILES", "1", 1);
    writeFile(tempPath("kept.bag"));
  });
  ASSERT_GT(child, 0);
  EXPECT_TRUE(fs::exists(folderOf(child) + "/kept.bag"));
  fs::remove_all(folderOf(child));
}

// A forked child (a death test) that exits with a copy of the parent's folder object must
// not remove the parent's folder.
TEST(TempPath, AForkedChildLeavesItsParentsFolder) {
  const std::string mine = tempPath("mine.bag");
  writeFile(mine);
  ASSERT_GT(inChild([] {}), 0);
  EXPECT_TRUE(fs::exists(mine));
}

}  // namespace
}  // namespace mono_plane_detection
