#!/usr/bin/env python3
"""Every GoogleTest case of every test program is a ctest test.

The middleware's integration tests are registered by hand, one add_test per case (they need the
IceStorm fixture and an environment): a case written in a source and left out of its list would
never run, and nothing would say so. This lists the cases of each program (--gtest_list_tests)
and the --gtest_filter of every ctest test (ctest --show-only=json-v1), and fails naming every case
that no ctest test runs.

    every_case_registered.py BUILD_DIR
"""
import fnmatch
import json
import os
import subprocess
import sys


def cases(program):
    """The full names of a GoogleTest program's cases (Suite.Case, Prefix/Suite.Case/Param)."""
    out = subprocess.run([program, "--gtest_list_tests"], capture_output=True, text=True, timeout=60)
    if out.returncode != 0:
        sys.exit(f"{program} --gtest_list_tests failed ({out.returncode}): {out.stderr.strip()}")
    names, suite = [], None
    for line in out.stdout.splitlines():
        line = line.split("#", 1)[0].rstrip()
        if not line:
            continue
        if not line.startswith(" "):
            suite = line.strip()
        elif suite is not None:
            names.append(suite + line.strip())
    return names


def gtest_filter_matches(spec, case):
    """GoogleTest's --gtest_filter: positive patterns, then '-' and negative ones; '*' and '?'."""
    positive, _, negative = spec.partition("-")
    def any_match(patterns):
        return any(fnmatch.fnmatchcase(case, p) for p in patterns.split(":") if p)
    return (any_match(positive) if positive else True) and not any_match(negative)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    build = sys.argv[1]
    shown = subprocess.run(["ctest", "--test-dir", build, "--show-only=json-v1"], capture_output=True, text=True,
                           timeout=120)
    if shown.returncode != 0:
        sys.exit(f"ctest --show-only failed: {shown.stderr.strip()}")
    # For each program, the filters its ctest tests run it with (None: the whole program).
    filters = {}
    for test in json.loads(shown.stdout).get("tests", []):
        command = test.get("command") or []
        if not command:
            continue
        program = os.path.basename(command[0])
        spec = None
        for i, arg in enumerate(command[1:], start=1):
            if arg.startswith("--gtest_filter="):
                spec = arg.split("=", 1)[1]
            elif arg == "--gtest_filter" and i + 1 < len(command):
                spec = command[i + 1]
        filters.setdefault(program, []).append(spec)
    bin_dir = os.path.join(build, "bin")
    programs = sorted(p for p in os.listdir(bin_dir) if p.startswith("test_"))
    missing, total = [], 0
    for name in programs:
        specs = filters.get(name, [])
        for case in cases(os.path.join(bin_dir, name)):
            total += 1
            if not any(spec is None or gtest_filter_matches(spec, case) for spec in specs):
                missing.append(f"{name}: {case}")
    if missing:
        print(f"{len(missing)} of {total} GoogleTest cases are run by no ctest test:")
        for m in missing:
            print("  " + m)
        return 1
    print(f"every one of the {total} GoogleTest cases of {len(programs)} test programs is run by a ctest test")
    return 0


if __name__ == "__main__":
    sys.exit(main())
