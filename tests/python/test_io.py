"""keyplace.read_log and keyplace.Scan against the log text itself and the C++ reader."""

import json
import math
import os
import re
import tempfile
import threading
import unittest

import numpy as np

import keyplace
from support import BUNDLED_LOG, SOURCE_DIR, robotlaser_lines, run_cli


class VersionTest(unittest.TestCase):
    def test_the_module_has_the_projects_version_as_the_command(self):
        with open(os.path.join(SOURCE_DIR, "CMakeLists.txt")) as cmake:
            project = re.search(r"project\(keyplace VERSION ([0-9.]+)", cmake.read()).group(1)
        self.assertEqual(keyplace.__version__, project)
        self.assertEqual(run_cli("--version").strip(), "keyplace " + project)


class ReadLogTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.log = keyplace.read_log(BUNDLED_LOG)
        cls.lines = robotlaser_lines()

    def test_scan_count_is_the_readers_and_the_files(self):
        self.assertEqual(len(self.log), len(self.lines))
        self.assertEqual(len(self.log.scans), 1464)
        with tempfile.TemporaryDirectory() as work:
            info = os.path.join(work, "info.json")
            run_cli("info", BUNDLED_LOG, "--json", info)
            with open(info) as stream:
                self.assertEqual(json.load(stream)["scans"], len(self.log))
        self.assertTrue(self.log.corrected)
        self.assertEqual(self.log.format, "CARMEN log")

    def test_ranges_angles_and_poses_are_those_of_the_log_lines(self):
        for index in (0, 700, 1463):
            fields = self.lines[index]
            count = int(fields[8])
            scan = self.log[index]
            np.testing.assert_array_equal(scan.ranges, [float(v) for v in fields[9:9 + count]])
            self.assertEqual(scan.ranges.dtype, np.float64)
            start, step = float(fields[2]), float(fields[4])
            np.testing.assert_allclose(scan.angles_rad, start + step * np.arange(count),
                                       atol=1e-12)
            self.assertEqual(scan.max_range_m, float(fields[5]))
            remissions = int(fields[9 + count])
            robot = [float(v) for v in fields[9 + count + remissions + 4:][:3]]
            np.testing.assert_allclose(scan.corrected_pose[:2], robot[:2], atol=0)
            self.assertAlmostEqual(math.remainder(scan.corrected_pose[2] - robot[2], 2 * math.pi),
                                   0.0, places=12)
            self.assertIsNone(scan.odometry_pose)
            self.assertEqual(scan.timestamp_s, float(fields[-3]))
            np.testing.assert_array_equal(
                scan.valid, (scan.ranges > 0) & (scan.ranges < scan.max_range_m))

    def test_log_arrays_match_the_scans(self):
        poses = self.log.corrected_poses
        self.assertEqual(poses.shape, (1464, 3))
        np.testing.assert_array_equal(poses[700], self.log[700].corrected_pose)
        self.assertTrue(np.isnan(self.log.odometry_poses).all())
        self.assertEqual(self.log.timestamps_s[5], self.log[5].timestamp_s)
        self.assertEqual(self.log[-1].line, self.log.scans[1463].line)

    def test_a_scan_built_from_arrays_marks_beams_as_the_reader(self):
        read = self.log[3]
        built = keyplace.Scan(read.ranges, read.angles_rad, max_range_m=read.max_range_m,
                              laser_pose=read.laser_pose)
        np.testing.assert_array_equal(built.valid, read.valid)
        np.testing.assert_array_equal(built.laser_pose, read.laser_pose)
        built = keyplace.Scan([1.0, 0.0, np.nan, 5.0], [0.0, 0.1, 0.2, 0.3], max_range_m=5.0)
        np.testing.assert_array_equal(built.valid, [True, False, False, False])


class GilTest(unittest.TestCase):
    def test_reading_lets_other_python_threads_run(self):
        # read_log takes about 0.3 s in C++; with the GIL released the main thread keeps counting.
        reader = threading.Thread(target=keyplace.read_log, args=(BUNDLED_LOG,))
        ticks = 0
        reader.start()
        while reader.is_alive():
            ticks += 1
            threading.Event().wait(0.001)
        reader.join()
        self.assertGreater(ticks, 20)


class ErrorsTest(unittest.TestCase):
    def test_a_missing_file_raises_naming_it(self):
        with self.assertRaisesRegex(RuntimeError, "no-such-log.gz"):
            keyplace.read_log("/nonexistent/no-such-log.gz")

    def test_a_file_without_scans_raises_naming_it(self):
        with tempfile.NamedTemporaryFile("w", suffix="-text.log") as text:
            text.write("not a log\n")
            text.flush()
            with self.assertRaisesRegex(ValueError, os.path.basename(text.name)):
                keyplace.read_log(text.name)

    def test_bad_configuration_keys_and_values_raise_naming_the_key(self):
        with self.assertRaisesRegex(ValueError, "place.no_such_key"):
            keyplace.Config(overrides={"place.no_such_key": 1})
        with self.assertRaisesRegex(ValueError, "place.min_pairs"):
            keyplace.Config(overrides={"place.min_pairs": "many"})
        with self.assertRaisesRegex(ValueError, "preset"):
            keyplace.Config("no-such-preset")
        # Issue 31: a bare "MemoryError std::bad_alloc" after reading gigabytes before.
        with self.assertRaisesRegex(RuntimeError, "/dev/zero: larger than 1 MiB, the limit of a "
                                                  "configuration file"):
            keyplace.Config(file="/dev/zero")

    def test_mismatched_beams_raise(self):
        with self.assertRaisesRegex(ValueError, "3 ranges but 2 angles"):
            keyplace.Scan([1.0, 2.0, 3.0], [0.0, 0.1])


class ConfigTest(unittest.TestCase):
    def test_overrides_and_presets_reach_the_configuration(self):
        config = keyplace.Config("paper", overrides={
            "place.min_pairs": 12, "mapping.use_distribution": False, "place.min_gamma": 0.25})
        self.assertEqual(config["place.min_pairs"], "12")
        self.assertEqual(config["mapping.use_distribution"], "false")
        self.assertEqual(float(config["place.min_gamma"]), 0.25)
        self.assertEqual(config.preset, "paper")
        self.assertIn("place:", config.to_yaml())
        self.assertEqual(keyplace.Config().to_dict()["place.min_pairs"], "10")
        self.assertEqual(set(keyplace.config_presets()), {"default", "paper", "strict"})

    def test_settings_valid_only_together_pass_in_either_order(self):
        # min_range_m must stay below max_range_m (default 30 m): validated after all overrides.
        for overrides in ({"odometry.min_range_m": 40, "odometry.max_range_m": 60},
                          {"odometry.max_range_m": 60, "odometry.min_range_m": 40}):
            config = keyplace.Config(overrides=overrides)
            self.assertEqual(float(config["odometry.min_range_m"]), 40, overrides)
            self.assertEqual(float(config["odometry.max_range_m"]), 60, overrides)
        with tempfile.NamedTemporaryFile("w", suffix=".yaml") as file:
            file.write("odometry:\n  min_range_m: 40\n")
            file.flush()
            config = keyplace.Config(file=file.name, overrides={"odometry.max_range_m": 60})
            self.assertEqual(float(config["odometry.min_range_m"]), 40)
        with self.assertRaisesRegex(ValueError, "odometry.min_range_m=70 from overrides"):
            keyplace.Config(overrides={"odometry.min_range_m": 70, "odometry.max_range_m": 60})


if __name__ == "__main__":
    unittest.main()
