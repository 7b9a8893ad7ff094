#!/usr/bin/env python3
"""Checks the namespace rule of docs/contributing.md: every named namespace of the tree is
`safecass` or `safecass::<module>` (two levels at most, STYLE); a module's internals stay in its
own namespace (its src/ headers are not installed), anonymous namespaces aside.

    lint-namespaces.py FILE...

Prints FILE:LINE: NAMESPACE for each namespace nested deeper than two named levels, and fails
when there is one. Comments, string and character literals and preprocessor lines are skipped;
braces are followed to know what encloses what.
"""

import re
import sys

MAX_LEVELS = 2
NAMESPACE = re.compile(r"\b(?:inline\s+)?namespace\b\s*([A-Za-z_][\w:]*)?\s*(=)?")


def code_of(text):
    """The text with comments, literals and preprocessor lines blanked (newlines kept)."""
    out = []
    i, n = 0, len(text)
    line_start = True
    while i < n:
        c = text[i]
        if line_start and c == "#":
            while i < n and text[i] != "\n":  # a directive, with its continuations
                if text[i] == "\\" and i + 1 < n and text[i + 1] == "\n":
                    out.append("\n")
                    i += 2
                    continue
                i += 1
            continue
        if c == "/" and text.startswith("//", i):
            while i < n and text[i] != "\n":
                i += 1
            continue
        if c == "/" and text.startswith("/*", i):
            end = text.find("*/", i + 2)
            end = n if end < 0 else end + 2
            out.append("\n" * text.count("\n", i, end))
            i = end
            continue
        raw = re.match(r'(?:u8|u|U|L)?R"([^(\s]*)\(', text[i:i + 20])
        if raw and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            close = ")" + raw.group(1) + '"'
            end = text.find(close, i + raw.end())
            end = n if end < 0 else end + len(close)
            out.append("\n" * text.count("\n", i, end))
            i = end
            continue
        if c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum():  # a digit separator: 1'000
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            i = j + 1
            out.append(" ")
            continue
        out.append(c)
        line_start = c == "\n" or (line_start and c in " \t")
        i += 1
    return "".join(out)


def check(path):
    try:
        text = open(path, encoding="utf-8").read()
    except (OSError, UnicodeDecodeError):
        return []
    code = code_of(text)
    found = []
    stack = []  # per open brace: the namespace names it opens ([] for any other brace)
    pending = None  # a namespace declaration waiting for its brace
    for m in re.finditer(r"[{};]|\b(?:inline\s+)?namespace\b", code):
        token = m.group(0)
        if token.endswith("namespace"):
            decl = NAMESPACE.match(code, m.start())
            if decl and decl.group(2):  # an alias: namespace fs = std::filesystem;
                continue
            name = decl.group(1) if decl else None
            pending = (name.split("::") if name else [], code.count("\n", 0, m.start()) + 1, name)
            continue
        if token == "{":
            if pending is not None:
                parts, line, name = pending
                stack.append(parts)
                depth = sum(len(p) for p in stack)
                if parts and depth > MAX_LEVELS:
                    enclosing = "::".join(p for frame in stack for p in frame)
                    found.append(f"{path}:{line}: namespace {enclosing}")
                pending = None
            else:
                stack.append([])
        elif token == "}":
            if stack:
                stack.pop()
        else:
            pending = None
    return found


def main(paths):
    found = [f for p in paths for f in check(p)]
    for f in found:
        print(f)
    if found:
        print(f"namespaces: {len(found)} namespace(s) deeper than {MAX_LEVELS} levels "
              "(the rule: safecass or safecass::<module>; docs/contributing.md)")
        return 1
    print(f"namespaces: clean ({len(paths)} files, none deeper than {MAX_LEVELS} levels)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
