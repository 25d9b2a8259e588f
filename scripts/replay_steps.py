#!/usr/bin/env python3
"""Replays the steps of `keyplace odometry --steps` under a rule that says, step by step, whether
the ICP estimate or the wheel odometry moves the robot, and scores the replayed trajectory on a
Kümmerle relation file (mean translational error, all / local / loop).

It answers "would my log be better off with the odometry here?" without running ICP again. The
local map is not rebuilt, so a rule that changes many steps is only approximated: ICP would have
registered later scans against a different map. With --rule icp the replay is the ICP trajectory
of `keyplace odometry --out`, and its errors are those `keyplace odometry --relations` prints.

Usage: replay_steps.py STEPS.tsv [--relations FILE] [--rule RULE] [--local-dt S] [--tolerance S]
                       [--out FILE]
Rules:
  icp                  every step as ICP estimated it (the default)
  odometry             every step as the odometry measured it (raw odometry)
  inlier-below:R       the odometry where ICP converged with an inlier ratio below R
  blend:KT,KR          odometry + KT * (ICP - odometry) in translation, KR in rotation
  blend:KX,KY,KR       the same with one gain along the robot's axis, one across it
Steps without odometry always take the ICP step.
Exit status: 0 done, 1 bad input (named with its line), 2 usage.
"""

import argparse
import bisect
import math
import os
import sys

STEP_COLUMNS = 15
CONVERGED = ("registered", "recovered")


class InputError(Exception):
    pass


def wrap(angle):
    return math.atan2(math.sin(angle), math.cos(angle))


def compose(pose, step):
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return (pose[0] + c * step[0] - s * step[1], pose[1] + s * step[0] + c * step[1],
            wrap(pose[2] + step[2]))


def between(a, b):
    dx, dy = b[0] - a[0], b[1] - a[1]
    c, s = math.cos(a[2]), math.sin(a[2])
    return (c * dx + s * dy, -s * dx + c * dy, wrap(b[2] - a[2]))


def text_lines(path):
    """The lines of a text file; InputError naming the file when it is not UTF-8 text."""
    try:
        with open(path, encoding="utf-8") as file:
            return file.read().splitlines(keepends=True)
    except UnicodeDecodeError as error:
        raise InputError(f"{path}: not a text file (byte {error.start}: {error.reason})") from None


def read_steps(path):
    steps = []
    for number, line in enumerate(text_lines(path), start=1):
        if line.startswith("#") or not line.strip():
            continue
        fields = line.rstrip("\n").split("\t")
        if len(fields) != STEP_COLUMNS:
            raise InputError(f"{path}:{number}: {len(fields)} columns, expected "
                             f"{STEP_COLUMNS} (keyplace odometry --steps)")
        try:
            icp = tuple(float(v) for v in fields[7:10])
            odometry = tuple(float(v) for v in fields[10:13])
            steps.append({"stamp": float(fields[1]), "status": fields[2],
                          "inlier_ratio": float(fields[3]), "icp": icp,
                          "odometry": None if math.isnan(odometry[0]) else odometry})
        except ValueError as error:
            raise InputError(f"{path}:{number}: {error}") from None
    if not steps:
        raise InputError(f"{path}: no steps")
    return steps


def parse_rule(text):
    name, _, argument = text.partition(":")
    try:
        if name in ("icp", "odometry") and not argument:
            return name, ()
        if name == "inlier-below":
            return name, (float(argument),)
        if name == "blend":
            gains = tuple(float(v) for v in argument.split(","))
            if len(gains) == 2:
                return name, (gains[0], gains[0], gains[1])
            if len(gains) == 3:
                return name, gains
    except ValueError:
        pass
    raise argparse.ArgumentTypeError(f"unknown rule {text!r} (icp, odometry, inlier-below:R, "
                                     "blend:KT,KR, blend:KX,KY,KR)")


def chosen_step(step, rule):
    name, arguments = rule
    icp, odometry = step["icp"], step["odometry"]
    if odometry is None or name == "icp":
        return icp
    if name == "odometry":
        return odometry
    if name == "inlier-below":
        converged = step["status"] in CONVERGED
        return odometry if converged and step["inlier_ratio"] < arguments[0] else icp
    k_x, k_y, k_rotation = arguments
    return (odometry[0] + k_x * (icp[0] - odometry[0]), odometry[1] + k_y * (icp[1] - odometry[1]),
            odometry[2] + k_rotation * wrap(icp[2] - odometry[2]))


def replay(steps, rule):
    poses = [(0.0, 0.0, 0.0)]
    for step in steps[1:]:
        poses.append(compose(poses[-1], chosen_step(step, rule)))
    return poses


def relation_errors(steps, poses, path, local_dt_s, tolerance_s):
    order = sorted(range(len(steps)), key=lambda k: steps[k]["stamp"])
    stamps = [steps[k]["stamp"] for k in order]

    def nearest(stamp):
        # The scan with the nearest stamp within the tolerance; a tie goes to the earlier one.
        i = bisect.bisect_left(stamps, stamp)
        best = None
        for j in (i - 1, i):
            if 0 <= j < len(stamps) and abs(stamps[j] - stamp) <= tolerance_s:
                if best is None or abs(stamps[j] - stamp) < abs(stamps[best] - stamp):
                    best = j
        return None if best is None else order[best]

    local, loop, relations = [], [], 0
    for number, line in enumerate(text_lines(path), start=1):
        if line.lstrip().startswith("#") or not line.strip():
            continue
        fields = line.split()
        try:
            if len(fields) < 8:
                raise ValueError
            t_a, t_b, dx, dy = (float(v) for v in fields[:4])
        except ValueError:
            raise InputError(f"{path}:{number}: not a relation (t_a t_b x y z roll pitch "
                             "yaw)") from None
        relations += 1
        a, b = nearest(t_a), nearest(t_b)
        if a is None or b is None:
            continue
        estimate = between(poses[a], poses[b])
        error = math.hypot(estimate[0] - dx, estimate[1] - dy)
        (local if abs(t_b - t_a) < local_dt_s else loop).append(error)
    return relations, local, loop


def write_poses(path, steps, poses):
    # Written beside the target and renamed into place: an interrupted run leaves any earlier
    # file whole.
    temporary = f"{path}.tmp-{os.getpid()}"
    try:
        with open(temporary, "w", encoding="utf-8") as out:
            out.write("# timestamp_s\tx_m\ty_m\ttheta_rad\n")
            for step, pose in zip(steps, poses):
                out.write(f"{step['stamp']:.6f}\t{pose[0]:.6f}\t{pose[1]:.6f}\t{pose[2]:.6f}\n")
        os.replace(temporary, path)
    finally:
        if os.path.exists(temporary):
            os.remove(temporary)


def mean(values):
    return sum(values) / len(values) if values else float("nan")


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("steps", help="the TSV of keyplace odometry --steps")
    parser.add_argument("--relations", help="Kümmerle relation file to score the replay on")
    parser.add_argument("--rule", type=parse_rule, default=("icp", ()),
                        help="which step moves the robot (see above; default icp)")
    parser.add_argument("--local-dt", type=float, default=5.0,
                        help="relations shorter than this (s) are local (default 5)")
    parser.add_argument("--tolerance", type=float, default=1e-4,
                        help="a relation stamp matches the nearest scan stamp within this (s; "
                             "default 1e-4, as evaluation.relation_stamp_tolerance_s)")
    parser.add_argument("--out", help="write the replayed poses (timestamp_s x_m y_m theta_rad)")
    options = parser.parse_args()
    try:
        steps = read_steps(options.steps)
        poses = replay(steps, options.rule)
        changed = sum(1 for step in steps[1:]
                      if max(abs(a - b) for a, b in zip(chosen_step(step, options.rule),
                                                        step["icp"])) > 1e-12)
        print(f"replayed {len(steps)} scans; {changed} steps differ from ICP")
        if options.out:
            write_poses(options.out, steps, poses)
        if options.relations:
            relations, local, loop = relation_errors(steps, poses, options.relations,
                                                     options.local_dt, options.tolerance)
            matched = len(local) + len(loop)
            print(f"relations matched {matched} of {relations}: all {mean(local + loop):.4f} m, "
                  f"local {mean(local):.4f} m ({len(local)}), loop {mean(loop):.4f} m "
                  f"({len(loop)})")
    except (OSError, InputError) as error:
        print(f"replay_steps: {error}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
