// The package as an installed user gets it (catkin_make install, a binary package): the
// install space alone, without the devel space or the source tree on any path, finds the
// package, its nodelets, messages, launch and config files, and the tools read their
// profiles from it. The tools used to read the build machine's source folder (config_dir.h).
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "support/temp_path.h"

namespace {

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

TEST(InstallSpace, RunsFromTheInstallSpaceAlone) {
  const std::string dir = mono_plane_detection::tempPath("install_space");
  const std::string prefix = dir + "/install";
  const std::string log = dir + ".log";
  // The build's install script with another prefix (what `make install` runs; `cmake
  // --install` needs CMake 3.15, the package 3.10). catkin's workspace setup files keep
  // their configured prefix: this test sets the paths itself, below.
  const std::string install = "rm -rf '" + dir + "' && mkdir -p '" + dir +
                              "' && cmake -DCMAKE_INSTALL_PREFIX='" + prefix + "' -P '" +
                              BINARY_DIR "/cmake_install.cmake' > '" + log + "' 2>&1";
  ASSERT_EQ(std::system(install.c_str()), 0) << readFile(log);

  // A clean environment: the system's ROS (Noetic's /opt/ros, or Debian's in /usr) and the
  // install prefix on every path, as the install space's setup.bash sets them (that file is
  // catkin's, written for the workspace's own prefix, and chains the devel space it was
  // configured from; this test must not see the devel space or the source tree).
  const std::string share = prefix + "/share/mono_plane_detection";
  const std::string script = dir + "/check.bash";
  std::ofstream(script)
      << "for setup in /opt/ros/*/setup.bash; do [ -f \"$setup\" ] && source \"$setup\"; break; "
         "done\n"
      << "P='" << prefix << "'\n"
      << "export CMAKE_PREFIX_PATH=\"$P${CMAKE_PREFIX_PATH:+:$CMAKE_PREFIX_PATH}\"\n"
      << "export ROS_PACKAGE_PATH=\"$P/share${ROS_PACKAGE_PATH:+:$ROS_PACKAGE_PATH}\"\n"
      << "export LD_LIBRARY_PATH=\"$P/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}\"\n"
      << "export PYTHONPATH=\"$P/lib/python3/dist-packages${PYTHONPATH:+:$PYTHONPATH}\"\n"
      << "echo \"find: $(rospack find mono_plane_detection)\"\n"
      << "rospack plugins --attrib=plugin nodelet | grep mono_plane_detection\n"
      << "python3 -c 'from mono_plane_detection.msg import PlaneArray, Tracks\n"
         "from mono_plane_detection.cfg import PlanesConfig\nprint(\"python ok\")'\n"
      << "roslaunch --dump-params mono_plane_detection plane_detection.launch > /dev/null"
         " && echo 'launch ok'\n"
      // A refused resize_scale stops the launch and names the value.
      << "roslaunch --nodes mono_plane_detection plane_detection.launch resize_scale:=0.3 2>&1"
         " | grep -o 'must be 0.5 or 0.25, not 0.3'\n"
      << "echo \"libraries not found: $(ldd $P/lib/libmono_plane_detection_nodelets.so"
         " $P/lib/mono_plane_detection/detect_target | grep -c 'not found')\"\n"
      << "rosrun mono_plane_detection detect_target --profile nosuch x.png\n"
      << "echo \"tool exit $?\"\n";
  const std::string out = dir + "/out.txt";
  const std::string run = "env -i HOME=\"$HOME\" PATH=/usr/bin:/bin ROS_HOME='" + dir +
                          "/ros_home' bash '" + script + "' > '" + out + "' 2>&1";
  (void)std::system(run.c_str());
  const std::string text = readFile(out);
  EXPECT_NE(text.find("find: " + share + "\n"), std::string::npos) << text;
  EXPECT_NE(text.find(share + "/nodelets.xml"), std::string::npos) << text;
  EXPECT_NE(text.find("python ok"), std::string::npos) << text;
  EXPECT_NE(text.find("launch ok"), std::string::npos) << text;
  EXPECT_NE(text.find("must be 0.5 or 0.25, not 0.3"), std::string::npos) << text;
  EXPECT_NE(text.find("libraries not found: 0\n"), std::string::npos) << text;
  // The tool names the profile it looked for: in the install space's config/.
  EXPECT_NE(text.find("no profile " + share + "/config/tracker_nosuch.yaml"), std::string::npos)
      << text;
  EXPECT_NE(text.find("tool exit 2"), std::string::npos) << text;
  EXPECT_EQ(std::system(("rm -rf '" + dir + "' '" + log + "'").c_str()), 0);
}
