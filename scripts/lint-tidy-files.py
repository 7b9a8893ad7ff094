#!/usr/bin/env python3
"""The sources clang-tidy checks (scripts/lint --tidy, --tidy-all), one absolute path per line.

  lint-tidy-files.py COMPILE_COMMANDS DB_DIR [--changed-since-baseline]

Writes DB_DIR/compile_commands.json, the database clang-tidy reads: COMPILE_COMMANDS with each of
CMake's unity sources (a test program's batch of files, tests/CMakeLists.txt) replaced by the files
it includes, each compiled by the batch's command. Then prints every source of the project's own
targets in that database (under the source tree, not under a build tree, not generated). With
--changed-since-baseline, only those that changed since the tidied baseline commit named in
.ci/tidy-baseline (committed, staged, unstaged or untracked), and those that include a changed
header by the path written in their #include; every source when .clang-tidy changed since then, or
when the baseline commit is not in this clone's history. The baseline moves only after a clean
whole-tree run (scripts/lint --tidy-all), or a clean incremental run on top of one. Says on stderr
which scope it chose and why. Standard library only.
"""
import json
import os
import re
import subprocess
import sys

BASELINE_FILE = ".ci/tidy-baseline"
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^>"]+)[>"]', re.M)
UNITY_SOURCE = re.compile(r"/CMakeFiles/[^/]+\.dir/Unity/unity_[0-9]+_cxx\.cxx$")


def git(*args):
    return subprocess.run(["git", *args], capture_output=True, text=True, check=False)


def changed_files():
    """The changed paths (relative to the root), or None when the whole tree must be checked."""
    base = ""
    try:
        for line in open(BASELINE_FILE, encoding="utf-8"):
            m = re.match(r"^([0-9a-f]{40})\b", line)
            if m:
                base = m.group(1)
                break
    except OSError:
        pass
    if not base or git("cat-file", "-e", base + "^{commit}").returncode != 0:
        print(f"tidy: the baseline commit of {BASELINE_FILE} is not in this clone's history: every source",
              file=sys.stderr)
        return None
    diff = git("diff", "--name-only", base, "--")
    others = git("ls-files", "--others", "--exclude-standard")
    if diff.returncode != 0 or others.returncode != 0:
        print(f"tidy: git cannot list the changes since {base[:12]}: every source", file=sys.stderr)
        return None
    changed = set(diff.stdout.split()) | set(others.stdout.split())
    if ".clang-tidy" in changed:
        print(f"tidy: .clang-tidy changed since {base[:12]}: every source", file=sys.stderr)
        return None
    print(f"tidy: the sources changed since the tidied baseline {base[:12]} and those including a changed header",
          file=sys.stderr)
    return changed


def includes_changed_header(rel, path, headers):
    try:
        text = open(path, encoding="utf-8", errors="replace").read()
    except OSError:
        return False
    for name in INCLUDE.findall(text):
        beside = os.path.normpath(os.path.join(os.path.dirname(rel), name))
        if any(h == beside or h.endswith("/" + name) for h in headers):
            return True
    return False


def without_unity_sources(entries):
    """The entries, each unity source's replaced by one per file that it includes."""
    out = []
    for entry in entries:
        path = os.path.normpath(os.path.join(entry["directory"], entry["file"]))
        if not UNITY_SOURCE.search(path):
            out.append(entry)
            continue
        for source in INCLUDE.findall(open(path, encoding="utf-8").read()):
            one = dict(entry, file=source)
            if "command" in one:
                one["command"] = one["command"].replace(path, source)
            if "arguments" in one:
                one["arguments"] = [source if a == path else a for a in one["arguments"]]
            out.append(one)
    return out


def main():
    if len(sys.argv) not in (3, 4) or (len(sys.argv) == 4 and sys.argv[3] != "--changed-since-baseline"):
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    root = os.getcwd()
    changed = changed_files() if len(sys.argv) == 4 else None
    headers = [c for c in changed or () if c.endswith((".hpp", ".h"))]
    entries = without_unity_sources(json.load(open(sys.argv[1], encoding="utf-8")))
    with open(os.path.join(sys.argv[2], "compile_commands.json"), "w", encoding="utf-8") as db:
        json.dump(entries, db, indent=1)
    seen = set()
    for entry in entries:
        path = os.path.normpath(os.path.join(entry["directory"], entry["file"]))
        rel = os.path.relpath(path, root)
        if rel.startswith("..") or rel.startswith("build") or "/generated/" in rel or path in seen:
            continue
        seen.add(path)
        if changed is None or rel in changed or (headers and includes_changed_header(rel, path, headers)):
            print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
