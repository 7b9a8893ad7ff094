#!/usr/bin/env bash
# scripts/lint-functions.py on generated samples: a function of 151 lines (its lambda included) is
# reported with its file, line and name, and the check fails; one of 150 lines passes.
set -euo pipefail
script=$1 work=$2
mkdir -p "$work"
# A function of `lines` lines in total: its head, a lambda, `lines - 6` statements, the closing brace.
write() {
  local file=$1 name=$2 lines=$3
  {
    echo "int $name(int x) {"
    echo "  const auto twice = [](int v) {"
    echo "    return 2 * v;"
    echo "  };"
    for ((i = 0; i < lines - 6; ++i)); do echo "  x = twice(x) + $i;"; done
    echo "  return x;"
    echo "}"
  } >"$file"
}
write "$work/long.cpp" too_long 151
write "$work/short.cpp" just_right 150
[ "$(wc -l <"$work/long.cpp")" -eq 151 ] || { echo "FAIL: the sample is not 151 lines"; exit 1; }
set +e
out=$(python3 "$script" "$work/long.cpp" "$work/short.cpp")
rc=$?
set -e
echo "$out"
[ "$rc" -eq 1 ] || { echo "FAIL: exit code $rc, not 1, with a function of 151 lines"; exit 1; }
echo "$out" | grep -q "^$work/long.cpp:1: too_long: 151 lines (at most 150)$" \
  || { echo "FAIL: the long function is not reported with its file, line, name and size"; exit 1; }
if echo "$out" | grep -q just_right; then echo "FAIL: a function of 150 lines is reported"; exit 1; fi
python3 "$script" "$work/short.cpp" || { echo "FAIL: a function of 150 lines fails the check"; exit 1; }
echo "PASS: 151 lines reported and failed, 150 lines pass"
