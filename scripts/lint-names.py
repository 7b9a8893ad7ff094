#!/usr/bin/env python3
"""Fails when docs/, the README or a comment names a file, a type or a command that does not exist.

    scripts/lint-names.py [FILE...]  (from the repository root; scripts/lint --names runs it)

With FILEs, checks those (a .md as a document, any other as C++ comments) instead of the tree's.

What it checks, in docs/*.md, README.md and the comments of every tracked C++ file:
- a path with a known extension or a folder of the tree (`middleware/src/receiver.hpp`,
  `scripts/start-icestorm`): the file exists, as written from the root or from the writer's folder,
  or, for a bare file name, somewhere in the tree;
- a type in backquotes, or named as `Type::member` (`RemoteClient`, `Supervisor::Impl`): a word in
  CamelCase with two humps or more is declared somewhere in the C++ sources (class, struct, enum,
  using, or a Slice type);
- a command in backquotes (`safecass NAME`): a subcommand the command declares.
Prints FILE:LINE: what is named and why it is not found; exits 1 when anything is, 0 otherwise.
Names that are meant not to exist in the tree (an example of a user's file, a ROS type) are listed
in ALLOWED below, each with its reason.
"""
import os
import re
import subprocess
import sys

# Named on purpose although not in the tree, with why.
ALLOWED = {
    # Files a user writes or a run produces, named in examples.
    "FILE.1", "FILE.2", "robot.token", "timeline.html", "robot.json", "hazards.json", "my_filter.hpp",
    "robot.local", "build/bench.json", "build/bench-middleware.json", "build/bench-peers.json",
    "build/bench-verify.json", "build/bench-scale-out.json", "robodoc.bag", "control.json.orig",
    "tests/scenarios", "robots/robodoc.json", "robots/jr3.json", "args.ice",
    # Prose: "filters/pipelines" is "filters and pipelines"; English words in CamelCase.
    "filters/pipelines", "PascalCase", "CamelCase",
    # Other projects' files, cited as the sources of ROS 2's conventions (extensions/dds).
    "rmw_cyclonedds_cpp/src/namespace_prefix.hpp", "rmw_cyclonedds_cpp/src/MessageTypeSupport_impl.hpp",
    "rmw_cyclonedds_cpp/src/rmw_node.cpp", "rmw/include/rmw/qos_profiles.h",
    "diagnostic_updater/include/diagnostic_updater/diagnostic_updater.hpp",
    "diagnostic_aggregator/src/aggregator.cpp", "rcl/src/rcl/domain_id.c",
    # Other projects' names: CMake, ROS, Ice (IceStorm's election properties and their source).
    "FetchContent", "GenericAnalyzer", "DiagnosticStatus", "DiagnosticArray", "MasterTimeout", "ElectionTimeout",
    "NodeI.cpp",
}
EXTENSIONS = ("hpp", "cpp", "h", "md", "py", "sh", "ice", "cmake", "mjs", "ts", "json", "txt", "yaml", "msg")
TOP = ("core", "filters", "introspect", "spec", "middleware", "record", "verify", "tools", "extensions", "tests",
       "scripts", "docs", "examples", "benchmarks", "cmake", "web", "packaging", ".ci")


def tracked():
    out = subprocess.run(["git", "ls-files"], capture_output=True, text=True, check=True).stdout
    return [f for f in out.splitlines() if f]


def comments(path, text):
    """(line number, comment text) of a C++ file's // comments."""
    for number, line in enumerate(text.splitlines(), 1):
        at = line.find("//")
        if at < 0:
            continue
        before = line[:at]
        if before.count('"') % 2 == 1:  # inside a string literal ("http://...")
            continue
        yield number, line[at + 2:]


def code_identifiers(files):
    """Every CamelCase word of the tree outside the docs and the C++ comments: types, enumerators,
    test names, the specification's type names (FilterThreshold), the examples' interfaces."""
    names = set()
    word = re.compile(r"\b[A-Z][A-Za-z0-9]+\b")
    for f in files:
        if ".md" in f or f.startswith(("docs/", "tests/lint/")) or "." not in os.path.basename(f) and not f.startswith("."):
            continue
        try:
            with open(f, encoding="utf-8", errors="strict") as handle:
                text = handle.read()
        except (OSError, UnicodeDecodeError):
            continue
        if f.endswith((".cpp", ".hpp", ".h")):
            text = "\n".join(line[:line.find("//")] if "//" in line else line for line in text.splitlines())
        names.update(word.findall(text))
    return names


def subcommands(files):
    names = set()
    for f in files:
        if f.startswith("tools/") and f.endswith(".cpp"):
            with open(f, encoding="utf-8") as handle:
                for m in re.finditer(r'add_subcommand\(\s*"([a-z0-9-]+)"', handle.read()):
                    names.add(m.group(1))
    return names


PATH = re.compile(r"(?<![\w./@*>-])((?:[\w.-]+/)*[\w.-]+\.(?:" + "|".join(EXTENSIONS) + r"))(?![\w/-]|\.\w)")
TREE_PATH = re.compile(r"(?<![\w./@-])((?:" + "|".join(re.escape(t) for t in TOP) + r")/[\w./-]*[\w-])")
TYPE = re.compile(r"`(?:\w+\.)?((?:[A-Z][a-z0-9]+){2,}[A-Za-z0-9]*)(?:::\w+)*(?:\(\))?`|\b((?:[A-Z][a-z0-9]+){2,})::\w")
COMMAND = re.compile(r"`safecass ([a-z][a-z0-9-]*)")


def main():
    files = tracked()
    present = set(files)
    folders = {os.path.dirname(f) for f in files}
    for f in list(folders):
        while f:
            f = os.path.dirname(f)
            folders.add(f)
    basenames = {os.path.basename(f) for f in files}
    types = code_identifiers(files)
    commands = subcommands(files)
    problems = []

    def exists(name, writer):
        name = name.rstrip(".")
        if name in ALLOWED or os.path.basename(name) in ALLOWED:
            return True
        # Made by a build or a run, relative to a file of the user's, a placeholder (NAME.json,
        # .scenario.json), or a system header.
        if name.startswith(("build/", "../", ".")) or "node_modules" in name or re.search(r"\b[A-Z]{3,}\b", name):
            return True
        if os.path.exists("/usr/include/" + name):
            return True
        if name in present or name in folders:
            return True
        here = os.path.normpath(os.path.join(os.path.dirname(writer), name))
        if here in present or here in folders:
            return True
        if "/" not in name:
            return name in basenames
        # A path given from inside a module (src/node.cpp, include/safecass/...): some file ends with it.
        return any(f.endswith("/" + name) for f in present) or any(d.endswith("/" + name) for d in folders)

    def check(writer, number, text):
        for m in PATH.finditer(text):
            name = m.group(1)
            if "*" in name or "<" in name or name.startswith(("http", "www.")):
                continue
            if re.fullmatch(r"[\w-]+\.(json|txt|yaml|md)", name) and "/" not in name and name not in basenames:
                # A bare data file name in prose is usually the user's (robot.json): only paths count.
                continue
            if not exists(name, writer):
                problems.append(f"{writer}:{number}: names '{name}', which is not in the tree")
        for m in TREE_PATH.finditer(text):
            name = m.group(1)
            if all(part in TOP or part in ("record", "verify", "introspect") for part in name.split("/")):
                continue  # the layering written as modules: "middleware/record/spec"
            if PATH.fullmatch(name) or "*" in name or "{" in name or name.endswith(("/", ".")):
                continue
            if re.search(r"\.[a-z]+$", name):  # a file with an extension: the PATH rule has it
                continue
            if not exists(name, writer) and not any(f.startswith(name + ".") for f in present):
                problems.append(f"{writer}:{number}: names '{name}', which is not in the tree")
        for m in TYPE.finditer(text):
            name = m.group(1) or m.group(2)
            if name and name not in types and name not in ALLOWED:
                problems.append(f"{writer}:{number}: names the type '{name}', which no source declares")
        for m in COMMAND.finditer(text):
            if m.group(1) not in commands:
                problems.append(f"{writer}:{number}: names the command 'safecass {m.group(1)}', which does not exist")

    given = sys.argv[1:]
    for f in given or files:
        if f.endswith((".md", ".md.in")) and (given or f.startswith("docs/") or f == "README.md"):
            with open(f, encoding="utf-8") as handle:
                for number, line in enumerate(handle, 1):
                    check(f, number, line)
        elif (given or f.endswith((".cpp", ".hpp", ".h"))) and not f.startswith("tests/data/"):
            with open(f, encoding="utf-8", errors="replace") as handle:
                text = handle.read()
            for number, comment in comments(f, text):
                check(f, number, comment)
    for p in problems:
        print(p)
    print(f"names: {len(problems)} name(s) of things that do not exist")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
