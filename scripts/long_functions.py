#!/usr/bin/env python3
"""Lists C++ function definitions longer than a limit (default 120 lines).

Usage: scripts/long_functions.py [--max N] [--include-tests] [PATH ...]   (default PATH: src)

A function's length is its lines from the first line of its signature to its closing brace,
comments and blank lines included. The scanner strips comments, string and character literals
(raw strings too) and preprocessor lines, then follows braces: a brace opened at namespace or
class scope whose declaration has a parameter list and no '=' is a function body; lambdas and
local classes count towards the function that holds them. Files ending in _test.cc are skipped
unless --include-tests. Prints "LINES NAME FILE:LINE" per long function, longest first, and
exits 1 when any is found.
"""

import argparse
import os
import re
import sys


def strip_code(text):
    """Returns text with comments, literals and preprocessor lines blanked (newlines kept)."""
    out = []
    i, n = 0, len(text)
    at_line_start = True
    while i < n:
        c = text[i]
        if at_line_start and c in " \t":
            out.append(c)
            i += 1
            continue
        if at_line_start and c == "#":
            # Preprocessor directive, with backslash continuations.
            while i < n and text[i] != "\n":
                if text[i] == "\\" and i + 1 < n and text[i + 1] == "\n":
                    out.append("\n")
                    i += 2
                    continue
                i += 1
            continue
        at_line_start = False
        if c == "\n":
            out.append(c)
            at_line_start = True
            i += 1
        elif text.startswith("//", i):
            while i < n and text[i] != "\n":
                i += 1
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("\n" * text.count("\n", i, j) or " ")
            i = j
        elif c == '"' or c == "'":
            raw = re.match(r'(?:u8|u|U|L)?R"([^(\s]*)\(', text[max(0, i - 3):i + 20])
            if c == '"' and i > 0 and text[i - 1] == "R" and raw is not None:
                delim = ")" + raw.group(1) + '"'
                j = text.find(delim, i)
                j = n if j < 0 else j + len(delim)
            elif c == "'" and i > 0 and text[i - 1].isalnum() and i + 1 < n and \
                    text[i + 1] in "0123456789abcdefABCDEF" and \
                    re.match(r"[0-9]", text[i - 1]) is not None:
                out.append(" ")  # digit separator as in 1'000
                i += 1
                continue
            else:
                j = i + 1
                while j < n and text[j] != c and text[j] != "\n":
                    j += 2 if text[j] == "\\" else 1
                j = min(n, j + 1)
            out.append(c + "\n" * text.count("\n", i, j) + c)
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def depth0(header, chars):
    """True when any of chars appears in header outside (), [] and <> of templates."""
    level = 0
    for k, ch in enumerate(header):
        if ch in "([":
            level += 1
        elif ch in ")]":
            level -= 1
        elif level == 0 and ch in chars:
            if ch == "=" and (header[k - 1:k] in ("=", "!", "<", ">") or
                              header[k + 1:k + 2] == "=" or
                              re.search(r"operator\s*\S?$", header[:k])):
                continue
            return True
    return False


def function_name(header):
    m = re.search(r"((?:[A-Za-z_~][\w]*\s*(?:<[^()]*>)?\s*::\s*)*"
                  r"(?:operator\s*[^\s(]+|operator\s*\(\)|~?[A-Za-z_]\w*))\s*\(", header)
    return re.sub(r"\s+", "", m.group(1)) if m else "?"


def classify(header):
    h = " ".join(header.split())
    if re.search(r"\bnamespace\b", h) or re.match(r'extern\s*"', h) or h.startswith("extern \""):
        return "scope"
    if re.search(r"\b(class|struct|union|enum)\b", h) and not depth0(h, "("):
        return "scope"
    if "(" in h and not depth0(h, "="):
        if h.endswith("=") or re.search(r"\breturn\b", h):
            return "other"
        return "function"
    return "other"


def scan(path):
    text = open(path, encoding="utf-8", errors="replace").read()
    code = strip_code(text)
    found = []
    # Stack of (kind, start_line, name); kinds: scope, function, other.
    stack = []
    header_start = 0
    line = 1
    for i, c in enumerate(code):
        if c == "\n":
            line += 1
            continue
        in_function = any(kind == "function" for kind, _, _ in stack)
        if c == "{":
            if in_function:
                stack.append(("other", line, ""))
                continue
            header = code[header_start:i]
            kind = classify(header)
            stripped = header.lstrip()
            start_line = line - header[len(header) - len(stripped):].count("\n") if stripped \
                else line
            if kind == "function":
                lead = header[:len(header) - len(stripped)]
                start_line = code.count("\n", 0, header_start + len(lead)) + 1
                stack.append(("function", start_line, function_name(header)))
            else:
                stack.append((kind, line, ""))
            if kind != "other":
                header_start = i + 1
        elif c == "}":
            if not stack:
                continue
            kind, start, name = stack.pop()
            if kind == "function":
                found.append((line - start + 1, name, path, start))
            if kind != "other" or not stack or stack[-1][0] == "scope":
                if kind != "other":
                    header_start = i + 1
        elif c == ";" and not in_function:
            if not stack or stack[-1][0] == "scope":
                header_start = i + 1
        elif c == ":" and not in_function:
            # Access specifiers (public:) end a declaration too.
            if re.search(r"\b(public|private|protected)\s*$", code[header_start:i]):
                header_start = i + 1
    return found


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("paths", nargs="*", default=["src"])
    parser.add_argument("--max", type=int, default=120, help="longest allowed (lines)")
    parser.add_argument("--include-tests", action="store_true")
    parser.add_argument("--all", action="store_true", help="print every function")
    args = parser.parse_args()
    files = []
    for p in args.paths:
        if os.path.isfile(p):
            files.append(p)
            continue
        for root, _, names in os.walk(p):
            for name in names:
                if name.endswith((".cc", ".h", ".cpp", ".hpp")):
                    files.append(os.path.join(root, name))
    rows = []
    for f in sorted(files):
        if f.endswith("_test.cc") and not args.include_tests:
            continue
        rows.extend(scan(f))
    rows.sort(key=lambda r: (-r[0], r[2], r[3]))
    long_rows = [r for r in rows if args.all or r[0] > args.max]
    for length, name, path, start in long_rows:
        print(f"{length:5d} {name} {path}:{start}")
    if not args.all:
        print(f"{len(long_rows)} function(s) over {args.max} lines", file=sys.stderr)
    return 1 if any(r[0] > args.max for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
