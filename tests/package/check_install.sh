#!/usr/bin/env bash
# Installs keyplace from BUILD_DIR into a temporary prefix, builds a consumer project against it
# with find_package(keyplace) and runs it on the bundled log.
set -euo pipefail
build_dir=$1
source_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build_dir" --prefix "$work/prefix" >/dev/null
cmake -S "$source_dir/tests/package/consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$work/prefix" \
  -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/consumer" >/dev/null
scans=$("$work/consumer/consumer" "$source_dir/data/fr079-corrected.log.gz")
if [ "$scans" != "1464" ]; then
  echo "consumer read $scans scans, expected 1464" >&2
  exit 1
fi
echo "installed package works: consumer read $scans scans"
