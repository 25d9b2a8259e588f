#include "keyplace/io/carmen_log.hpp"

#include <zlib.h>

#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "support/test_data.hpp"

namespace keyplace {
namespace {

std::string WriteText(const std::string& name, const std::string& text) {
  std::string path = testing::MakeTempDir("carmen") + "/" + name;
  std::ofstream(path) << text;
  return path;
}

std::string Flaser(int beams, const std::string& range, const std::string& tail) {
  std::string line = "FLASER " + std::to_string(beams);
  for (int i = 0; i < beams; ++i) line += " " + range;
  return line + " " + tail + "\n";
}

// Expects `read` to throw E whose message contains every fragment.
template <typename E>
void ExpectError(const std::string& path, std::initializer_list<std::string> fragments) {
  try {
    ReadCarmenLog(path);
    FAIL() << "no exception for " << path;
  } catch (const E& error) {
    const std::string message = error.what();
    for (const auto& fragment : fragments) {
      EXPECT_NE(message.find(fragment), std::string::npos)
          << "message '" << message << "' lacks '" << fragment << "'";
    }
  }
}

TEST(CarmenLog, ReadsRawLogLineTypes) {
  const std::string path =
      WriteText("raw.log",
                "# a header comment\n"
                "PARAM robot_frontlaser_offset -0.04 nohost 0\n"
                "ODOM 1.0 2.0 0.5 0.1 0.2 0 100.5 host 0.5\n" +
                    Flaser(4, "2.5", "0.96 2.0 0.5 1.0 2.0 0.5 100.6 host 0.6") +
                    "SYNC something 1 2\n"
                    "\n" +
                    Flaser(4, "81.9", "1 2 0 1 2 0 100.7 host 0.7"));
  const CarmenLog log = ReadCarmenLog(path);
  ASSERT_EQ(log.scans.size(), 2u);
  EXPECT_FALSE(log.corrected);
  EXPECT_EQ(log.line_counts.at("FLASER"), 2u);
  EXPECT_EQ(log.line_counts.at("ODOM"), 1u);
  EXPECT_EQ(log.line_counts.at("PARAM"), 1u);
  EXPECT_EQ(log.line_counts.at("#comment"), 1u);
  EXPECT_EQ(log.line_counts.at("unknown"), 1u);
  EXPECT_EQ(log.params.at("robot_frontlaser_offset"), "-0.04");
  ASSERT_EQ(log.odometry.size(), 1u);
  EXPECT_DOUBLE_EQ(log.odometry[0].pose.theta, 0.5);
  EXPECT_DOUBLE_EQ(log.odometry[0].timestamp_s, 100.5);

  const LogScan& scan = log.scans[0];
  EXPECT_EQ(scan.line, 4u);
  ASSERT_EQ(scan.size(), 4u);
  // FLASER: 180 degrees, start -pi/2, step pi/n (FLIRTLib's convention).
  EXPECT_DOUBLE_EQ(scan.angles_rad[0], -M_PI / 2.0);
  EXPECT_NEAR(scan.angles_rad[1] - scan.angles_rad[0], M_PI / 4.0, 1e-12);
  EXPECT_EQ(scan.CountValid(), 4u);
  ASSERT_TRUE(scan.odometry_pose.has_value());
  EXPECT_FALSE(scan.corrected_pose.has_value());
  EXPECT_DOUBLE_EQ(scan.odometry_pose->x, 1.0);
  // Laser 4 cm behind the robot along its heading (0.5 rad).
  EXPECT_NEAR(scan.T_robot_laser.x, -0.04, 1e-2);
  EXPECT_NEAR(scan.T_robot_laser.theta, 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(scan.logged_laser_pose.x, 0.96);  // as written, not recomposed
  EXPECT_DOUBLE_EQ(scan.logged_laser_pose.y, 2.0);
  EXPECT_DOUBLE_EQ(scan.timestamp_s, 100.6);
  EXPECT_DOUBLE_EQ(scan.logger_timestamp_s, 0.6);
  // 81.9 m readings are "no return": beyond the 80 m FLASER threshold.
  EXPECT_EQ(log.scans[1].CountValid(), 0u);
  EXPECT_EQ(log.no_return_beams, 4u);
  EXPECT_EQ(log.invalid_beams, 0u);
}

TEST(CarmenLog, FieldOfViewFromParam) {
  const std::string path = WriteText("fov.log", "PARAM laser_front_laser_fov 100 nohost 0\n" +
                                                    Flaser(10, "1.0", "0 0 0 0 0 0 1 h 1"));
  const CarmenLog log = ReadCarmenLog(path);
  ASSERT_EQ(log.scans.size(), 1u);
  EXPECT_NEAR(log.scans[0].angles_rad[0], -50.0 * M_PI / 180.0, 1e-12);
  EXPECT_NEAR(log.scans[0].angles_rad[1] - log.scans[0].angles_rad[0], 10.0 * M_PI / 180.0, 1e-12);
}

TEST(CarmenLog, EvenBeamCountsKeepFlirtLibsSpacingOddOnesSpanFirstToLastBeam) {
  // Even counts: n steps of 180/n from -90 degrees, FLIRTLib's convention (the last beam at
  // 90 - 180/n). Odd counts (SICK at 1 or 0.5 degrees): first and last beam at -90 and +90.
  for (const auto& [beams, step_deg, last_deg] :
       {std::make_tuple(180, 1.0, 89.0), std::make_tuple(360, 0.5, 89.5),
        std::make_tuple(181, 1.0, 90.0), std::make_tuple(361, 0.5, 90.0)}) {
    const std::string path = WriteText(
        "spacing_" + std::to_string(beams) + ".log",
        Flaser(beams, "1.0", "0 0 0 0 0 0 1 h 1") + Flaser(beams, "1.0", "0 0 0 0 0 0 2 h 2"));
    const CarmenLog log = ReadCarmenLog(path);
    ASSERT_EQ(log.scans.size(), 2u) << path;
    const std::vector<double>& angles = log.scans[1].angles_rad;
    EXPECT_NEAR(angles.front(), -M_PI / 2.0, 1e-12) << beams;
    EXPECT_NEAR(angles[1] - angles[0], step_deg * M_PI / 180.0, 1e-12) << beams;
    EXPECT_NEAR(angles.back(), last_deg * M_PI / 180.0, 1e-12) << beams;
    EXPECT_NEAR(log.first_scan_field_of_view_rad, M_PI, 1e-12) << beams;
    const bool odd = beams % 2 == 1;
    EXPECT_EQ(log.flaser_scans_fov_over_beams, odd ? 0u : 2u) << beams;
    EXPECT_EQ(log.flaser_scans_fov_over_beams_minus_one, odd ? 2u : 0u) << beams;
  }
  EXPECT_EQ(FlaserSpacingOf(181), FlaserSpacing::kFovOverBeamsMinusOne);
  EXPECT_EQ(FlaserSpacingOf(1), FlaserSpacing::kFovOverBeams);  // one beam has no span
  EXPECT_DOUBLE_EQ(FlaserBeamAngle(0, 1, M_PI), -M_PI / 2.0);
  // A resolution alone: the step is the resolution in both conventions.
  const std::string resolution =
      WriteText("spacing_resolution.log", "PARAM laser_front_laser_resolution 0.5 nohost 0\n" +
                                              Flaser(361, "1", "0 0 0 0 0 0 1 h 1"));
  const CarmenLog log = ReadCarmenLog(resolution);
  EXPECT_TRUE(log.warnings.empty());
  EXPECT_NEAR(log.scans[0].angles_rad.front(), -M_PI / 2.0, 1e-12);
  EXPECT_NEAR(log.scans[0].angles_rad.back(), M_PI / 2.0, 1e-12);
}

TEST(CarmenLog, BadBeamsAreMarkedInvalidAndCounted) {
  const std::string path =
      WriteText("bad_beams.log", "FLASER 5 1.0 nan inf -2.0 0 0 0 0 0 0 0 1 h 1\n");
  const CarmenLog log = ReadCarmenLog(path);
  ASSERT_EQ(log.scans.size(), 1u);
  EXPECT_EQ(log.scans[0].CountValid(), 1u);
  EXPECT_EQ(log.scans[0].valid[0], 1);
  EXPECT_EQ(log.invalid_beams, 4u);  // NaN, inf, negative and zero
}

TEST(CarmenLog, CorrectedLogKeepsCorrectedPoseAndGraph) {
  const std::string path =
      WriteText("corrected.log",
                "VERTEX2 0 1.5 -2.0 0.25\n"
                "ROBOTLASER1 0 -1.570796 3.141593 0.785398 50.0 0.1 0 5 1 2 60 3 4 0 "
                "1.46 -2.01 0.25 1.5 -2.0 0.25 0 0 0 0 0 10.5 x 0.0\n"
                "#LOOP EDGES\n"
                "EDGE2 0 1 0.1 0.2 0.3 100 0 100 500 0 0\n");
  const CarmenLog log = ReadCarmenLog(path);
  ASSERT_EQ(log.scans.size(), 1u);
  EXPECT_TRUE(log.corrected);
  const LogScan& scan = log.scans[0];
  ASSERT_TRUE(scan.corrected_pose.has_value());
  EXPECT_FALSE(scan.odometry_pose.has_value());
  EXPECT_DOUBLE_EQ(scan.corrected_pose->x, 1.5);
  EXPECT_DOUBLE_EQ(scan.max_range_m, 50.0);
  EXPECT_DOUBLE_EQ(scan.angles_rad[2], -1.570796 + 2 * 0.785398);  // from the line's own fields
  EXPECT_EQ(scan.CountValid(), 4u);  // 60 m >= the line's 50 m max range
  ASSERT_EQ(log.edges.size(), 1u);
  EXPECT_TRUE(log.edges[0].loop);
  EXPECT_DOUBLE_EQ(log.edges[0].information[3], 500.0);
  ASSERT_EQ(log.vertices.size(), 1u);
}

TEST(CarmenLog, ReadsBundledGzipLog) {
  const CarmenLog log = ReadCarmenLog(testing::SourceDir() + "/data/fr079-corrected.log.gz");
  ASSERT_EQ(log.scans.size(), 1464u);
  EXPECT_TRUE(log.corrected);
  EXPECT_EQ(log.vertices.size(), 1464u);
  EXPECT_EQ(log.edges.size(), 2307u);
  for (std::size_t i = 0; i < log.scans.size(); i += 97) {
    const auto& scan = log.scans[i];
    ASSERT_EQ(scan.size(), 360u);
    ASSERT_TRUE(scan.corrected_pose.has_value());
    // VERTEX2 i is the corrected robot pose of the i-th laser line.
    EXPECT_NEAR(scan.corrected_pose->x, log.vertices[i].pose.x, 1e-9);
    EXPECT_NEAR(scan.corrected_pose->theta, log.vertices[i].pose.theta, 1e-9);
    // FR079's laser sits 4 cm behind the robot centre.
    EXPECT_NEAR(scan.T_robot_laser.x, -0.04, 1e-3);
    EXPECT_NEAR(scan.T_robot_laser.y, 0.0, 1e-3);
  }
}

TEST(CarmenLog, WrongBeamCountNamesFileLineAndLayout) {
  const std::string path = WriteText("short.log", "# c\nFLASER 5 1 2 3 4 0 0 0 0 0 0 1 h 1\n");
  ExpectError<std::invalid_argument>(path, {path + ":2", "FLASER", "expected 16 fields"});
}

TEST(CarmenLog, NonNumericFieldIsNamed) {
  const std::string path = WriteText("nan_pose.log", "FLASER 2 1 2 0 zero 0 0 0 0 1 h 1\n");
  ExpectError<std::invalid_argument>(path, {path + ":1", "laser y", "'zero'"});
  const std::string odom = WriteText("odom.log", "ODOM 1 2 3 4 5 6 7 h\n");
  ExpectError<std::invalid_argument>(odom, {odom + ":1", "ODOM", "expected 10 fields"});
  const std::string count = WriteText("count.log", "FLASER -3 1 2\n");
  ExpectError<std::invalid_argument>(count, {count + ":1", "beam count"});
}

// Issue 31: a file whose magic is a bag's or a database's but for a byte or two is that file
// damaged; it used to read as a log without scans ("is this a CARMEN log?").
TEST(CarmenLog, ABagOrDatabaseWithADamagedMagicIsNamedAsSuch) {
  const struct {
    std::string head;
    const char* kind;
  } cases[] = {
      {"#ROSBAG V2.1\n", "a damaged ROS 1 bag"},
      {"#ROSBAX V2.0\n", "a damaged ROS 1 bag"},
      {std::string("\x89MCAP1\r\n", 8), "a damaged ROS 2 MCAP file"},
      {std::string("\x89MCAP0\n\n", 8), "a damaged ROS 2 MCAP file"},
      {std::string("SQLite format 4\0", 16), "a damaged SQLite database"},
  };
  for (const auto& damaged : cases) {
    SCOPED_TRACE(damaged.kind);
    const std::string path =
        WriteText("damaged.bin", damaged.head + std::string(64, '\x01') + "FLASER 1 1\n");
    ExpectError<std::invalid_argument>(path, {path + ": " + damaged.kind, "not read"});
  }
  // Text that merely begins like a comment is still a log.
  const std::string log = WriteText(
      "comment.log", "#ROSBAG-like comment, but a log\n" + Flaser(4, "1", "0 0 0 0 0 0 1 h 1"));
  EXPECT_EQ(ReadCarmenLog(log).scans.size(), 1u);
}

// Issue 31: a NUL byte cut the quoted text where C strings end; a long field was quoted whole.
TEST(CarmenLog, QuotedFieldsAreEscapedAndBounded) {
  static constexpr char kNulLine[] = "FLASER 2 1 2 0 ze\0ro 0 0 0 0 1 h 1\n";
  const std::string nul = WriteText("nul.log", std::string(kNulLine, sizeof(kNulLine) - 1));
  ExpectError<std::invalid_argument>(nul, {nul + ":1", "'ze\\0ro'"});
  const std::string long_field =
      WriteText("long.log", "FLASER 2 1 2 0 " + std::string(100000, 'y') + " 0 0 0 0 1 h 1\n");
  try {
    ReadCarmenLog(long_field);
    FAIL() << "accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_LT(std::string(error.what()).size(), 400u);
    EXPECT_NE(std::string(error.what()).find("... (100000 bytes)"), std::string::npos)
        << error.what();
  }
}

TEST(CarmenLog, NonFiniteOrAbsurdFieldOfViewIsAnErrorNamingTheLine) {
  // Formerly an infinite field of view was taken and made every beam angle NaN.
  // NaN was ignored (the default applied) while infinity was refused (issue 31).
  for (const std::string value : {"inf", "1e300", "720", "nan", "-nan", "NaN"}) {
    const std::string path = WriteText("fov_" + value + ".log",
                                       "# c\nPARAM laser_front_laser_fov " + value + " nohost 0\n" +
                                           Flaser(10, "1.0", "0 0 0 0 0 0 1 h 1"));
    ExpectError<std::invalid_argument>(path, {path + ":2", "laser_front_laser_fov", value});
  }
  const std::string resolution =
      WriteText("resolution.log", "PARAM laser_front_laser_resolution inf nohost 0\n" +
                                      Flaser(4, "1", "0 0 0 0 0 0 1 h 1"));
  ExpectError<std::invalid_argument>(resolution, {resolution + ":1", "resolution"});
  // A value that is no angle at all is still ignored (180 degrees), as before.
  const std::string ignored =
      WriteText("ignored.log", "PARAM laser_front_laser_fov none nohost 0\n" +
                                   Flaser(4, "1", "0 0 0 0 0 0 1 h 1"));
  const CarmenLog log = ReadCarmenLog(ignored);
  ASSERT_EQ(log.scans.size(), 1u);
  EXPECT_DOUBLE_EQ(log.scans[0].angles_rad[0], -M_PI / 2.0);
  // ROBOTLASER1 carries its own geometry: fov and angular resolution must be finite angles.
  const std::string robot_laser =
      "ROBOTLASER1 0 -1.570796 FOV RES 50.0 0.1 0 2 1 2 0 "
      "0 0 0 0 0 0 0 0 0 0 0 10.5 x 0.0\n";
  const auto with = [&](const std::string& fov, const std::string& res) {
    std::string line = robot_laser;
    line.replace(line.find("FOV"), 3, fov);
    line.replace(line.find("RES"), 3, res);
    return line;
  };
  const std::string fov_inf = WriteText("rl_fov.log", with("inf", "0.01"));
  ExpectError<std::invalid_argument>(fov_inf, {fov_inf + ":1", "'fov'"});
  const std::string res_huge = WriteText("rl_res.log", with("3.14", "1e300"));
  ExpectError<std::invalid_argument>(res_huge, {res_huge + ":1", "'angular_resolution'"});
  EXPECT_EQ(ReadCarmenLog(WriteText("rl_ok.log", with("0.02", "0.01"))).scans.size(), 1u);
}

TEST(CarmenLog, FieldOfViewInRadiansWhereDegreesAreExpectedIsReadAsRadiansWithANote) {
  // Formerly read as 3.1 degrees, silently (issue 18).
  const std::string path =
      WriteText("fov_rad.log", "PARAM laser_front_laser_fov 3.14159 nohost 0\n" +
                                   Flaser(10, "1.0", "0 0 0 0 0 0 1 h 1") +
                                   Flaser(10, "1.0", "0 0 0 0 0 0 2 h 2"));
  const CarmenLog log = ReadCarmenLog(path);
  ASSERT_EQ(log.scans.size(), 2u);
  EXPECT_NEAR(log.scans[0].angles_rad[0], -0.5 * 3.14159, 1e-12);
  EXPECT_NEAR(log.scans[0].angles_rad[1] - log.scans[0].angles_rad[0], 0.314159, 1e-12);
  ASSERT_EQ(log.warnings.size(), 1u);  // one note per PARAM line, not one per scan
  for (const std::string& fragment : std::initializer_list<std::string>{
           path + ":1", "laser_front_laser_fov", "3.14159", "radians", "180 degrees"}) {
    EXPECT_NE(log.warnings[0].find(fragment), std::string::npos) << log.warnings[0];
  }
  // In degrees: no note.
  const std::string degrees =
      WriteText("fov_deg.log", "PARAM laser_front_laser_fov 180 nohost 0\n" +
                                   Flaser(10, "1.0", "0 0 0 0 0 0 1 h 1"));
  EXPECT_TRUE(ReadCarmenLog(degrees).warnings.empty());
}

TEST(CarmenLog, FieldOfViewResolutionAndBeamCountMustAgree) {
  const auto log_with = [](const std::string& name, const std::string& fov,
                           const std::string& resolution, int beams) {
    return WriteText(name, "PARAM laser_front_laser_fov " + fov + " nohost 0\n" +
                               "PARAM laser_front_laser_resolution " + resolution + " nohost 0\n" +
                               Flaser(beams, "1.0", "0 0 0 0 0 0 1 h 1"));
  };
  // Both conventions: n steps (CARMEN, FLIRTLib) and n - 1 steps (first to last beam).
  for (const auto& [fov, resolution, beams] :
       {std::make_tuple("180", "1", 180), std::make_tuple("180", "1", 181),
        std::make_tuple("180", "0.5", 360), std::make_tuple("270", "0.25", 1081),
        std::make_tuple("100", "0.333", 301)}) {
    const std::string path = log_with(
        std::string("agree_") + fov + "_" + std::to_string(beams) + ".log", fov, resolution, beams);
    const CarmenLog log = ReadCarmenLog(path);
    ASSERT_EQ(log.scans.size(), 1u) << path;
    EXPECT_TRUE(log.warnings.empty()) << path;
    // The field of view decides the angles, spread by the convention of the beam count.
    EXPECT_NEAR(log.scans[0].angles_rad[0], -0.5 * std::stod(fov) * M_PI / 180.0, 1e-12);
    EXPECT_NEAR(log.scans[0].angles_rad.back(),
                (beams % 2 == 1 ? 0.5 : 0.5 - 1.0 / beams) * std::stod(fov) * M_PI / 180.0, 1e-12);
  }
  // Half the beams, ten beams too many (1 % + half a step is 2.3 here), a resolution twice too
  // fine.
  for (const auto& [fov, resolution, beams] :
       {std::make_tuple("180", "1", 90), std::make_tuple("180", "1", 190),
        std::make_tuple("180", "0.25", 360)}) {
    const std::string path =
        log_with(std::string("disagree_") + resolution + "_" + std::to_string(beams) + ".log", fov,
                 resolution, beams);
    ExpectError<std::invalid_argument>(
        path, {path + ":3: FLASER", "laser_front_laser_fov = 180 (line 1)",
               std::string("laser_front_laser_resolution = ") + resolution + " (line 2)",
               std::to_string(beams) + " beams", "disagree"});
  }
  // A resolution alone that spans more than a full turn.
  const std::string turn = WriteText("turn.log", "PARAM laser_front_laser_resolution 2 nohost 0\n" +
                                                     Flaser(360, "1", "0 0 0 0 0 0 1 h 1"));
  ExpectError<std::invalid_argument>(turn, {turn + ":2: FLASER", "resolution = 2 (line 1)",
                                            "720 degrees", "more than a full turn"});
}

TEST(CarmenLog, ResolutionInRadiansIsReadAsRadiansWithANote) {
  // Beside a field of view in degrees, only radians agree with the beam count.
  const std::string with_fov = WriteText("res_rad.log",
                                         "PARAM laser_front_laser_fov 180 nohost 0\n"
                                         "PARAM laser_front_laser_resolution 0.008727 nohost 0\n" +
                                             Flaser(360, "1", "0 0 0 0 0 0 1 h 1"));
  const CarmenLog log = ReadCarmenLog(with_fov);
  ASSERT_EQ(log.warnings.size(), 1u);
  EXPECT_NE(log.warnings[0].find(with_fov + ":2: PARAM laser_front_laser_resolution = 0.008727"),
            std::string::npos)
      << log.warnings[0];
  EXPECT_NEAR(log.scans[0].angles_rad[0], -M_PI / 2.0, 1e-12);
  // Alone: 180 beams at 0.0174533 "degrees" would see 3.1 degrees.
  const std::string alone =
      WriteText("res_rad_alone.log", "PARAM laser_front_laser_resolution 0.0174533 nohost 0\n" +
                                         Flaser(180, "1", "0 0 0 0 0 0 1 h 1"));
  const CarmenLog alone_log = ReadCarmenLog(alone);
  ASSERT_EQ(alone_log.warnings.size(), 1u);
  EXPECT_NE(alone_log.warnings[0].find(alone + ":1: PARAM laser_front_laser_resolution"),
            std::string::npos);
  EXPECT_NEAR(alone_log.scans[0].angles_rad[0], -0.5 * 180 * 0.0174533, 1e-12);
  // In degrees, as expected: 180 beams at 1 degree, no note.
  const std::string degrees =
      WriteText("res_deg.log", "PARAM laser_front_laser_resolution 1 nohost 0\n" +
                                   Flaser(180, "1", "0 0 0 0 0 0 1 h 1"));
  const CarmenLog degrees_log = ReadCarmenLog(degrees);
  EXPECT_TRUE(degrees_log.warnings.empty());
  EXPECT_NEAR(degrees_log.scans[0].angles_rad[0], -M_PI / 2.0, 1e-12);
}

TEST(CarmenLog, RobotLaserFieldOfViewResolutionAndBeamCountMustAgree) {
  const auto line = [](const std::string& fov, const std::string& resolution, int beams) {
    std::string text = "ROBOTLASER1 0 -1.570796 " + fov + " " + resolution + " 50.0 0.1 0 " +
                       std::to_string(beams);
    for (int i = 0; i < beams; ++i) text += " 1.5";
    return text + " 0 0 0 0 0 0 0 0 0 0 0 0 10.5 x 0.0\n";
  };
  // FR079's and Intel's headers (n steps), and the n - 1 convention.
  EXPECT_EQ(ReadCarmenLog(WriteText("fr079.log", line("3.141720", "0.008727", 360))).scans.size(),
            1u);
  EXPECT_EQ(ReadCarmenLog(WriteText("intel.log", line("3.141593", "0.017453", 180))).scans.size(),
            1u);
  EXPECT_EQ(ReadCarmenLog(WriteText("ros.log", line("3.141593", "0.017453", 181))).scans.size(),
            1u);
  // Degrees where radians are expected, and half the beams.
  const std::string degrees = WriteText("rl_deg.log", line("3.141593", "0.5", 360));
  ExpectError<std::invalid_argument>(
      degrees, {degrees + ":1: ROBOTLASER1", "'fov' = 3.141593", "'angular_resolution' = 0.5",
                "'n' = 360", "disagree"});
  const std::string half = WriteText("rl_half.log", line("3.141593", "0.017453", 90));
  ExpectError<std::invalid_argument>(half, {half + ":1: ROBOTLASER1", "'n' = 90", "disagree"});
}

TEST(CarmenLog, FarCoordinatesAreAnErrorNamingLineAndField) {
  // A pose 3e8 m away is a corrupt line (formerly it crashed keyplace map).
  const std::string far =
      WriteText("far.log", "# c\n# d\n" + Flaser(2, "1", "0 0 0 3e8 0 0 1 h 1"));
  ExpectError<std::invalid_argument>(far, {far + ":3", "'robot x'", "max_coordinate_m"});
  const std::string odom = WriteText("far_odom.log", "ODOM 1 -1e300 0 0 0 0 7 h 8\n");
  ExpectError<std::invalid_argument>(odom, {odom + ":1", "ODOM", "'y'"});
  const std::string vertex = WriteText("far_vertex.log", "VERTEX2 0 2e7 0 0\n");
  ExpectError<std::invalid_argument>(vertex, {vertex + ":1", "VERTEX2", "'x'"});
  // UTM-sized coordinates are fine; the bound is an option.
  const std::string utm =
      WriteText("utm.log", Flaser(2, "1", "412000 5318000 0 412000 5318000 0 1 h 1"));
  EXPECT_EQ(ReadCarmenLog(utm).scans.size(), 1u);
  CarmenReadOptions tight;
  tight.max_coordinate_m = 1e5;
  EXPECT_THROW(ReadCarmenLog(utm, tight), std::invalid_argument);
}

TEST(CarmenLog, MoreBeamsThanRealLidarsGiveIsAnErrorNamingTheLine) {
  // Formerly 100 000 beams per scan were read, and FLIRT then asked for n^2 doubles.
  const std::size_t too_many = kMaxScanBeams + 1;
  const std::string path = WriteText(
      "beams.log", "# c\n" + Flaser(static_cast<int>(too_many), "1", "0 0 0 0 0 0 1 h 1"));
  ExpectError<std::invalid_argument>(
      path, {path + ":2", "beam count", std::to_string(too_many), std::to_string(kMaxScanBeams)});
  const std::string most =
      WriteText("most.log", Flaser(static_cast<int>(kMaxScanBeams), "1", "0 0 0 0 0 0 1 h 1"));
  EXPECT_EQ(ReadCarmenLog(most).scans.at(0).size(), kMaxScanBeams);
}

TEST(CarmenLog, EndlessLineIsAnErrorNamingTheLine) {
  // Formerly a 2 GiB line was read whole; the reader now stops at 4 MiB.
  const std::string long_line = "FLASER 1 " + std::string(5u << 20, '7') + " 0 0 0 0 0 0 1 h 1\n";
  const std::string path = WriteText("endless.log", "# c\n" + long_line);
  ExpectError<std::invalid_argument>(path, {path + ":2", "line longer than 4 MiB"});
  // The same without an end of line (the last line of a cut-off log) is no different.
  const std::string cut = WriteText("endless-cut.log", "# c\n" + long_line.substr(0, 5u << 20));
  ExpectError<std::invalid_argument>(cut, {cut + ":2", "line longer than 4 MiB"});
  // A line just under the bound is read (and rejected for what it says, not for its length).
  const std::string under =
      WriteText("under.log", "# " + std::string((std::size_t{4} << 20) - 16, 'c') + "\n" +
                                 Flaser(2, "1", "0 0 0 0 0 0 1 h 1"));
  EXPECT_EQ(ReadCarmenLog(under).scans.size(), 1U);
}

TEST(CarmenLog, CutOffLastLineIsDroppedWithAWarning) {
  const std::string complete = Flaser(4, "1.5", "0 0 0 0 0 0 1 h 1");
  std::string cut = Flaser(4, "1.5", "0 0 0 0 0 0 2 h 2");
  cut = cut.substr(0, cut.size() / 2);  // no end of line, too few fields
  const std::string path = WriteText("cut.log", complete + complete + cut);
  const CarmenLog log = ReadCarmenLog(path);
  EXPECT_EQ(log.scans.size(), 2u);
  EXPECT_TRUE(log.truncated_last_line);
  ASSERT_EQ(log.warnings.size(), 1u);
  EXPECT_NE(log.warnings[0].find(path + ":3"), std::string::npos) << log.warnings[0];
  EXPECT_NE(log.warnings[0].find("incomplete"), std::string::npos) << log.warnings[0];
  EXPECT_EQ(log.skipped_lines, 0u);
  // A complete last line without end of line is kept, silently.
  const std::string unterminated = complete.substr(0, complete.size() - 1);
  const CarmenLog kept = ReadCarmenLog(WriteText("unterminated.log", complete + unterminated));
  EXPECT_EQ(kept.scans.size(), 2u);
  EXPECT_FALSE(kept.truncated_last_line);
  EXPECT_TRUE(kept.warnings.empty());
  // A cut-off line anywhere else is a malformed line: an error.
  const std::string middle = WriteText("middle.log", complete + cut + "\n" + complete);
  ExpectError<std::invalid_argument>(middle, {middle + ":2", "--skip-bad-lines"});
}

// Formerly the whole log was rejected because its last line was cut off (a logger killed by
// power loss): the first 400 000 bytes of FR101 end in the middle of a FLASER line.
TEST(CarmenLog, CutOffSharedLogKeepsEveryCompleteLine) {
  const std::string source = testing::SharedFile("data/fr101-corrected.log.gz");
  gzFile in = gzopen(source.c_str(), "rb");
  ASSERT_NE(in, nullptr);
  std::string text(400000, '\0');
  ASSERT_EQ(gzread(in, text.data(), static_cast<unsigned>(text.size())), 400000);
  gzclose(in);
  ASSERT_NE(text.back(), '\n');
  const std::string path = testing::MakeTempDir("carmen-cut") + "/fr101-cut.log";
  std::ofstream(path, std::ios::binary) << text;
  std::size_t complete_scans = 0;
  for (std::size_t start = 0, end; (end = text.find('\n', start)) != std::string::npos;
       start = end + 1) {
    if (text.compare(start, 7, "FLASER ") == 0) ++complete_scans;
  }
  const CarmenLog log = ReadCarmenLog(path);
  EXPECT_EQ(log.scans.size(), complete_scans);
  EXPECT_EQ(complete_scans, 146u);
  EXPECT_TRUE(log.corrected);
  EXPECT_TRUE(log.truncated_last_line);
  ASSERT_EQ(log.warnings.size(), 1u);
  EXPECT_NE(log.warnings[0].find("FLASER"), std::string::npos) << log.warnings[0];
}

TEST(CarmenLog, MalformedLinesStopTheReadingUnlessSkipped) {
  const std::string good = Flaser(4, "1.5", "0 0 0 0 0 0 1 h 1");
  std::string text = good;
  for (int k = 0; k < 12; ++k) text += "ODOM 1 2 3\n" + good;  // 12 bad lines: 2, 4, ..., 24
  const std::string path = WriteText("bad_lines.log", text);
  ExpectError<std::invalid_argument>(path, {path + ":2", "ODOM", "--skip-bad-lines"});
  CarmenReadOptions skip;
  skip.skip_bad_lines = true;
  const CarmenLog log = ReadCarmenLog(path, skip);
  EXPECT_EQ(log.scans.size(), 13u);
  EXPECT_EQ(log.skipped_lines, 12u);
  ASSERT_EQ(log.skipped_line_numbers.size(), CarmenLog::kMaxListedSkippedLines);
  EXPECT_EQ(log.skipped_line_numbers.front(), 2u);
  EXPECT_EQ(log.skipped_line_numbers.back(), 20u);
  EXPECT_EQ(log.scans.back().line, 25u);
  EXPECT_EQ(log.line_counts.count("ODOM"), 0u);  // a skipped line leaves no trace
  ASSERT_EQ(log.warnings.size(), 1u);
  EXPECT_NE(log.warnings[0].find("skipped 12 malformed lines (line 2, 4,"), std::string::npos)
      << log.warnings[0];
  EXPECT_NE(log.warnings[0].find(path + ":2: ODOM"), std::string::npos) << log.warnings[0];
  // A far pose or a bad field of view is a malformed line too.
  const std::string far = WriteText("far_skip.log", good + Flaser(2, "1", "0 0 0 3e8 0 0 1 h 1"));
  EXPECT_EQ(ReadCarmenLog(far, skip).scans.size(), 1u);
}

TEST(CarmenLog, TruncatedGzipIsAnError) {
  const std::string dir = testing::MakeTempDir("carmen-gz");
  const std::string path = dir + "/truncated.log.gz";
  std::string text;
  for (int i = 0; i < 2000; ++i) text += Flaser(20, "1.25", "0 0 0 0 0 0 1 h 1");
  gzFile out = gzopen(path.c_str(), "wb");
  gzwrite(out, text.data(), static_cast<unsigned>(text.size()));
  gzclose(out);
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), bytes.size() / 2);
  ExpectError<std::runtime_error>(path, {path, "truncated"});
}

TEST(CarmenLog, MissingFileIsAnError) {
  ExpectError<std::runtime_error>("/nonexistent/keyplace.log", {"/nonexistent/keyplace.log"});
}

}  // namespace
}  // namespace keyplace
