#include "keyplace/io/ros2_bag.hpp"

#include <sys/stat.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <set>
#include <stdexcept>
#include <utility>

#include "common/shown_text.hpp"
#include "io/bag_log.hpp"
#include "io/bag_messages.hpp"
#include "io/bounded_read.hpp"
#include "io/file_fingerprint.hpp"
#include "io/ros2_cdr.hpp"
#include "io/ros2_storage.hpp"
#include "io/sqlite_magic.hpp"
#include "io/yaml_document.hpp"

namespace keyplace {
namespace {

namespace fs = std::filesystem;

constexpr char kMetadataName[] = "metadata.yaml";

enum class Storage { kSqlite3, kMcap };

// The storage files of a bag and how to read them.
struct BagFiles {
  Storage storage = Storage::kMcap;
  std::vector<std::string> paths;
};

bool IsSqliteFile(const std::string& path) {
  char head[kSqliteMagic.size()] = {};
  std::ifstream file(path, std::ios::binary);
  file.read(head, sizeof(head));
  return StartsWithSqliteMagic(head, static_cast<std::size_t>(file.gcount()));
}

// A storage file given alone: its kind from its first bytes.
BagFiles SingleFile(const std::string& path) {
  if (StartsWithMcapMagic(path)) return {Storage::kMcap, {path}};
  if (IsSqliteFile(path)) return {Storage::kSqlite3, {path}};
  throw std::invalid_argument(path + ": neither an MCAP nor an sqlite3 file (a ROS 2 bag file?)");
}

// A file named in metadata.yaml; rosbag2 before Foxy wrote sqlite3 names without ".db3".
std::string StorageFile(const fs::path& folder, const std::string& name, Storage storage,
                        const std::string& metadata) {
  const fs::path path = folder / name;
  std::error_code error;
  if (fs::is_regular_file(path, error)) return path.string();
  const fs::path with_extension = path.string() + (storage == Storage::kMcap ? ".mcap" : ".db3");
  if (fs::is_regular_file(with_extension, error)) return with_extension.string();
  throw std::invalid_argument(metadata + ": lists the storage file " + ShownText(name) +
                              ", which is not in " + folder.string());
}

std::string Scalar(const YAML::Node& node) {
  return node && node.IsScalar() ? node.as<std::string>() : std::string();
}

BagFiles FilesOfMetadata(const std::string& metadata) {
  YAML::Node info;
  try {
    info = LoadYamlDocument(ReadWholeFile(metadata, kMaxBagMetadataBytes, "rosbag2 metadata file"),
                            metadata)["rosbag2_bagfile_information"];
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(std::string(error.what()) + " (not a valid rosbag2 metadata file)");
  }
  if (!info || !info.IsMap()) {
    throw std::invalid_argument(metadata +
                                ": not a rosbag2 metadata file (no "
                                "rosbag2_bagfile_information)");
  }
  BagFiles files;
  const std::string storage = Scalar(info["storage_identifier"]);
  if (storage == "sqlite3") {
    files.storage = Storage::kSqlite3;
  } else if (storage != "mcap") {
    throw std::invalid_argument(metadata + ": unknown storage '" + ShownText(storage) +
                                "' (keyplace reads sqlite3 and mcap)");
  }
  const std::string compression = Scalar(info["compression_format"]);
  if (!compression.empty()) {
    throw std::invalid_argument(
        metadata + ": compression '" + ShownText(compression) + "' (mode " +
        ShownText(Scalar(info["compression_mode"])) +
        ") is unknown to keyplace, which reads uncompressed rosbag2 files and MCAP's own lz4 or "
        "zstd chunks; convert the bag without rosbag2 compression (ros2 bag convert)");
  }
  const fs::path folder = fs::path(metadata).parent_path();
  const YAML::Node names = info["relative_file_paths"];
  if (!names || !names.IsSequence() || names.size() == 0) {
    throw std::invalid_argument(metadata + ": lists no storage file (relative_file_paths)");
  }
  std::set<std::pair<dev_t, ino_t>> listed;
  for (const YAML::Node& name : names) {
    const std::string path = StorageFile(folder, Scalar(name), files.storage, metadata);
    // One file listed twice would be read twice, its scans repeated (2000 entries made a 450 KB
    // bag 300 000 scans): the same file under any name is refused.
    struct stat status {};
    if (::stat(path.c_str(), &status) == 0 &&
        !listed.emplace(status.st_dev, status.st_ino).second) {
      throw std::invalid_argument(metadata + ": lists the storage file " + ShownText(Scalar(name)) +
                                  " more than once (relative_file_paths); each file is read once");
    }
    files.paths.push_back(path);
  }
  return files;
}

BagFiles FilesOf(const std::string& path) {
  std::error_code error;
  if (fs::is_directory(path, error)) {
    const fs::path metadata = fs::path(path) / kMetadataName;
    if (!fs::is_regular_file(metadata, error)) {
      throw std::invalid_argument(path + ": a directory without " + kMetadataName +
                                  ": not a ROS 2 bag (rosbag2) directory");
    }
    return FilesOfMetadata(metadata.string());
  }
  if (fs::path(path).filename() == kMetadataName) return FilesOfMetadata(path);
  return SingleFile(path);
}

// A storage file's messages into the shared sink, decoded from CDR.
class Ros2Decoder {
 public:
  Ros2Decoder(const std::string& path, const BagInputConfig& config, double max_coordinate_m)
      : path_(path), sink_(path, config, max_coordinate_m, kRos2TypeNames) {}

  void operator()(const StorageMessage& message) {
    const std::string& topic = message.topic.name;
    ++counts_[topic];
    const BagMessageKind kind = sink_.Classify(topic, message.topic.type);
    if (kind == BagMessageKind::kNone) return;
    if (message.topic.serialization != "cdr") {
      throw std::invalid_argument(path_ + ": topic " + topic + ": messages serialized as '" +
                                  message.topic.serialization + "', keyplace reads cdr");
    }
    const double receive_s =
        StampSeconds({static_cast<std::int64_t>(message.log_time_ns / 1000000000U),
                      static_cast<std::uint32_t>(message.log_time_ns % 1000000000U)});
    try {
      switch (kind) {
        case BagMessageKind::kScan:
          sink_.AddScan(topic, DecodeRos2LaserScan(message.data, message.size), receive_s);
          break;
        case BagMessageKind::kOdometry:
          sink_.AddOdometry(topic, DecodeRos2Odometry(message.data, message.size), receive_s);
          break;
        case BagMessageKind::kTransforms:
          sink_.AddTransforms(topic, DecodeRos2TfMessage(message.data, message.size));
          break;
        case BagMessageKind::kNone:
          break;
      }
    } catch (const CdrError& error) {
      sink_.Damaged(topic, sink_.NextNumber(kind), error.what());
    }
  }

  void AddTopics(const std::vector<StorageTopic>& topics) {
    for (const StorageTopic& topic : topics) types_.try_emplace(topic.name, topic.type);
  }

  std::vector<LogTopic> Topics() const {
    std::vector<LogTopic> topics;
    for (const auto& [name, type] : types_) {
      const auto count = counts_.find(name);
      topics.push_back({name, type, count == counts_.end() ? 0 : count->second});
    }
    return topics;
  }

  std::size_t Messages() const {
    std::size_t total = 0;
    for (const auto& [name, count] : counts_) total += count;
    return total;
  }

  BagContents& contents() { return sink_.contents(); }

 private:
  const std::string& path_;
  BagMessageSink sink_;
  std::map<std::string, std::string> types_;
  std::map<std::string, std::size_t> counts_;
};

// Scans in recorder-time order (MCAP files may interleave), keeping each frame with its scan.
void SortScansByReceiveTime(BagContents& contents) {
  std::vector<std::size_t> order(contents.scans.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return contents.scans[a].logger_timestamp_s < contents.scans[b].logger_timestamp_s;
  });
  std::vector<LogScan> scans;
  std::vector<std::string> frames;
  scans.reserve(order.size());
  frames.reserve(order.size());
  for (const std::size_t i : order) {
    scans.push_back(std::move(contents.scans[i]));
    frames.push_back(std::move(contents.scan_frames[i]));
  }
  contents.scans = std::move(scans);
  contents.scan_frames = std::move(frames);
}

}  // namespace

bool IsRos2Bag(const std::string& path) {
  std::error_code error;
  if (fs::is_directory(path, error)) return true;
  if (!fs::is_regular_file(path, error)) return false;
  if (fs::path(path).filename() == kMetadataName) return true;
  return StartsWithMcapMagic(path) || (fs::path(path).extension() == ".db3" && IsSqliteFile(path));
}

CarmenLog ReadRos2Bag(const std::string& path, const BagInputConfig& config,
                      double max_coordinate_m) {
  Validate(config);
  const BagFiles files = FilesOf(path);
  Ros2Decoder decoder(path, config, max_coordinate_m);
  const StorageVisitor visit = [&decoder](const StorageMessage& message) { decoder(message); };
  BagSummary summary;
  bool time_ordered = true;
  for (const std::string& file : files.paths) {
    StorageWalk walk = files.storage == Storage::kMcap ? ReadMcapMessages(file, visit)
                                                       : ReadSqliteMessages(file, visit);
    decoder.AddTopics(walk.topics);
    time_ordered = time_ordered && walk.time_ordered;
    for (std::string& warning : walk.warnings) summary.warnings.push_back(std::move(warning));
  }
  summary.topics = decoder.Topics();
  summary.messages = decoder.Messages();
  BagContents& contents = decoder.contents();
  if (!time_ordered || files.paths.size() > 1) SortScansByReceiveTime(contents);
  CarmenLog log = AssembleBagLog(path, config, kRos2TypeNames, summary, std::move(contents));
  log.fingerprint = FilesFingerprint(files.paths);
  std::error_code ignored;
  for (const std::string& file : files.paths) log.file_bytes += fs::file_size(file, ignored);
  return log;
}

}  // namespace keyplace
