// keyplace's indexed read of a ROS 1 bag (src/io/ros1_bag_index.cpp) against Debian's rosbag
// library, the oracle: the same messages, bytes and receive times, in the same order as rosbag's
// View gives them, on the real bags of ../shared/data and the bags of the fuzzer's seeds (written
// with rosbag: /odom and /tf_static, a /tf chain, LZ4 and BZ2 chunks).

#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "io/ros1_bag_source.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

struct Message {
  std::string topic;
  std::uint32_t sec = 0;
  std::uint32_t nsec = 0;
  std::vector<std::uint8_t> bytes;

  bool operator==(const Message& other) const {
    return topic == other.topic && sec == other.sec && nsec == other.nsec && bytes == other.bytes;
  }
};

std::vector<Message> ThroughRosbag(const std::string& path, const std::set<std::string>& topics) {
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  std::vector<Message> messages;
  rosbag::View view(bag,
                    rosbag::TopicQuery(std::vector<std::string>(topics.begin(), topics.end())));
  for (const rosbag::MessageInstance& instance : view) {
    Message message{instance.getTopic(), instance.getTime().sec, instance.getTime().nsec, {}};
    message.bytes.resize(instance.size());
    ros::serialization::OStream stream(message.bytes.data(),
                                       static_cast<std::uint32_t>(message.bytes.size()));
    instance.write(stream);
    messages.push_back(std::move(message));
  }
  return messages;
}

std::vector<Message> ThroughKeyplace(const std::string& path, const std::set<std::string>& topics,
                                     BagSummary* summary) {
  std::vector<Message> messages;
  *summary = VisitIndexedBag(path, topics, [&messages](const RawBagMessage& raw) {
    messages.push_back({raw.topic, raw.receive_sec, raw.receive_nsec,
                        std::vector<std::uint8_t>(raw.data, raw.data + raw.size)});
  });
  return messages;
}

void ExpectRosbagsOrder(const std::string& path, std::size_t expected_messages) {
  SCOPED_TRACE(path);
  BagSummary summary;
  const std::set<std::string> all = {"/odom", "/scan", "/tf", "/tf_static"};
  const std::vector<Message> ours = ThroughKeyplace(path, all, &summary);
  const std::vector<Message> theirs = ThroughRosbag(path, all);
  EXPECT_EQ(summary.messages, expected_messages);
  ASSERT_EQ(ours.size(), theirs.size());
  for (std::size_t i = 0; i < ours.size(); ++i) {
    ASSERT_TRUE(ours[i] == theirs[i])
        << "message " << i << ": " << ours[i].topic << " " << ours[i].sec << "." << ours[i].nsec
        << " against " << theirs[i].topic << " " << theirs[i].sec << "." << theirs[i].nsec;
  }
  // One topic alone: the same messages as rosbag's view of it.
  const std::vector<Message> scans = ThroughKeyplace(path, {"/scan"}, &summary);
  EXPECT_TRUE(scans == ThroughRosbag(path, {"/scan"}));
}

TEST(Ros1BagIndex, Fr079GivesRosbagsMessagesInRosbagsOrder) {
  ExpectRosbagsOrder(testing::SharedFile("data/fr079.orig.bag"), 22837);
}

TEST(Ros1BagIndex, FrClinicGivesRosbagsMessagesInRosbagsOrder) {
  ExpectRosbagsOrder(testing::SharedFile("data/fr-clinic.orig.bag"), 20752);
}

TEST(Ros1BagIndex, WrittenBagsGiveRosbagsMessagesInRosbagsOrder) {
  const std::string seeds = testing::SourceDir() + "/tests/fuzz/corpus/ros1_bag/";
  for (const char* name : {"odom-bz2.bag", "odom-lz4.bag", "odom-tf-static.bag", "tf-chain.bag"}) {
    const std::string path = seeds + name;
    ExpectRosbagsOrder(path, ThroughRosbag(path, {"/odom", "/scan", "/tf", "/tf_static"}).size());
  }
}

}  // namespace
}  // namespace keyplace
