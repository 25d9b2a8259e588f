"""keyplace.extract_keypoints against what `keyplace features` writes for the same scans."""

import os
import tempfile
import unittest

import numpy as np

import keyplace
from support import BUNDLED_LOG, run_cli

SCANS = range(0, 25)


def tsv_rows(scan_index, keypoints):
    """Rows as `keyplace features --tsv` writes them (6 decimals)."""
    return [f"{scan_index}\t{x:.6f}\t{y:.6f}\t{o:.6f}\t{s:.6f}"
            for (x, y), o, s in zip(keypoints.positions_m, keypoints.orientations_rad,
                                    keypoints.scales_m)]


class KeypointsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.log = keyplace.read_log(BUNDLED_LOG)
        with tempfile.TemporaryDirectory() as work:
            tsv = os.path.join(work, "keypoints.tsv")
            run_cli("features", BUNDLED_LOG, "--scans", f"{SCANS.start}:{SCANS.stop}", "--tsv", tsv)
            with open(tsv) as stream:
                cls.cli_rows = stream.read().splitlines()[1:]

    def test_keypoints_of_read_scans_equal_the_clis(self):
        rows = []
        for index in SCANS:
            scan = self.log[index]
            rows += tsv_rows(index, keyplace.extract_keypoints(
                scan, T_world_laser=scan.logged_laser_pose))
        self.assertGreater(len(self.cli_rows), 10 * len(SCANS))
        self.assertEqual(rows, self.cli_rows)

    def test_keypoints_of_range_arrays_equal_those_of_the_scan(self):
        scan = self.log[7]
        from_scan = keyplace.extract_keypoints(scan, T_world_laser=scan.logged_laser_pose)
        from_ranges = keyplace.extract_keypoints(
            np.array(scan.ranges), angles_rad=scan.angles_rad, max_range_m=scan.max_range_m,
            T_world_laser=scan.logged_laser_pose)
        self.assertEqual(tsv_rows(7, from_ranges), tsv_rows(7, from_scan))
        np.testing.assert_array_equal(from_ranges.descriptors, from_scan.descriptors)
        np.testing.assert_array_equal(from_ranges.beam_indices, from_scan.beam_indices)

    def test_keypoint_columns_are_consistent(self):
        scan = self.log[12]
        keypoints = keyplace.extract_keypoints(scan, T_world_laser=scan.logged_laser_pose)
        count = len(keypoints)
        self.assertEqual(keypoints.positions_m.shape, (count, 2))
        self.assertEqual(keypoints.descriptors.shape, (count, 48))
        self.assertEqual(keypoints.descriptors.dtype, np.float32)
        np.testing.assert_allclose(keypoints.descriptors.sum(axis=1), 1.0, atol=1e-5)
        # Each keypoint sits on the end point of its beam (laser frame).
        beams = keypoints.beam_indices
        ends = np.column_stack([scan.ranges[beams] * np.cos(scan.angles_rad[beams]),
                                scan.ranges[beams] * np.sin(scan.angles_rad[beams])])
        np.testing.assert_allclose(keypoints.positions_m, ends, atol=1e-12)
        self.assertTrue((np.diff(keypoints.scale_levels) >= 0).all())
        self.assertEqual(keyplace.descriptor_distance(keypoints.descriptors[0],
                                                      keypoints.descriptors[0]), 0.0)
        self.assertGreater(keyplace.descriptor_distance(keypoints.descriptors[0],
                                                        keypoints.descriptors[1]), 0.0)

    def test_feature_settings_change_the_keypoints(self):
        scan = self.log[12]
        default = keyplace.extract_keypoints(scan)
        fewer = keyplace.extract_keypoints(scan, overrides={"features.num_scales": 2})
        self.assertTrue((fewer.scale_levels < 2).all())
        self.assertLess(len(fewer), len(default))

    def test_ranges_without_angles_raise(self):
        with self.assertRaisesRegex(ValueError, "angles_rad"):
            keyplace.extract_keypoints(np.ones(10))


if __name__ == "__main__":
    unittest.main()
