#!/usr/bin/env bash
# scripts/lint-nodiscard.py on tests/lint/nodiscard_bad.hpp.in: it reports exactly the lines marked
# BAD (file:line), fails, and --fix makes the file pass.
set -euo pipefail
script=$1 sample=$2 work=$3
mkdir -p "$work"
cp "$sample" "$work/sample.hpp"
expected=$(grep -n '// BAD' "$work/sample.hpp" | cut -d: -f1 | sed "s|^|$work/sample.hpp:|" | sort)
set +e
out=$(python3 "$script" "$work/sample.hpp")
rc=$?
set -e
echo "$out"
[ "$rc" -eq 1 ] || { echo "FAIL: exit code $rc, not 1, on a file with undecorated declarations"; exit 1; }
reported=$(echo "$out" | grep -o "^$work/sample.hpp:[0-9]*" | sort)
if [ "$reported" != "$expected" ]; then
  echo "FAIL: reported lines differ from the lines marked BAD"
  diff <(echo "$expected") <(echo "$reported") || true
  exit 1
fi
python3 "$script" --fix "$work/sample.hpp" >/dev/null
python3 "$script" "$work/sample.hpp" || { echo "FAIL: --fix left declarations without [[nodiscard]]"; exit 1; }
grep -q '^template <class T> \[\[nodiscard\]\] Expected<T> make(T value);' "$work/sample.hpp" \
  || { echo "FAIL: --fix put the attribute elsewhere than after the template head"; exit 1; }
echo "PASS: $(echo "$expected" | wc -l) declarations reported with their lines, none else; --fix fixes them"
