#!/usr/bin/env bash
# Installs the Debian 12 packages keyplace needs to build, test and run its demo.
# Only missing packages are installed; prints nothing when everything is already there.
# Usage: scripts/install-deps.sh [--demo] [--check]
#   --demo   only what `make demo` builds (the library, the CLI, the streaming example)
#   --check  list what is missing, exit 1 if any
set -euo pipefail

demo_packages=(
  # toolchain
  build-essential cmake pkg-config git
  # libraries (DESIGN.md: dependencies)
  libeigen3-dev libnanoflann-dev libceres-dev zlib1g-dev libsqlite3-dev
  libcli11-dev libfmt-dev libspdlog-dev libtbb-dev libcairo2-dev libyaml-cpp-dev
  nlohmann-json3-dev
  # ROS 1 bags: the message headers and the chunk codecs
  libsensor-msgs-dev libnav-msgs-dev libtf2-msgs-dev libgeometry-msgs-dev libroslz4-dev libbz2-dev
  # ROS 2 bags: MCAP chunk codecs (LZ4 frames, zstd); sqlite3 and yaml-cpp are above
  liblz4-dev libzstd-dev
)

test_packages=(
  sqlite3
  # the Python module (pybind11, built for Debian's python3)
  pybind11-dev python3-dev
  # Debian's rosbag storage library is the tests' oracle and writes their bags (the library does
  # not link it)
  librosbag-storage-dev
  # the ROS 1 nodes (ros/): roscpp, tf2_ros and the service and status messages; their live
  # tests run a roscore (ros-core), rosbag play and a rospy subscriber
  libroscpp-dev libtf2-ros-dev libstd-srvs-dev libdiagnostic-msgs-dev ros-core python3-rospy
  python3-rosbag python3-geometry-msgs python3-diagnostic-msgs python3-std-srvs python3-nav-msgs
  # the CLI tests read JSON with python3; the Python module's tests and example (Debian's
  # /usr/bin/python3) use numpy and matplotlib
  python3 python3-numpy python3-matplotlib
  # the Python module's type stubs are checked with mypy's stubtest; pip installs the checkout
  python3-mypy python3-venv python3-pip
  # tests, benchmarks, style
  libgtest-dev libgmock-dev libbenchmark-dev clang-format clang-tidy
  # make fuzz: clang and its libFuzzer and sanitizer runtimes
  clang libclang-rt-14-dev
  # the report check opens the page in headless Chromium (scripts/check-report.sh)
  chromium
)

demo_only=false
check_only=false
for argument in "$@"; do
  case "$argument" in
    --demo) demo_only=true ;;
    --check) check_only=true ;;
    *)
      echo "install-deps: unknown option '$argument' (expected --demo or --check)" >&2
      exit 2
      ;;
  esac
done

packages=("${demo_packages[@]}")
$demo_only || packages+=("${test_packages[@]}")

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done

if $check_only; then
  if [ ${#missing[@]} -gt 0 ]; then
    echo "missing: ${missing[*]}"
    exit 1
  fi
  exit 0
fi

[ ${#missing[@]} -eq 0 ] && exit 0

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then
    sudo_cmd=(sudo)
  else
    echo "install-deps: not root and no sudo; install these packages yourself: ${missing[*]}" >&2
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
