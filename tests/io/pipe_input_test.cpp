// Logs given as pipes, FIFOs and /dev/fd/N (`keyplace info <(zcat log.gz)`) are read once,
// completely (issue 18): the reader can neither reopen nor rewind them.

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <future>
#include <iterator>
#include <stdexcept>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "io/file_fingerprint.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

std::string BundledLog() { return testing::SourceDir() + "/data/fr079-corrected.log.gz"; }

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string Decompressed(const std::string& path) {
  gzFile in = gzopen(path.c_str(), "rb");
  std::string text;
  char buffer[1 << 16];
  int got = 0;
  while ((got = gzread(in, buffer, sizeof(buffer))) > 0) text.append(buffer, got);
  gzclose(in);
  return text;
}

std::string Compressed(const std::string& text) {
  uLongf size = compressBound(static_cast<uLong>(text.size())) + 64;
  std::string out(size, '\0');
  z_stream stream{};
  deflateInit2(&stream, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY);
  stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(text.data()));
  stream.avail_in = static_cast<uInt>(text.size());
  stream.next_out = reinterpret_cast<Bytef*>(out.data());
  stream.avail_out = static_cast<uInt>(out.size());
  deflate(&stream, Z_FINISH);
  out.resize(stream.total_out);
  deflateEnd(&stream);
  return out;
}

std::string FingerprintOf(const std::string& bytes) {
  const uLong crc = crc32(crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(bytes.data()),
                          static_cast<uInt>(bytes.size()));
  return FormatFingerprint(static_cast<std::uint32_t>(crc), bytes.size());
}

// Writes `bytes` to `fd` in uneven pieces, the first a single byte (fewer than the gzip and
// SQLite magic numbers: a pipe may deliver that little per read), then closes it.
void WriteInPieces(int fd, const std::string& bytes) {
  std::size_t at = 0;
  std::size_t piece = 1;
  while (at < bytes.size()) {
    const ssize_t wrote = write(fd, bytes.data() + at, std::min(piece, bytes.size() - at));
    if (wrote < 0 && errno == EINTR) continue;
    if (wrote < 0) break;  // the reader stopped early (EPIPE)
    at += static_cast<std::size_t>(wrote);
    piece = piece * 7 % 65521 + 1;
  }
  close(fd);
}

// Runs `read` with a time limit: a reader that blocks (a FIFO opened a second time waits for a
// writer that never comes) fails the test instead of hanging it.
template <typename Read>
auto WithinSeconds(Read read) {
  auto future = std::async(std::launch::async, read);
  if (future.wait_for(std::chrono::seconds(60)) != std::future_status::ready) {
    std::fprintf(stderr, "FAILED: reading the pipe blocked for 60 s\n");
    std::_Exit(1);
  }
  return future.get();
}

class PipeInput : public ::testing::Test {
 protected:
  // A writer that finds the reader gone gets EPIPE instead of being killed.
  void SetUp() override { std::signal(SIGPIPE, SIG_IGN); }

  // ReadCarmenLog of /dev/fd/N, the read end of a pipe a thread writes `bytes` into: what the
  // shell's <(command) gives.
  static CarmenLog ReadThroughPipe(const std::string& bytes) {
    int fds[2];
    if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
    std::thread writer(WriteInPieces, fds[1], bytes);
    const std::string path = "/dev/fd/" + std::to_string(fds[0]);
    try {
      CarmenLog log = WithinSeconds([&] { return ReadCarmenLog(path); });
      close(fds[0]);
      writer.join();
      return log;
    } catch (...) {
      close(fds[0]);
      writer.join();
      throw;
    }
  }

  // `read(path)` of a named FIFO a thread writes `bytes` into.
  template <typename Read>
  static auto ReadThroughFifo(const std::string& bytes, Read read) {
    const std::string path = testing::MakeTempDir("fifo") + "/log.fifo";
    if (mkfifo(path.c_str(), 0600) != 0) throw std::runtime_error("mkfifo failed");
    std::thread writer([&] {
      const int fd = open(path.c_str(), O_WRONLY);
      if (fd >= 0) WriteInPieces(fd, bytes);
    });
    try {
      auto result = WithinSeconds([&] { return read(path); });
      writer.join();
      return result;
    } catch (...) {
      writer.join();
      throw;
    }
  }
};

void ExpectSameLog(const CarmenLog& actual, const CarmenLog& expected) {
  EXPECT_EQ(actual.lines, expected.lines);
  ASSERT_EQ(actual.scans.size(), expected.scans.size());
  EXPECT_EQ(actual.line_counts, expected.line_counts);
  EXPECT_EQ(actual.scans.front().ranges_m, expected.scans.front().ranges_m);
  EXPECT_EQ(actual.scans.back().ranges_m, expected.scans.back().ranges_m);
  EXPECT_EQ(actual.scans.back().angles_rad, expected.scans.back().angles_rad);
}

TEST_F(PipeInput, PlainLogThroughAPipeIsReadCompletely) {
  // Formerly `keyplace info <(zcat log.gz)` lost the first scans to the SQLite sniff.
  const CarmenLog regular = ReadCarmenLog(BundledLog());
  const std::string text = Decompressed(BundledLog());
  const CarmenLog piped = ReadThroughPipe(text);
  ExpectSameLog(piped, regular);
  EXPECT_EQ(piped.fingerprint, FingerprintOf(text));
  EXPECT_EQ(piped.file_bytes, text.size());
}

TEST_F(PipeInput, GzipLogThroughAPipeIsReadCompletely) {
  // Formerly failed: zlib could not tell the format of a stream it could not rewind.
  const CarmenLog regular = ReadCarmenLog(BundledLog());
  const CarmenLog piped = ReadThroughPipe(ReadBytes(BundledLog()));
  ExpectSameLog(piped, regular);
  // The fingerprint of the compressed bytes, as of the file: a map made from a pipe names the
  // same log.
  EXPECT_EQ(piped.fingerprint, FileFingerprint(BundledLog()));
  EXPECT_EQ(regular.fingerprint, FileFingerprint(BundledLog()));
}

TEST_F(PipeInput, NamedFifoIsReadOnceWithItsFingerprint) {
  // Formerly PrepareLogInputs read the log, then opened it again for its fingerprint: on a FIFO
  // that second open waits for a writer forever.
  LogInputOptions options;
  options.keypoints = false;
  options.compute_poses = false;
  const LogInputs inputs = ReadThroughFifo(ReadBytes(BundledLog()), [&](const std::string& path) {
    return PrepareLogInputs(path, options);
  });
  EXPECT_EQ(inputs.log.scans.size(), ReadCarmenLog(BundledLog()).scans.size());
  EXPECT_EQ(inputs.source_hash, FileFingerprint(BundledLog()));
}

TEST_F(PipeInput, ConcatenatedGzipMembersAreReadAndTrailingBytesIgnored) {
  // As zlib's gzread: members one after another are one text; other bytes after a member are
  // ignored (but fingerprinted).
  const std::string first = "FLASER 2 1 1 0 0 0 0 0 0 1 h 1\n";
  const std::string second = "FLASER 2 2 2 0 0 0 0 0 0 2 h 2\n";
  const std::string bytes = Compressed(first) + Compressed(second) + "trailing";
  const CarmenLog piped = ReadThroughPipe(bytes);
  ASSERT_EQ(piped.scans.size(), 2u);
  EXPECT_EQ(piped.scans[1].ranges_m[0], 2.0);
  EXPECT_EQ(piped.fingerprint, FingerprintOf(bytes));
  const std::string path = testing::MakeTempDir("members") + "/two.log.gz";
  std::ofstream(path, std::ios::binary) << bytes;
  EXPECT_EQ(ReadCarmenLog(path).scans.size(), 2u);
  EXPECT_EQ(ReadCarmenLog(path).fingerprint, FileFingerprint(path));
}

TEST_F(PipeInput, TruncatedGzipThroughAPipeIsAnError) {
  const std::string bytes = Compressed(std::string(2000, 'x') + "\n");
  try {
    ReadThroughPipe(bytes.substr(0, bytes.size() / 2));
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("truncated"), std::string::npos) << error.what();
  }
}

TEST_F(PipeInput, EmptyPipeIsAnEmptyLog) {
  const CarmenLog piped = ReadThroughPipe("");
  EXPECT_EQ(piped.lines, 0u);
  EXPECT_EQ(piped.fingerprint, "crc32:00000000:0");
}

TEST_F(PipeInput, MapFileIsRefusedAsALogNamingThePath) {
  const std::string sqlite = std::string("SQLite format 3") + '\0' + std::string(4096, 'm');
  try {
    ReadThroughFifo(sqlite, [](const std::string& path) { return ReadCarmenLog(path); });
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("log.fifo: an SQLite database"), std::string::npos) << message;
    EXPECT_NE(message.find("map files must be regular files"), std::string::npos) << message;
  }
  const std::string path = testing::MakeTempDir("sqlite") + "/map.kpm";
  std::ofstream(path, std::ios::binary) << sqlite;
  try {
    ReadCarmenLog(path);
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(path + ": an SQLite database"), std::string::npos) << message;
    EXPECT_EQ(message.find("regular files"), std::string::npos) << message;
  }
}

// A directory is read as a ROS 2 bag (rosbag2 directory); one without metadata.yaml is not.
TEST_F(PipeInput, DirectoryIsAnErrorNamingIt) {
  const std::string dir = testing::MakeTempDir("dir");
  try {
    ReadCarmenLog(dir);
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find(dir + ": a directory without metadata.yaml"),
              std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace keyplace
