// Zero copy: the segmentation nodelet receives the very ColorLut object the ACT trainer
// published when both run in one manager (same address for every table), and a copy when they
// run in two (different addresses: the negative control). Both nodelets publish the address of
// each table they send or receive with ~debug_lut_addresses.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <std_msgs/UInt64MultiArray.h>

#include <map>

#include "test_util.hpp"

namespace {

TEST(ZeroCopy, TableAddresses) {
  ros::NodeHandle nh, pnh("~");
  const bool expect_same = pnh.param("expect_same_object", true);
  const int tables = pnh.param("tables", 20);
  act_color_test::Waiter waiter;
  std::map<uint64_t, uint64_t> published, received;  // stamp (ns) -> address
  auto collect = [&](std::map<uint64_t, uint64_t>* into) {
    return [&waiter, into](const std_msgs::UInt64MultiArrayConstPtr& msg) {
      if (msg->data.size() < 2) return;
      std::lock_guard<std::mutex> lock(waiter.mutex());
      (*into)[msg->data[0]] = msg->data[1];
      waiter.notify();
    };
  };
  ros::Subscriber pub_sub =
      nh.subscribe<std_msgs::UInt64MultiArray>("/act_trainer/published_lut", 100, collect(&published));
  ros::Subscriber rec_sub =
      nh.subscribe<std_msgs::UInt64MultiArray>("/segmentation/received_lut", 100, collect(&received));
  ros::AsyncSpinner spinner(2);
  spinner.start();

  auto common = [&] {
    int n = 0;
    for (const auto& [stamp, address] : received) n += published.count(stamp) ? 1 : 0;
    return n;
  };
  ASSERT_TRUE(waiter.waitFor(90.0, [&] { return common() >= tables; }))
      << published.size() << " tables published, " << received.size() << " received";
  std::lock_guard<std::mutex> lock(waiter.mutex());
  int same = 0, different = 0;
  for (const auto& [stamp, address] : received) {
    auto p = published.find(stamp);
    if (p == published.end()) continue;
    (p->second == address ? same : different) += 1;
  }
  std::printf("%d tables with the same address in trainer and segmentation, %d with different ones\n", same, different);
  if (expect_same) {
    EXPECT_EQ(different, 0) << "the segmentation received copies of the trainer's table";
    EXPECT_GE(same, tables);
  } else {
    EXPECT_EQ(same, 0) << "two processes cannot share an object: the address test is broken";
    EXPECT_GE(different, tables);
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_zero_copy");
  return RUN_ALL_TESTS();
}
