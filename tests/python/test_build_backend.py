"""The wheel writer of `pip install .`'s backend (python/build_backend/keyplace_backend.py): what
pip checks when it installs a wheel (name, tag, RECORD), without building anything.
`python.pip_install` (pip_install.py) runs the whole `pip install` through it."""

import base64
import csv
import hashlib
import io
import os
import sys
import sysconfig
import tempfile
import unittest
import zipfile

from support import SOURCE_DIR

sys.path.insert(0, os.path.join(SOURCE_DIR, "python", "build_backend"))
import keyplace_backend  # noqa: E402  (found through the path above)

FAKE_EXTENSION = "keyplace" + sysconfig.get_config_var("EXT_SUFFIX")


def write_fake_wheel(folder, version="1.2.3"):
    files = {FAKE_EXTENSION: b"\x7fELF not really an extension" * 100}
    name = keyplace_backend.write_wheel(folder, version, keyplace_backend.wheel_tag(), files)
    return os.path.join(folder, name), files


class WheelWriter(unittest.TestCase):
    def setUp(self):
        self.folder = tempfile.TemporaryDirectory()
        self.addCleanup(self.folder.cleanup)

    def test_record_lists_every_other_file_with_its_sha256_and_size(self):
        wheel_path, _ = write_fake_wheel(self.folder.name)
        with zipfile.ZipFile(wheel_path) as wheel:
            names = set(wheel.namelist())
            record_name = "keyplace-1.2.3.dist-info/RECORD"
            rows = list(csv.reader(io.StringIO(wheel.read(record_name).decode())))
            self.assertEqual({row[0] for row in rows}, names)
            for path, digest, size in rows:
                if path == record_name:
                    self.assertEqual((digest, size), ("", ""))
                    continue
                data = wheel.read(path)
                expected = base64.urlsafe_b64encode(hashlib.sha256(data).digest())
                self.assertEqual(digest, "sha256=" + expected.rstrip(b"=").decode(), path)
                self.assertEqual(int(size), len(data), path)

    def test_wheel_holds_the_extension_at_its_root_and_says_so(self):
        wheel_path, files = write_fake_wheel(self.folder.name)
        with zipfile.ZipFile(wheel_path) as wheel:
            self.assertEqual(wheel.read(FAKE_EXTENSION), files[FAKE_EXTENSION])
            wheel_file = wheel.read("keyplace-1.2.3.dist-info/WHEEL").decode()
            metadata = wheel.read("keyplace-1.2.3.dist-info/METADATA").decode().splitlines()
        self.assertIn("Root-Is-Purelib: false", wheel_file)
        self.assertIn(f"Tag: {keyplace_backend.wheel_tag()}", wheel_file)
        self.assertIn("Name: keyplace", metadata)
        self.assertIn("Version: 1.2.3", metadata)
        self.assertIn("Requires-Dist: numpy", metadata)
        minor = f"{sys.version_info.major}.{sys.version_info.minor}"
        self.assertIn(f"Requires-Python: =={minor}.*", metadata)

    def test_wheel_name_is_project_version_and_the_interpreters_tag(self):
        wheel_path, _ = write_fake_wheel(self.folder.name)
        python = f"cp{sys.version_info.major}{sys.version_info.minor}"
        platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
        self.assertEqual(os.path.basename(wheel_path),
                         f"keyplace-1.2.3-{python}-{python}-{platform}.whl")
        # The tag names the interpreter the extension suffix is for (cpython-311 <-> cp311).
        self.assertIn(f"cpython-{python[2:]}", sysconfig.get_config_var("EXT_SUFFIX"))

    def test_same_files_give_the_same_wheel_bytes(self):
        first, _ = write_fake_wheel(os.path.join(self.folder.name, "a"))
        second, _ = write_fake_wheel(os.path.join(self.folder.name, "b"))
        with open(first, "rb") as a, open(second, "rb") as b:
            self.assertEqual(a.read(), b.read())


class BuildWheel(unittest.TestCase):
    """build_wheel, the hook pip calls, with the CMake build replaced by a file of ours: what it
    puts in the wheel, and where."""

    def test_wheel_holds_the_built_extension_and_the_stubs_as_a_stub_package(self):
        with tempfile.TemporaryDirectory() as folder:
            extension = os.path.join(folder, FAKE_EXTENSION)
            with open(extension, "wb") as out:
                out.write(b"\x7fELF the extension CMake built")
            built = []

            def fake_build(root):
                built.append(root)
                return extension

            real_build, real_cwd = keyplace_backend.build_extension, os.getcwd()
            keyplace_backend.build_extension = fake_build
            try:
                os.chdir(SOURCE_DIR)  # PEP 517 runs hooks in the checkout
                name = keyplace_backend.build_wheel(os.path.join(folder, "wheels"))
            finally:
                keyplace_backend.build_extension = real_build
                os.chdir(real_cwd)
            with zipfile.ZipFile(os.path.join(folder, "wheels", name)) as wheel:
                contents = {path: wheel.read(path) for path in wheel.namelist()}
        version = keyplace_backend.project_version(SOURCE_DIR)
        dist_info = f"keyplace-{version}.dist-info"
        self.assertEqual(len(built), 1)
        self.assertEqual(os.path.realpath(built[0]), os.path.realpath(SOURCE_DIR))
        self.assertEqual(set(contents), {FAKE_EXTENSION, "keyplace-stubs/__init__.pyi",
                                         f"{dist_info}/METADATA", f"{dist_info}/WHEEL",
                                         f"{dist_info}/RECORD"})
        self.assertEqual(contents[FAKE_EXTENSION], b"\x7fELF the extension CMake built")
        with open(os.path.join(SOURCE_DIR, "python", "keyplace.pyi"), "rb") as stub:
            self.assertEqual(contents["keyplace-stubs/__init__.pyi"], stub.read())
        self.assertIn("Requires-Dist: numpy", contents[f"{dist_info}/METADATA"].decode())


class ProjectFacts(unittest.TestCase):
    def test_version_is_the_one_the_module_reports(self):
        import keyplace  # the module of this build (PYTHONPATH), built with PROJECT_VERSION
        self.assertEqual(keyplace_backend.project_version(SOURCE_DIR), keyplace.__version__)

    def test_a_cmake_lists_without_a_project_version_is_an_error_naming_it(self):
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "CMakeLists.txt")
            with open(path, "w") as cmake_lists:
                cmake_lists.write("project(keyplace LANGUAGES CXX)\n")
            with self.assertRaisesRegex(keyplace_backend.BuildError, path):
                keyplace_backend.project_version(folder)

    def test_no_source_distribution(self):
        with self.assertRaisesRegex(keyplace_backend.UnsupportedOperation, "pip install"):
            keyplace_backend.build_sdist(tempfile.gettempdir())


if __name__ == "__main__":
    unittest.main()
