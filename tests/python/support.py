"""Paths and helpers shared by the Python tests (run by ctest: tests/CMakeLists.txt).

ctest sets PYTHONPATH to build/python, KEYPLACE_SOURCE_DIR and KEYPLACE_CLI (the keyplace
command, the C++ oracle the tests compare the module with).
"""

import gzip
import os
import subprocess
import unittest

SOURCE_DIR = os.environ.get(
    "KEYPLACE_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
BUNDLED_LOG = os.path.join(SOURCE_DIR, "data", "fr079-corrected.log.gz")
CLI = os.environ.get("KEYPLACE_CLI", "")


def run_cli(*arguments):
    """Runs the keyplace command; fails the test with its stderr when it fails."""
    if not CLI or not os.path.exists(CLI):
        raise unittest.SkipTest("the keyplace command is not built (KEYPLACE_CLI)")
    result = subprocess.run([CLI, *arguments], capture_output=True, text=True, check=False)
    if result.returncode != 0:
        raise AssertionError(f"keyplace {' '.join(arguments)} failed:\n{result.stderr}")
    return result.stdout


def robotlaser_lines(path=BUNDLED_LOG):
    """The ROBOTLASER1 lines of a gzip CARMEN log, split in fields (an independent oracle)."""
    with gzip.open(path, "rt") as log:
        return [line.split() for line in log if line.startswith("ROBOTLASER1 ")]


def write_log_part(folder, scans):
    """The first `scans` scans of the bundled log as a plain log in `folder` (the log interleaves
    VERTEX2 and ROBOTLASER1 lines: two lines a scan). Returns its path."""
    path = os.path.join(folder, f"fr079-first-{scans}.log")
    with gzip.open(BUNDLED_LOG, "rt") as source, open(path, "w") as part:
        part.writelines(line for _, line in zip(range(2 * scans), source))
    return path


def flat_config(node, prefix=""):
    """The `config` of a CLI JSON (nested sections, text values) as Config.to_dict() gives it:
    {"section.key": text}."""
    if not isinstance(node, dict):
        return {prefix[:-1]: node}
    return {key: value for name, child in node.items()
            for key, value in flat_config(child, prefix + name + ".").items()}
