#include "io/ros1_bag_source.hpp"

#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <exception>
#include <map>
#include <memory>

namespace keyplace {
namespace {

// rosbag's open either works or throws; the bag is closed when this goes out of scope.
std::unique_ptr<rosbag::Bag> OpenIndexed(const std::string& path) {
  CheckBagRecords(path);
  auto bag = std::make_unique<rosbag::Bag>();
  try {
    bag->open(path, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& error) {
    throw BagIndexError(error.what());
  }
  return bag;
}

}  // namespace

BagSummary VisitIndexedBag(const std::string& path, const std::set<std::string>& topics,
                           const RawMessageVisitor& visitor) {
  const std::unique_ptr<rosbag::Bag> bag = OpenIndexed(path);
  BagSummary summary;
  rosbag::View everything(*bag);
  std::map<std::string, LogTopic> by_name;
  for (const rosbag::ConnectionInfo* connection : everything.getConnections()) {
    LogTopic& topic = by_name[connection->topic];
    topic.name = connection->topic;
    topic.type = connection->datatype;
  }
  for (auto& [name, topic] : by_name) {
    topic.messages = rosbag::View(*bag, rosbag::TopicQuery(name)).size();
    summary.messages += topic.messages;
    summary.topics.push_back(topic);
  }
  const std::vector<std::string> wanted(topics.begin(), topics.end());
  rosbag::View view(*bag, rosbag::TopicQuery(wanted));
  std::vector<std::uint8_t> buffer;
  for (const rosbag::MessageInstance& message : view) {
    try {
      buffer.resize(message.size());
      ros::serialization::OStream stream(buffer.data(), static_cast<std::uint32_t>(buffer.size()));
      message.write(stream);
    } catch (const std::exception& error) {
      throw std::invalid_argument(
          path + ": topic " + message.getTopic() + ": cannot read a message at bag time " +
          std::to_string(message.getTime().toSec()) + " (rosbag: " + error.what() + ")");
    }
    const ros::Time& time = message.getTime();
    visitor({message.getTopic(), message.getDataType(), message.getMD5Sum(), time.sec, time.nsec,
             buffer.data(), static_cast<std::uint32_t>(buffer.size())});
  }
  return summary;
}

}  // namespace keyplace
