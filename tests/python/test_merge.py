"""keyplace.merge_maps against `keyplace merge` on the bundled log split in two halves, each
mapped in its own frame (as tests/cli/merge_test.sh)."""

import json
import os
import tempfile
import unittest

import numpy as np

import keyplace
from support import BUNDLED_LOG, flat_config, run_cli

SPLIT = 732  # the middle of the bundled log


class MergeTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = tempfile.TemporaryDirectory()
        cls.a_path = os.path.join(cls.work.name, "a.kpm")
        cls.b_path = os.path.join(cls.work.name, "b.kpm")
        run_cli("map", BUNDLED_LOG, "--scans", f"0:{SPLIT}", "--start-at-origin", "--out",
                cls.a_path)
        run_cli("map", BUNDLED_LOG, "--scans", f"{SPLIT}:", "--start-at-origin", "--out",
                cls.b_path)
        cls.merged_path = os.path.join(cls.work.name, "ab.kpm")
        figures = os.path.join(cls.work.name, "merge.json")
        run_cli("merge", cls.a_path, cls.b_path, "--out", cls.merged_path, "--json", figures)
        with open(figures) as stream:
            cls.cli = json.load(stream)
        cls.calls = []
        cls.result = keyplace.merge_maps(cls.a_path, cls.b_path,
                                         progress=lambda *call: cls.calls.append(call))

    @classmethod
    def tearDownClass(cls):
        cls.work.cleanup()

    def test_transform_and_counts_equal_the_clis(self):
        transform = self.cli["T_a_b"]
        np.testing.assert_array_equal(
            self.result.T_a_b, [transform["x_m"], transform["y_m"], transform["theta_rad"]])
        self.assertEqual(self.result.submaps_queried, self.cli["submaps_queried"])
        self.assertEqual(self.result.recognised, self.cli["recognised"])
        self.assertEqual(self.result.agreeing, self.cli["agreeing"])
        self.assertGreaterEqual(self.result.agreeing, 3)
        self.assertEqual(self.result.merged.submap_count, self.cli["submaps_merged"])
        self.assertEqual(self.result.submaps_merged, self.cli["submaps_merged"])
        self.assertEqual(len(self.result.recognitions), len(self.cli["recognitions"]))
        # The same configuration, the CLI's default preset (strict) included.
        self.assertEqual(self.result.config.to_dict(), flat_config(self.cli["config"]))
        self.assertEqual(self.result.config.preset, "strict")
        for mine, theirs in zip(self.result.recognitions, self.cli["recognitions"]):
            self.assertEqual((mine.submap_b, mine.submap_a, mine.agrees),
                             (theirs["submap_b"], theirs["submap_a"], theirs["agrees"]))
            self.assertEqual(mine.confidence, theirs["confidence"])
            np.testing.assert_array_equal(mine.T_a_b,
                                          [theirs["x_m"], theirs["y_m"], theirs["theta_rad"]])

    def test_merged_map_equals_the_one_the_cli_wrote(self):
        written = keyplace.load_map(self.merged_path)
        merged = self.result.merged
        self.assertEqual([s.id for s in merged.submaps], [s.id for s in written.submaps])
        np.testing.assert_array_equal(merged.origins, written.origins)
        self.assertEqual(merged.keypoint_count, written.keypoint_count)
        self.assertEqual(merged.source_hash, "")
        # A first, unchanged; B after it, moved by T_a_b.
        a = keyplace.load_map(self.a_path)
        b = keyplace.load_map(self.b_path)
        np.testing.assert_array_equal(merged.origins[:a.submap_count], a.origins)
        x, y, theta = self.result.T_a_b
        origin_b = b.origins[0]
        moved = [x + np.cos(theta) * origin_b[0] - np.sin(theta) * origin_b[1],
                 y + np.sin(theta) * origin_b[0] + np.cos(theta) * origin_b[1]]
        np.testing.assert_allclose(merged.origins[a.submap_count][:2], moved, atol=1e-9)

    def test_progress_counts_every_b_submap(self):
        queried = self.result.submaps_queried
        self.assertEqual(self.calls, [(done, queried) for done in range(1, queried + 1)])

    def test_maps_as_objects_give_the_same_answer(self):
        result = keyplace.merge_maps(keyplace.load_map(self.a_path), keyplace.load_map(self.b_path),
                                     config="strict")
        np.testing.assert_array_equal(result.T_a_b, self.result.T_a_b)

    def test_refusals_raise_with_the_librarys_reason(self):
        with self.assertRaisesRegex(ValueError, "no reliable overlap"):
            keyplace.merge_maps(self.a_path, self.b_path, overrides={"merge.min_agreeing": 1000})
        with self.assertRaisesRegex(ValueError, "merge.min_agreeing"):
            keyplace.merge_maps(self.a_path, self.b_path, overrides={"merge.min_agreeing": 0})
        other = keyplace.build_map(BUNDLED_LOG, scans=(SPLIT, SPLIT + 100),
                                   overrides={"mapping.cell_size_m": 0.2})
        with self.assertRaisesRegex(ValueError, "different mapping settings"):
            keyplace.merge_maps(self.a_path, other)
        with self.assertRaisesRegex(RuntimeError, "no-such-map"):
            keyplace.merge_maps(self.a_path, os.path.join(self.work.name, "no-such-map.kpm"))
        with self.assertRaisesRegex(TypeError, "progress"):
            keyplace.merge_maps(self.a_path, self.b_path, progress=3)

    def test_an_exception_in_progress_reaches_the_caller(self):
        def stop(done, total):
            raise KeyboardInterrupt("stopped at %d of %d" % (done, total))
        with self.assertRaisesRegex(KeyboardInterrupt, "stopped at 1 of"):
            keyplace.merge_maps(self.a_path, self.b_path, progress=stop)


if __name__ == "__main__":
    unittest.main()
