#!/usr/bin/env python3
"""Checks the project's size limits: no source file over 900 lines, and no function over 200
lines outside tests/ (C++ function bodies and Python functions).

C++ is read the way clang-format leaves it: comments and literals are blanked, then every brace
block opened at namespace or class scope after a parenthesis is a function body (a constructor's
member initialisers count with it). Python functions come from the standard ast module.

Usage: scripts/ci/check_sizes.py [--max-file N] [--max-function N] [--list N]
Prints each file or function over its limit and exits 1 if there is any; --list N prints the N
longest functions as well.
"""

import argparse
import ast
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SOURCE_SUFFIXES = {".cpp", ".h", ".py", ".mjs", ".js", ".sh", ".html"}
CONTAINER = re.compile(r"\b(namespace|class|struct|union|enum)\b[^()]*$|extern\s+\"C\"\s*$")


def tracked_sources():
    out = subprocess.run(["git", "ls-files"], cwd=ROOT, check=True, capture_output=True,
                         text=True).stdout.split("\n")
    for name in out:
        p = Path(name)
        if name and p.suffix in SOURCE_SUFFIXES and "node_modules" not in p.parts \
                and (ROOT / p).is_file():
            yield p


def blank_comments_and_literals(text):
    """The text with comments, strings and character literals replaced by spaces (newlines kept),
    so that braces inside them do not count."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'R"([^(\s]*)\(', text[i:])
            end = text.find(")" + m.group(1) + '"', i) if m else -1
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum():  # digit separator: 1'000
                out.append(" ")
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(n, j + 1)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def cpp_functions(text):
    """(name, first line, lines) of each function body at namespace or class scope."""
    s = blank_comments_and_literals(text)
    line_at = [0] * (len(s) + 1)
    line = 1
    for k, ch in enumerate(s):
        line_at[k] = line
        if ch == "\n":
            line += 1
    line_at[len(s)] = line

    def match(k):  # index just past the brace block opened at k
        depth = 0
        for j in range(k, len(s)):
            if s[j] == "{":
                depth += 1
            elif s[j] == "}":
                depth -= 1
                if depth == 0:
                    return j + 1
        return len(s)

    found = []

    def scan(start, end):
        last = start  # just past the last ';', '{' or '}' at this level
        k = start
        while k < end:
            ch = s[k]
            if ch in ";}":
                last = k + 1
            elif ch == "{":
                head = s[last:k]
                stripped = head.strip()
                if CONTAINER.search(stripped) or not stripped:
                    close = match(k)
                    if CONTAINER.search(stripped):
                        scan(k + 1, close - 1)
                    k, last = close, close
                    continue
                close = match(k)
                if "(" in stripped and not re.match(r"^(=|return\b)", stripped):
                    # a member initialiser list goes on (`, b_{x}` or the body's `{`)
                    while True:
                        rest = s[close:end].lstrip()
                        if not rest or rest[0] not in ",{":
                            break
                        nxt = s.find("{", close)
                        if nxt < 0 or nxt >= end:
                            break
                        close = match(nxt)
                    first = last + (len(head) - len(head.lstrip()))
                    name = re.sub(r"\s+", " ", stripped.split("(")[0]).split(" ")[-1]
                    found.append((name, line_at[first], line_at[close - 1] - line_at[first] + 1))
                k, last = close, close
                continue
            k += 1

    scan(0, len(s))
    return found


def python_functions(text, path):
    try:
        tree = ast.parse(text, filename=str(path))
    except SyntaxError:
        return []
    return [(node.name, node.lineno, node.end_lineno - node.lineno + 1)
            for node in ast.walk(tree)
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--max-file", type=int, default=900, help="lines per source file (900)")
    ap.add_argument("--max-function", type=int, default=200,
                    help="lines per function outside tests/ (200)")
    ap.add_argument("--list", type=int, default=0, metavar="N",
                    help="also print the N longest functions")
    args = ap.parse_args()
    problems, functions = [], []
    for rel in tracked_sources():
        text = (ROOT / rel).read_text(errors="replace")
        lines = text.count("\n") + (0 if text.endswith("\n") or not text else 1)
        if lines > args.max_file:
            problems.append(f"{rel}: {lines} lines (at most {args.max_file})")
        if rel.parts[0] == "tests":
            continue
        if rel.suffix in (".cpp", ".h"):
            fns = cpp_functions(text)
        elif rel.suffix == ".py":
            fns = python_functions(text, rel)
        else:
            continue
        for name, first, n in fns:
            functions.append((n, f"{rel}:{first}", name))
            if n > args.max_function:
                problems.append(f"{rel}:{first}: function {name} is {n} lines "
                                f"(at most {args.max_function})")
    for n, where, name in sorted(functions, reverse=True)[:args.list]:
        print(f"{n:5d}  {where}  {name}")
    for p in problems:
        print(p, file=sys.stderr)
    print(f"check_sizes: {len(problems)} over the limits", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
