#pragma once
// Reader for ROS 2 bags (rosbag2: a directory with metadata.yaml and sqlite3 or MCAP storage
// files): the scans of a sensor_msgs/msg/LaserScan topic, each with the robot's odometry pose at
// its stamp and the laser's pose on the robot, as the CarmenLog every command reads. The same
// rules as ReadRos1Bag (ros1_bag.hpp) turn messages into scans and poses.

#include <string>

#include "keyplace/io/bag_input_config.hpp"
#include "keyplace/io/carmen_log.hpp"

namespace keyplace {

/// Whether `path` is to be read as a ROS 2 bag: a directory (a rosbag2 bag, or an error saying
/// it lacks metadata.yaml), a file named metadata.yaml, a file starting with the MCAP magic, or
/// an SQLite file named *.db3.
bool IsRos2Bag(const std::string& path);

/// Reads the bag at `path`: a rosbag2 directory, its metadata.yaml, or one .db3 / .mcap file
/// (storage then told by content). Storage files are read in the order metadata.yaml lists
/// them; MCAP chunks may be uncompressed, lz4 or zstd; messages must be CDR. Scans are taken in
/// recorder-time order; per scan, as ReadRos1Bag: ranges and angles (float32 as their shortest
/// decimal), beam validity, header stamp, odometry from config.odom_topic or the /tf chain
/// interpolated at the stamp, laser pose from config.laser_pose or /tf_static or /tf.
/// An MCAP file cut off is read up to its last complete record, with a warning naming the file
/// and byte. Throws std::invalid_argument naming the bag (and topic or file) and the problem: no
/// metadata.yaml, an unknown storage or compression, a missing or mistyped topic (listing those
/// the bag has), no odometry, no laser pose, a damaged message, chunk or database.
CarmenLog ReadRos2Bag(const std::string& path, const BagInputConfig& config = {},
                      double max_coordinate_m = 1e7);

}  // namespace keyplace
