#pragma once
// Reader for ROS 1 bags (format 2.0; uncompressed, BZ2 or LZ4 chunks), keyplace's own, with the
// message headers of Debian's ROS 1 packages: the scans of a sensor_msgs/LaserScan topic, each with
// the robot's odometry pose at its stamp and the laser's pose on the robot, as the CarmenLog every
// command reads.

#include <string>

#include "keyplace/io/bag_input_config.hpp"
#include "keyplace/io/carmen_log.hpp"

namespace keyplace {

/// Whether `path` is a regular file that starts with the ROS 1 bag magic "#ROSBAG V2.0\n".
bool IsRos1Bag(const std::string& path);

/// Reads the bag at `path` (a regular file: the reader seeks). Per scan message on
/// config.scan_topic, in the bag's time order (rosbag's):
/// - ranges and angles as the message gives them (or spread over config.scan_fov_rad); each
///   float32 becomes the double of its shortest decimal spelling, as a text log would give it;
///   beams below range_min or NaN are invalid, at or beyond range_max (or +inf) "no return";
/// - timestamp_s = header.stamp, logger_timestamp_s = the recorder's time;
/// - odometry_pose: nav_msgs/Odometry on config.odom_topic, or when the bag has no such topic
///   the /tf chain config.odom_frame -> config.base_frame, linearly interpolated at the stamp
///   (heading on the circle; before the first or after the last sample the end is held, with a
///   warning);
/// - T_robot_laser: config.laser_pose when given, else /tf_static or /tf base_frame -> the
///   scan's frame_id.
/// A bag whose index is missing (cut off) is read up to its last complete chunk, with a warning
/// saying what was dropped. Throws std::invalid_argument naming the bag, the topic and the
/// problem: a missing topic (listing those the bag has), a message of the wrong type, no
/// odometry, no laser pose, an unreadable chunk (e.g. unknown compression), an index entry that
/// points elsewhere than at a message of its topic, a pose beyond +-max_coordinate_m.
CarmenLog ReadRos1Bag(const std::string& path, const BagInputConfig& config = {},
                      double max_coordinate_m = 1e7);

}  // namespace keyplace
