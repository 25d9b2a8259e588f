"""keyplace.build_grid against the map_server files `keyplace map --grid` and `keyplace slam --grid`
write, on the first 300 scans of the bundled log; keyplace.InitialPose and
RelocalizationUpdate.initial_pose against the message's documented fields."""

import json
import math
import os
import tempfile
import unittest

import numpy as np

import keyplace
from support import run_cli, write_log_part

SCANS = 300


def read_pgm(path):
    """Width, height and pixels (H x W uint8) of a binary PGM, read here without the library."""
    with open(path, "rb") as stream:
        data = stream.read()
    fields, at = [], 0
    while len(fields) < 4:
        while data[at:at + 1].isspace():
            at += 1
        if data[at:at + 1] == b"#":
            at = data.index(b"\n", at) + 1
            continue
        end = at
        while not data[end:end + 1].isspace():
            end += 1
        fields.append(data[at:end])
        at = end
    assert fields[0] == b"P5" and fields[3] == b"255", fields
    width, height = int(fields[1]), int(fields[2])
    pixels = np.frombuffer(data[at + 1:], dtype=np.uint8)
    return width, height, pixels.reshape(height, width)


class GridTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = tempfile.TemporaryDirectory()
        cls.log_path = write_log_part(cls.work.name, SCANS)
        os.mkdir(os.path.join(cls.work.name, "cli"))
        os.mkdir(os.path.join(cls.work.name, "py"))
        cls.cli_yaml = os.path.join(cls.work.name, "cli", "grid.yaml")
        run_cli("map", cls.log_path, "--grid", cls.cli_yaml)
        cls.grid = keyplace.build_grid(cls.log_path)

    @classmethod
    def tearDownClass(cls):
        cls.work.cleanup()

    def test_image_equals_the_pgm_the_cli_wrote(self):
        width, height, pixels = read_pgm(os.path.join(self.work.name, "cli", "grid.pgm"))
        self.assertEqual((self.grid.width, self.grid.height), (width, height))
        self.assertEqual(self.grid.image.shape, (height, width))
        self.assertEqual(self.grid.image.dtype, np.uint8)
        np.testing.assert_array_equal(self.grid.image, pixels)
        self.assertEqual(set(np.unique(pixels)), {0, 205, 254})

    def test_written_files_equal_the_clis(self):
        yaml_path = os.path.join(self.work.name, "py", "grid.yaml")
        image_path = self.grid.write_map_server(yaml_path)
        self.assertEqual(image_path, os.path.join(self.work.name, "py", "grid.pgm"))
        for name in ("grid.yaml", "grid.pgm"):
            with open(os.path.join(self.work.name, "cli", name), "rb") as cli, \
                    open(os.path.join(self.work.name, "py", name), "rb") as mine:
                self.assertEqual(mine.read(), cli.read(), name)
        read = keyplace.read_map_server(self.cli_yaml)
        np.testing.assert_array_equal(read.image, self.grid.image)
        self.assertEqual(read.resolution_m, self.grid.resolution_m)
        np.testing.assert_array_equal(read.origin[:2], self.grid.origin_m)
        self.assertEqual(read.mode, "trinary")

    def test_arrays_are_in_the_images_order_and_the_map_frame(self):
        grid = self.grid
        probabilities, observed, image = grid.probabilities, grid.observed, grid.image
        self.assertEqual(probabilities.shape, image.shape)
        # The default thresholds classify the cells: occupied >= 0.65, free <= 0.196.
        np.testing.assert_array_equal(image == 0, observed & (probabilities >= 0.65))
        np.testing.assert_array_equal(image == 254, observed & (probabilities <= 0.196))
        self.assertTrue(np.all(probabilities[~observed] == 0.5))
        # Half a metre ahead of the robot, where its laser looks, is free space at (almost) every
        # corrected pose: row 0 is the top (largest y), column 0 the smallest x.
        poses = keyplace.read_log(self.log_path).corrected_poses
        ahead = poses[:, :2] + 0.5 * np.column_stack([np.cos(poses[:, 2]), np.sin(poses[:, 2])])
        columns = np.floor((ahead[:, 0] - grid.origin_m[0]) / grid.resolution_m).astype(int)
        rows = grid.height - 1 - np.floor((ahead[:, 1] - grid.origin_m[1]) /
                                          grid.resolution_m).astype(int)
        self.assertGreater(np.mean(image[rows, columns] == 254), 0.95)
        # Upside down or mirrored, far fewer of those cells are free (0.55 and 0.34 measured).
        self.assertLess(np.mean(image[::-1][rows, columns] == 254), 0.8)
        self.assertLess(np.mean(image[:, ::-1][rows, columns] == 254), 0.8)

    def test_slam_grid_equals_the_clis(self):
        cli_yaml = os.path.join(self.work.name, "cli", "slam.yaml")
        run_cli("slam", self.log_path, "--grid", cli_yaml)
        run, _ = keyplace.slam(self.log_path)
        grid = keyplace.build_grid(self.log_path, slam_run=run)
        _, _, pixels = read_pgm(os.path.join(self.work.name, "cli", "slam.pgm"))
        np.testing.assert_array_equal(grid.image, pixels)
        with self.assertRaisesRegex(ValueError, "slam_run was run on 300 scans"):
            keyplace.build_grid(self.log_path, slam_run=run, scans=(0, 100))
        with self.assertRaisesRegex(ValueError, "not both"):
            keyplace.build_grid(self.log_path, slam_run=run, poses="corrected")

    def test_settings_and_bad_inputs(self):
        coarse = keyplace.build_grid(self.log_path, overrides={"grid.resolution_m": 0.1})
        self.assertEqual(coarse.resolution_m, 0.1)
        self.assertLess(abs(coarse.width * 2 - self.grid.width), 4)
        with self.assertRaisesRegex(ValueError, "grid.max_cells"):
            keyplace.build_grid(self.log_path, overrides={"grid.max_cells": 1000})
        with self.assertRaisesRegex(RuntimeError, "no-such-dir"):
            self.grid.write_map_server(os.path.join(self.work.name, "no-such-dir", "g.yaml"))

    def test_write_map_server_refuses_the_log_it_was_built_from(self):
        # Issue 31: the Python writers protect their inputs as the CLI does, under any name.
        with open(self.log_path, "rb") as stream:
            before = stream.read()
        yaml_alias = os.path.join(self.work.name, "log-alias.yaml")
        os.symlink(self.log_path, yaml_alias)
        for target in (yaml_alias,):
            with self.assertRaisesRegex(ValueError, "would destroy the input"):
                self.grid.write_map_server(target)
        image_alias = os.path.join(self.work.name, "image-alias.pgm")
        os.link(self.log_path, image_alias)
        with self.assertRaisesRegex(ValueError, "image-alias.pgm: is the input"):
            self.grid.write_map_server(os.path.join(self.work.name, "image-alias.yaml"))
        with open(self.log_path, "rb") as stream:
            self.assertEqual(stream.read(), before)
        self.assertFalse(os.path.exists(os.path.join(self.work.name, "image-alias.yaml")))


class InitialPoseTest(unittest.TestCase):
    def test_message_fields(self):
        xy_yaw = np.array([[0.04, 0.01, 0.002], [0.01, 0.03, -0.001], [0.002, -0.001, 0.01]])
        pose = keyplace.InitialPose([1.5, -2.0, 0.5], pose_covariance=xy_yaw)
        message = json.loads(pose.to_json())
        self.assertEqual(message["header"]["frame_id"], "map")
        position = message["pose"]["pose"]["position"]
        self.assertEqual((position["x"], position["y"], position["z"]), (1.5, -2.0, 0.0))
        q = message["pose"]["pose"]["orientation"]
        self.assertAlmostEqual(2 * math.atan2(q["z"], q["w"]), 0.5, places=12)
        # The (x, y, yaw) block in rows and columns 0, 1 and 5 of x, y, z, roll, pitch, yaw.
        expected = np.zeros((6, 6))
        expected[np.ix_([0, 1, 5], [0, 1, 5])] = xy_yaw
        np.testing.assert_array_equal(pose.pose_covariance, xy_yaw)
        np.testing.assert_array_equal(pose.covariance, expected)
        np.testing.assert_array_equal(np.reshape(message["pose"]["covariance"], (6, 6)), expected)
        self.assertIn("frame_id: map", pose.to_yaml())
        with tempfile.TemporaryDirectory() as folder:
            for name, text in (("fix.yaml", pose.to_yaml()), ("fix.json", pose.to_json())):
                path = os.path.join(folder, name)
                pose.write(path)
                with open(path) as stream:
                    self.assertEqual(stream.read(), text)
        with self.assertRaisesRegex(ValueError, "not a ROS frame name"):
            keyplace.InitialPose([0, 0, 0], frame_id="my map").to_yaml()
        # Issue 31: refused when made, as the docs say, not only when written.
        with self.assertRaisesRegex(ValueError, "frame id 'bad name!' is not a ROS frame name"):
            keyplace.InitialPose([0, 0, 0], frame_id="bad name!")
        with self.assertRaisesRegex(ValueError, r"'a\\0b' is not a ROS frame name"):
            keyplace.InitialPose([0, 0, 0], frame_id="a\0b")
        with self.assertRaisesRegex(ValueError, "pose"):
            keyplace.InitialPose([0, 0])
        with self.assertRaisesRegex(ValueError, "covariance"):
            keyplace.InitialPose([0, 0, 0], pose_covariance=np.zeros((2, 2)))
        np.testing.assert_array_equal(keyplace.InitialPose([0, 0, 0]).pose_covariance,
                                      np.zeros((3, 3)))

    def test_relocalizer_fix_as_initial_pose(self):
        with tempfile.TemporaryDirectory() as folder:
            log_path = write_log_part(folder, SCANS)
            map_path = os.path.join(folder, "map.kpm")
            run_cli("map", log_path, "--out", map_path)
            relocalizer = keyplace.Relocalizer(map_path)
            fixed = None
            for scan in keyplace.read_log(log_path).scans:
                update = relocalizer.add_scan(scan, scan.corrected_pose)
                if update.status == "fixed":
                    fixed = update
                    break
                with self.assertRaisesRegex(ValueError, "needs a fix"):
                    update.initial_pose()
        self.assertIsNotNone(fixed)
        pose = fixed.initial_pose(frame_id="world")
        self.assertEqual(pose.frame_id, "world")
        np.testing.assert_array_equal(pose.pose, fixed.pose)
        # The covariance derived from the matches: symmetric, positive definite, decimetres at
        # most, and the fix's own answer's (PlaceMatch) with the map's error added.
        np.testing.assert_array_equal(pose.pose_covariance, fixed.covariance)
        np.testing.assert_allclose(fixed.covariance, fixed.covariance.T, atol=1e-15)
        self.assertTrue((np.linalg.eigvalsh(fixed.covariance) > 0).all())
        self.assertLess(fixed.covariance[0, 0], 0.5 ** 2)
        # The answer judged last made the fix: a search of the whole map's when one came too.
        made_fix = fixed.map_search_answer if fixed.map_search_answer is not None else fixed.answer
        match_covariance = made_fix.match.estimated_pose_covariance
        self.assertGreater(match_covariance[0, 0], 0)
        map_error = np.diag([0.03 ** 2, 0.03 ** 2, math.radians(0.3) ** 2])  # localization.fix
        np.testing.assert_allclose(fixed.covariance, match_covariance + map_error, rtol=1e-12)


if __name__ == "__main__":
    unittest.main()
