"""keyplace.relocalize against `keyplace relocalize --json --initialpose` on the first 600 scans of
the bundled log and its map."""

import json
import os
import tempfile
import unittest

import numpy as np

import keyplace
from support import flat_config, run_cli, write_log_part

SCANS = 600
STARTS = 6

# The summary figures of --json the evaluation holds under the same names (times aside).
FIGURES = [
    "starts", "starts_with_revisit", "fixed", "fixed_with_revisit", "fixed_fraction",
    "starts_with_room", "fixed_with_room", "fixed_fraction_with_room", "fixes",
    "wrong_fixes", "wrong_fix_rate", "wrong_first_fixes", "wrong_fix_confident",
    "wrong_fix_confidence_max", "distance_to_fix_median_m", "distance_to_fix_p90_m",
    "scans_to_fix_median", "distance_after_revisit_median_m", "distance_after_revisit_p90_m",
    "lost_signals", "lost_on_correct_track", "lost_on_wrong_track", "query_log_is_map_log",
    "exclude_shared_scans", "give_up_m", "follow_m", "revisit_room_m", "pose_source"]


class RelocalizationTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = tempfile.TemporaryDirectory()
        cls.log_path = write_log_part(cls.work.name, SCANS)
        cls.map_path = os.path.join(cls.work.name, "map.kpm")
        run_cli("map", cls.log_path, "--out", cls.map_path)

    @classmethod
    def tearDownClass(cls):
        cls.work.cleanup()

    def run_both(self, name, *arguments, **keywords):
        """The CLI's JSON, its --initialpose text (None when it wrote none), its --fixes TSV path
        and the module's evaluation of the same run."""
        figures = os.path.join(self.work.name, name + ".json")
        fix = os.path.join(self.work.name, name + "-fix.yaml")
        fixes = os.path.join(self.work.name, name + "-fixes.tsv")
        run_cli("relocalize", "--map", self.map_path, "--log", self.log_path, "--starts",
                str(STARTS), "--json", figures, "--initialpose", fix, "--fixes", fixes,
                "--tsv", os.path.join(self.work.name, name + "-starts.tsv"), *arguments)
        with open(figures) as stream:
            cli = json.load(stream)
        text = None
        if os.path.exists(fix):
            with open(fix) as stream:
                text = stream.read()
        calls = []
        evaluation = keyplace.relocalize(self.log_path, self.map_path, starts=STARTS,
                                         progress=lambda *call: calls.append(call), **keywords)
        self.assertEqual(sorted(calls), [(done, STARTS) for done in range(1, STARTS + 1)])
        return cli, text, fixes, evaluation

    def check_equal(self, cli, evaluation):
        for key in FIGURES:
            self.assertEqual(getattr(evaluation, key), cli[key], key)
        self.assertEqual(list(evaluation.scans), cli["scans"])
        self.assertEqual(len(evaluation.records), evaluation.starts)
        # The same configuration: the CLI's preset (strict) and settings, key by key.
        self.assertEqual(evaluation.config.to_dict(), flat_config(cli["config"]))
        self.assertEqual(evaluation.config.get("place.min_reference_coverage"), "0.5")

    def test_own_log_without_the_shared_scan_rule(self):
        cli, text, fixes_path, evaluation = self.run_both("none", "--self-match", "none",
                                                          self_match="none")
        self.check_equal(cli, evaluation)
        self.assertTrue(evaluation.query_log_is_map_log)
        self.assertFalse(evaluation.exclude_shared_scans)
        # On its own map every start is fixed: the comparison covers fixes.
        self.assertGreater(evaluation.fixes, 0)
        rows = np.genfromtxt(fixes_path, delimiter="\t", names=True, ndmin=1)
        fixes = [f for record in evaluation.records for f in record.fixes]
        self.assertEqual(len(fixes), len(rows))
        # Each column named as the property and written from the same table, exactly.
        for name in rows.dtype.names:
            if hasattr(fixes[0], name):
                self.assertEqual([float(getattr(f, name)) for f in fixes], list(rows[name]), name)
        self.assertEqual([f.pose[0] for f in fixes], list(rows["est_x"]))
        starts = np.genfromtxt(os.path.join(self.work.name, "none-starts.tsv"), delimiter="\t",
                               names=True, ndmin=1)
        self.assertEqual(len(starts), len(evaluation.records))
        self.assertIn("fixes_reported", starts.dtype.names)
        for name in starts.dtype.names:
            if "seconds" not in name:
                self.assertEqual([float(getattr(r, name)) for r in evaluation.records],
                                 list(starts[name]), name)
        # The first fix as the /initialpose message, the text --initialpose wrote.
        start_scan, first = evaluation.first_fix()
        self.assertTrue(first.first)
        self.assertIn(start_scan, [record.start_scan for record in evaluation.records])
        self.assertEqual(evaluation.initial_pose().to_yaml(), text)
        self.assertEqual(first.initial_pose().to_yaml(), text)
        np.testing.assert_array_equal(evaluation.initial_pose().pose, first.pose_at_fix)

    def test_own_log_with_the_shared_scan_rule(self):
        cli, text, _, evaluation = self.run_both("shared")
        self.check_equal(cli, evaluation)
        self.assertTrue(evaluation.exclude_shared_scans)
        initial = evaluation.initial_pose()
        self.assertEqual(None if initial is None else initial.to_yaml(), text)

    def test_bad_arguments_raise(self):
        with self.assertRaisesRegex(ValueError, "self_match"):
            keyplace.relocalize(self.log_path, self.map_path, self_match="some")
        with self.assertRaisesRegex(ValueError, "starts"):
            keyplace.relocalize(self.log_path, self.map_path, starts=0)
        with self.assertRaisesRegex(ValueError, "pose source .gps."):
            keyplace.relocalize(self.log_path, self.map_path, poses="gps")
        with self.assertRaisesRegex(RuntimeError, "missing.kpm"):
            keyplace.relocalize(self.log_path, os.path.join(self.work.name, "missing.kpm"))


if __name__ == "__main__":
    unittest.main()
