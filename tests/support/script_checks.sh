# Shared by the shell tests (source it): a temporary directory $work removed on exit, pass/fail
# counters, and the checks. End a test script with `finish NAME`.

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
passed=0
failed=0

ok() { passed=$((passed + 1)); }

fail() {  # fail DESCRIPTION
  failed=$((failed + 1))
  echo "FAILED: $1"
}

check() {  # check NAME COMMAND...: the command must succeed
  local name=$1
  shift
  if "$@" >"$work/out" 2>"$work/err"; then
    ok
  else
    fail "$name"
    sed 's/^/  | /' "$work/out" "$work/err" | head -20
  fi
}

fails_with() {  # fails_with NAME FRAGMENT COMMAND...: must fail, stderr containing FRAGMENT
  local name=$1 fragment=$2
  shift 2
  if "$@" >"$work/out" 2>"$work/err"; then
    fail "$name (succeeded, expected an error)"
  elif grep -qF -- "$fragment" "$work/err"; then
    ok
  else
    fail "$name (error does not mention '$fragment')"
    sed 's/^/  | /' "$work/err" | head -10
  fi
}

finish() {  # finish NAME: prints the counts; the script's status is 0 only without failures
  echo "$1: $passed passed, $failed failed"
  [ "$failed" -eq 0 ]
}
