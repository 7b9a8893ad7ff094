#!/usr/bin/env bash
# scripts/lint-names.py on a sample (names_bad.md.in): it reports exactly the three names of things
# that do not exist (a type, a file, a command), each with its line, and fails; the tree itself is
# clean (the check `make lint` runs).
#   names_test.sh SOURCE_DIR
set -uo pipefail
src="$1"
cd "$src" || exit 2
out=$(python3 scripts/lint-names.py tests/lint/names_bad.md.in)
rc=$?
expected="tests/lint/names_bad.md.in:7: names the type 'RemoteQuery', which no source declares
tests/lint/names_bad.md.in:8: names 'middleware/src/remote_query.hpp', which is not in the tree
tests/lint/names_bad.md.in:9: names the command 'safecass nosuch', which does not exist
names: 3 name(s) of things that do not exist"
if [ "$rc" -ne 1 ] || [ "$out" != "$expected" ]; then
  echo "FAILED: the sample's report (exit $rc):"; echo "$out"; echo "--- expected (exit 1):"; echo "$expected"
  exit 1
fi
tree=$(python3 scripts/lint-names.py) || { echo "FAILED: the tree names things that do not exist:"; echo "$tree"; exit 1; }
echo "ok: the sample's three names are reported, and the tree is clean"
