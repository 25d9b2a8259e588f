"""The PEP 517 build backend of `pip install .` (docs/PYTHON.md, "Build, import, install").

It lives in the tree and needs only the standard library: pip installs a backend's requirements
from PyPI into an isolated environment before building, which fails without a network, and this
one has none (pyproject.toml: requires = []). It builds the CMake target keyplace_python for the
running interpreter and zips the extension into a wheel; the version is the one of project() in
CMakeLists.txt, the same the module reports as keyplace.__version__.

Environment:
  KEYPLACE_BUILD_DIR   an existing CMake build folder to build the module in (its options are
                       kept; only `cmake --build --target keyplace_python` runs there). Default:
                       build-pip/ in the checkout, configured with everything but the module off.
  KEYPLACE_BUILD_JOBS  parallel compile jobs (default: the number of processors).
"""

import base64
import csv
import hashlib
import io
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import time
import zipfile

PROJECT_NAME = "keyplace"
SUMMARY = "2D-LiDAR place recognition (FLIRT keypoints, submaps, global localization)"
DEPENDENCIES = ["numpy"]
STUB_PACKAGE = PROJECT_NAME + "-stubs"
# What the default build folder enables: the module and the library it links, nothing else.
CONFIGURE_OPTIONS = [
    "-DCMAKE_BUILD_TYPE=Release",
    "-DKEYPLACE_BUILD_TESTS=OFF",
    "-DKEYPLACE_BUILD_BENCHMARKS=OFF",
    "-DKEYPLACE_BUILD_APPS=OFF",
    "-DKEYPLACE_BUILD_EXAMPLES=OFF",
    "-DKEYPLACE_BUILD_ROS=OFF",
]
# Zip entries get this date, so that the same files give the same wheel bytes.
ZIP_DATE_TIME = (1980, 1, 1, 0, 0, 0)


class UnsupportedOperation(Exception):
    """Raised by a hook this backend does not offer (pip's hook runner knows the name)."""


class BuildError(Exception):
    """A build step failed; the message says which and where its output is."""


# ---------------------------------------------------------------------------------------------
# PEP 517 / PEP 660 hooks


def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_editable(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    return write_dist_info(metadata_directory, project_version(source_root()))


def prepare_metadata_for_build_editable(metadata_directory, config_settings=None):
    return prepare_metadata_for_build_wheel(metadata_directory, config_settings)


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    root = source_root()
    extension = build_extension(root)
    stub = read_bytes(os.path.join(root, "python", "keyplace.pyi"))
    # The type stubs go where type checkers look for a module's stubs (PEP 561).
    files = {os.path.basename(extension): read_bytes(extension),
             STUB_PACKAGE + "/__init__.pyi": stub}
    return write_wheel(wheel_directory, project_version(root), wheel_tag(), files)


def build_editable(wheel_directory, config_settings=None, metadata_directory=None):
    # The editable install is a .pth file naming the build folder's python/, where the module is
    # built: rebuilding the target there changes what `import keyplace` loads, no reinstall.
    root = source_root()
    extension = build_extension(root)
    pth_line = os.path.dirname(os.path.abspath(extension)) + "\n"
    files = {"_keyplace_editable.pth": pth_line.encode()}
    return write_wheel(wheel_directory, project_version(root), wheel_tag(), files)


def build_sdist(sdist_directory, config_settings=None):
    raise UnsupportedOperation(
        "keyplace has no source distribution: install from a checkout (`pip install .`) "
        "or build a wheel there (`pip wheel --no-deps .`)")


# ---------------------------------------------------------------------------------------------
# Project facts


def source_root():
    """The checkout: PEP 517 runs hooks in the source tree's root."""
    root = os.getcwd()
    if not os.path.isfile(os.path.join(root, "CMakeLists.txt")):
        raise BuildError(f"{root} is not the keyplace checkout (no CMakeLists.txt)")
    return root


def project_version(root):
    """The x.y.z of `project(keyplace VERSION x.y.z ...)` in the top CMakeLists.txt."""
    path = os.path.join(root, "CMakeLists.txt")
    with open(path, encoding="utf-8") as cmake_lists:
        match = re.search(r"^\s*project\s*\(\s*keyplace\s+VERSION\s+([0-9]+(?:\.[0-9]+)*)",
                          cmake_lists.read(), re.MULTILINE | re.IGNORECASE)
    if not match:
        raise BuildError(f"{path}: no `project(keyplace VERSION x.y.z)` to take the version from")
    return match.group(1)


def wheel_tag():
    """python-abi-platform of the running interpreter, e.g. cp311-cp311-linux_x86_64.

    The extension is built for exactly this interpreter (its EXT_SUFFIX), so the wheel says so.
    """
    if sys.implementation.name != "cpython":
        raise BuildError(f"the keyplace module is built for CPython, not {sys.implementation.name}")
    python = f"cp{sys.version_info.major}{sys.version_info.minor}"
    abi = python + ("d" if sysconfig.get_config_var("Py_DEBUG") else "")
    platform = re.sub(r"[^A-Za-z0-9]", "_", sysconfig.get_platform())
    return f"{python}-{abi}-{platform}"


def metadata_text(version):
    minor_version = f"{sys.version_info.major}.{sys.version_info.minor}"
    lines = [
        "Metadata-Version: 2.1",
        f"Name: {PROJECT_NAME}",
        f"Version: {version}",
        f"Summary: {SUMMARY}",
        # The wheel holds an extension compiled for this minor version only.
        f"Requires-Python: =={minor_version}.*",
    ]
    lines += [f"Requires-Dist: {name}" for name in DEPENDENCIES]
    return "\n".join(lines) + "\n"


def wheel_file_text(tag):
    return "\n".join([
        "Wheel-Version: 1.0",
        "Generator: keyplace_backend (python/build_backend)",
        "Root-Is-Purelib: false",
        f"Tag: {tag}",
    ]) + "\n"


def dist_info_name(version):
    return f"{PROJECT_NAME}-{version}.dist-info"


def write_dist_info(directory, version):
    dist_info = os.path.join(directory, dist_info_name(version))
    os.makedirs(dist_info, exist_ok=True)
    for name, text in [("METADATA", metadata_text(version)),
                       ("WHEEL", wheel_file_text(wheel_tag()))]:
        with open(os.path.join(dist_info, name), "w", encoding="utf-8") as out:
            out.write(text)
    return os.path.basename(dist_info)


# ---------------------------------------------------------------------------------------------
# The wheel


def record_hash(data):
    """RECORD's digest: sha256, urlsafe base64 without padding (the wheel specification)."""
    digest = hashlib.sha256(data).digest()
    return "sha256=" + base64.urlsafe_b64encode(digest).rstrip(b"=").decode("ascii")


def write_wheel(wheel_directory, version, tag, files):
    """Writes keyplace-VERSION-TAG.whl holding `files` ({name in the wheel: bytes}) at its root
    and the dist-info folder (METADATA, WHEEL, RECORD); returns the wheel's file name."""
    dist_info = dist_info_name(version)
    entries = dict(files)
    entries[f"{dist_info}/METADATA"] = metadata_text(version).encode()
    entries[f"{dist_info}/WHEEL"] = wheel_file_text(tag).encode()

    record = io.StringIO()
    writer = csv.writer(record, lineterminator="\n")
    for name, data in entries.items():
        writer.writerow([name, record_hash(data), len(data)])
    writer.writerow([f"{dist_info}/RECORD", "", ""])  # a file cannot hold its own hash
    entries[f"{dist_info}/RECORD"] = record.getvalue().encode()

    wheel_name = f"{PROJECT_NAME}-{version}-{tag}.whl"
    os.makedirs(wheel_directory, exist_ok=True)
    wheel_path = os.path.join(wheel_directory, wheel_name)
    partial_path = wheel_path + ".partial"
    with zipfile.ZipFile(partial_path, "w", zipfile.ZIP_DEFLATED) as wheel:
        for name, data in entries.items():
            info = zipfile.ZipInfo(name, ZIP_DATE_TIME)
            executable = name.endswith(".so")
            info.external_attr = (0o755 if executable else 0o644) << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            wheel.writestr(info, data)
    os.replace(partial_path, wheel_path)  # no half-written wheel under the final name
    return wheel_name


def read_bytes(path):
    with open(path, "rb") as source:
        return source.read()


# ---------------------------------------------------------------------------------------------
# The CMake build


def progress(message):
    # pip shows a backend's output with -v and when the build fails; stdout is its hook channel
    # in some front ends, so everything goes to stderr.
    print(f"keyplace: {message}", file=sys.stderr, flush=True)


def build_extension(root):
    """Builds keyplace_python and returns the path of keyplace<EXT_SUFFIX>."""
    cmake = shutil.which("cmake")
    if cmake is None:
        raise BuildError("cmake not found on PATH: install it (scripts/install-deps.sh, or "
                         "`apt-get install cmake`) to build the keyplace module")
    given_build_dir = os.environ.get("KEYPLACE_BUILD_DIR")
    build_dir = os.path.abspath(os.path.join(root, given_build_dir or "build-pip"))
    log_path = os.path.join(build_dir, "keyplace-pip-build.log")
    os.makedirs(build_dir, exist_ok=True)
    started = time.monotonic()
    with open(log_path, "w", encoding="utf-8") as log:
        # A build folder someone gave keeps its options (it may be the developer's own, with
        # tests on); one without a cache, and our own build-pip/, are configured here.
        has_cache = os.path.isfile(os.path.join(build_dir, "CMakeCache.txt"))
        if not (given_build_dir and has_cache):
            run_logged([cmake, "-S", root, "-B", build_dir, *CONFIGURE_OPTIONS,
                        f"-DPython3_EXECUTABLE={sys.executable}"], log, log_path)
        jobs = os.environ.get("KEYPLACE_BUILD_JOBS") or str(os.cpu_count() or 1)
        run_logged([cmake, "--build", build_dir, "--target", "keyplace_python", "-j", jobs],
                   log, log_path)
    progress(f"module built in {time.monotonic() - started:.0f} s ({build_dir})")

    extension = os.path.join(build_dir, "python",
                             PROJECT_NAME + sysconfig.get_config_var("EXT_SUFFIX"))
    if not os.path.isfile(extension):
        built = [name for name in os.listdir(os.path.join(build_dir, "python"))
                 if name.startswith(PROJECT_NAME + ".")] if os.path.isdir(
                     os.path.join(build_dir, "python")) else []
        raise BuildError(
            f"{extension} was not built for this interpreter ({sys.executable}); the build "
            f"folder has {built or 'no module'}: its CMake cache is for another Python "
            "(Python3_EXECUTABLE), or the module was skipped (pybind11-dev or python3-dev "
            f"missing; see {log_path})")
    return extension


def run_logged(command, log, log_path):
    """Runs command, copying its output to stderr and the log; a failure names both."""
    shown = " ".join(command)
    progress(f"running {shown}")
    log.write(f"$ {shown}\n")
    try:
        process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                   text=True, errors="replace")
    except OSError as error:
        raise BuildError(f"cannot run {shown}: {error}") from error
    for line in process.stdout:
        sys.stderr.write(line)
        log.write(line)
    if process.wait() != 0:
        log.flush()
        raise BuildError(f"`{shown}` failed (exit {process.returncode}); its output is above "
                         f"and in {log_path}")
