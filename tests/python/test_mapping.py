"""keyplace.build_map, Map.save and load_map against the map `keyplace map` builds."""

import os
import tempfile
import unittest

import numpy as np

import keyplace
from support import BUNDLED_LOG, run_cli

SCANS = (100, 500)
OVERRIDES = {"mapping.min_stable_keypoints": 8, "features.num_scales": 4}


class MapTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = tempfile.TemporaryDirectory()
        cls.cli_path = os.path.join(cls.work.name, "cli.kpm")
        run_cli("map", BUNDLED_LOG, "--scans", f"{SCANS[0]}:{SCANS[1]}", "--out", cls.cli_path,
                "--set", "mapping.min_stable_keypoints=8", "--set", "features.num_scales=4")
        cls.map = keyplace.build_map(BUNDLED_LOG, overrides=OVERRIDES, scans=SCANS)

    @classmethod
    def tearDownClass(cls):
        cls.work.cleanup()

    def assertSameMap(self, a, b):
        self.assertEqual(a.submap_count, b.submap_count)
        self.assertEqual(a.keypoint_count, b.keypoint_count)
        for sa, sb in zip(a.submaps, b.submaps):
            self.assertEqual(sa.id, sb.id)
            np.testing.assert_array_equal(sa.scan_indices, sb.scan_indices)
            np.testing.assert_array_equal(sa.poses, sb.poses)
            np.testing.assert_array_equal(sa.keypoint_positions_m, sb.keypoint_positions_m)
            np.testing.assert_array_equal(sa.descriptors, sb.descriptors)
            np.testing.assert_array_equal(sa.keypoint_occurrences, sb.keypoint_occurrences)

    def test_the_map_is_the_clis(self):
        cli_map = keyplace.load_map(self.cli_path)
        self.assertGreater(self.map.submap_count, 5)
        self.assertSameMap(self.map, cli_map)
        self.assertEqual(self.map.configuration, cli_map.configuration)
        self.assertIn("min_stable_keypoints: 8", self.map.configuration)

    def test_saved_and_loaded_map_is_the_same(self):
        path = os.path.join(self.work.name, "python.kpm")
        self.map.save(path)
        loaded = keyplace.load_map(path)
        self.assertSameMap(self.map, loaded)
        self.assertEqual(loaded.source_hash, self.map.source_hash)
        self.assertEqual(loaded.pose_source, "corrected")

    def test_scan_range_settings_and_summary(self):
        first = self.map.submaps[0]
        self.assertEqual(first.scan_indices[0], SCANS[0])
        self.assertLess(self.map.submaps[-1].scan_indices[-1], SCANS[1])
        np.testing.assert_array_equal(first.origin, first.poses[0])
        np.testing.assert_array_equal(self.map.origins[3], self.map.submaps[3].origin)
        log = keyplace.read_log(BUNDLED_LOG)
        np.testing.assert_array_equal(first.poses[1], log[first.scan_indices[1]].corrected_pose)
        stats = self.map.stats()
        self.assertEqual(stats.submaps, self.map.submap_count)
        self.assertEqual(stats.stable_keypoints, self.map.keypoint_count)
        self.assertEqual(sum(s.keypoint_count for s in self.map.submaps), self.map.keypoint_count)
        self.assertTrue(0 < stats.compression < 1)
        default = keyplace.build_map(BUNDLED_LOG, scans=SCANS)
        self.assertNotEqual(default.keypoint_count, self.map.keypoint_count)

    def test_bad_map_paths_raise_naming_the_file(self):
        with self.assertRaisesRegex(RuntimeError, "missing-map.kpm"):
            keyplace.load_map(os.path.join(self.work.name, "missing-map.kpm"))
        with self.assertRaisesRegex(RuntimeError, "no-such-dir"):
            self.map.save("/nonexistent/no-such-dir/map.kpm")
        with self.assertRaisesRegex(RuntimeError, "no-such-log"):
            keyplace.build_map("/nonexistent/no-such-log.gz")
        with self.assertRaisesRegex(ValueError, "mapping.no_such_key"):
            keyplace.build_map(BUNDLED_LOG, overrides={"mapping.no_such_key": 1})

    def test_bad_scan_ranges_raise_naming_the_argument(self):
        # Issue 31: pybind11's "Unable to cast" before.
        for scans in ("9:3", (9, 3), (-1, 5), (1, 2, 3), (1.5, 3), 7):
            with self.assertRaisesRegex(ValueError, r"scans=.*: expected \(first, end\), two "
                                                    r"integers with 0 <= first <= end"):
                keyplace.build_map(BUNDLED_LOG, scans=scans)

    def test_save_refuses_the_log_the_map_was_made_from(self):
        # Issue 31: the Python writers protect their inputs as the CLI does; the map knows its
        # log by content (source_hash), so a copy or a link of it is refused too.
        copy = os.path.join(self.work.name, "copy.log.gz")
        with open(BUNDLED_LOG, "rb") as source, open(copy, "wb") as target:
            before = source.read()
            target.write(before)
        link = os.path.join(self.work.name, "link.log.gz")
        os.symlink(copy, link)
        for path in (copy, link):
            with self.assertRaisesRegex(ValueError, "is the log the map was made from"):
                self.map.save(path)
        with open(copy, "rb") as stream:
            self.assertEqual(stream.read(), before)


if __name__ == "__main__":
    unittest.main()
