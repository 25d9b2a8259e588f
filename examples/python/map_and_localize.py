"""Map the bundled log, localize in the map, and draw both (notebook style: run it whole, or
cell by cell in an editor that knows `# %%` cells).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/map_and_localize.py [OUT_DIR [SCANS]]

Writes OUT_DIR/map.kpm and OUT_DIR/map_and_localize.png (default OUT_DIR: the current folder).
SCANS: stream only the first SCANS scans through the localizer (default: all; the test: 250).
"""

# %% Setup: the module, numpy, matplotlib without a display.
import math
import os
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after choosing the backend)
import numpy as np  # noqa: E402

import keyplace  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
LOG = os.path.join(HERE, "..", "..", "data", "fr079-corrected.log.gz")
OUT = sys.argv[1] if len(sys.argv) > 1 else "."
STREAM_SCANS = int(sys.argv[2]) if len(sys.argv) > 2 else None
os.makedirs(OUT, exist_ok=True)

# %% Read the log: 1464 scans of 360 beams, each with its SLAM-corrected pose.
log = keyplace.read_log(LOG)
print(f"log: {len(log)} scans, corrected poses: {log.corrected}")

# %% Build the map of stable keypoints (the defaults of `keyplace map`) and save it.
start = time.perf_counter()
world_map = keyplace.build_map(LOG)
stats = world_map.stats()
print(f"map: {world_map.submap_count} submaps, {world_map.keypoint_count} stable keypoints, "
      f"compression {stats.compression:.3f}, {time.perf_counter() - start:.1f} s")
world_map.save(os.path.join(OUT, "map.kpm"))

# %% Stream the scans through the GlobalLocalizer as a robot would. The corrected poses stand in
# for odometry; a fix is correct within 0.5 m and 10 degrees of the corrected pose. These are the
# scans the map was made from: docs/RESULTS.md has other recordings and time splits.
localizer = keyplace.GlobalLocalizer(world_map)
fixes, correct = [], []
for scan in log.scans[:STREAM_SCANS]:
    answer = localizer.add_scan(scan, scan.corrected_pose)
    if answer is not None and answer.found:
        truth = scan.corrected_pose
        error_m = np.hypot(*(answer.pose[:2] - truth[:2]))
        error_deg = abs(math.degrees(math.remainder(answer.pose[2] - truth[2], 2 * math.pi)))
        fixes.append(answer.pose)
        correct.append(error_m <= 0.5 and error_deg <= 10.0)
fixes, correct = np.array(fixes), np.array(correct)
print(f"streaming: {len(fixes)} fixes, {correct.sum()} correct")

# %% The evaluation `keyplace localize` runs: 100 query submaps, precision and recall.
evaluation = keyplace.localize(LOG, world_map, n_pos=100)
print(f"localize: precision {evaluation.precision:.3f}, recall {evaluation.recall:.3f} "
      f"({evaluation.n_cor} of {evaluation.n_pos} queries)")

# %% Draw the trajectory, the stable keypoints in the world, the submap origins and the fixes.
figure, axes = plt.subplots(figsize=(9, 9))
trajectory = log.corrected_poses
axes.plot(trajectory[:, 0], trajectory[:, 1], color="0.6", linewidth=0.8, label="trajectory")
for submap in world_map.submaps:
    x, y, theta = submap.origin
    rotation = np.array([[math.cos(theta), -math.sin(theta)], [math.sin(theta), math.cos(theta)]])
    world = submap.keypoint_positions_m @ rotation.T + [x, y]
    axes.scatter(world[:, 0], world[:, 1], s=1, color="tab:blue", alpha=0.4)
origins = world_map.origins
axes.scatter(origins[:, 0], origins[:, 1], s=12, marker="s", color="tab:orange", zorder=3,
             label=f"submap origins ({world_map.submap_count})")
if len(fixes):
    axes.scatter(fixes[correct, 0], fixes[correct, 1], s=40, facecolors="none",
                 edgecolors="tab:green", label=f"correct fixes ({correct.sum()})")
    axes.scatter(fixes[~correct, 0], fixes[~correct, 1], s=40, marker="x", color="tab:red",
                 label=f"wrong fixes ({(~correct).sum()})")
axes.scatter([], [], s=4, color="tab:blue", label=f"stable keypoints ({world_map.keypoint_count})")
axes.set_aspect("equal")
axes.set_xlabel("x (m)")
axes.set_ylabel("y (m)")
axes.set_title(f"FR079: map and localization (precision {evaluation.precision:.2f}, "
               f"recall {evaluation.recall:.2f})")
axes.legend(loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=3, fontsize=8)
png = os.path.join(OUT, "map_and_localize.png")
figure.savefig(png, dpi=110, bbox_inches="tight")
print(f"figure: {png}")
