#!/usr/bin/env python3
"""Checks the size of a class's public surface (docs/contributing.md): the coordinator keeps at
most 35 public member functions, its other groups in headers of their own (structure.hpp,
named.hpp; docs/architecture.md).

    lint-surface.py HEADER CLASS LIMIT

Counts the public member functions of CLASS declared in HEADER, each overload once; constructors,
the destructor, deleted functions and assignment operators are not counted. Prints the count and
the names, and fails above LIMIT. Comments, literals and preprocessor lines are skipped
(lint-namespaces.py's reader).
"""

import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from importlib import import_module  # noqa: E402

code_of = import_module("lint-namespaces").code_of
ACCESS = re.compile(r"^\s*(public|private|protected)\s*:\s*")
FUNCTION = re.compile(r"(~?[A-Za-z_]\w*|operator\s*[^\s(]+)\s*\(")
NOT_A_FUNCTION = re.compile(r"^\s*(using|friend|struct|class|enum|static_assert|typedef)\b")


def statements(body):
    """The class body's member declarations: text up to `;` or a definition's closing brace."""
    out, depth, start = [], 0, 0
    for i, c in enumerate(body):
        if c in "{(":
            depth += 1
        elif c in "})":
            depth -= 1
            if depth == 0 and c == "}" and body[start:i].find("(") >= 0:
                nxt = body[i + 1:].lstrip()
                if not nxt.startswith(";") and not nxt.startswith(","):
                    out.append(body[start:i + 1])
                    start = i + 1
        elif c == ";" and depth == 0:
            out.append(body[start:i + 1])
            start = i + 1
    return out


def surface(text, cls):
    code = code_of(text)
    m = re.search(r"\bclass\s+" + cls + r"\b[^;{]*\{", code)
    if not m:
        raise SystemExit(f"lint-surface: no class {cls}")
    depth, i = 1, m.end()
    while depth:
        depth += {"{": 1, "}": -1}.get(code[i], 0)
        i += 1
    names, public = [], False
    for s in statements(code[m.end():i - 1]):
        while (a := ACCESS.match(s)) is not None:
            public = a.group(1) == "public"
            s = s[a.end():]
        s = re.sub(r"\[\[[^\]]*\]\]|template\s*<[^>]*>", " ", s).strip()
        f = FUNCTION.search(s)
        if not public or not f or NOT_A_FUNCTION.match(s) or re.search(r"=\s*delete", s):
            continue
        name = f.group(1)
        if name in (cls, "~" + cls) or name.replace(" ", "") == "operator=":
            continue
        if "=" in s[:f.start()]:  # a data member's initialiser that calls something
            continue
        names.append(name)
    return names


def main(argv):
    if len(argv) != 4:
        print(__doc__.strip().splitlines()[3].strip(), file=sys.stderr)
        return 2
    header, cls, limit = argv[1], argv[2], int(argv[3])
    with open(header, encoding="utf-8") as f:
        names = surface(f.read(), cls)
    print(f"{header}: {cls} has {len(names)} public member functions (at most {limit}): {' '.join(names)}")
    if len(names) > limit:
        print(f"{header}: {cls}: {len(names)} public member functions, more than {limit}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
