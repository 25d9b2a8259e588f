// VisitIndexedBag: a ROS 1 bag read through its index, by keyplace. The index is loaded the way
// Debian's rosbag library loads it (bag header; at index_pos the connection records, then the
// chunk-info records; after each chunk its index data records), but nothing it gives is trusted:
// every record must start where the walk over the file found one and be as long as its counts
// say, and every index entry must point at a message record of its own connection in its
// decompressed chunk. (rosbag allocated what a length field said and read messages at the index's
// offsets without a bounds check: a fuzzed offset made it parse a header beyond its chunk buffer.)
// The messages are then visited in the order rosbag's View gives them (its merge is reproduced
// below), so results do not change; each chunk is decompressed once.

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "io/chunk_limits.hpp"
#include "io/ros1_bag_records.hpp"
#include "io/ros1_bag_source.hpp"

namespace keyplace {
namespace {

// A record of the file (outside chunks): its header and where its data lie.
struct FileRecord {
  BagFields fields;
  std::uint64_t data_offset = 0;
  std::uint32_t data_bytes = 0;
};

// Every record of the file by its start, walked from the magic to the end. Throws BagIndexError
// when a record runs past the end of the file, has a damaged header or is a compressed chunk
// claiming an implausible size (then the chunk walk reads what is complete, allocating nothing
// for lengths beyond the file's end).
std::map<std::uint64_t, FileRecord> WalkFileRecords(std::ifstream& file, std::uint64_t file_bytes) {
  std::map<std::uint64_t, FileRecord> records;
  std::uint64_t offset = kRos1BagMagicBytes;
  std::vector<std::uint8_t> header;
  const auto fail = [&offset](const std::string& why) {
    throw BagIndexError("record at byte " + std::to_string(offset) + ": " + why);
  };
  while (offset < file_bytes) {
    std::uint8_t length_bytes[4];
    file.seekg(static_cast<std::streamoff>(offset));
    if (file_bytes - offset < 8 || !file.read(reinterpret_cast<char*>(length_bytes), 4)) {
      fail("cut off");
    }
    const std::uint32_t header_bytes = ReadU32(length_bytes);
    if (header_bytes > file_bytes - offset - 8) fail("its header runs past the end of the file");
    header.resize(header_bytes);
    if ((header_bytes > 0 && !file.read(reinterpret_cast<char*>(header.data()), header_bytes)) ||
        !file.read(reinterpret_cast<char*>(length_bytes), 4)) {
      fail("cut off");
    }
    const std::uint32_t data_bytes = ReadU32(length_bytes);
    if (data_bytes > file_bytes - offset - 8 - header_bytes) {
      fail("its data run past the end of the file");
    }
    auto fields = ParseFields(header.data(), header.size());
    if (!fields) fail("a damaged header");
    const auto compression = fields->find("compression");
    const std::uint32_t size = FieldU32(*fields, "size").value_or(0);
    if (FieldOp(*fields) == kOpChunk && compression != fields->end() &&
        compression->second != "none" && !PlausibleChunkBytes(size, data_bytes)) {
      fail("a chunk claiming " + std::to_string(size) + " bytes uncompressed from " +
           std::to_string(data_bytes));
    }
    const std::uint64_t data_offset = offset + 8 + header_bytes;
    records[offset] = {std::move(*fields), data_offset, data_bytes};
    offset = data_offset + data_bytes;
  }
  return records;
}

// One entry of a connection's index data: the message at byte `offset` of the records of the
// chunk at byte `chunk`, received at sec/nsec; `data` holds the message of a wanted topic.
struct IndexEntry {
  std::uint32_t sec = 0;
  std::uint32_t nsec = 0;
  std::uint64_t chunk = 0;
  std::uint32_t offset = 0;
  std::vector<std::uint8_t> data;

  // ros::Time's order: seconds, then nanoseconds.
  std::uint64_t Time() const { return static_cast<std::uint64_t>(sec) << 32 | nsec; }
};

class IndexReader {
 public:
  IndexReader(const std::string& path, std::ifstream& file,
              const std::map<std::uint64_t, FileRecord>& records)
      : path_(path), file_(file), records_(records) {}

  // Loads and checks the index, then decompresses every chunk an entry points into, checks its
  // entries and keeps the messages of `topics`.
  void Read(const std::set<std::string>& topics) {
    const FileRecord& header = At(kRos1BagMagicBytes, kOpBagHeader, "the bag header");
    CheckNotEncrypted(header.fields);
    const std::uint64_t index_offset = U64(header.fields, "index_pos", "the bag header");
    if (index_offset == 0) throw BagIndexError("the bag header gives no index (index_pos 0)");
    const std::uint32_t connection_count = U32(header.fields, "conn_count", "the bag header");
    const std::uint32_t chunk_count = U32(header.fields, "chunk_count", "the bag header");
    // A header that counts other chunks than the file holds (chunk_count 0 read as "no topics")
    // is damaged: the chunks are walked instead, with the warning of a missing index.
    const auto chunks_in_file = static_cast<std::uint64_t>(std::count_if(
        records_.begin(), records_.end(),
        [](const auto& record) { return FieldOp(record.second.fields) == kOpChunk; }));
    if (chunks_in_file != chunk_count) {
      throw BagIndexError("the bag header counts " + std::to_string(chunk_count) +
                          " chunks (chunk_count), the file holds " +
                          std::to_string(chunks_in_file));
    }

    // The index's records lie one after the other from index_pos.
    std::uint64_t offset = index_offset;
    for (std::uint32_t i = 0; i < connection_count; ++i) {
      const FileRecord& connection = At(offset, kOpConnection, "a connection record");
      ReadConnection(connection);
      offset = End(connection);
    }
    std::vector<std::pair<std::uint64_t, std::size_t>> chunks;  // position, index data records
    for (std::uint32_t i = 0; i < chunk_count; ++i) {
      const FileRecord& info = At(offset, kOpChunkInfo, "a chunk-info record");
      chunks.emplace_back(ReadChunkInfo(info));
      offset = End(info);
    }
    for (const auto& [chunk_offset, index_records] : chunks) {
      const FileRecord& chunk = At(chunk_offset, kOpChunk, "a chunk");
      if (chunk.fields.count("compression") == 0 || !FieldU32(chunk.fields, "size")) {
        throw BagIndexError("the chunk at byte " + std::to_string(chunk_offset) +
                            " has no compression or size field");
      }
      offset = End(chunk);
      for (std::size_t i = 0; i < index_records; ++i) {
        const FileRecord& index = At(offset, kOpIndexData, "the index data of a chunk");
        ReadIndexData(index, chunk_offset);
        offset = End(index);
      }
    }
    for (const auto& [chunk_offset, entries] : entries_by_chunk_) {
      ReadChunk(chunk_offset, entries, topics);
    }
  }

  // Every topic with entries, its type (that of its last connection) and message count.
  BagSummary Summary() const {
    std::map<std::string, LogTopic> by_name;
    BagSummary summary;
    for (const auto& [id, entries] : entries_) {
      if (entries.empty()) continue;
      const BagConnection& connection = connections_.at(id);
      LogTopic& topic = by_name[connection.topic];
      topic.name = connection.topic;
      topic.type = connection.datatype;
      topic.messages += entries.size();
      summary.messages += entries.size();
    }
    for (auto& [name, topic] : by_name) summary.topics.push_back(std::move(topic));
    return summary;
  }

  // The messages of `topics` in the order of rosbag's View: one cursor per connection (in id
  // order) over its entries sorted by time, equal times in index order (a std::multiset filled
  // in that order); the cursors kept sorted by their entry's time, latest first, with std::sort
  // after every step, and the last one's entry visited. std::sort on the same sequence with the
  // same comparisons gives rosbag's order of equal times across connections too.
  void Visit(const std::set<std::string>& topics, const RawMessageVisitor& visitor) {
    struct Cursor {
      std::uint32_t connection = 0;
      std::vector<IndexEntry>* entries = nullptr;
      std::size_t next = 0;
    };
    std::vector<Cursor> cursors;
    for (auto& [id, entries] : entries_) {
      if (entries.empty() || topics.count(connections_.at(id).topic) == 0) continue;
      std::stable_sort(entries.begin(), entries.end(),
                       [](const auto& a, const auto& b) { return a.Time() < b.Time(); });
      cursors.push_back({id, &entries, 0});
    }
    const auto later = [](const Cursor& a, const Cursor& b) {
      return (*a.entries)[a.next].Time() > (*b.entries)[b.next].Time();
    };
    std::sort(cursors.begin(), cursors.end(), later);
    while (!cursors.empty()) {
      Cursor& cursor = cursors.back();
      const IndexEntry& entry = (*cursor.entries)[cursor.next];
      const BagConnection& connection = connections_.at(cursor.connection);
      visitor({connection.topic, connection.datatype, connection.md5sum, entry.sec, entry.nsec,
               entry.data.data(), static_cast<std::uint32_t>(entry.data.size())});
      if (++cursor.next == cursor.entries->size()) cursors.pop_back();
      std::sort(cursors.begin(), cursors.end(), later);
    }
  }

 private:
  // The record at `offset`, which must start there and be of op `op`.
  const FileRecord& At(std::uint64_t offset, std::uint8_t op, const std::string& what) const {
    const auto it = records_.find(offset);
    if (it == records_.end()) {
      throw BagIndexError(what + " is expected at byte " + std::to_string(offset) +
                          ", where no record starts");
    }
    if (FieldOp(it->second.fields) != op) {
      throw BagIndexError(what + " is expected at byte " + std::to_string(offset) +
                          ", where another kind of record starts");
    }
    return it->second;
  }

  static std::uint64_t End(const FileRecord& record) {
    return record.data_offset + record.data_bytes;
  }

  static std::uint32_t U32(const BagFields& fields, const std::string& name,
                           const std::string& what) {
    const auto value = FieldU32(fields, name);
    if (!value) throw BagIndexError(what + " has no 4-byte field " + name);
    return *value;
  }

  static std::uint64_t U64(const BagFields& fields, const std::string& name,
                           const std::string& what) {
    const auto value = FieldU64(fields, name);
    if (!value) throw BagIndexError(what + " has no 8-byte field " + name);
    return *value;
  }

  std::vector<std::uint8_t> Data(const FileRecord& record) {
    std::vector<std::uint8_t> data(record.data_bytes);
    file_.seekg(static_cast<std::streamoff>(record.data_offset));
    if (record.data_bytes > 0 &&
        !file_.read(reinterpret_cast<char*>(data.data()), record.data_bytes)) {
      throw BagIndexError("cannot read the record data at byte " +
                          std::to_string(record.data_offset));
    }
    return data;
  }

  // rosbag's encryption plugins encrypt the chunks; keyplace reads plain bags.
  void CheckNotEncrypted(const BagFields& fields) const {
    const auto encryptor = fields.find("encryptor");
    if (encryptor != fields.end() && !encryptor->second.empty() &&
        encryptor->second != "rosbag/NoEncryptor") {
      throw std::invalid_argument(path_ + ": the bag is encrypted (" + encryptor->second +
                                  "); keyplace reads unencrypted bags");
    }
  }

  void ReadConnection(const FileRecord& record) {
    const std::uint32_t id = U32(record.fields, "conn", "a connection record");
    const auto topic = record.fields.find("topic");
    if (topic == record.fields.end() || topic->second.empty()) {
      throw BagIndexError("the connection record of connection " + std::to_string(id) +
                          " has no topic");
    }
    // Its data are a header too: the connection's type, md5sum, definition.
    const std::vector<std::uint8_t> data = Data(record);
    const auto header = ParseFields(data.data(), data.size());
    if (!header) {
      throw BagIndexError("the connection record of topic " + topic->second +
                          " holds a damaged connection header");
    }
    const auto field = [&header](const char* name) {
      const auto it = header->find(name);
      return it == header->end() ? std::string() : it->second;
    };
    // The first record of an id counts, as in rosbag.
    connections_.emplace(id, BagConnection{topic->second, field("type"), field("md5sum")});
  }

  // The chunk's position and how many index data records follow it: one per distinct connection
  // the record lists.
  std::pair<std::uint64_t, std::size_t> ReadChunkInfo(const FileRecord& record) {
    const std::string what = "a chunk-info record";
    if (U32(record.fields, "ver", what) != 1) throw BagIndexError(what + " of another version");
    const std::uint64_t chunk_offset = U64(record.fields, "chunk_pos", what);
    U64(record.fields, "start_time", what);
    U64(record.fields, "end_time", what);
    const std::uint32_t count = U32(record.fields, "count", what);
    if (record.data_bytes != 8ULL * count) {
      throw BagIndexError(what + " counts " + std::to_string(count) + " connections in " +
                          std::to_string(record.data_bytes) + " bytes");
    }
    const std::vector<std::uint8_t> data = Data(record);
    std::map<std::uint32_t, std::uint32_t> messages_by_connection;
    for (std::size_t i = 0; i < count; ++i) {
      messages_by_connection[ReadU32(data.data() + 8 * i)] = ReadU32(data.data() + 8 * i + 4);
    }
    return {chunk_offset, messages_by_connection.size()};
  }

  void ReadIndexData(const FileRecord& record, std::uint64_t chunk_offset) {
    const std::string what = "the index data of the chunk at byte " + std::to_string(chunk_offset);
    if (U32(record.fields, "ver", what) != 1) throw BagIndexError(what + " is of another version");
    const std::uint32_t connection = U32(record.fields, "conn", what);
    const std::uint32_t count = U32(record.fields, "count", what);
    if (record.data_bytes != 12ULL * count) {
      throw BagIndexError(what + " counts " + std::to_string(count) + " entries in " +
                          std::to_string(record.data_bytes) + " bytes");
    }
    if (connections_.count(connection) == 0) {
      throw std::invalid_argument(path_ + ": " + what + " lists connection " +
                                  std::to_string(connection) +
                                  ", of which the bag has no connection record");
    }
    const std::vector<std::uint8_t> data = Data(record);
    std::vector<IndexEntry>& entries = entries_[connection];
    for (std::size_t i = 0; i < count; ++i) {
      const std::uint8_t* bytes = data.data() + 12 * i;
      IndexEntry entry;
      entry.sec = ReadU32(bytes);
      entry.nsec = ReadU32(bytes + 4);
      entry.chunk = chunk_offset;
      entry.offset = ReadU32(bytes + 8);
      // A recorder writes nanoseconds below one second (ros::Time would carry them over).
      if (entry.nsec >= 1000000000U) {
        throw std::invalid_argument(path_ + ": index entry for topic " + Topic(connection) +
                                    " has a time of " + std::to_string(entry.sec) + " s and " +
                                    std::to_string(entry.nsec) + " ns (at most 999999999 ns)");
      }
      // rosbag drops an entry at time 0 (before ros::TIME_MIN), so does keyplace.
      if (entry.sec == 0 && entry.nsec == 0) continue;
      entries_by_chunk_[chunk_offset].emplace_back(connection, entries.size());
      entries.push_back(std::move(entry));
    }
  }

  const std::string& Topic(std::uint32_t connection) const {
    return connections_.at(connection).topic;
  }

  // Every entry into the chunk must point at a message record of its connection; the messages
  // of `topics` are kept.
  void ReadChunk(std::uint64_t chunk_offset,
                 const std::vector<std::pair<std::uint32_t, std::size_t>>& chunk_entries,
                 const std::set<std::string>& topics) {
    const FileRecord& chunk_record = records_.at(chunk_offset);
    // Errors while decompressing name the topic of the chunk's first entry.
    const std::string source = path_ + ": topic " + Topic(chunk_entries.front().first);
    const std::vector<std::uint8_t> chunk =
        DecompressChunk(source, chunk_record.fields, Data(chunk_record), chunk_offset);
    // The message records (starts increasing): their connections and data.
    struct Message {
      std::size_t start = 0;
      std::optional<std::uint32_t> connection;
      const std::uint8_t* data = nullptr;
      std::uint32_t size = 0;
    };
    std::vector<Message> messages;
    const auto damage = ForEachChunkRecord(chunk, [&messages](const ChunkRecord& record) {
      if (record.op == kOpMessage) {
        messages.push_back(
            {record.start, FieldU32(record.fields, "conn"), record.data, record.size});
      }
    });
    for (const auto& [connection, index] : chunk_entries) {
      IndexEntry& entry = entries_.at(connection)[index];
      const auto message =
          std::lower_bound(messages.begin(), messages.end(), entry.offset,
                           [](const Message& m, std::size_t offset) { return m.start < offset; });
      const auto where = [&, connection = connection]() {
        return path_ + ": index entry for topic " + Topic(connection) + " points at byte " +
               std::to_string(entry.offset) + " of the chunk at byte " +
               std::to_string(chunk_offset);
      };
      if (message == messages.end() || message->start != entry.offset) {
        throw std::invalid_argument(where() + ", which is not where a message record starts" +
                                    (damage ? " (" + *damage + ")" : ""));
      }
      if (message->connection != connection) {
        const auto other =
            message->connection ? connections_.find(*message->connection) : connections_.end();
        throw std::invalid_argument(where() + ", a message of " +
                                    (other == connections_.end()
                                         ? std::string("an unknown connection")
                                         : "topic " + other->second.topic));
      }
      if (topics.count(Topic(connection)) != 0) {
        entry.data.assign(message->data, message->data + message->size);
      }
    }
  }

  const std::string& path_;
  std::ifstream& file_;
  const std::map<std::uint64_t, FileRecord>& records_;
  std::map<std::uint32_t, BagConnection> connections_;
  std::map<std::uint32_t, std::vector<IndexEntry>> entries_;  // by connection, in index order
  // Chunk position -> its entries (connection, position in entries_[connection]).
  std::map<std::uint64_t, std::vector<std::pair<std::uint32_t, std::size_t>>> entries_by_chunk_;
};

}  // namespace

BagSummary VisitIndexedBag(const std::string& path, const std::set<std::string>& topics,
                           const RawMessageVisitor& visitor) {
  std::ifstream file(path, std::ios::binary | std::ios::ate);
  if (!file) throw BagIndexError("cannot open the bag");
  const auto file_bytes = static_cast<std::uint64_t>(file.tellg());
  file.seekg(0);
  char magic[kRos1BagMagicBytes];
  if (!file.read(magic, kRos1BagMagicBytes) ||
      std::string(magic, kRos1BagMagicBytes) != kRos1BagMagic) {
    throw BagIndexError("not a ROS 1 bag of format 2.0");
  }
  const std::map<std::uint64_t, FileRecord> records = WalkFileRecords(file, file_bytes);
  file.clear();
  IndexReader reader(path, file, records);
  reader.Read(topics);
  BagSummary summary = reader.Summary();
  reader.Visit(topics, visitor);
  return summary;
}

}  // namespace keyplace
