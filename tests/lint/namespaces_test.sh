#!/usr/bin/env bash
# scripts/lint-namespaces.py on samples: a namespace three named levels deep is reported with its
# file and line, whether written qualified or nested; two levels, anonymous namespaces, aliases and
# the word in comments and strings pass. Then the tree itself is clean.
set -euo pipefail
script=$1 source=$2 work=$3
mkdir -p "$work"
cat >"$work/bad.hpp" <<'CPP'
namespace safecass::middleware::detail {
int a();
}
namespace safecass::spec {
namespace detail {
int b();
}
}
CPP
cat >"$work/good.hpp" <<'CPP'
// namespace safecass::not::real { in a comment
namespace safecass::spec {
namespace {
const char* text = "namespace a::b::c {";
}
namespace in = safecass::spec;
struct S {
  int f() { return 1'000; }
};
}  // namespace safecass::spec
namespace safecass {
namespace detail {
int c();
}
}
CPP
set +e
out=$(python3 "$script" "$work/bad.hpp" "$work/good.hpp")
rc=$?
set -e
echo "$out"
[ "$rc" -eq 1 ] || { echo "FAIL: exit code $rc, not 1, with namespaces three levels deep"; exit 1; }
echo "$out" | grep -q "^$work/bad.hpp:1: namespace safecass::middleware::detail$" \
  || { echo "FAIL: the qualified three-level namespace is not reported"; exit 1; }
echo "$out" | grep -q "^$work/bad.hpp:5: namespace safecass::spec::detail$" \
  || { echo "FAIL: the nested three-level namespace is not reported"; exit 1; }
if echo "$out" | grep -q good.hpp; then echo "FAIL: a namespace of two levels is reported"; exit 1; fi
cd "$source"
# shellcheck disable=SC2046
python3 "$script" $(git ls-files '*.cpp' '*.hpp' '*.h') || { echo "FAIL: the tree is not clean"; exit 1; }
echo "PASS: three levels reported (qualified and nested), two levels pass, the tree is clean"
