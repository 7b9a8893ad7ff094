#!/usr/bin/env python3
"""Every function that returns an Expected carries [[nodiscard]] (docs/contributing.md, "Lint").

    scripts/lint-nodiscard.py [--fix] FILE...

Looks, line by line, for a declaration or definition whose return type is `Expected<...>`,
`tl::expected<...>` or `Opened<...>` (the aliases of tl::expected in this code) followed by an
unqualified function name and `(`: declarations in headers, in-class definitions and functions
local to a .cpp file. Out-of-class definitions (`Expected<X> Class::f(`) and friend declarations
are skipped: the attribute is on the function's own declaration (and C++ forbids attributes on a
friend declaration that is not a definition). Lambdas (`-> Expected<...>`),
`std::function<Expected<...>(...)>` and comments are not declarations of functions and are
skipped. A trailing return type counts when the line reads `auto f(... -> Expected<...>`. Prints FILE:LINE: and the line for
each declaration without `[[nodiscard]]` (on the same line or the line before); exits 1 if any.
--fix inserts `[[nodiscard]] ` in front of each such declaration instead.
"""
import re
import sys

RETURN_TYPES = ("Expected<", "safecass::Expected<", "tl::expected<", "Opened<", "runner::Opened<")
SPECIFIERS = ("static", "inline", "virtual", "constexpr", "extern", "explicit")
IDENT = re.compile(r"\s*(~?[A-Za-z_][A-Za-z0-9_]*(?:\s*::\s*~?[A-Za-z_][A-Za-z0-9_]*)*)\s*\(")


def close_angle(text, start):
    """Index just past the '>' that closes the '<' at text[start], or -1."""
    depth = 0
    for i in range(start, len(text)):
        c = text[i]
        if c == "<":
            depth += 1
        elif c == ">":
            depth -= 1
            if depth == 0:
                return i + 1
        elif c in ";{}":
            return -1
    return -1


def strip_comment(line):
    return line.split("//", 1)[0]


def check(path, lines):
    """Yields (index, column) of each declaration lacking [[nodiscard]]; column is where it goes."""
    in_block_comment = False
    for i, raw in enumerate(lines):
        line = strip_comment(raw)
        if in_block_comment:
            if "*/" not in line:
                continue
            line = line.split("*/", 1)[1]
            in_block_comment = False
        if "/*" in line and "*/" not in line.split("/*", 1)[1]:
            in_block_comment = True
            line = line.split("/*", 1)[0]
        pos = len(line) - len(line.lstrip())
        insert_at = pos
        rest = line[pos:]
        has_attr = False
        m = re.match(r"template\s*<", rest)
        if m:
            end = close_angle(rest, m.end() - 1)
            if end < 0:
                continue
            ws = len(rest[end:]) - len(rest[end:].lstrip())
            pos += end + ws
            insert_at = pos
            rest = line[pos:]
        while True:
            if rest.startswith("[[nodiscard"):
                has_attr = True
                end = rest.find("]]")
                if end < 0:
                    break
                rest = rest[end + 2:].lstrip()
                continue
            word = re.match(r"([a-z]+)\s+", rest)
            if word and word.group(1) in SPECIFIERS:
                rest = rest[word.end():]
                continue
            break
        kind = next((t for t in RETURN_TYPES if rest.startswith(t)), None)
        if kind is None:
            trailing = re.match(r"auto\s+([A-Za-z_][A-Za-z0-9_]*)\s*\(", rest)
            if trailing and re.search(r"\)\s*(const\s*)?(noexcept\s*)?->\s*(" + "|".join(re.escape(t) for t in RETURN_TYPES) + ")", rest):
                if not has_attr and not (i > 0 and strip_comment(lines[i - 1]).rstrip().endswith("[[nodiscard]]")):
                    yield i, insert_at
            continue
        end = close_angle(rest, len(kind) - 1)
        if end < 0:
            continue
        after = rest[end:]
        if not after.strip() and i + 1 < len(lines):  # the name on the next line
            after = strip_comment(lines[i + 1])
        name = IDENT.match(after)
        # the name follows the type after white space or a line break (else it is no declaration)
        if not name or (name.start(1) == 0 and rest[end:].strip()):
            continue
        if "::" in name.group(1) or name.group(1) == "operator":
            continue
        if has_attr or (i > 0 and strip_comment(lines[i - 1]).rstrip().endswith("[[nodiscard]]")):
            continue
        yield i, insert_at


def main(argv):
    fix = "--fix" in argv
    files = [a for a in argv if a != "--fix"]
    missing = 0
    for path in files:
        with open(path, encoding="utf-8") as f:
            lines = f.read().split("\n")
        found = list(check(path, lines))
        for i, col in found:
            missing += 1
            if not fix:
                print(f"{path}:{i + 1}: a function returning Expected without [[nodiscard]]: {lines[i].strip()}")
        if fix and found:
            for i, col in found:
                lines[i] = lines[i][:col] + "[[nodiscard]] " + lines[i][col:]
            with open(path, "w", encoding="utf-8") as f:
                f.write("\n".join(lines))
    if fix:
        print(f"nodiscard: added to {missing} declarations")
        return 0
    if missing:
        print(f"nodiscard: {missing} functions returning Expected lack [[nodiscard]]")
        return 1
    print("nodiscard: clean")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
