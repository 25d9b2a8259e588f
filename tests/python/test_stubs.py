"""The module's type stubs (python/keyplace.pyi) against the built module, with mypy's stubtest:
every class, function, method and property of the module must be in the stub with a matching
signature, and the stub must name nothing the module lacks. Only "metaclass differs" is not a
failure: pybind11 gives every class its own metaclass, which a stub does not spell out.
"""

import importlib.util
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

from support import SOURCE_DIR

STUB = os.path.join(SOURCE_DIR, "python", "keyplace.pyi")
METACLASS_ONLY = "is inconsistent, metaclass differs"

HAVE_MYPY = importlib.util.find_spec("mypy") is not None  # Debian's python3-mypy


def stubtest_errors(stub_text):
    """stubtest's errors (one line each) for `stub_text` as the stub of the built module."""
    with tempfile.TemporaryDirectory() as folder:
        with open(os.path.join(folder, "keyplace.pyi"), "w", encoding="utf-8") as stub:
            stub.write(stub_text)
        environment = dict(os.environ, MYPYPATH=folder)
        result = subprocess.run(
            [sys.executable, "-c",
             "import sys; from mypy.stubtest import main; sys.exit(main())",
             "--concise", "--mypy-config-file", os.devnull, "keyplace"],
            capture_output=True, text=True, env=environment, cwd=folder, check=False,
            timeout=240)
        shutil.rmtree(os.path.join(folder, ".mypy_cache"), ignore_errors=True)
    output = result.stdout + result.stderr
    if result.returncode not in (0, 1) or "not checking stubs" in output:
        raise AssertionError(f"stubtest did not run (exit {result.returncode}):\n{output}")
    return [line for line in output.splitlines()
            if line.startswith("keyplace") and METACLASS_ONLY not in line]


@unittest.skipUnless(HAVE_MYPY, "mypy (python3-mypy) is not installed")
class Stubs(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        with open(STUB, encoding="utf-8") as stub:
            cls.stub_text = stub.read()

    def test_stub_matches_the_module(self):
        self.assertEqual(stubtest_errors(self.stub_text), [],
                         f"{STUB} disagrees with the built module; see the lines above")

    def test_a_binding_missing_from_the_stub_is_reported(self):
        # The check itself can fail: drop one method and one class from the stub (a class no
        # other stub entry names, so that the rest of the stub stays valid).
        without_method = re.sub(r"\n    def localize_now\(self\)[^\n]*", "", self.stub_text)
        self.assertNotEqual(without_method, self.stub_text)
        without_class = re.sub(r"\nclass Relocalizer:\n(    [^\n]*\n)+", "\n", self.stub_text)
        self.assertNotEqual(without_class, self.stub_text)
        errors = stubtest_errors(without_method)
        self.assertTrue(any("GlobalLocalizer.localize_now" in line for line in errors), errors)
        errors = stubtest_errors(without_class)
        self.assertTrue(any(line.startswith("keyplace.Relocalizer ") for line in errors), errors)

    def test_a_name_the_module_lacks_is_reported(self):
        extra = self.stub_text + "\ndef no_such_function(x: int) -> int: ...\n"
        errors = stubtest_errors(extra)
        self.assertTrue(any("keyplace.no_such_function" in line for line in errors), errors)


if __name__ == "__main__":
    unittest.main()
