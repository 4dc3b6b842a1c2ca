// Issue 14, item 8: a downstream package built as Noetic builds it (-std=gnu++14) against
// the exported headers compiles: the package exports the C++17 they need.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "support/temp_path.h"

TEST(DownstreamBuild, Gnu14PackageCompilesAgainstTheHeaders) {
  // Its own folder per run: make test and make sanitize (or two workspaces) run it at once.
  const std::string dir = mono_plane_detection::tempPath("downstream_build");
  const std::string log = dir + ".log";
  // The outer make's MAKEFLAGS (make test) must not reach this build.
  const std::string command = "rm -rf '" + dir + "' && mkdir -p '" + dir + "' && cd '" + dir +
                              "' && env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL cmake '" SOURCE_DIR
                              "/test/downstream' -DCMAKE_PREFIX_PATH='" +
                              DEVEL_PREFIX ";/usr' -DCMAKE_CXX_FLAGS=-std=gnu++14"
                              " -DCMAKE_EXPORT_COMPILE_COMMANDS=ON > '" + log +
                              "' 2>&1 && env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL make >> '" +
                              log + "' 2>&1";
  const int status = std::system(command.c_str());
  std::ifstream in(log);
  std::stringstream text;
  text << in.rdbuf();
  ASSERT_EQ(status, 0) << text.str();
  // It really was compiled with Noetic's flag, and the export added C++17 after it.
  std::ifstream commands(dir + "/compile_commands.json");
  std::stringstream json;
  json << commands.rdbuf();
  const std::string out = json.str();
  const size_t gnu14 = out.find("-std=gnu++14"), cxx17 = out.find("++17", gnu14);
  EXPECT_NE(gnu14, std::string::npos) << out;
  EXPECT_NE(cxx17, std::string::npos) << out;
  EXPECT_EQ(std::system(("rm -rf '" + dir + "' '" + log + "'").c_str()), 0);
}
