# ROS 1 bags. The library reads bags itself (src/io/ros1_bag_*.cpp) and needs only the message
# headers of libsensor-msgs-dev, libnav-msgs-dev and libtf2-msgs-dev with their serialization
# library, and the chunk codecs (roslz4, bz2): KEYPLACE_ROS1_INCLUDE_DIRS and
# KEYPLACE_ROS1_LIBRARIES (absolute paths, so that the exported static library links in a
# downstream project too). Debian's rosbag (librosbag-storage-dev) is the tests' oracle and
# writer only: KEYPLACE_ROSBAG_TEST_INCLUDE_DIRS and KEYPLACE_ROSBAG_TEST_LIBRARIES, found when
# the tests are built. Their catkin CMake packages pull in ROS 2's ament tooling (pluginlib), so
# headers and libraries are found directly.

# Sets VARIABLE to the include directories of the headers named by the KEYPLACE_<dir>_INCLUDE_DIR
# results in `dirs`, failing with `what` when one is missing.
function(keyplace_collect_include_dirs variable what)
  set(collected)
  foreach(dir IN LISTS ARGN)
    if(NOT KEYPLACE_${dir}_INCLUDE_DIR)
      message(FATAL_ERROR "${what} headers missing (${dir}): run scripts/install-deps.sh")
    endif()
    list(APPEND collected ${KEYPLACE_${dir}_INCLUDE_DIR})
  endforeach()
  list(REMOVE_DUPLICATES collected)
  set(${variable} ${collected} PARENT_SCOPE)
endfunction()

# Sets VARIABLE to the absolute paths of the libraries `names`, failing with `what`.
function(keyplace_collect_libraries variable what)
  set(collected)
  foreach(name IN LISTS ARGN)
    find_library(KEYPLACE_ROS1_LIBRARY_${name} ${name})
    if(NOT KEYPLACE_ROS1_LIBRARY_${name})
      message(FATAL_ERROR "${what} library lib${name} missing: run scripts/install-deps.sh")
    endif()
    list(APPEND collected ${KEYPLACE_ROS1_LIBRARY_${name}})
  endforeach()
  set(${variable} ${collected} PARENT_SCOPE)
endfunction()

find_path(KEYPLACE_ROS_SERIALIZATION_INCLUDE_DIR ros/serialization.h)
find_path(KEYPLACE_SENSOR_MSGS_INCLUDE_DIR sensor_msgs/LaserScan.h)
find_path(KEYPLACE_NAV_MSGS_INCLUDE_DIR nav_msgs/Odometry.h)
find_path(KEYPLACE_TF2_MSGS_INCLUDE_DIR tf2_msgs/TFMessage.h)
find_path(KEYPLACE_ROSLZ4_INCLUDE_DIR roslz4/lz4s.h)
find_path(KEYPLACE_BZ2_INCLUDE_DIR bzlib.h)
keyplace_collect_include_dirs(KEYPLACE_ROS1_INCLUDE_DIRS "ROS 1 message" ROS_SERIALIZATION
                              SENSOR_MSGS NAV_MSGS TF2_MSGS ROSLZ4 BZ2)
keyplace_collect_libraries(KEYPLACE_ROS1_LIBRARIES "ROS 1 message" roscpp_serialization roslz4
                           bz2)

if(KEYPLACE_BUILD_TESTS)
  find_path(KEYPLACE_ROSBAG_INCLUDE_DIR rosbag/bag.h)
  find_path(KEYPLACE_PLUGINLIB_INCLUDE_DIR pluginlib/class_loader.hpp PATH_SUFFIXES pluginlib)
  find_path(KEYPLACE_CLASS_LOADER_INCLUDE_DIR class_loader/class_loader.hpp
            PATH_SUFFIXES class_loader)
  find_path(KEYPLACE_RCUTILS_INCLUDE_DIR rcutils/types.h PATH_SUFFIXES rcutils)
  find_path(KEYPLACE_RCPPUTILS_INCLUDE_DIR rcpputils/shared_library.hpp PATH_SUFFIXES rcpputils)
  find_path(KEYPLACE_AMENT_INDEX_INCLUDE_DIR ament_index_cpp/get_resource.hpp
            PATH_SUFFIXES ament_index_cpp)
  keyplace_collect_include_dirs(KEYPLACE_ROSBAG_TEST_INCLUDE_DIRS "rosbag (tests)" ROSBAG
                                PLUGINLIB CLASS_LOADER RCUTILS RCPPUTILS AMENT_INDEX)
  keyplace_collect_libraries(KEYPLACE_ROSBAG_TEST_LIBRARIES "rosbag (tests)" rosbag_storage
                             rostime cpp_common console_bridge class_loader boost_filesystem)
endif()
