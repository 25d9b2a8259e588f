"""`pip install` of the checkout into a fresh virtual environment, as docs/PYTHON.md tells users
(no network: --no-index, numpy from Debian's python3-numpy through --system-site-packages).

Usage: pip_install.py PYTHON SOURCE_DIR BUILD_DIR VERSION SCRATCH_PARENT

KEYPLACE_BUILD_DIR=BUILD_DIR makes the backend reuse the project's build (only the up-to-date
check of keyplace_python runs). The module is imported outside the source and build trees with
no PYTHONPATH, so it can only come from the environment pip installed it into. With mypy
(python3-mypy), `mypy --strict` type-checks typed_usage.py there against the installed stubs,
as a type checker finds them (PEP 561), and must name a stub's type in an error it reports.
Then keyplace is uninstalled, and every file pip put there must be gone (the installed RECORD
lists them).
"""

import csv
import os
import shutil
import subprocess
import sys
import tempfile

python, source_dir, build_dir, version, scratch_parent = sys.argv[1:6]


def run(command, **options):
    print("$", " ".join(command), flush=True)
    result = subprocess.run(command, capture_output=True, text=True, check=False, **options)
    print(result.stdout + result.stderr, flush=True)
    if result.returncode != 0:
        sys.exit(f"FAILED (exit {result.returncode}): {' '.join(command)}")
    return result.stdout


def type_checks(venv_python, folder, environment, cache_dir):
    """(ok, what) checks of the installed stubs with mypy in the environment, or none without
    mypy. Both files are copied into `folder`, outside the trees, so that only the installed
    stubs can be found."""
    has_mypy = subprocess.run([venv_python, "-c", "import mypy"], env=environment,
                              capture_output=True, check=False).returncode == 0
    if not has_mypy:
        print("skip: mypy (python3-mypy) is not installed; the installed stubs are not checked")
        return []
    usage = os.path.join(folder, "typed_usage.py")
    shutil.copyfile(os.path.join(os.path.dirname(os.path.abspath(__file__)), "typed_usage.py"),
                    usage)
    wrong = os.path.join(folder, "wrong_type.py")
    with open(wrong, "w", encoding="utf-8") as out:
        out.write("import keyplace\n\nresult: str = keyplace.merge_maps('a.kpm', 'b.kpm')\n")
    mypy = [venv_python, "-m", "mypy", "--strict", "--config-file", os.devnull,
            "--cache-dir", cache_dir]
    outputs = []
    for path in (usage, wrong):
        print("$", " ".join(mypy + [path]), flush=True)
        result = subprocess.run(mypy + [path], cwd=folder, env=environment, capture_output=True,
                                text=True, check=False)
        print(result.stdout + result.stderr, flush=True)
        outputs.append((result.returncode, result.stdout))
    return [
        (outputs[0][0] == 0, "mypy --strict accepts typed_usage.py with the installed stubs"),
        (outputs[1][0] == 1 and 'expression has type "MergeResult"' in outputs[1][1],
         "mypy reports a wrong use with the stubs' type (merge_maps -> MergeResult)"),
    ]


os.makedirs(scratch_parent, exist_ok=True)
scratch = tempfile.mkdtemp(prefix="pip-install-", dir=scratch_parent)
try:
    # Only this environment: no PYTHONPATH (ctest points it at build/python), no user site, no
    # index, and a pip cache inside the scratch folder.
    environment = {key: value for key, value in os.environ.items()
                   if key not in ("PYTHONPATH", "PIP_INDEX_URL", "PIP_EXTRA_INDEX_URL")}
    environment.update(PYTHONNOUSERSITE="1", PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1",
                       PIP_CACHE_DIR=os.path.join(scratch, "pip-cache"),
                       KEYPLACE_BUILD_DIR=os.path.abspath(build_dir))
    venv = os.path.join(scratch, "venv")
    run([python, "-m", "venv", "--system-site-packages", venv], env=environment)
    venv_python = os.path.join(venv, "bin", "python")
    pip = [venv_python, "-m", "pip"]

    run(pip + ["install", "--no-index", source_dir], env=environment)

    # From a folder of its own: the current directory is on sys.path first.
    elsewhere = os.path.join(scratch, "elsewhere")
    os.mkdir(elsewhere)
    found = run([venv_python, "-c",
                 "import keyplace, numpy, sysconfig; print(keyplace.__version__); "
                 "print(keyplace.__file__); print('default' in keyplace.config_presets()); "
                 "print(sysconfig.get_paths()['platlib'])"],
                cwd=elsewhere, env=environment).split("\n")
    module_path = os.path.realpath(found[1])
    stub_path = os.path.join(found[3], "keyplace-stubs", "__init__.pyi")
    checks = [
        (found[0] == version, f"keyplace.__version__ is {found[0]!r}, CMake's version {version}"),
        (module_path.startswith(os.path.realpath(venv) + os.sep),
         f"keyplace is imported from {module_path}, inside the environment {venv}"),
        (found[2] == "True", "the installed module answers a library call"),
    ]
    with open(os.path.join(source_dir, "python", "keyplace.pyi"), "rb") as source_stub:
        stub_installed = os.path.isfile(stub_path) and open(stub_path, "rb").read() == \
            source_stub.read()
    checks.append((stub_installed, f"the type stubs are installed as {stub_path}"))
    checks += type_checks(venv_python, elsewhere, environment, os.path.join(scratch, "mypy"))
    with open(os.path.join(found[3], f"keyplace-{version}.dist-info", "RECORD"),
              encoding="utf-8") as record:
        installed = [os.path.normpath(os.path.join(found[3], row[0]))
                     for row in csv.reader(record) if row]
    shown = run(pip + ["show", "keyplace"], env=environment).splitlines()
    checks.append(("Requires: numpy" in shown, "pip show keyplace lists numpy as its requirement"))
    checks.append((f"Version: {version}" in shown, f"pip show keyplace says version {version}"))

    run(pip + ["uninstall", "-y", "keyplace"], env=environment)
    checks.append((not os.path.exists(module_path), f"pip uninstall removed {module_path}"))
    checks.append((not os.path.exists(stub_path), f"pip uninstall removed {stub_path}"))
    still_there = [path for path in installed if os.path.exists(path)]
    checks.append((not still_there, f"pip uninstall removed the {len(installed)} files of RECORD "
                   f"(left: {still_there})"))
    left = subprocess.run([venv_python, "-c", "import keyplace"], cwd=elsewhere, env=environment,
                          capture_output=True, check=False)
    checks.append((left.returncode != 0, "keyplace is not importable after pip uninstall"))

    failed = [what for ok, what in checks if not ok]
    for ok, what in checks:
        print("ok  " if ok else "FAIL", what)
    if failed:
        sys.exit(f"pip install: {len(failed)} check(s) failed")
    print("pip install: installed, imported, uninstalled")
finally:
    shutil.rmtree(scratch, ignore_errors=True)
