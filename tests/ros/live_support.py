"""What the live ROS 1 tests share (tests/ros/*_live_test.py): a private loopback ROS
environment, a roscore on it with simulated time, processes started in their own sessions and
killed by id, bounded waits, and the corrected poses of the FR079 log as truth."""

import argparse
import gzip
import os
import signal
import socket
import subprocess
import time


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def corrected_poses(path):
    """(stamp, x, y, theta) of every ROBOTLASER1 line: its ipc_timestamp and its robot pose."""
    poses = []
    with gzip.open(path, "rt") as log:
        for line in log:
            fields = line.split()
            if not fields or fields[0] != "ROBOTLASER1":
                continue
            beams = int(fields[8])
            rest = fields[9 + beams:]
            remissions = int(rest[0])
            rest = rest[1 + remissions:]
            # laser x y theta, robot x y theta, tv rv forward side turn, ipc_timestamp ...
            robot = [float(v) for v in rest[3:6]]
            poses.append((float(rest[11]), robot[0], robot[1], robot[2]))
    return poses


class Processes:
    """Processes started by the test, each in its own session, killed by id at the end."""

    def __init__(self, env, log_dir):
        self.env = env
        self.log_dir = log_dir
        self.started = []

    def start(self, name, command):
        log = open(os.path.join(self.log_dir, name + ".log"), "w")
        process = subprocess.Popen(command, env=self.env, stdout=log, stderr=subprocess.STDOUT,
                                   start_new_session=True)
        self.started.append((name, process, log))
        return process

    def stop(self, process, timeout_s=10.0):
        if process.poll() is not None:
            return
        os.killpg(process.pid, signal.SIGINT)
        try:
            process.wait(timeout_s)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait(timeout_s)

    def stop_all(self):
        for _, process, log in reversed(self.started):
            self.stop(process)
            log.close()

    def log_of(self, name):
        with open(os.path.join(self.log_dir, name + ".log")) as log:
            return log.read()


def wait_for(condition, timeout_s, what):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if condition():
            return
        time.sleep(0.05)
    raise AssertionError("timed out after %.0f s waiting for %s" % (timeout_s, what))


# The bag's converter wrote the laser at x = +0.04 m and beams pi/359 apart; the log has -0.04 m
# and pi/360 (docs/ROS.md, "Checked against a real bag").
BAG_FIXES = "input.laser_pose=-0.04,0,0 input.scan_fov_rad=3.141592653589793"


def live_arguments(default_rate):
    """The live tests' command line (KEYPLACE_CLI NODE_BINARY SOURCE_DIR [--rate R]
    [--duration S]) and the shared data they play: (args, fr079.orig.bag, fr079-corrected.log.gz).
    Exits naming a file that is missing."""
    parser = argparse.ArgumentParser()
    parser.add_argument("keyplace")
    parser.add_argument("node")
    parser.add_argument("source_dir")
    parser.add_argument("--rate", type=float, default=default_rate)
    parser.add_argument("--duration", type=float, default=150.0, help="bag seconds played")
    args = parser.parse_args()
    shared = os.environ.get("KEYPLACE_SHARED", os.path.join(args.source_dir, "..", "shared"))
    bag = os.path.join(shared, "data", "fr079.orig.bag")
    truth_log = os.path.join(shared, "data", "fr079-corrected.log.gz")
    for path in (bag, truth_log):
        if not os.path.exists(path):
            raise SystemExit("missing " + path)
    return args, bag, truth_log


def ros_environment(work):
    """A ROS environment on a free loopback port with its home and logs under `work`; this
    process's own environment (for rospy) is set to it too."""
    env = dict(os.environ)
    env.update({"ROS_MASTER_URI": "http://127.0.0.1:%d" % free_port(), "ROS_IP": "127.0.0.1",
                "ROS_HOSTNAME": "127.0.0.1", "ROS_HOME": work,
                "ROS_LOG_DIR": os.path.join(work, "log")})
    os.environ.update(env)
    return env


def start_roscore(processes, env):
    """A roscore on env's port, online, with /use_sim_time set (rosbag play --clock)."""
    roscore = processes.start("roscore", ["roscore", "-p", env["ROS_MASTER_URI"].split(":")[-1]])
    import rosgraph  # after the environment names the private master

    master = rosgraph.Master("/keyplace_live_test")
    wait_for(lambda: master.is_online() or roscore.poll() is not None, 30, "roscore")
    assert roscore.poll() is None, processes.log_of("roscore")
    master.setParam("/use_sim_time", True)
    return roscore


def collect_statuses(status_name):
    """Subscribes to /diagnostics; returns the list the statuses named `status_name` (suffix) are
    appended to, as (wall time, {key: value}) in arrival order."""
    import rospy
    from diagnostic_msgs.msg import DiagnosticArray

    statuses = []

    def on_diagnostics(message):
        for status in message.status:
            if status.name.endswith(status_name):
                statuses.append((time.monotonic(),
                                 {entry.key: entry.value for entry in status.values}))

    rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics, queue_size=1000)
    return statuses


def wait_for_service(service, node, processes):
    """Waits (30 s at most) until the node offers `service` (a rospy.ServiceProxy); fails with the
    node's log if it exits first."""
    import rospy

    def node_up():
        try:
            service.wait_for_service(0.2)
            return True
        except rospy.ROSException:
            return node.poll() is not None

    wait_for(node_up, 30, "the node's services")
    assert node.poll() is None, processes.log_of("node")


SCAN_RATE_HZ = 4934 / 1061.7  # fr079.orig.bag: 4934 scans over 1061.7 s


def check_scans_and_latency(last, args, play_wall_s):
    """Prints the node's per-scan latency and the real-time factors from its last status, and
    checks that it received the played scans and processed every one: rosbag play starts /scan
    and /odom at the same instant, so the first scan may precede the first odometry message
    (dropped, as it has no pose), and rosbag play may stop after a scan whose odometry it never
    plays (left waiting)."""
    received, processed = int(last["scans_received"]), int(last["scans_processed"])
    dropped, waiting = int(last["scans_dropped"]), int(last["scans_waiting"])
    mean_s, p99_s = float(last["latency_mean_s"]), float(last["latency_p99_s"])
    print("per-scan latency: mean %.1f ms, p99 %.1f ms, max %.1f ms" % (
        1e3 * mean_s, 1e3 * p99_s, 1e3 * float(last["latency_max_s"])))
    print("bag played at %.1fx: %.0f bag s in %.1f wall s (%.1fx real time); the node's mean "
          "latency allows %.1fx, its p99 %.1fx" % (
              args.rate, args.duration, play_wall_s, args.duration / play_wall_s,
              1.0 / (SCAN_RATE_HZ * mean_s), 1.0 / (SCAN_RATE_HZ * p99_s)))
    expected = SCAN_RATE_HZ * args.duration
    assert received > 0.9 * expected, (received, expected)
    assert dropped <= 1 and waiting <= 1, "the node dropped scans"
    assert processed + dropped + waiting == received, (processed, dropped, waiting, received)
