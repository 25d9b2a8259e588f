#!/usr/bin/env bash
# roslaunch keyplace relocalize.launch (ros/launch/relocalize.launch) as roslaunch reads it, without
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

finish launch
