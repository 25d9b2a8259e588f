// The log reader's memory (issue 18): a summary read holds no beams, and a reader that runs out of
// memory names the file and line instead of a bare std::bad_alloc.

#include <sys/resource.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "keyplace/io/carmen_log.hpp"
#include "support/sanitizers.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

constexpr std::size_t kGeneratedScans = 30000;  // 184 MB of beams held, 8 MB without them
constexpr rlim_t kHeadroomBytes = rlim_t{64} << 20U;

std::string BundledLog() { return testing::SourceDir() + "/data/fr079-corrected.log.gz"; }

TEST(ReaderMemory, ASummaryReadCountsEveryBeamAndKeepsNone) {
  const CarmenLog full = ReadCarmenLog(BundledLog());
  CarmenReadOptions summary_only;
  summary_only.keep_beams = false;
  const CarmenLog summary = ReadCarmenLog(BundledLog(), summary_only);
  ASSERT_EQ(summary.scans.size(), full.scans.size());
  std::size_t beams = 0;
  for (std::size_t i = 0; i < full.scans.size(); ++i) {
    beams += full.scans[i].size();
    EXPECT_EQ(summary.scans[i].size(), 0U);
    EXPECT_EQ(summary.scans[i].timestamp_s, full.scans[i].timestamp_s);
    EXPECT_EQ(summary.scans[i].corrected_pose->x, full.scans[i].corrected_pose->x);
  }
  EXPECT_EQ(full.beams_total, beams);
  EXPECT_EQ(summary.beams_total, beams);
  EXPECT_EQ(summary.beams_per_scan_min, 360U);
  EXPECT_EQ(summary.beams_per_scan_max, 360U);
  EXPECT_EQ(summary.invalid_beams, full.invalid_beams);
  EXPECT_EQ(summary.no_return_beams, full.no_return_beams);
  const auto& bearings_rad = full.scans.front().angles_rad;
  const double step_rad = bearings_rad[1] - bearings_rad[0];
  EXPECT_NEAR(summary.first_scan_field_of_view_rad,
              bearings_rad.back() - bearings_rad.front() + step_rad, 1e-12);
  EXPECT_NEAR(summary.first_scan_field_of_view_rad, M_PI, 1e-3);  // 360 beams of 0.5 degrees
}

std::size_t VirtualMemoryBytes() {
  std::ifstream status("/proc/self/status");
  std::string key;
  std::size_t kib = 0;
  while (status >> key) {
    if (key == "VmSize:") {
      status >> kib;
      return kib << 10U;
    }
    status.ignore(1 << 12, '\n');
  }
  return 0;
}

// Writes `text` to fd; false when the reader has gone (EPIPE).
bool WriteAll(int fd, const std::string& text) {
  std::size_t at = 0;
  while (at < text.size()) {
    const ssize_t wrote = write(fd, text.data() + at, text.size() - at);
    if (wrote < 0 && errno == EINTR) continue;
    if (wrote < 0) return false;
    at += static_cast<std::size_t>(wrote);
  }
  return true;
}

// Writes kGeneratedScans FLASER lines of 360 beams into fd, 64 lines per write, then closes it;
// stops when the reader has gone. It allocates nothing: the address-space limit applies to the
// whole process, and a std::bad_alloc here would end the test in std::terminate instead of
// showing the reader's behaviour. `batch` is reserved before the limit is set.
void WriteGeneratedLog(int fd, const std::string& beams, std::string& batch) {
  constexpr const char* kOdometry = " 1.0 2.0 0.5 1.0 2.0 0.5 ";
  std::array<char, 32> stamp{};
  for (std::size_t scan = 0; scan < kGeneratedScans; ++scan) {
    std::snprintf(stamp.data(), stamp.size(), "%.6f", 1000.0 + 0.1 * static_cast<double>(scan));
    batch.append(beams).append(kOdometry).append(stamp.data()).append(" host ");
    batch.append(stamp.data()).push_back('\n');
    if (scan % 64 == 63 || scan + 1 == kGeneratedScans) {
      if (!WriteAll(fd, batch)) break;
      batch.clear();  // keeps its capacity
    }
  }
  close(fd);
}

// Reads the generated log through a pipe with the address space limited to what the process
// uses plus kHeadroomBytes. Exit 0: read whole; 10: the named out-of-memory error; others: wrong.
[[noreturn]] void ReadGeneratedLogWithHeadroom(bool keep_beams) {
  std::signal(SIGPIPE, SIG_IGN);
  int fds[2];
  if (pipe(fds) != 0) std::exit(2);
  std::string beams = "FLASER 360";
  for (int beam = 0; beam < 360; ++beam) beams += " 2.50";
  std::string batch;
  batch.reserve(64 * (beams.size() + 128));
  // The writer's stack and buffers exist before the limit.
  std::thread writer(WriteGeneratedLog, fds[1], std::cref(beams), std::ref(batch));
  rlimit limit{};
  limit.rlim_cur = limit.rlim_max = VirtualMemoryBytes() + kHeadroomBytes;
  if (setrlimit(RLIMIT_AS, &limit) != 0) std::exit(2);
  const std::string path = "/dev/fd/" + std::to_string(fds[0]);
  CarmenReadOptions options;
  options.keep_beams = keep_beams;
  int code = 5;
  try {
    const CarmenLog log = ReadCarmenLog(path, options);
    code = log.scans.size() == kGeneratedScans ? 0 : 3;
  } catch (const std::runtime_error& error) {
    const std::string what = error.what();
    std::fprintf(stderr, "%s\n", what.c_str());
    code = what.rfind(path + ":", 0) == 0 &&
                   what.find(": out of memory after reading ") != std::string::npos &&
                   what.find("split the log") != std::string::npos
               ? 10
               : 4;
  } catch (...) {
    code = 6;  // e.g. a bare std::bad_alloc
  }
  close(fds[0]);
  writer.join();
  std::exit(code);
}

TEST(ReaderMemoryDeathTest, ALogLargerThanMemoryIsANamedErrorAndItsSummaryFits) {
  if (testing::kAddressSanitizer) GTEST_SKIP() << testing::kAddressSpaceLimitUnderAsan;
  ::testing::FLAGS_gtest_death_test_style = "threadsafe";
  EXPECT_EXIT(ReadGeneratedLogWithHeadroom(true), ::testing::ExitedWithCode(10),
              "out of memory after reading");
  EXPECT_EXIT(ReadGeneratedLogWithHeadroom(false), ::testing::ExitedWithCode(0), "");
}

}  // namespace
}  // namespace keyplace
