# Debian's ROS 1 bag libraries (librosbag-storage-dev and the message headers of
# libsensor-msgs-dev, libnav-msgs-dev, libtf2-msgs-dev). Their catkin CMake package pulls in
# ROS 2's ament tooling (pluginlib), so headers and libraries are found directly; sets
# KEYPLACE_ROS1_INCLUDE_DIRS and KEYPLACE_ROS1_LIBRARIES (absolute paths, so that the exported
# static library links in a downstream project too).

find_path(KEYPLACE_ROSBAG_INCLUDE_DIR rosbag/bag.h)
find_path(KEYPLACE_PLUGINLIB_INCLUDE_DIR pluginlib/class_loader.hpp PATH_SUFFIXES pluginlib)
find_path(KEYPLACE_CLASS_LOADER_INCLUDE_DIR class_loader/class_loader.hpp PATH_SUFFIXES class_loader)
find_path(KEYPLACE_RCUTILS_INCLUDE_DIR rcutils/types.h PATH_SUFFIXES rcutils)
find_path(KEYPLACE_RCPPUTILS_INCLUDE_DIR rcpputils/shared_library.hpp PATH_SUFFIXES rcpputils)
find_path(KEYPLACE_AMENT_INDEX_INCLUDE_DIR ament_index_cpp/get_resource.hpp
          PATH_SUFFIXES ament_index_cpp)
find_path(KEYPLACE_SENSOR_MSGS_INCLUDE_DIR sensor_msgs/LaserScan.h)
find_path(KEYPLACE_NAV_MSGS_INCLUDE_DIR nav_msgs/Odometry.h)
find_path(KEYPLACE_TF2_MSGS_INCLUDE_DIR tf2_msgs/TFMessage.h)
find_path(KEYPLACE_ROSLZ4_INCLUDE_DIR roslz4/lz4s.h)
find_path(KEYPLACE_BZ2_INCLUDE_DIR bzlib.h)

set(KEYPLACE_ROS1_INCLUDE_DIRS)
foreach(dir ROSBAG PLUGINLIB CLASS_LOADER RCUTILS RCPPUTILS AMENT_INDEX SENSOR_MSGS NAV_MSGS
        TF2_MSGS ROSLZ4 BZ2)
  if(NOT KEYPLACE_${dir}_INCLUDE_DIR)
    message(FATAL_ERROR "ROS 1 bag headers missing (${dir}): run scripts/install-deps.sh")
  endif()
  list(APPEND KEYPLACE_ROS1_INCLUDE_DIRS ${KEYPLACE_${dir}_INCLUDE_DIR})
endforeach()
list(REMOVE_DUPLICATES KEYPLACE_ROS1_INCLUDE_DIRS)

set(KEYPLACE_ROS1_LIBRARIES)
foreach(name rosbag_storage roscpp_serialization rostime cpp_common console_bridge class_loader
        roslz4 bz2 boost_filesystem)
  find_library(KEYPLACE_ROS1_LIBRARY_${name} ${name})
  if(NOT KEYPLACE_ROS1_LIBRARY_${name})
    message(FATAL_ERROR "ROS 1 bag library lib${name} missing: run scripts/install-deps.sh")
  endif()
  list(APPEND KEYPLACE_ROS1_LIBRARIES ${KEYPLACE_ROS1_LIBRARY_${name}})
endforeach()
