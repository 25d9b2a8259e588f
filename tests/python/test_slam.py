"""keyplace.slam against `keyplace slam` on the first 500 scans of the bundled log."""

import json
import os
import tempfile
import unittest

import numpy as np

import keyplace
from support import run_cli, write_log_part

SCANS = 500


class SlamTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = tempfile.TemporaryDirectory()
        cls.log_path = write_log_part(cls.work.name, SCANS)
        cls.slam_run, cls.evaluation = keyplace.slam(cls.log_path)

    @classmethod
    def tearDownClass(cls):
        cls.work.cleanup()

    def test_trajectory_and_loops_equal_the_clis(self):
        trajectory = os.path.join(self.work.name, "trajectory.tsv")
        figures = os.path.join(self.work.name, "slam.json")
        run_cli("slam", self.log_path, "--trajectory", trajectory, "--json", figures)
        rows = np.genfromtxt(trajectory, delimiter="\t", names=True)
        self.assertEqual(len(rows), SCANS)
        np.testing.assert_array_equal(self.slam_run.scan_indices, rows["scan_index"])
        np.testing.assert_allclose(self.slam_run.poses[:, 0], rows["x_m"], atol=5e-7)
        np.testing.assert_allclose(self.slam_run.poses[:, 1], rows["y_m"], atol=5e-7)
        np.testing.assert_allclose(self.slam_run.icp_poses[:, 2], rows["icp_theta_rad"], atol=5e-7)
        with open(figures) as stream:
            cli = json.load(stream)
        self.assertEqual(self.slam_run.loops_detected, cli["loops_detected"])
        self.assertEqual(self.slam_run.map.submap_count, cli["submaps"])
        # The figures come from one table on both sides: same names, same values (the CLI does
        # not take a corrected log as its own truth, so the truth figures are null there).
        run_figures = [name for name in cli if hasattr(self.slam_run, name)]
        self.assertIn("loops_rejected_by_point_overlap", run_figures)
        for name in run_figures:
            if "seconds" not in name:
                self.assertEqual(getattr(self.slam_run, name), cli[name], name)
        loop_figures = [name for name in cli
                        if name.startswith(("precision_overlap", "loops_used", "loops_below"))]
        self.assertEqual(len(loop_figures), 10)
        for name in loop_figures:
            self.assertEqual(getattr(self.evaluation, name), cli[name], name)
        self.assertIsNone(cli["ate_rmse_m"])
        self.assertIsNotNone(self.evaluation.ate_rmse_m)

    def test_the_corrected_log_is_its_own_truth(self):
        # The ATE recomputed here: the corrected poses of the scans, the SLAM positions aligned to
        # them by the least-squares rotation and translation (Kabsch), the RMSE of the rest.
        self.assertTrue(self.evaluation.has_truth)
        truth = keyplace.read_log(self.log_path).corrected_poses[self.slam_run.scan_indices, :2]
        np.testing.assert_array_equal(self.evaluation.truth_positions, truth)
        estimate = self.slam_run.poses[:, :2]
        centred_estimate, centred_truth = estimate - estimate.mean(0), truth - truth.mean(0)
        u, _, vt = np.linalg.svd(centred_estimate.T @ centred_truth)
        rotation = vt.T @ np.diag([1.0, np.sign(np.linalg.det(vt.T @ u.T))]) @ u.T
        aligned = centred_estimate @ rotation.T + truth.mean(0)
        np.testing.assert_allclose(self.evaluation.aligned_positions, aligned, atol=1e-9)
        ate = np.sqrt(((aligned - truth) ** 2).sum(axis=1).mean())
        self.assertAlmostEqual(self.evaluation.ate_rmse_m, ate, places=9)
        rpe = self.evaluation.rpe
        self.assertEqual(rpe.shape[1], 4)
        self.assertEqual(tuple(rpe[0, :2]), (1, SCANS - 1))
        self.assertEqual(self.slam_run.map.pose_source, "slam")
        self.assertEqual(self.evaluation.mapping.submaps, self.slam_run.map.submap_count)

    def test_bad_inputs_raise_naming_them(self):
        with self.assertRaisesRegex(ValueError, "order"):
            keyplace.slam(self.log_path, order="sideways")
        with self.assertRaisesRegex(RuntimeError, "no-relations"):
            keyplace.slam(self.log_path, relations="/nonexistent/no-relations.txt")


if __name__ == "__main__":
    unittest.main()
