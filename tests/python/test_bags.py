"""keyplace.read_log on bags: the committed ROS 2 fixtures (tests/data/ros2, written by other
projects' writers from the first 150 scans of the raw FR079 log) and the real ROS 1 bag of the
shared data give the scans of the CARMEN logs they were made from, and what the keyplace
command reads in them."""

import json
import math
import os
import tempfile
import unittest

import numpy as np

import keyplace
from support import SOURCE_DIR, run_cli

ROS2 = os.path.join(SOURCE_DIR, "tests", "data", "ros2")
SLICE = os.path.join(ROS2, "fr079-raw-first150.log.gz")
SHARED_DATA = os.path.join(os.environ.get("KEYPLACE_SHARED",
                                          os.path.join(SOURCE_DIR, "..", "shared")), "data")


def assert_same_scans(test, bag, log, odometry_atol, stamp_atol=0.0):
    """Ranges equal as float32 (bags hold float32), valid flags equal, stamps within
    `stamp_atol`, bearings within 1e-6 rad (float32 angle_min / increment), odometry within
    `odometry_atol`."""
    test.assertEqual(len(bag), len(log))
    np.testing.assert_allclose(bag.timestamps_s, log.timestamps_s, rtol=0, atol=stamp_atol)
    for index in range(len(log)):
        b, c = bag[index], log[index]
        np.testing.assert_array_equal(b.ranges.astype(np.float32), c.ranges.astype(np.float32))
        np.testing.assert_array_equal(b.valid, c.valid)
        np.testing.assert_allclose(b.angles_rad, c.angles_rad, atol=1e-6)
    odometry_bag, odometry_log = bag.odometry_poses, log.odometry_poses
    np.testing.assert_allclose(odometry_bag[:, :2], odometry_log[:, :2], atol=odometry_atol)
    heading = np.remainder(odometry_bag[:, 2] - odometry_log[:, 2] + math.pi, 2 * math.pi) - math.pi
    np.testing.assert_allclose(heading, 0.0, atol=odometry_atol)


class Ros2BagTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.slice = keyplace.read_log(SLICE)

    def test_every_storage_gives_the_scans_of_the_slice(self):
        self.assertEqual(len(self.slice), 150)
        for name in ("mcap-none", "mcap-zstd", "mcap-lz4", "sqlite3", "mcap-tf"):
            with self.subTest(bag=name):
                bag = keyplace.read_log(os.path.join(ROS2, name))
                self.assertEqual(bag.format, "ROS 2 bag")
                self.assertFalse(bag.corrected)
                # The slice's FLASER odometry is /odom interpolated by the converter and printed
                # with 6 decimals; the bag's is our interpolation of the same messages (for
                # mcap-tf: of the odom -> base_link transforms on /tf).
                assert_same_scans(self, bag, self.slice, 2e-6)

    def test_a_storage_file_and_metadata_yaml_read_as_the_directory(self):
        directory = keyplace.read_log(os.path.join(ROS2, "sqlite3"))
        for path in (os.path.join(ROS2, "sqlite3", "sqlite3_0.db3"),
                     os.path.join(ROS2, "sqlite3", "metadata.yaml")):
            with self.subTest(path=path):
                assert_same_scans(self, keyplace.read_log(path), directory, 0.0)

    def test_the_command_reads_the_same_scans(self):
        bag_path = os.path.join(ROS2, "mcap-zstd")
        bag = keyplace.read_log(bag_path)
        with tempfile.TemporaryDirectory() as work:
            info = os.path.join(work, "info.json")
            run_cli("info", bag_path, "--json", info)
            with open(info) as stream:
                described = json.load(stream)
        self.assertEqual(described["format"], "ROS 2 bag")
        self.assertEqual(described["scans"], len(bag))
        self.assertEqual(described["beams_total"], sum(len(scan) for scan in bag.scans))
        self.assertEqual(described["no_return_beams"] + described["invalid_beams"],
                         sum(int((~scan.valid).sum()) for scan in bag.scans))
        odometry = bag.odometry_poses[:, :2]
        self.assertAlmostEqual(described["path_length_m"],
                               float(np.linalg.norm(np.diff(odometry, axis=0), axis=1).sum()),
                               places=4)

    def test_topics_are_arguments_and_a_missing_one_names_the_bag(self):
        bag_path = os.path.join(ROS2, "mcap-zstd")
        with self.assertRaises(ValueError) as raised:
            keyplace.read_log(bag_path, scan_topic="/base_scan")
        self.assertIn(bag_path, str(raised.exception))
        self.assertIn("/base_scan", str(raised.exception))
        explicit = keyplace.read_log(bag_path, scan_topic="/scan", odom_topic="/odom")
        assert_same_scans(self, explicit, self.slice, 2e-6)


@unittest.skipUnless(os.path.exists(os.path.join(SHARED_DATA, "fr079.orig.bag")),
                     "the shared data (fr079.orig.bag) is not available")
class Ros1BagTest(unittest.TestCase):
    def test_the_fr079_bag_gives_the_scans_of_the_raw_log(self):
        # Its /tf_static puts the laser at +0.04 m, the log (and the original geometry) at
        # -0.04 m: the flag overrides it; its angle_increment spreads the 360 beams over 179
        # degrees, the log's FLASER lines over 180 (docs/ROS.md, "Checked against a real bag").
        flasher = keyplace.Config(overrides={"input.scan_fov_rad": math.pi})
        bag = keyplace.read_log(os.path.join(SHARED_DATA, "fr079.orig.bag"),
                                laser_pose=[-0.04, 0.0, 0.0], config=flasher)
        log = keyplace.read_log(os.path.join(SHARED_DATA, "fr079-raw.log.gz"))
        self.assertEqual(bag.format, "ROS 1 bag")
        self.assertEqual(len(bag), 4934)
        # Stamps to the microsecond (the log prints them with 6 decimals).
        assert_same_scans(self, bag, log, 1e-6, stamp_atol=1e-6)
        # (the log writes laser and robot poses with 6 decimals: their relation to 1e-6)
        np.testing.assert_allclose(bag[100].laser_pose, log[100].laser_pose, atol=1e-6)


if __name__ == "__main__":
    unittest.main()
