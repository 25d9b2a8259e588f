#include "keyplace/io/carmen_log.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "common/shown_text.hpp"
#include "io/file_fingerprint.hpp"
#include "io/ros2_storage.hpp"
#include "io/sqlite_magic.hpp"
#include "keyplace/io/ros1_bag.hpp"
#include "keyplace/io/ros2_bag.hpp"

namespace keyplace {
namespace {

// A held beam: its range and bearing (double) and its validity flag.
constexpr std::size_t kBytesPerHeldBeam = 2 * sizeof(double) + sizeof(std::uint8_t);

// Reads a plain or gzip-compressed text file line by line, once, front to back: the input may be a
// pipe or a FIFO (`keyplace info <(zcat log.gz)`), which can be neither reopened nor rewound, so
// the format is decided from bytes already read and the fingerprint (CRC32 and size of every
// byte, as FileFingerprint) is taken on the way instead of by a second read.
class LineReader {
 public:
  explicit LineReader(const std::string& path) : path_(path), raw_(kBufferBytes) {
    file_.fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (file_.fd < 0) {
      throw std::runtime_error(path + ": cannot open file (" + std::strerror(errno) + ")");
    }
    struct stat status {};
    if (fstat(file_.fd, &status) == 0 && S_ISDIR(status.st_mode)) {
      throw std::runtime_error(path + ": is a directory, not a log file");
    }
    regular_ = S_ISREG(status.st_mode);
    // A pipe may deliver fewer bytes per read than the magic numbers need.
    EnsureRaw(kSqliteMagic.size());
    if (StartsWithSqliteMagic(raw_.data(), raw_end_)) {
      throw std::invalid_argument(
          path + ": an SQLite database (a keyplace map file or a rosbag2 sqlite3 file?), not a " +
          "CARMEN log" +
          (regular_ ? "" : "; map files must be regular files (bags too), not pipes or devices"));
    }
    // A regular file never gets past these two (ReadCarmenLog hands bags to their readers).
    static constexpr std::string_view kBagMagic = "#ROSBAG V2.0\n";
    if (StartsWithRaw(kBagMagic)) {
      throw std::invalid_argument(path +
                                  ": a ROS 1 bag through a pipe or device: its reader seeks, " +
                                  "so give the bag as a regular file");
    }
    if (StartsWithRaw(kMcapMagic)) {
      throw std::invalid_argument(path +
                                  ": a ROS 2 MCAP file through a pipe or device: give the bag as "
                                  "a regular file or a rosbag2 directory");
    }
    RefuseDamagedMagic(kBagMagic, "ROS 1 bag", 3);
    RefuseDamagedMagic(kMcapMagic, "ROS 2 MCAP file", 2);
    RefuseDamagedMagic(kSqliteMagic, "SQLite database (keyplace map or rosbag2 .db3)", 3);
    gzip_ = StartsWithGzipMagic();
    if (gzip_) StartInflating();
  }
  ~LineReader() {
    if (inflating_) inflateEnd(&stream_);
  }
  LineReader(const LineReader&) = delete;
  LineReader& operator=(const LineReader&) = delete;

  // Next line without its end-of-line characters; false at the end of the file.
  bool Next(std::string& line) {
    line.clear();
    terminated_ = false;
    while (true) {
      if (text_begin_ == text_end_ && !FillText()) break;
      const char* begin = text_ + text_begin_;
      const auto* newline =
          static_cast<const char*>(std::memchr(begin, '\n', text_end_ - text_begin_));
      const std::size_t take = newline != nullptr ? static_cast<std::size_t>(newline - begin) + 1
                                                  : text_end_ - text_begin_;
      if (line.size() + take > kMaxLineBytes) {
        // Before growing: one endless line (a binary file, a damaged log) must not take all memory.
        throw std::invalid_argument(path_ + ":" + std::to_string(line_number_ + 1) +
                                    ": line longer than " + std::to_string(kMaxLineBytes >> 20) +
                                    " MiB, not a CARMEN log line (the longest keyplace reads, " +
                                    std::to_string(kMaxScanBeams) +
                                    " ranges and remissions, is under 1 MiB)");
      }
      line.append(begin, take);
      text_begin_ += take;
      if (newline != nullptr) {
        terminated_ = true;
        break;
      }
    }
    if (line.empty()) return false;
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
    ++line_number_;
    return true;
  }

  std::size_t line_number() const { return line_number_; }
  // Whether the latest line ended with an end of line (only the file's last line may not).
  bool terminated() const { return terminated_; }

  // Reads what follows the last line (bytes after the compressed data) so that the fingerprint
  // covers the whole input, then FormatFingerprint of it.
  std::string Fingerprint() {
    raw_begin_ = raw_end_ = 0;
    while (ReadRaw(0) > 0) raw_end_ = 0;
    return FormatFingerprint(static_cast<std::uint32_t>(crc_), bytes_);
  }
  std::uint64_t bytes() const { return bytes_; }

 private:
  static constexpr std::size_t kBufferBytes = 1 << 17;
  // 2 x 8192 numbers of up to 24 characters are 0.4 MiB: 4 MiB leaves room for any spelling.
  static constexpr std::size_t kMaxLineBytes = std::size_t{4} << 20;

  // Appends up to the free space of raw_ after `at` from the input; 0 at its end.
  std::size_t ReadRaw(std::size_t at) {
    if (eof_) return 0;
    while (true) {
      const ssize_t got = read(file_.fd, raw_.data() + at, raw_.size() - at);
      if (got < 0 && errno == EINTR) continue;
      if (got < 0) {
        throw std::runtime_error(path_ + ": read error after line " + std::to_string(line_number_) +
                                 " (" + std::strerror(errno) + ")");
      }
      if (got == 0) eof_ = true;
      const auto count = static_cast<std::size_t>(got);
      crc_ = crc32(crc_, raw_.data() + at, static_cast<uInt>(count));
      bytes_ += count;
      raw_end_ = at + count;
      return count;
    }
  }

  // At least `count` unread raw bytes at raw_begin_, unless the input ends first.
  void EnsureRaw(std::size_t count) {
    if (raw_begin_ > 0) {
      std::memmove(raw_.data(), raw_.data() + raw_begin_, raw_end_ - raw_begin_);
      raw_end_ -= raw_begin_;
      raw_begin_ = 0;
    }
    while (raw_end_ < count && ReadRaw(raw_end_) > 0) {
    }
  }

  // A file whose first bytes are a bag's or database's magic but for up to `allowed` bytes is
  // that file damaged, not a log: read as a log it only said "no laser scans ... is this a CARMEN
  // log?". No CARMEN log begins so (its lines are text: a type name or a '#' comment).
  void RefuseDamagedMagic(std::string_view magic, const char* kind, std::size_t allowed) {
    EnsureRaw(magic.size());
    if (raw_end_ < magic.size()) return;
    std::size_t differing = 0;
    for (std::size_t i = 0; i < magic.size(); ++i)
      differing += raw_[i] != static_cast<unsigned char>(magic[i]) ? 1 : 0;
    if (differing == 0 || differing > allowed) return;
    const std::string_view head(reinterpret_cast<const char*>(raw_.data()), magic.size());
    throw std::invalid_argument(path_ + ": a damaged " + kind + ": its first bytes are '" +
                                ShownText(head) + "', not the magic '" + ShownText(magic) + "' (" +
                                std::to_string(differing) + " of " + std::to_string(magic.size()) +
                                " bytes differ); not read");
  }

  bool StartsWithRaw(std::string_view magic) {
    EnsureRaw(magic.size());
    return raw_end_ >= magic.size() && std::memcmp(raw_.data(), magic.data(), magic.size()) == 0;
  }

  bool StartsWithGzipMagic() const {
    return raw_end_ - raw_begin_ >= 2 && raw_[raw_begin_] == 0x1f && raw_[raw_begin_ + 1] == 0x8b;
  }

  void StartInflating() {
    stream_ = z_stream{};
    // 15 + 16: a gzip wrapper only (a plain file is read as it is, as zlib's gzread does).
    if (inflateInit2(&stream_, 15 + 16) != Z_OK) {
      throw std::runtime_error(path_ + ": cannot start gzip decompression");
    }
    inflating_ = true;
  }

  [[noreturn]] void FailCompressed(const std::string& why) const {
    throw std::runtime_error(path_ + ": truncated or corrupt compressed data after line " +
                             std::to_string(line_number_) + " (" + why + ")");
  }

  // Makes more text available in text_[text_begin_, text_end_); false at the end of the input.
  bool FillText() {
    if (!gzip_) {
      if (raw_begin_ == raw_end_ && ReadRaw(0) == 0) return false;
      text_ = reinterpret_cast<const char*>(raw_.data());
      text_begin_ = raw_begin_;
      text_end_ = raw_end_;
      raw_begin_ = raw_end_ = 0;
      return true;
    }
    if (text_buffer_.empty()) text_buffer_.resize(kBufferBytes);
    while (true) {
      if (member_ended_) {
        // gzip members may be concatenated; anything else after one is ignored, as gzread does.
        EnsureRaw(2);
        if (!StartsWithGzipMagic()) return false;
        inflateReset(&stream_);
        member_ended_ = false;
      }
      if (raw_begin_ == raw_end_) {
        raw_begin_ = 0;
        if (ReadRaw(0) == 0) FailCompressed("unexpected end of file");
      }
      stream_.next_in = raw_.data() + raw_begin_;
      stream_.avail_in = static_cast<uInt>(raw_end_ - raw_begin_);
      stream_.next_out = reinterpret_cast<Bytef*>(text_buffer_.data());
      stream_.avail_out = static_cast<uInt>(text_buffer_.size());
      const int result = inflate(&stream_, Z_NO_FLUSH);
      raw_begin_ = raw_end_ - stream_.avail_in;
      if (result == Z_STREAM_END) {
        member_ended_ = true;
      } else if (result != Z_OK && result != Z_BUF_ERROR) {
        FailCompressed(stream_.msg != nullptr ? stream_.msg
                                              : "zlib error " + std::to_string(result));
      }
      const std::size_t produced = text_buffer_.size() - stream_.avail_out;
      if (produced > 0) {
        text_ = text_buffer_.data();
        text_begin_ = 0;
        text_end_ = produced;
        return true;
      }
    }
  }

  // Closed however the constructor or the reading ends.
  struct FileDescriptor {
    int fd = -1;
    FileDescriptor() = default;
    FileDescriptor(const FileDescriptor&) = delete;
    FileDescriptor& operator=(const FileDescriptor&) = delete;
    ~FileDescriptor() {
      if (fd >= 0) close(fd);
    }
  };

  std::string path_;
  FileDescriptor file_;
  bool regular_ = false;
  bool eof_ = false;
  std::vector<unsigned char> raw_;  // bytes as read from the input
  std::size_t raw_begin_ = 0;
  std::size_t raw_end_ = 0;
  uLong crc_ = crc32(0L, Z_NULL, 0);
  std::uint64_t bytes_ = 0;
  bool gzip_ = false;
  bool inflating_ = false;
  bool member_ended_ = false;
  z_stream stream_{};
  std::vector<char> text_buffer_;  // decompressed text (gzip input)
  const char* text_ = nullptr;     // where the unread text lies: raw_ or text_buffer_
  std::size_t text_begin_ = 0;
  std::size_t text_end_ = 0;
  std::size_t line_number_ = 0;
  bool terminated_ = true;
};

void Tokenize(std::string_view line, std::vector<std::string_view>& tokens) {
  tokens.clear();
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
}

// Parses the fields of one line; every error names file, line, message type and field.
class FieldParser {
 public:
  FieldParser(const std::string& path, std::size_t line,
              const std::vector<std::string_view>& tokens, double max_coordinate_m)
      : path_(path), line_(line), tokens_(tokens), max_coordinate_m_(max_coordinate_m) {}

  [[noreturn]] void Fail(const std::string& what) const {
    throw std::invalid_argument(path_ + ":" + std::to_string(line_) + ": " +
                                std::string(tokens_.front()) + ": " + what);
  }

  void ExpectFieldCount(std::size_t expected, const std::string& layout) const {
    if (tokens_.size() != expected) {
      Fail("expected " + std::to_string(expected) + " fields (" + layout + "), found " +
           std::to_string(tokens_.size()));
    }
  }

  void ExpectAtLeast(std::size_t expected, const std::string& layout) const {
    if (tokens_.size() < expected) {
      Fail("expected at least " + std::to_string(expected) + " fields (" + layout + "), found " +
           std::to_string(tokens_.size()));
    }
  }

  // A number that must be finite.
  double Number(std::size_t index, const std::string& field) const {
    const double value = AnyNumber(index, field);
    if (!std::isfinite(value))
      Fail("field '" + field + "' is not finite: '" + ShownText(Token(index)) + "'");
    return value;
  }

  // A position coordinate (m): finite and within +-max_coordinate_m.
  double Coordinate(std::size_t index, const std::string& field) const {
    const double value = Number(index, field);
    if (!(std::abs(value) <= max_coordinate_m_)) {
      Fail("field '" + field + "' = " + ShownText(Token(index)) + " m lies beyond +-" +
           FormatNumber(max_coordinate_m_) + " m (CarmenReadOptions::max_coordinate_m)");
    }
    return value;
  }

  // An angle (rad): finite and within +-2 pi.
  double Angle(std::size_t index, const std::string& field) const {
    const double value = Number(index, field);
    if (!(std::abs(value) <= 2.0 * M_PI)) {
      Fail("field '" + field + "' = " + ShownText(Token(index)) +
           " rad is not an angle in [-2 pi, 2 pi]");
    }
    return value;
  }

  // A number that may be NaN or infinite (ranges: such beams are marked invalid).
  double AnyNumber(std::size_t index, const std::string& field) const {
    if (index >= tokens_.size()) Fail("missing field '" + field + "'");
    const std::string_view token = tokens_[index];
    double value = 0.0;
    const char* begin = token.data();
    const char* end = token.data() + token.size();
    if (begin != end && *begin == '+') ++begin;
    const auto result = std::from_chars(begin, end, value);
    if (result.ec != std::errc() || result.ptr != end) {
      Fail("field '" + field + "' is not a number: '" + ShownText(token) + "'");
    }
    return value;
  }

  long Integer(std::size_t index, const std::string& field) const {
    if (index >= tokens_.size()) Fail("missing field '" + field + "'");
    const std::string_view token = tokens_[index];
    long value = 0;
    const auto result = std::from_chars(token.data(), token.data() + token.size(), value);
    if (result.ec != std::errc() || result.ptr != token.data() + token.size()) {
      Fail("field '" + field + "' is not an integer: '" + ShownText(token) + "'");
    }
    return value;
  }

  // A beam (or remission) count: at most kMaxScanBeams.
  std::size_t BeamCount(std::size_t index, const std::string& field) const {
    const long value = Integer(index, field);
    if (value < 0) Fail("field '" + field + "' = " + std::to_string(value) + " is negative");
    if (static_cast<unsigned long>(value) > kMaxScanBeams) {
      Fail("field '" + field + "' = " + std::to_string(value) + " is above " +
           std::to_string(kMaxScanBeams) +
           ", the most beams per scan keyplace takes (real 2D lidars give at most about 4000; "
           "downsample the scan)");
    }
    return static_cast<std::size_t>(value);
  }

  std::string Token(std::size_t index) const { return std::string(tokens_.at(index)); }
  std::size_t size() const { return tokens_.size(); }

 private:
  static std::string FormatNumber(double value) {
    char text[32];
    std::snprintf(text, sizeof(text), "%g", value);
    return text;
  }

  const std::string& path_;
  std::size_t line_;
  const std::vector<std::string_view>& tokens_;
  double max_coordinate_m_;
};

// A PARAM laser_{front,rear}_laser_{fov,resolution} in effect: its number (degrees expected) and
// the line that set it, for notes and errors.
struct GeometryParam {
  double value = 0.0;
  std::string token;
  std::size_t line = 0;
};

struct LaserParams {
  std::optional<GeometryParam> fov;
  std::optional<GeometryParam> resolution;
};

struct ReaderState {
  CarmenLog log;
  CarmenReadOptions options;
  LaserParams front_laser;
  LaserParams rear_laser;
  std::set<std::size_t> noted_param_lines;  // PARAM lines whose reading was already noted
  bool in_loop_edges = false;
  bool saw_corrected_marker = false;
};

// Marks each beam valid or not and counts the bad ones.
void ClassifyBeams(LaserScan& scan, CarmenLog& log) {
  scan.valid.assign(scan.ranges_m.size(), 0);
  for (std::size_t i = 0; i < scan.ranges_m.size(); ++i) {
    const double range = scan.ranges_m[i];
    if (!std::isfinite(range) || range <= 0.0) {
      ++log.invalid_beams;
    } else if (range >= scan.max_range_m) {
      ++log.no_return_beams;
    } else {
      scan.valid[i] = 1;
    }
  }
}

// The PARAMs that give FLASER/RLASER lines their angles: a number there must be a finite angle
// in (0, 360] degrees (an infinite field of view made every beam angle NaN; NaN is refused
// likewise). A value that is no number, zero or negative keeps being ignored (the defaults apply).
// Returns the PARAM's laser and value when it is one of them, to be recorded once the line is
// accepted.
std::optional<std::pair<GeometryParam, std::string>> LaserGeometryParam(const FieldParser& fields,
                                                                        std::size_t line) {
  const std::string name = fields.Token(1);
  if (name != "laser_front_laser_fov" && name != "laser_front_laser_resolution" &&
      name != "laser_rear_laser_fov" && name != "laser_rear_laser_resolution") {
    return std::nullopt;
  }
  GeometryParam param;
  param.token = fields.Token(2);
  param.line = line;
  const auto result =
      std::from_chars(param.token.data(), param.token.data() + param.token.size(), param.value);
  // NaN is refused as infinity is: it is a number, and not an angle.
  const bool nan = result.ec == std::errc() && std::isnan(param.value);
  if (result.ec != std::errc() || !(param.value > 0.0)) param.value = 0.0;  // ignored
  if (nan || !(param.value <= 360.0)) {
    fields.Fail(name + " = '" + ShownText(param.token) + "' is not an angle in (0, 360] degrees");
  }
  return std::make_pair(param, name);
}

void RecordLaserGeometryParam(const GeometryParam& param, const std::string& name,
                              ReaderState& state) {
  LaserParams& laser = name.rfind("laser_front_", 0) == 0 ? state.front_laser : state.rear_laser;
  std::optional<GeometryParam>& slot =
      name.size() >= 4 && name.compare(name.size() - 4, 4, "_fov") == 0 ? laser.fov
                                                                        : laser.resolution;
  if (param.value > 0.0) {
    slot = param;
  } else {
    slot.reset();
  }
}

// Whether a field of view, an angular resolution and a beam count describe one scan. Two
// conventions are in use: the field of view spans n steps (each beam owns a sector of one
// resolution: CARMEN's writer, FLIRTLib, and this reader, which spreads FLASER beams from -fov/2
// in steps of fov/n) or n-1 steps (first to last beam, as a ROS LaserScan's angle_max -
// angle_min). Both are accepted, widened by half a step (a field of view rounded to the nearest
// step, whole degrees) and 1 % of the field of view (resolutions written with three significant
// digits, 0.333 for 1/3 degree, are 0.1 % off; six-decimal radians over 8192 beams 0.07 %). The
// contradictions that corrupt the geometry are far outside: degrees read as radians are 57x off,
// a halved resolution or a doubled beam count 2x.
bool GeometryAgrees(double fov_rad, double resolution_rad, std::size_t beams) {
  const double step_rad = std::abs(resolution_rad);
  const double tolerance_rad = 0.5 * step_rad + 0.01 * std::abs(fov_rad);
  const double n = static_cast<double>(beams);
  return fov_rad >= (n - 1.0) * step_rad - tolerance_rad && fov_rad <= n * step_rad + tolerance_rad;
}

std::string Degrees(double angle_rad) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.4g", angle_rad * 180.0 / M_PI);
  return text;
}

std::string DisagreementText(double fov_rad, double resolution_rad, std::size_t beams) {
  char steps[32];
  std::snprintf(steps, sizeof(steps), "%.4g", fov_rad / std::abs(resolution_rad));
  return "a field of view of " + Degrees(fov_rad) + " degrees spans " + steps +
         " steps of the resolution " + Degrees(resolution_rad) + " degrees, but " +
         std::to_string(beams) + " beams need " + std::to_string(beams - 1) + " or " +
         std::to_string(beams) + " (within half a step + 1 %)";
}

// The field of view of a FLASER/RLASER line with `beams` beams from the PARAMs in effect, which
// are checked against each other and the beam count, not trusted. A value at most 2 pi where
// degrees are expected is a field of view in radians (no 2D lidar sees less than 6.3 degrees):
// it is read so, with a note. `notes` gets one sentence per PARAM line read as radians.
double FlaserFieldOfView(const FieldParser& fields, const std::string& path,
                         const LaserParams& params, const std::string& prefix, std::size_t beams,
                         std::vector<std::pair<std::size_t, std::string>>& notes) {
  const auto note = [&](const GeometryParam& param, const std::string& name,
                        const std::string& why) {
    notes.emplace_back(param.line, path + ":" + std::to_string(param.line) + ": PARAM " + prefix +
                                       name + " = " + param.token + " " + why +
                                       ": read as radians (" + Degrees(param.value) +
                                       " degrees), not degrees");
  };
  const auto name_of = [&](const GeometryParam& param, const std::string& name) {
    return "PARAM " + prefix + name + " = " + param.token + " (line " + std::to_string(param.line) +
           ")";
  };
  std::optional<double> fov_rad;
  if (params.fov) {
    if (params.fov->value <= 2.0 * M_PI) {
      fov_rad = params.fov->value;
      note(*params.fov, "fov", "is at most 2 pi");
    } else {
      fov_rad = params.fov->value * M_PI / 180.0;
    }
  }
  if (!params.resolution) return fov_rad.value_or(M_PI);  // 180 degrees when nothing is given
  const GeometryParam& resolution = *params.resolution;
  const double as_degrees_rad = resolution.value * M_PI / 180.0;
  const double as_radians_rad = resolution.value;
  if (fov_rad) {
    if (beams < 2 || GeometryAgrees(*fov_rad, as_degrees_rad, beams)) return *fov_rad;
    if (GeometryAgrees(*fov_rad, as_radians_rad, beams)) {
      note(resolution, "resolution",
           "agrees with the field of view and beam count only in radians");
      return *fov_rad;
    }
    fields.Fail(name_of(*params.fov, "fov") + " and " + name_of(resolution, "resolution") +
                " disagree with this line's " + std::to_string(beams) +
                " beams: " + DisagreementText(*fov_rad, as_degrees_rad, beams));
  }
  // No field of view: the beams span n or n - 1 steps of the resolution (FlaserSpacingOf).
  const double steps = FlaserSteps(beams);
  const double implied_deg = steps * resolution.value;
  if (beams >= 2 && implied_deg <= 2.0 * M_PI) {
    note(resolution, "resolution",
         "gives " + std::to_string(beams) + " beams a field of view of at most 2 pi");
    return steps * as_radians_rad;
  }
  if (implied_deg > 360.0 + 0.5 * resolution.value) {
    fields.Fail(name_of(resolution, "resolution") + " gives this line's " + std::to_string(beams) +
                " beams a field of view of " + Degrees(steps * as_degrees_rad) +
                " degrees, more than a full turn");
  }
  return steps * as_degrees_rad;
}

// FLASER/RLASER n r1..rn x y theta odom_x odom_y odom_theta ipc_timestamp host logger_timestamp
LogScan ParseFlaser(const FieldParser& fields, std::size_t line, ReaderState& state, bool front) {
  fields.ExpectAtLeast(2, "name n ...");
  const std::size_t n = fields.BeamCount(1, "n (beam count)");
  const std::string layout = "name n, " + std::to_string(n) +
                             " ranges, laser x y theta, robot x y theta, ipc_timestamp, host, "
                             "logger_timestamp";
  fields.ExpectFieldCount(n + 11, layout);
  LogScan scan;
  scan.line = line;
  scan.max_range_m = state.options.flaser_max_range_m;
  // FLASER carries no angular geometry: take the field of view from PARAM when the log gives it,
  // else 180 degrees, and spread the beams by the convention of their count (FlaserSpacingOf).
  const std::string prefix = front ? "laser_front_laser_" : "laser_rear_laser_";
  std::vector<std::pair<std::size_t, std::string>> notes;
  const double fov_rad = FlaserFieldOfView(
      fields, state.log.path, front ? state.front_laser : state.rear_laser, prefix, n, notes);
  scan.ranges_m.resize(n);
  scan.angles_rad.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    scan.ranges_m[i] = fields.AnyNumber(2 + i, "range[" + std::to_string(i) + "]");
    scan.angles_rad[i] = FlaserBeamAngle(i, n, fov_rad);
  }
  const std::size_t p = 2 + n;
  const Pose2 laser(fields.Coordinate(p, "laser x"), fields.Coordinate(p + 1, "laser y"),
                    fields.Number(p + 2, "laser theta"));
  const Pose2 robot(fields.Coordinate(p + 3, "robot x"), fields.Coordinate(p + 4, "robot y"),
                    fields.Number(p + 5, "robot theta"));
  scan.odometry_pose = robot;  // moved to corrected_pose at the end for corrected logs
  scan.T_robot_laser = Between(robot, laser);
  scan.logged_laser_pose = laser;
  scan.timestamp_s = fields.Number(p + 6, "ipc_timestamp");
  scan.logger_timestamp_s = fields.Number(p + 8, "logger_timestamp");
  ClassifyBeams(scan, state.log);
  if (front) {
    ++(FlaserSpacingOf(n) == FlaserSpacing::kFovOverBeams
           ? state.log.flaser_scans_fov_over_beams
           : state.log.flaser_scans_fov_over_beams_minus_one);
  }
  // Only an accepted line notes how it read a PARAM, once per PARAM line.
  for (auto& [param_line, text] : notes) {
    if (state.noted_param_lines.insert(param_line).second) {
      state.log.warnings.push_back(std::move(text));
    }
  }
  return scan;
}

// ROBOTLASER1 type start fov res max_range accuracy remission_mode n r1..rn m rem1..remm
//   laser x y theta robot x y theta tv rv forward_safety side_safety turn_axis ipc host logger
LogScan ParseRobotLaser(const FieldParser& fields, std::size_t line, ReaderState& state) {
  fields.ExpectAtLeast(9,
                       "name type start_angle fov resolution max_range accuracy "
                       "remission_mode n ...");
  const double start_rad = fields.Angle(2, "start_angle");
  // Not used (the beams are start + i * resolution), but checked against resolution and count.
  const double fov_rad = fields.Angle(3, "fov");
  const double resolution_rad = fields.Angle(4, "angular_resolution");
  const double max_range_m = fields.Number(5, "max_range");
  const std::size_t n = fields.BeamCount(8, "n (beam count)");
  if (n >= 2 && !GeometryAgrees(fov_rad, resolution_rad, n)) {
    fields.Fail("fields 'fov' = " + fields.Token(3) + " rad, 'angular_resolution' = " +
                fields.Token(4) + " rad and 'n' = " + fields.Token(8) +
                " disagree: " + DisagreementText(fov_rad, resolution_rad, n));
  }
  fields.ExpectAtLeast(10 + n, "9 header fields, " + std::to_string(n) + " ranges, m ...");
  const std::size_t m = fields.BeamCount(9 + n, "m (remission count)");
  fields.ExpectFieldCount(n + m + 24, "9 header fields, " + std::to_string(n) + " ranges, m, " +
                                          std::to_string(m) +
                                          " remissions, laser pose, robot pose, tv rv "
                                          "forward_safety side_safety turn_axis, ipc_timestamp, "
                                          "host, logger_timestamp");
  if (max_range_m <= 0.0) fields.Fail("field 'max_range' must be positive");
  LogScan scan;
  scan.line = line;
  scan.max_range_m = max_range_m;
  scan.ranges_m.resize(n);
  scan.angles_rad.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    scan.ranges_m[i] = fields.AnyNumber(9 + i, "range[" + std::to_string(i) + "]");
    scan.angles_rad[i] = start_rad + static_cast<double>(i) * resolution_rad;
  }
  const std::size_t p = 10 + n + m;
  const Pose2 laser(fields.Coordinate(p, "laser x"), fields.Coordinate(p + 1, "laser y"),
                    fields.Number(p + 2, "laser theta"));
  const Pose2 robot(fields.Coordinate(p + 3, "robot x"), fields.Coordinate(p + 4, "robot y"),
                    fields.Number(p + 5, "robot theta"));
  scan.odometry_pose = robot;
  scan.T_robot_laser = Between(robot, laser);
  scan.logged_laser_pose = laser;
  scan.timestamp_s = fields.Number(p + 11, "ipc_timestamp");
  scan.logger_timestamp_s = fields.Number(p + 13, "logger_timestamp");
  ClassifyBeams(scan, state.log);
  return scan;
}

// Adds the scan's beams to the log's counts (the first scan also gives the field of view: first to
// last bearing, plus one step unless its beams span first to last, FlaserSpacing).
void CountBeams(const LogScan& scan, bool first, bool first_to_last, CarmenLog& log) {
  const std::size_t beams = scan.size();
  if (first) {
    log.beams_per_scan_min = log.beams_per_scan_max = beams;
    if (beams > 1) {
      const double span_rad = scan.angles_rad.back() - scan.angles_rad.front();
      log.first_scan_field_of_view_rad =
          first_to_last ? span_rad : span_rad + span_rad / static_cast<double>(beams - 1);
    }
  }
  log.beams_per_scan_min = std::min(log.beams_per_scan_min, beams);
  log.beams_per_scan_max = std::max(log.beams_per_scan_max, beams);
  log.beams_total += beams;
}

void ReleaseBeams(LogScan& scan) {
  std::vector<double>().swap(scan.ranges_m);
  std::vector<double>().swap(scan.angles_rad);
  std::vector<std::uint8_t>().swap(scan.valid);
}

// Counts the scan's beams and keeps it, without its beams unless the options keep them.
void AddScan(LogScan scan, ReaderState& state, bool first_to_last = false) {
  CountBeams(scan, state.log.scans.empty(), first_to_last, state.log);
  if (!state.options.keep_beams) ReleaseBeams(scan);
  state.log.scans.push_back(std::move(scan));
}

void ParseLine(const std::string& path, std::size_t line_number,
               const std::vector<std::string_view>& tokens, ReaderState& state) {
  CarmenLog& log = state.log;
  const std::string_view type = tokens.front();
  if (type.front() == '#') {
    ++log.line_counts["#comment"];
    std::string text;
    for (const auto& token : tokens) text.append(token).push_back(' ');
    if (text.find("LOOP EDGES") != std::string::npos) state.in_loop_edges = true;
    if (text.find("SEQUENTIAL EDGES") != std::string::npos) state.in_loop_edges = false;
    return;
  }
  const FieldParser fields(path, line_number, tokens, state.options.max_coordinate_m);
  if (type == "FLASER") {
    LogScan scan = ParseFlaser(fields, line_number, state, true);
    const bool first_to_last = FlaserSpacingOf(scan.size()) == FlaserSpacing::kFovOverBeamsMinusOne;
    AddScan(std::move(scan), state, first_to_last);
  } else if (type == "RLASER") {
    ParseFlaser(fields, line_number, state, false);  // validated and counted, not a front scan
  } else if (type == "ROBOTLASER1") {
    AddScan(ParseRobotLaser(fields, line_number, state), state);
  } else if (type == "ODOM") {
    fields.ExpectFieldCount(10, "ODOM x y theta tv rv accel ipc_timestamp host logger_timestamp");
    OdometryMessage odom;
    odom.pose =
        Pose2(fields.Coordinate(1, "x"), fields.Coordinate(2, "y"), fields.Number(3, "theta"));
    odom.tv_mps = fields.Number(4, "tv");
    odom.rv_radps = fields.Number(5, "rv");
    odom.timestamp_s = fields.Number(7, "ipc_timestamp");
    odom.logger_timestamp_s = fields.Number(9, "logger_timestamp");
    log.odometry.push_back(odom);
  } else if (type == "PARAM") {
    fields.ExpectAtLeast(3, "PARAM name value ...");
    const auto geometry = LaserGeometryParam(fields, line_number);
    if (geometry) RecordLaserGeometryParam(geometry->first, geometry->second, state);
    log.params[fields.Token(1)] = fields.Token(2);
  } else if (type == "VERTEX2") {
    fields.ExpectFieldCount(5, "VERTEX2 id x y theta");
    GraphVertex vertex;
    vertex.id = fields.Integer(1, "id");
    vertex.pose =
        Pose2(fields.Coordinate(2, "x"), fields.Coordinate(3, "y"), fields.Number(4, "theta"));
    log.vertices.push_back(vertex);
    state.saw_corrected_marker = true;
  } else if (type == "EDGE2") {
    fields.ExpectFieldCount(12, "EDGE2 from to dx dy dtheta I_xx I_xy I_yy I_tt I_xt I_yt");
    GraphEdge edge;
    edge.from = fields.Integer(1, "from");
    edge.to = fields.Integer(2, "to");
    edge.T_from_to =
        Pose2(fields.Coordinate(3, "dx"), fields.Coordinate(4, "dy"), fields.Number(5, "dtheta"));
    static const char* const kInfoNames[6] = {"I_xx", "I_xy", "I_yy", "I_tt", "I_xt", "I_yt"};
    for (int k = 0; k < 6; ++k) edge.information[k] = fields.Number(6 + k, kInfoNames[k]);
    edge.loop = state.in_loop_edges;
    log.edges.push_back(edge);
  } else if (type == "NEFF") {
    state.saw_corrected_marker = true;  // GMapping output: the scans carry corrected poses
  } else {
    ++log.line_counts["unknown"];
    return;
  }
  ++log.line_counts[std::string(type)];
}

// Reads every line into state; the text of the first skipped line's error goes to
// first_skipped_error.
void ReadLines(const std::string& path, LineReader& reader, ReaderState& state,
               std::string& first_skipped_error) {
  const CarmenReadOptions& options = state.options;
  CarmenLog& log = state.log;
  std::string line;
  std::vector<std::string_view> tokens;
  while (reader.Next(line)) {
    Tokenize(line, tokens);
    if (tokens.empty()) continue;
    try {
      ParseLine(path, reader.line_number(), tokens, state);  // changes nothing when it throws
    } catch (const std::invalid_argument& error) {
      if (!reader.terminated()) {  // the last line, cut off
        const std::string where = path + ":" + std::to_string(reader.line_number()) + ": ";
        std::string what = error.what();
        if (what.compare(0, where.size(), where) == 0) what.erase(0, where.size());
        log.truncated_last_line = true;
        std::string warning = where;
        warning.append("the last line is incomplete (no end of line) and was dropped (")
            .append(what)
            .append(")");
        log.warnings.push_back(std::move(warning));
      } else if (options.skip_bad_lines) {
        if (log.skipped_lines == 0) first_skipped_error = error.what();
        ++log.skipped_lines;
        if (log.skipped_line_numbers.size() < CarmenLog::kMaxListedSkippedLines) {
          log.skipped_line_numbers.push_back(reader.line_number());
        }
      } else {
        throw std::invalid_argument(std::string(error.what()) +
                                    " (to skip malformed lines: --skip-bad-lines, "
                                    "CarmenReadOptions::skip_bad_lines)");
      }
    }
  }
}

// A bag read as a log, with the beam counts the line reader keeps as it goes, and without beams
// when the options say so.
CarmenLog BagLog(CarmenLog log, const CarmenReadOptions& options) {
  for (std::size_t k = 0; k < log.scans.size(); ++k) {
    CountBeams(log.scans[k], k == 0, false, log);
    if (!options.keep_beams) ReleaseBeams(log.scans[k]);
  }
  return log;
}

// What a reader out of memory says instead of a bare std::bad_alloc: where it was and how much
// it held, so the user knows the log itself is too large for this machine. The scans are
// released first: the message itself needs memory.
std::string OutOfMemoryText(const std::string& path, std::size_t line_number, ReaderState& state) {
  const std::size_t scans = state.log.scans.size();
  const std::size_t beams = state.options.keep_beams ? state.log.beams_total : 0;
  std::vector<LogScan>().swap(state.log.scans);
  const std::size_t held_mib = (beams * kBytesPerHeldBeam + scans * sizeof(LogScan)) >> 20U;
  return path + ":" + std::to_string(line_number) + ": out of memory after reading " +
         std::to_string(scans) + " scans (about " + std::to_string(held_mib) +
         " MiB held: the whole log is kept in memory, " + std::to_string(kBytesPerHeldBeam) +
         " bytes per beam); split the log or use a machine with more memory";
}

}  // namespace

FlaserSpacing FlaserSpacingOf(std::size_t beams) {
  return beams % 2 == 1 && beams > 1 ? FlaserSpacing::kFovOverBeamsMinusOne
                                     : FlaserSpacing::kFovOverBeams;
}

double FlaserSteps(std::size_t beams) {
  const double n = static_cast<double>(beams);
  return FlaserSpacingOf(beams) == FlaserSpacing::kFovOverBeamsMinusOne ? n - 1.0 : n;
}

double FlaserBeamAngle(std::size_t i, std::size_t beams, double fov_rad) {
  if (beams == 0) return -0.5 * fov_rad;
  return -0.5 * fov_rad + static_cast<double>(i) * (fov_rad / FlaserSteps(beams));
}

std::string ToString(FlaserSpacing spacing) {
  return spacing == FlaserSpacing::kFovOverBeams ? "fov/n" : "fov/(n-1)";
}

CarmenLog ReadCarmenLog(const std::string& path, const CarmenReadOptions& options) {
  if (!(options.flaser_max_range_m > 0.0)) {
    throw std::invalid_argument("CarmenReadOptions.flaser_max_range_m must be positive");
  }
  if (!(options.max_coordinate_m > 0.0)) {
    throw std::invalid_argument("CarmenReadOptions.max_coordinate_m must be positive");
  }
  if (IsRos2Bag(path)) {
    return BagLog(ReadRos2Bag(path, options.bag, options.max_coordinate_m), options);
  }
  if (IsRos1Bag(path)) {
    return BagLog(ReadRos1Bag(path, options.bag, options.max_coordinate_m), options);
  }
  ReaderState state;
  state.options = options;
  state.log.path = path;
  LineReader reader(path);
  CarmenLog& log = state.log;
  std::string first_skipped_error;
  try {
    ReadLines(path, reader, state, first_skipped_error);
  } catch (const std::bad_alloc&) {
    throw std::runtime_error(OutOfMemoryText(path, reader.line_number(), state));
  }
  if (log.skipped_lines > 0) {
    std::string numbers;
    for (const std::size_t number : log.skipped_line_numbers) {
      numbers += (numbers.empty() ? "" : ", ") + std::to_string(number);
    }
    if (log.skipped_lines > log.skipped_line_numbers.size()) numbers += ", ...";
    log.warnings.push_back(path + ": skipped " + std::to_string(log.skipped_lines) +
                           (log.skipped_lines == 1 ? " malformed line" : " malformed lines") +
                           " (line " + numbers + "); the first: " + first_skipped_error);
  }
  log.lines = reader.line_number();
  log.fingerprint = reader.Fingerprint();
  log.file_bytes = reader.bytes();
  switch (options.pose_kind) {
    case CarmenReadOptions::PoseKind::kCorrected:
      log.corrected = true;
      break;
    case CarmenReadOptions::PoseKind::kOdometry:
      log.corrected = false;
      break;
    case CarmenReadOptions::PoseKind::kAuto:
      log.corrected = state.saw_corrected_marker;
      break;
  }
  if (log.corrected) {
    for (auto& scan : log.scans) {
      scan.corrected_pose = scan.odometry_pose;
      scan.odometry_pose.reset();
    }
  }
  return std::move(state.log);
}

CarmenLog ReadCarmenLogWithScans(const std::string& path, const CarmenReadOptions& options) {
  CarmenLog log = ReadCarmenLog(path, options);
  if (log.scans.empty()) {
    // A bag without scans is an error in ReadRos1Bag and ReadRos2Bag, naming the topic.
    throw std::invalid_argument(path +
                                ": no laser scans (FLASER, RLASER or ROBOTLASER1 lines) in " +
                                std::to_string(log.lines) + " lines: is this a CARMEN log?");
  }
  return log;
}

}  // namespace keyplace
