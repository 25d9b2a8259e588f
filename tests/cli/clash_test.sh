#!/usr/bin/env bash
# Every command protects every input from every output (issue 31): each output option of each
# command, given one of the command's inputs under its own name, as ./name, through a hard link and
# through a symbolic link, is refused before any work, naming the option, and the input is left
# byte for byte as it was. Formerly `keyplace info LOG --json LOG` replaced the log with its JSON.
# Also: a file of an input rosbag2 directory is refused, and a missing input exits with status 1.
# Usage: clash_test.sh KEYPLACE_BINARY SOURCE_DIR
set -uo pipefail
keyplace=$1
source_dir=$2
log="$source_dir/data/fr079-corrected.log.gz"
# shellcheck source=../support/script_checks.sh
source "$source_dir/tests/support/script_checks.sh"
export KEYPLACE_PROGRESS=0

cd "$work" || exit 1
mkdir pristine
# Small inputs: nothing runs, but the map must be a map for the commands that check it first.
zcat "$log" | head -400 >pristine/small.log
"$keyplace" map pristine/small.log --out pristine/small.kpm >/dev/null 2>&1 ||
  fail "map of the small log"
cp pristine/small.kpm pristine/other.kpm
"$keyplace" dump-config >pristine/config.yaml

# refused NAME INPUT COMMAND...: COMMAND has the placeholder @ where the output goes; it is run
# with @ replaced by INPUT, ./INPUT, a hard link and a symbolic link to INPUT, each time from a
# fresh copy of the inputs; each must fail with "would destroy the input" and leave INPUT as it was.
refused() {
  local name=$1 input=$2
  shift 2
  local alias
  for alias in same dot hard symbolic; do
    rm -rf run && cp -r pristine run
    local target="run/$input"
    case $alias in
      dot) target="./run/$input" ;;
      # The links keep the input's name at their end: --grid wants a .yaml.
      hard) ln "run/$input" "run/hard-$input" && target="run/hard-$input" ;;
      symbolic) ln -s "$input" "run/symbolic-$input" && target="run/symbolic-$input" ;;
    esac
    local args=() arg
    for arg in "$@"; do
      if [ "$arg" = @ ]; then args+=("$target"); else args+=("${arg//@IN@/run}"); fi
    done
    fails_with "$name ($alias)" "would destroy the input" "$keyplace" "${args[@]}"
    if ! cmp -s "run/$input" "pristine/$input"; then fail "$name ($alias): $input changed"; fi
  done
}

L=@IN@/small.log
M=@IN@/small.kpm
C=@IN@/config.yaml
refused "info --json onto the log" small.log info "$L" --json @
refused "info --json onto the map" small.kpm info "$M" --json @
refused "info --check --json onto the map" small.kpm info "$M" --check --json @
refused "info --json onto --config" config.yaml info "$L" --config "$C" --json @
for option in --tsv --json; do
  refused "features $option" small.log features "$L" $option @
done
for option in --out --steps --json --relation-errors; do
  refused "odometry $option" small.log odometry "$L" $option @
done
for option in --out --json --png --svg; do
  refused "map $option" small.log map "$L" $option @
done
refused "map --json onto --config" config.yaml map "$L" --config "$C" --json @
for option in --json --queries --curve --reliability; do
  refused "localize $option onto --log" small.log localize --map "$M" --log "$L" $option @
  refused "localize $option onto --map" small.kpm localize --map "$M" --log "$L" $option @
done
for option in --json --tsv --fixes --figure --initialpose; do
  refused "relocalize $option onto --log" small.log relocalize --map "$M" --log "$L" $option @
  refused "relocalize $option onto --map" small.kpm relocalize --map "$M" --log "$L" $option @
done
for option in --out --trajectory --json --loops; do
  refused "slam $option" small.log slam "$L" $option @
done
refused "slam --grid onto --config" config.yaml slam "$L" --config "$C" --grid @
refused "map --grid onto --config" config.yaml map "$L" --config "$C" --grid @
refused "merge --out onto map a" small.kpm merge "$M" @IN@/other.kpm --out @
refused "merge --out onto map b" other.kpm merge "$M" @IN@/other.kpm --out @
refused "merge --json onto map a" small.kpm merge "$M" @IN@/other.kpm --out @IN@/ab.kpm --json @
refused "merge --json onto map b" other.kpm merge "$M" @IN@/other.kpm --out @IN@/ab.kpm --json @
refused "merge --json onto --log" small.log merge "$M" @IN@/other.kpm --out @IN@/ab.kpm \
  --log "$L" --json @
refused "sweep mapping --json" small.log sweep mapping --log "$L" --out @IN@/sweep --json @
refused "sweep place --json" small.log sweep place --map-log "$L" --out @IN@/sweep --json @
refused "dump-config --json" config.yaml dump-config --config "$C" --json @
# The report reads its logs from --data: a file there is an input though no option names it.
refused "report --json onto a file of --data" small.log report --data @IN@ --out @IN@/report \
  --no-run --json @

# A file of an input rosbag2 directory (its metadata.yaml, its storage files).
cp -r "$source_dir/tests/data/ros2/mcap-none" bagdir
if [ -f bagdir/metadata.yaml ]; then
  cp bagdir/metadata.yaml metadata-before.yaml
  fails_with "info --json into the input bag directory" "is a file of the input bag directory" \
    "$keyplace" info bagdir --json bagdir/metadata.yaml
  check "metadata.yaml unchanged" cmp bagdir/metadata.yaml metadata-before.yaml
else
  fail "the rosbag2 fixture tests/data/ros2/mcap-none has no metadata.yaml"
fi

# The same map twice (by another name too) is refused before any work; a copy is another map.
ln -s small.kpm pristine/link.kpm
fails_with "merge A A" "is the same file as" "$keyplace" merge pristine/small.kpm \
  pristine/link.kpm --out merged.kpm
check "merge A A writes nothing" test ! -e merged.kpm

# A missing input is a usage error with the usual status 1 (CLI11's own code was 105).
"$keyplace" info "$work/missing.log" >/dev/null 2>missing.err
status=$?
check "a missing path exits with status 1" test "$status" = 1
check "a missing path is a keyplace error" grep -q "^keyplace: error: .*missing.log" missing.err

finish clash
