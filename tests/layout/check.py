#!/usr/bin/env python3
"""The code stays easy to see: no Rust module over MAX_MODULE_LINES lines and no function
over MAX_FUNCTION_LINES lines, in the pipeline (src/) and the workspace crates
(crates/). Tests (`tests.rs`, files under tests/) count too: they are read as often as the code.

    python3 tests/layout/check.py [--list]     # exit 1 and one line per offender

Functions are found by a small Rust lexer (comments, strings, raw strings and char
literals skipped) that matches each `fn` item's braces.
"""

import re
import sys
from pathlib import Path

MAX_MODULE_LINES = 1200
MAX_FUNCTION_LINES = 150
ROOT = Path(__file__).resolve().parents[2]


def code_only(text):
    """`text` with comments, strings and char literals blanked (newlines kept)."""
    out = []
    i, n = 0, len(text)
    keep = lambda s: "".join(c if c == "\n" else " " for c in s)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(keep(text[i:j]))
            i = j
        elif text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(keep(text[i:j]))
            i = j
        elif (m := re.match(r'b?r(#*)"', text[i:])) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            end = '"' + m.group(1)
            j = text.find(end, i + m.end())
            j = n if j < 0 else j + len(end)
            out.append(keep(text[i:j]))
            i = j
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append(keep(text[i : j + 1]))
            i = j + 1
        elif c == "'" and (m := re.match(r"'(\\.[^']*|[^\\'])'", text[i:])):
            out.append(keep(m.group(0)))
            i += m.end()
        else:
            out.append(c)
            i += 1
    return "".join(out)


def long_functions(path):
    code = code_only(path.read_text())
    for m in re.finditer(r"\bfn\s+([A-Za-z_][A-Za-z0-9_]*)", code):
        # The body starts at the first `{` after the signature, unless a `;` comes first
        # (a declaration without a body).
        j = m.end()
        depth_paren = 0
        while j < len(code):
            ch = code[j]
            if ch in "([<":
                depth_paren += 1
            elif ch in ")]>":
                depth_paren -= 1
            elif ch == ";" and depth_paren <= 0:
                j = -1
                break
            elif ch == "{" and depth_paren <= 0:
                break
            j += 1
        if j < 0 or j >= len(code):
            continue
        depth, k = 0, j
        while k < len(code):
            if code[k] == "{":
                depth += 1
            elif code[k] == "}":
                depth -= 1
                if depth == 0:
                    break
            k += 1
        first = code.count("\n", 0, m.start()) + 1
        last = code.count("\n", 0, k) + 1
        if last - first + 1 > MAX_FUNCTION_LINES:
            yield m.group(1), first, last - first + 1


def main():
    offenders = []
    for folder in ("src", "crates", "tests"):
        for path in sorted((ROOT / folder).rglob("*.rs")):
            rel = path.relative_to(ROOT)
            lines = path.read_text().count("\n")
            if lines > MAX_MODULE_LINES:
                offenders.append(f"{rel}: {lines} lines (at most {MAX_MODULE_LINES})")
            for name, line, length in long_functions(path):
                offenders.append(f"{rel}:{line}: fn {name} has {length} lines (at most {MAX_FUNCTION_LINES})")
    for o in offenders:
        print(o)
    print(f"layout: {len(offenders)} offenders" if offenders else "layout: ok")
    return 1 if offenders else 0


if __name__ == "__main__":
    sys.exit(main())
