#!/usr/bin/python3
"""keyplace_ros_relocalize live on ROS 1 (issue 33), loopback only.

A roscore on a private port, the node on a map of the first half of FR079 (the bundled corrected
log's scans 0:732, which end at raw scan 2465 of 4934), and `rosbag play --clock` of
../shared/data/fr079.orig.bag from that time on. The test subscribes to /initialpose and
/diagnostics and checks: /initialpose arrives; every published pose lies within 0.5 m and 10 deg
of the corrected pose of the nearest corrected scan; the status goes searching -> fixed;
~relocalize sends it back to searching; ~save_status writes the status, whose counts show that
every received scan was processed (at most one dropped, one waiting). It prints the per-scan
latency (mean, p99) and the real-time factor. Every process is started here, in its own process
group, and killed here by its id; every wait is bounded.

Usage: relocalize_live_test.py KEYPLACE_CLI NODE_BINARY SOURCE_DIR [--rate R] [--duration S]
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

MAP_SCANS = "0:732"     # corrected scans of the map: raw scans 0..2465, bag time up to 1743.1 s
PLAY_START_S = 532.0    # bag offset of raw scan 2466 (1743.6 s; the bag starts at 1211.52 s)
TOLERANCE_M = 0.5
TOLERANCE_DEG = 10.0


def main():
    args, bag, truth_log = live_arguments(10.0)

    work = tempfile.mkdtemp(prefix="keyplace_ros_live_")
    env = ros_environment(work)

    map_path = os.path.join(work, "first_half.kpm")
    subprocess.run([args.keyplace, "map", os.path.join(args.source_dir, "data",
                                                       "fr079-corrected.log.gz"),
                    "--scans", MAP_SCANS, "--out", map_path, "--threads", "1"],
                   check=True, stdout=subprocess.DEVNULL, timeout=120)

    processes = Processes(env, work)
    try:
        run(args, processes, env, work, map_path, bag, truth_log)
    finally:
        processes.stop_all()


def run(args, processes, env, work, map_path, bag, truth_log):
    start_roscore(processes, env)
    import rospy
    from geometry_msgs.msg import PoseWithCovarianceStamped
    from std_srvs.srv import Trigger

    status_path = os.path.join(work, "status.yaml")
    # Half a second of wall time for a scan's odometry to arrive, whatever the rate
    # (node.odometry_wait_s is in the stamps' time).
    node = processes.start("node", [
        args.node, "__name:=keyplace_relocalize", "_map:=" + map_path,
        "_set:=%s node.status_path=%s node.odometry_wait_s=%g" % (
            BAG_FIXES, status_path, args.rate * 0.5)])

    rospy.init_node("keyplace_live_test", anonymous=True, disable_signals=True)
    fixes = []
    rospy.Subscriber("/initialpose", PoseWithCovarianceStamped, fixes.append, queue_size=100)
    statuses = collect_statuses("keyplace_relocalize: relocalization")
    relocalize = rospy.ServiceProxy("/keyplace_relocalize/relocalize", Trigger)
    save_status = rospy.ServiceProxy("/keyplace_relocalize/save_status", Trigger)
    wait_for_service(relocalize, node, processes)
    time.sleep(0.5)  # the subscriptions connect

    play_started = time.monotonic()
    play = processes.start("rosbag_play", [
        "rosbag", "play", "--clock", "-q", "--wait-for-subscribers", "-r", str(args.rate),
        "-s", str(PLAY_START_S),
        "-u", str(args.duration), bag])
    wait_for(lambda: fixes or play.poll() is not None, args.duration / args.rate + 30,
             "/initialpose")
    assert fixes, "no /initialpose while the bag played:\n" + processes.log_of("node")
    wait_for(lambda: any(s["status"] == "fixed" for _, s in statuses), 10, "status fixed")

    asked_at = time.monotonic()
    answer = relocalize()
    assert answer.success, answer
    wait_for(lambda: any(t >= asked_at and s["status"] == "searching" for t, s in statuses), 10,
             "status searching after ~relocalize")

    wait_for(lambda: play.poll() is not None, args.duration / args.rate + 60, "rosbag play")
    play_wall_s = time.monotonic() - play_started
    time.sleep(1.5)  # the last scans
    saved = save_status()
    assert saved.success and saved.message == status_path, saved
    # The final counts come from ~save_status, written now: under simulated time the last
    # /diagnostics status is the one published before /clock stopped, possibly while the node
    # still waited for the odometry of the last scans.
    final = saved_status(status_path)

    check(fixes, statuses, final, truth_log, args, play_wall_s, asked_at)
    processes.stop(node)
    print(processes.log_of("node").splitlines()[-1])


def saved_status(path):
    """The top-level scalar fields of the status file ~save_status wrote."""
    with open(path) as status_file:
        text = status_file.read()
    assert text.startswith("status: "), path
    fields = {}
    for line in text.splitlines():
        key, _, value = line.partition(": ")
        if value and not value.startswith(("{", "[")):
            fields[key] = value
    return fields


def check(fixes, statuses, final, truth_log, args, play_wall_s, asked_at):
    truth = corrected_poses(truth_log)
    worst_m, worst_deg, worst_dt = 0.0, 0.0, 0.0
    for fix in fixes:
        stamp = fix.header.stamp.to_sec()
        t, x, y, theta = min(truth, key=lambda pose: abs(pose[0] - stamp))
        pose = fix.pose.pose
        yaw = 2.0 * math.atan2(pose.orientation.z, pose.orientation.w)
        error_m = math.hypot(pose.position.x - x, pose.position.y - y)
        error_deg = abs(math.degrees(math.remainder(yaw - theta, 2.0 * math.pi)))
        print("fix at %.3f: (%.3f, %.3f, %.1f deg), nearest corrected scan %.3f s away at "
              "(%.3f, %.3f, %.1f deg): %.3f m, %.2f deg off" % (
                  stamp, pose.position.x, pose.position.y, math.degrees(yaw), t - stamp, x, y,
                  math.degrees(theta), error_m, error_deg))
        assert fix.header.frame_id == "map"
        assert error_m < TOLERANCE_M and error_deg < TOLERANCE_DEG, "fix too far from the truth"
        covariance = fix.pose.covariance
        assert covariance[0] > 0 and covariance[7] > 0 and covariance[35] > 0, covariance
        worst_m, worst_deg = max(worst_m, error_m), max(worst_deg, error_deg)
        worst_dt = max(worst_dt, abs(t - stamp))
    sequence = [s["status"] for _, s in statuses]
    first_fixed = sequence.index("fixed")
    assert "searching" in sequence[:first_fixed], sequence[:first_fixed + 1]
    assert any(t >= asked_at and s["status"] == "searching" for t, s in statuses)
    last = final
    received, processed = int(last["scans_received"]), int(last["scans_processed"])
    dropped, waiting = int(last["scans_dropped"]), int(last["scans_waiting"])
    print("fixes published: %d (worst %.3f m, %.2f deg; truth at most %.3f s away)" % (
        len(fixes), worst_m, worst_deg, worst_dt))
    print("status sequence: %s" % " -> ".join(
        s for i, s in enumerate(sequence) if i == 0 or sequence[i - 1] != s))
    print("scans received %d, processed %d, dropped %d, waiting %d, answers %s" % (
        received, processed, dropped, waiting, last["answers"]))
    check_scans_and_latency(last, args, play_wall_s)

if __name__ == "__main__":
    main()
