#!/usr/bin/env bash
# keyplace's launch files (ros/launch/*.launch) as roslaunch reads them, without
# a roscore: the arguments become the node's private parameters, an argument left empty sets
# nothing (the configuration file and the preset decide), the map is required, and roslaunch
# finds the node's executable in the package directory. Usage: launch_test.sh SHARE_DIR SOURCE_DIR
set -uo pipefail
share_dir=$1
source_dir=$2
# shellcheck source=../support/script_checks.sh
source "$source_dir/tests/support/script_checks.sh"
export ROS_PACKAGE_PATH=$share_dir ROS_HOME=$work/ros-home ROS_LOG_DIR=$work/ros-log
# No master is contacted by these options; a loopback URI keeps any attempt local.
export ROS_MASTER_URI=http://127.0.0.1:1
launch=(roslaunch keyplace relocalize.launch)

check "dump the parameters" timeout 60 "${launch[@]}" --dump-params map:=/maps/site.kpm \
  publish:=map_to_odom scan_topic:=/base_scan
cp "$work/out" "$work/params.yaml"  # check writes its own command's output to $work/out
check "the parameters of the arguments given" /usr/bin/python3 -c "
import sys, yaml
params = yaml.safe_load(open(sys.argv[1]))
node = '/keyplace_relocalize/'
assert params[node + 'map'] == '/maps/site.kpm', params
assert params[node + 'node/publish'] == 'map_to_odom', params
assert params[node + 'input/scan_topic'] == '/base_scan', params
assert params[node + 'preset'] == 'strict', params
assert params[node + 'config_file'] == '', params
# Arguments left empty set nothing: the node's configuration decides.
for key in ('node/odometry', 'node/map_frame', 'input/odom_topic', 'input/odom_frame',
            'input/base_frame'):
    assert node + key not in params, (key, params)
" "$work/params.yaml"
check "the node's command line" timeout 60 "${launch[@]}" --args /keyplace_relocalize \
  map:=/maps/site.kpm
cp "$work/out" "$work/args.txt"
check "the node is found in the package" grep -q "$share_dir/keyplace/keyplace_ros_relocalize" \
  "$work/args.txt"
# (--dump-params prints nothing and exits 0 without it; --args says what is missing.)
fails_with "the map is required" "requires the 'map' arg to be set" timeout 60 "${launch[@]}" \
  --args /keyplace_relocalize

# The SLAM node's launch file: the same rule, and its node found in the package too.
slam=(roslaunch keyplace slam.launch)
check "dump the SLAM parameters" timeout 60 "${slam[@]}" --dump-params map_path:=/maps/new.kpm \
  map_period:=2.5
cp "$work/out" "$work/slam_params.yaml"
check "the SLAM parameters of the arguments given" /usr/bin/python3 -c "
import sys, yaml
params = yaml.safe_load(open(sys.argv[1]))
node = '/keyplace_slam/'
assert params[node + 'node/map_path'] == '/maps/new.kpm', params
assert params[node + 'node/map_period_s'] == 2.5, params
assert params[node + 'preset'] == 'default', params
for key in ('node/odometry', 'input/scan_topic', 'input/base_frame'):
    assert node + key not in params, (key, params)
" "$work/slam_params.yaml"
check "the SLAM node's command line" timeout 60 "${slam[@]}" --args /keyplace_slam
cp "$work/out" "$work/slam_args.txt"
check "the SLAM node is found in the package" grep -q "$share_dir/keyplace/keyplace_ros_slam" \
  "$work/slam_args.txt"

# Beside AMCL: keyplace publishes /initialpose only, with odometry from the tf chain AMCL uses,
# and map_server serves the grid (AMCL and map_server themselves are not in Debian 12).
amcl=(roslaunch keyplace relocalize_amcl.launch)
check "dump the AMCL launch parameters" timeout 60 "${amcl[@]}" --dump-params \
  map:=/maps/site.kpm grid:=/maps/site.yaml base_frame:=base_footprint
cp "$work/out" "$work/amcl_params.yaml"
check "AMCL and keyplace agree on the frames" /usr/bin/python3 -c "
import sys, yaml
params = yaml.safe_load(open(sys.argv[1]))
keyplace, amcl = '/keyplace_relocalize/', '/amcl/'
assert params[keyplace + 'map'] == '/maps/site.kpm', params
assert params[keyplace + 'node/publish'] == 'initialpose', params
assert params[keyplace + 'node/odometry'] == 'tf', params
assert params[keyplace + 'input/base_frame'] == params[amcl + 'base_frame_id'] == 'base_footprint'
assert params[keyplace + 'input/odom_frame'] == params[amcl + 'odom_frame_id'] == 'odom'
assert params[keyplace + 'node/map_frame'] == params[amcl + 'global_frame_id'] == 'map'
assert params['/map_server/frame_id'] == 'map', params
" "$work/amcl_params.yaml"
check "keyplace's command line beside AMCL" timeout 60 "${amcl[@]}" --args \
  /keyplace_relocalize map:=/maps/site.kpm grid:=/maps/site.yaml
fails_with "the grid is required" "requires the 'grid' arg to be set" timeout 60 "${amcl[@]}" \
  --args /keyplace_relocalize map:=/maps/site.kpm

finish launch
