"""The streaming GlobalLocalizer and Relocalizer, and keyplace.localize, against the C++
programs (examples/localize_stream, `keyplace localize`) on the first 300 scans of the bundled
log (its map, and the same scans streamed)."""

import json
import math
import os
import re
import subprocess
import tempfile
import unittest

import numpy as np

import keyplace
from support import run_cli, write_log_part

STREAM = os.environ.get("KEYPLACE_LOCALIZE_STREAM", "")


class LocalizationTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = tempfile.TemporaryDirectory()
        cls.log_path = write_log_part(cls.work.name, 300)
        cls.map_path = os.path.join(cls.work.name, "map.kpm")
        run_cli("map", cls.log_path, "--out", cls.map_path)
        cls.log = keyplace.read_log(cls.log_path)
        # The corrected poses stand in for odometry, as in examples/localize_stream.cpp.
        localizer = keyplace.GlobalLocalizer(cls.map_path)
        cls.answers = []
        for index, scan in enumerate(cls.log.scans):
            answer = localizer.add_scan(scan, scan.corrected_pose)
            if answer is not None:
                cls.answers.append((index, answer))

    @classmethod
    def tearDownClass(cls):
        cls.work.cleanup()

    def test_fixes_are_close_to_the_corrected_poses(self):
        fixes = [(i, a) for i, a in self.answers if a.found]
        self.assertGreater(len(fixes), 10)
        correct = 0
        for index, fix in fixes:
            truth = self.log[index].corrected_pose
            error_m = np.hypot(*(fix.pose[:2] - truth[:2]))
            error_deg = abs(math.degrees(math.remainder(fix.pose[2] - truth[2], 2 * math.pi)))
            correct += error_m <= 0.5 and error_deg <= 10
            self.assertEqual(fix.match.place_id, fix.submap_id)
            self.assertTrue(0 < fix.confidence <= 1)
        self.assertGreaterEqual(correct / len(fixes), 0.9)

    def test_fixes_equal_those_of_the_cpp_streaming_example(self):
        if not STREAM or not os.path.exists(STREAM):
            self.skipTest("examples/localize_stream is not built (KEYPLACE_LOCALIZE_STREAM)")
        output = subprocess.run([STREAM, self.map_path, self.log_path], capture_output=True,
                                text=True, check=True).stdout
        expected = re.findall(r"scan +(\d+) +x +(\S+) m +y +(\S+) m +theta +(\S+) deg +"
                              r"confidence (\S+) +submap (\d+)", output)
        got = [(str(i), f"{a.pose[0]:.3f}", f"{a.pose[1]:.3f}", f"{math.degrees(a.pose[2]):.2f}",
                f"{a.confidence:.2f}", str(a.submap_id)) for i, a in self.answers if a.found]
        self.assertGreater(len(expected), 10)
        self.assertEqual(got, expected)

    def test_weak_answers_come_only_with_answers_not_accepted(self):
        weak_answers = 0
        for _, answer in self.answers:
            weak = answer.weak_T_world_odom
            if answer.found:
                self.assertIsNone(weak)
            elif weak is not None:
                weak_answers += 1
                self.assertEqual(weak.shape, (3,))
                self.assertTrue(np.all(np.isfinite(weak)))
        # One of the 77 answers on these scans is not accepted but names a weak answer.
        self.assertGreater(weak_answers, 0)

    def test_range_arrays_give_the_answers_of_scans(self):
        localizer = keyplace.GlobalLocalizer(keyplace.load_map(self.map_path))
        first_index, first_answer = self.answers[0]
        answer = None
        for scan in self.log.scans[:first_index + 1]:
            answer = localizer.add_scan(np.array(scan.ranges), scan.corrected_pose,
                                        angles_rad=scan.angles_rad, max_range_m=scan.max_range_m,
                                        laser_pose=scan.laser_pose)
            if answer is not None:
                break
        # A complete query starts over; one answered on the way (query_every_m) keeps growing.
        self.assertIn(localizer.buffered_scans, (0, answer.scans))
        np.testing.assert_array_equal(answer.pose, first_answer.pose)
        self.assertEqual(answer.scans, first_answer.scans)
        self.assertEqual(answer.found, first_answer.found)
        with self.assertRaisesRegex(ValueError, "odom_pose"):
            localizer.add_scan(self.log[0], [0.0, 1.0])

    def test_the_relocalizer_fixes_on_the_corrected_pose(self):
        relocalizer = keyplace.Relocalizer(self.map_path)
        for scan in self.log.scans:
            update = relocalizer.add_scan(scan, scan.corrected_pose)
            if update.status == "fixed":
                truth = scan.corrected_pose
                self.assertLess(np.hypot(*(update.pose[:2] - truth[:2])), 0.5)
                break
        self.assertEqual(relocalizer.status, "fixed")

    def test_poses_as_3x3_homogeneous_matrices_give_the_same_answers(self):
        def matrix(pose):
            c, s = math.cos(pose[2]), math.sin(pose[2])
            return np.array([[c, -s, pose[0]], [s, c, pose[1]], [0.0, 0.0, 1.0]])

        by_vector = keyplace.Relocalizer(self.map_path)
        by_matrix = keyplace.Relocalizer(self.map_path)
        fixed = 0
        for scan in self.log.scans:
            a = by_vector.add_scan(scan, scan.corrected_pose)
            b = by_matrix.add_scan(scan, matrix(scan.corrected_pose))
            self.assertEqual(a.status, b.status)
            if a.status == "fixed":
                fixed += 1
                np.testing.assert_allclose(a.pose, b.pose, atol=1e-9)
                if fixed == 20:
                    break
        self.assertEqual(fixed, 20)
        scan = self.log.scans[0]
        bad_row = matrix(scan.corrected_pose)
        bad_row[2, 0] = 0.5
        with self.assertRaisesRegex(ValueError, r"odom_pose: the last row .* \[0, 0, 1\]"):
            by_matrix.add_scan(scan, bad_row)
        scaled = matrix(scan.corrected_pose)
        scaled[:2, :2] *= 2.0
        with self.assertRaisesRegex(ValueError, "odom_pose: the upper left 2 x 2 block is not"):
            by_matrix.add_scan(scan, scaled)
        with self.assertRaisesRegex(ValueError, "or a 3 x 3 homogeneous transform"):
            by_matrix.add_scan(scan, np.eye(4))

    def test_localize_equals_the_cli(self):
        figures = os.path.join(self.work.name, "localize.json")
        queries = os.path.join(self.work.name, "queries.tsv")
        run_cli("localize", "--map", self.map_path, "--log", self.log_path, "--n-pos", "30",
                "--json", figures, "--queries", queries)
        with open(figures) as stream:
            cli = json.load(stream)
        result = keyplace.localize(self.log_path, self.map_path, n_pos=30)
        for key in ("n_pos", "n_acc", "n_cor", "precision", "recall", "p_gl", "p_cl",
                    "n_revisitable", "recall_revisitable", "rank_by"):
            self.assertEqual(getattr(result, key), cli[key], key)
        self.assertGreaterEqual(result.precision, 0.9)
        rows = np.genfromtxt(queries, delimiter="\t", names=True)
        np.testing.assert_array_equal(result.start_scans, rows["start_scan"])
        np.testing.assert_array_equal(result.correct, rows["correct"] == 1)
        np.testing.assert_allclose(result.estimated_poses[:, 0], rows["est_x"], atol=5e-5)
        np.testing.assert_allclose(result.truth_poses[:, 1], rows["true_y"], atol=5e-5)
        self.assertEqual(result.curve.shape[1], 3)
        # A Map object gives the same figures as its file.
        again = keyplace.localize(self.log_path, keyplace.load_map(self.map_path), n_pos=30)
        self.assertEqual((again.n_acc, again.n_cor), (result.n_acc, result.n_cor))


if __name__ == "__main__":
    unittest.main()
