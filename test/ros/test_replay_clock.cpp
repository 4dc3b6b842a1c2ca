// replay.launch's player publishes the simulated time on /clock, where use_sim_time reads
// it, and nothing on the camera namespace's clock (rosbag names its clock publisher
// relative to its namespace).
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>

#include <string>

#include "../support/test_timeouts.h"

namespace {

bool advertised(const std::string& topic) {
  ros::master::V_TopicInfo topics;
  if (!ros::master::getTopics(topics)) return false;
  for (const auto& t : topics)
    if (t.name == topic) return true;
  return false;
}

}  // namespace

TEST(ReplayLaunch, ThePlayerPublishesClockWhereSimulatedTimeReadsIt) {
  ros::NodeHandle nh;
  bool sim_time = false;
  ASSERT_TRUE(ros::param::get("/use_sim_time", sim_time));
  ASSERT_TRUE(sim_time);
  int ticks = 0;
  ros::Time last;
  ros::Subscriber clock = nh.subscribe<rosgraph_msgs::Clock>(
      "/clock", 10, [&](const rosgraph_msgs::ClockConstPtr& m) {
        ++ticks;
        last = m->clock;
      });
  EXPECT_TRUE(spinUntil([&] { return ticks >= 5; }, 30.0))
      << ticks << " /clock messages";
  EXPECT_GT(last.toSec(), 0.0);
  EXPECT_GT(ros::Time::now().toSec(), 0.0);  // simulated time runs
  EXPECT_FALSE(advertised("/camera/clock"));
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_replay_clock");
  return RUN_ALL_TESTS();
}
