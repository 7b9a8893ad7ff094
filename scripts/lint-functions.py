#!/usr/bin/env python3
"""No production function is longer than 150 lines (docs/contributing.md, "Lint").

    scripts/lint-functions.py [--limit N] FILE...

Asks Universal Ctags for every function definition in FILE... with its first and last line, and
prints FILE:LINE: NAME: N lines for each one longer than the limit (150 by default; a lambda counts
as part of the function that holds it). Exits 1 when there is one, 2 when ctags is missing or fails.
scripts/lint runs it over every tracked C++ file outside tests/, benchmarks/ and the middleware's
bench/ folder: a test or a measurement program is not product code.
"""
import shutil
import subprocess
import sys


def main(argv):
    limit = 150
    files = []
    args = iter(argv)
    for arg in args:
        if arg == "--limit":
            limit = int(next(args))
        else:
            files.append(arg)
    ctags = shutil.which("ctags-universal") or shutil.which("ctags")
    if ctags is None:
        print("functions: ctags is missing (apt-get install universal-ctags)", file=sys.stderr)
        return 2
    if not files:
        print("functions: no file to check")
        return 0
    run = subprocess.run([ctags, "--kinds-c++=f", "--fields=+ne", "-o", "-", *files],
                         capture_output=True, text=True)
    if run.returncode != 0:
        print("functions: ctags failed: " + run.stderr.strip(), file=sys.stderr)
        return 2
    long_ones = []
    for line in run.stdout.splitlines():
        fields = line.split("\t")
        if len(fields) < 3:
            continue
        extra = dict(f.split(":", 1) for f in fields[3:] if ":" in f)
        if "line" not in extra or "end" not in extra:
            continue
        first, last = int(extra["line"]), int(extra["end"])
        if last - first + 1 > limit:
            long_ones.append((fields[1], first, fields[0], last - first + 1))
    for path, first, name, size in sorted(long_ones):
        print(f"{path}:{first}: {name}: {size} lines (at most {limit})")
    checked = len(files)
    if long_ones:
        print(f"functions: {len(long_ones)} functions longer than {limit} lines in {checked} files (split them)")
        return 1
    print(f"functions: clean ({checked} files, none longer than {limit} lines)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
