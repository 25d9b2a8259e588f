#!/usr/bin/python3
"""keyplace_ros_slam live on ROS 1 (issue 33), loopback only.

A roscore on a private port, the SLAM node, and `rosbag play --clock` of the first bag seconds of
../shared/data/fr079.orig.bag. The test subscribes to /map and /diagnostics and checks: /map
arrives in the map frame with walls in it; the node processes every scan it receives (bar the
first, which may precede the first odometry, and the last, whose odometry may never come); its
pose, aligned with the corrected trajectory at the first scan, stays within 1 m of the corrected
pose of the nearest scan; ~save_map writes a map that `keyplace info --check` accepts and a
map_server grid. It prints the per-scan latency (mean, p99) and the real-time factor. Every
process is started here, in its own session, and killed here by its id; every wait is bounded.

Usage: slam_live_test.py KEYPLACE_CLI NODE_BINARY SOURCE_DIR [--rate R] [--duration S]
"""

import math
import os
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from live_support import (BAG_FIXES, Processes, check_scans_and_latency,  # noqa: E402
                          collect_statuses, corrected_poses, live_arguments, ros_environment, start_roscore,
                          wait_for, wait_for_service)

TOLERANCE_M = 1.0


def main():
    args, bag, truth_log = live_arguments(5.0)
    work = tempfile.mkdtemp(prefix="keyplace_ros_slam_")
    env = ros_environment(work)
    processes = Processes(env, work)
    try:
        run(args, processes, work, bag, truth_log)
    finally:
        processes.stop_all()


def run(args, processes, work, bag, truth_log):
    start_roscore(processes, processes.env)
    import rospy
    from nav_msgs.msg import OccupancyGrid
    from std_srvs.srv import Trigger

    map_path = os.path.join(work, "site.kpm")
    # Half a second of wall time for a scan's odometry to arrive, whatever the rate
    # (node.odometry_wait_s is in the stamps' time); /map every 10 bag seconds.
    node = processes.start("node", [
        args.node, "__name:=keyplace_slam",
        "_set:=%s node.map_path=%s node.odometry_wait_s=%g node.map_period_s=10" % (
            BAG_FIXES, map_path, args.rate * 0.5)])

    rospy.init_node("keyplace_slam_live_test", anonymous=True, disable_signals=True)
    maps = []
    rospy.Subscriber("/map", OccupancyGrid, maps.append, queue_size=10)
    statuses = collect_statuses("keyplace_slam: slam")
    save_map = rospy.ServiceProxy("/keyplace_slam/save_map", Trigger)
    wait_for_service(save_map, node, processes)
    early = save_map()
    assert not early.success and "no submap completed yet" in early.message, early
    time.sleep(0.5)  # the subscriptions connect

    play_started = time.monotonic()
    play = processes.start("rosbag_play", [
        "rosbag", "play", "--clock", "-q", "--wait-for-subscribers", "-r", str(args.rate),
        "-u", str(args.duration), bag])
    wait_for(lambda: play.poll() is not None, args.duration / args.rate + 60, "rosbag play")
    play_wall_s = time.monotonic() - play_started
    time.sleep(1.5)  # the last scans and one more status
    assert maps, "no /map while the bag played:\n" + processes.log_of("node")
    # Every /map the node reports has arrived (under simulated time /clock stops with rosbag
    # play, so no later one comes from the node's clock).
    wait_for(lambda: statuses and maps and
             int(statuses[-1][1]["maps_published"]) == len(maps), 15, "the last /map")

    saved = save_map()
    assert saved.success, saved
    kpm_path, grid_path = saved.message.split()
    assert kpm_path == map_path, saved
    check = subprocess.run([args.keyplace, "info", "--check", kpm_path], capture_output=True,
                           text=True, timeout=60)
    assert check.returncode == 0, check.stdout + check.stderr
    assert os.path.exists(grid_path) and os.path.exists(grid_path[:-len(".yaml")] + ".pgm")
    print("~save_map: %s (keyplace info --check: exit 0), %s" % (kpm_path, grid_path))

    check_map(maps[-1])
    check_status(statuses, truth_log, args, play_wall_s)
    processes.stop(node)
    print(processes.log_of("node").splitlines()[-1])


def check_map(grid):
    assert grid.header.frame_id == "map", grid.header
    assert abs(grid.info.resolution - 0.05) < 1e-6, grid.info
    cells = grid.info.width * grid.info.height
    assert len(grid.data) == cells, (len(grid.data), cells)
    occupied = sum(1 for value in grid.data if value == 100)
    free = sum(1 for value in grid.data if value == 0)
    unknown = sum(1 for value in grid.data if value == -1)
    assert occupied + free + unknown == cells
    print("/map: %d x %d cells of %.2f m: %d occupied, %d free, %d unknown" % (
        grid.info.width, grid.info.height, grid.info.resolution, occupied, free, unknown))
    assert occupied > 1000 and free > 10 * occupied, (occupied, free)


def check_status(statuses, truth_log, args, play_wall_s):
    last = statuses[-1][1]
    received, processed = int(last["scans_received"]), int(last["scans_processed"])
    dropped, waiting = int(last["scans_dropped"]), int(last["scans_waiting"])
    print("scans received %d, processed %d, dropped %d, waiting %d; %s submaps, %s loops used, "
          "%s maps published (the last took %.0f ms)" % (
              received, processed, dropped, waiting, last["submaps"], last["loops_used"],
              last["maps_published"], 1e3 * float(last["last_map_seconds"])))
    check_scans_and_latency(last, args, play_wall_s)
    assert int(last["submaps"]) >= 3, last

    # The SLAM frame is the odometry frame of the first scan; the corrected trajectory's frame
    # differs by a rigid motion: align them at the first status with a pose.
    truth = corrected_poses(truth_log)
    poses = [(float(s["last_scan_stamp"]), float(s["x"]), float(s["y"]), float(s["theta"]))
             for _, s in statuses if int(s["scans_processed"]) > 0]
    first = poses[0]
    anchor = min(truth, key=lambda pose: abs(pose[0] - first[0]))
    rotation = anchor[3] - first[3]
    cos_r, sin_r = math.cos(rotation), math.sin(rotation)
    worst_m, worst_dt = 0.0, 0.0
    for stamp, x, y, _ in poses:
        dx, dy = x - first[1], y - first[2]
        aligned = (anchor[1] + cos_r * dx - sin_r * dy, anchor[2] + sin_r * dx + cos_r * dy)
        t, tx, ty, _ = min(truth, key=lambda pose: abs(pose[0] - stamp))
        error_m = math.hypot(aligned[0] - tx, aligned[1] - ty)
        worst_m, worst_dt = max(worst_m, error_m), max(worst_dt, abs(t - stamp))
    print("SLAM pose vs corrected (aligned at the first scan): worst %.3f m over %d statuses "
          "(truth at most %.3f s away)" % (worst_m, len(poses), worst_dt))
    assert worst_m < TOLERANCE_M, worst_m


if __name__ == "__main__":
    main()
