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

same_figures() {  # same_figures A B: two JSON (.json) or TSV outputs equal but for times
  # (keys and columns with "seconds" in the name); prints the first differences.
  /usr/bin/python3 - "$1" "$2" <<'EOF'
import csv, json, sys
def drop(x):
    if isinstance(x, dict):
        return {k: drop(v) for k, v in x.items() if 'seconds' not in k}
    if isinstance(x, list):
        return [drop(v) for v in x]
    return x
def load(path):
    with open(path) as f:
        if path.endswith('.json'):
            return drop(json.load(f))
        return [drop(row) for row in csv.DictReader(f, delimiter='\t')]
a, b = load(sys.argv[1]), load(sys.argv[2])
if a != b:
    if isinstance(a, dict) and isinstance(b, dict):
        keys = sorted(k for k in set(a) | set(b) if a.get(k) != b.get(k))
    else:
        keys = [i for i in range(max(len(a), len(b))) if i >= len(a) or i >= len(b) or a[i] != b[i]]
    print('differ at', keys[:10])
    sys.exit(1)
EOF
}

finish() {  # finish NAME: prints the counts; the script's status is 0 only without failures
  echo "$1: $passed passed, $failed failed"
  [ "$failed" -eq 0 ]
}
