#!/usr/bin/env python3
"""Fails when a function in the core is longer than the limit (docs/design.md, Conventions:
functions stay short, split along the physics).

Usage: check_function_size.py [--limit N] [--root DIR] [--exceptions FILE] [--all] [FOLDER ...]

Counts, like clang-tidy's readability-function-size (LineThreshold), the lines of every
function body from its opening brace to its closing brace, comments and blank lines
included; a lambda or a local class inside a function counts toward that function.  The
scan is lexical (comments, string and character literals are skipped; raw strings too), so
it runs over the whole core in well under a second, where clang-tidy takes minutes.  Prints
one line per function over the limit, "FILE:LINE: NAME: N lines (limit L)", and exits 1 if
there is any.

--exceptions FILE lists the functions not yet split, one per line, "PATH NAME LINES" (# starts
a comment): such a function may stay over the limit but never grow beyond LINES, and an entry
whose function is now within the limit (or gone) fails too, so the list only shrinks.
"""

import argparse
import os
import re
import sys

CORE = ["symbolic", "codegen", "numeric", "measurements", "discrepancy", "api", "model", "reports"]
SUFFIXES = (".cpp", ".hpp", ".h", ".cc")


def blank_out(text):
    """The text with comments and literals replaced by spaces (newlines kept)."""
    out = []
    i, n = 0, len(text)
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
        elif c == "R" and text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'R"([^()\\ ]{0,16})\(', text[i:])
            if not m:
                out.append(c)
                i += 1
                continue
            end = text.find(")" + m.group(1) + '"', i + m.end())
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum():  # digit separator: 1'000'000
                out.append(" ")
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(" " * (j - i))
            i = j
        elif c == "#" and (i == 0 or text[i - 1] == "\n"):  # preprocessor line (with continuations)
            j = i
            while True:
                k = text.find("\n", j)
                if k < 0:
                    k = n
                    break
                if text[k - 1] != "\\":
                    break
                j = k + 1
            out.append(re.sub(r"[^\n]", " ", text[i:k]))
            i = k
        else:
            out.append(c)
            i += 1
    return "".join(out)


SCOPE_KEYWORD = re.compile(r"\b(namespace|class|struct|union|enum)\b")


def classify(header):
    """What an opening brace at namespace or class scope opens, from the text before it."""
    h = re.sub(r"\s+", " ", header).strip()
    h = re.sub(r"^template ?<.*?> ?", "", h)  # template heads (simple ones)
    if not h:
        return "block"
    if "(" not in h:
        if SCOPE_KEYWORD.search(h):
            return "scope"
        return "block"  # an initialiser list, a variable's braces
    # A lambda at namespace scope: "... = [..](..) {" is a function body too.
    if re.search(r"=\s*\[[^\]]*\]\s*(\(.*\))?[^=]*$", h):
        return "function"
    depth = 0
    for ch in h:  # an "=" outside parentheses before the brace: a variable's initialiser
        if ch in "(<[":
            depth += 1
        elif ch in ")>]":
            depth -= 1
        elif ch == "=" and depth == 0:
            return "block"
    if SCOPE_KEYWORD.match(h) and not h.rstrip().endswith(")"):
        return "scope"
    # A member initialiser in braces, "Foo(int a) : a_{a}" or ", b_{b}": the brace follows a name
    # after a top-level ":" or "," that comes after the parameter list.
    if re.search(r"\)\s*(noexcept\s*)?:\s*.*[,:]\s*[A-Za-z_][\w:]*\s*$", h) or re.search(
        r"\)\s*(noexcept\s*)?:\s*[A-Za-z_][\w:]*\s*$", h
    ):
        return "member-init"
    return "function"


def name_of(header):
    h = re.sub(r"\s+", " ", header)
    m = re.search(r"([~\w:]+(?:operator\s*\S+?)?)\s*\((?:[^()]|\([^()]*\))*\)[^()]*$", h)
    if not m:
        m = re.search(r"([~\w:]+)\s*\(", h)
    return m.group(1) if m else h.strip()[:40]


def functions(text):
    """(name, first line, line count) of every function body in the text."""
    code = blank_out(text)
    stack = []  # kinds: scope, function, block, member-init
    header_start = 0
    line = 1
    result = []
    for i, c in enumerate(code):
        if c == "\n":
            line += 1
        elif c == "{":
            inside_function = any(k[0] == "function" for k in stack)
            kind = "block" if inside_function else classify(code[header_start:i])
            stack.append((kind, line, code[header_start:i]))
            if kind != "member-init":
                header_start = i + 1
        elif c == "}":
            if not stack:
                continue
            kind, first, header = stack.pop()
            if kind == "function":
                result.append((name_of(header), first, line - first))  # as clang-tidy counts
            if kind != "member-init":
                header_start = i + 1
        elif c == ";" and not any(k[0] == "function" for k in stack):
            header_start = i + 1
        elif c == ":" and not any(k[0] in ("function", "member-init") for k in stack):
            # "public:" / "private:" in a class: the header starts after it
            before = code[header_start:i].strip()
            if before in ("public", "private", "protected"):
                header_start = i + 1
    return result


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--limit", type=int, default=80)
    parser.add_argument("--root", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    parser.add_argument("--all", action="store_true", help="print every function's size, longest first")
    parser.add_argument("--exceptions", help="functions not yet split: PATH NAME LINES per line")
    parser.add_argument("folders", nargs="*", default=CORE)
    args = parser.parse_args()
    found = []
    for folder in args.folders:
        base = os.path.join(args.root, folder)
        if os.path.isfile(base):
            paths = [base]
        else:
            paths = sorted(
                os.path.join(d, f) for d, _, fs in os.walk(base) for f in fs if f.endswith(SUFFIXES)
            )
        for path in paths:
            with open(path, encoding="utf-8") as f:
                text = f.read()
            rel = os.path.relpath(path, args.root)
            found += [(size, rel, first, name) for name, first, size in functions(text)]
    found.sort(key=lambda x: (-x[0], x[1], x[2]))
    if args.all:
        for size, rel, first, name in found:
            print(f"{rel}:{first}: {name}: {size} lines")
        return 0
    allowed = read_exceptions(args.exceptions) if args.exceptions else {}
    failures, excepted = [], 0
    for size, rel, first, name in found:
        if size <= args.limit:
            continue
        cap = allowed.pop((rel, name), None)
        if cap is None:
            failures.append(f"{rel}:{first}: {name}: {size} lines (limit {args.limit})")
        elif size > cap:
            failures.append(f"{rel}:{first}: {name}: {size} lines, grown beyond its listed {cap} (limit {args.limit})")
        else:
            excepted += 1
    for (rel, name), cap in sorted(allowed.items()):
        failures.append(f"{args.exceptions}: {rel} {name}: listed ({cap} lines) but within the limit or gone: "
                        "remove the entry")
    for line in failures:
        print(line)
    print(f"{len(found)} functions, {excepted} listed exceptions over {args.limit} lines, {len(failures)} failures",
          file=sys.stderr)
    return 1 if failures else 0


def read_exceptions(path):
    allowed = {}
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            fields = line.split()
            if len(fields) != 3 or not fields[2].isdigit():
                raise SystemExit(f"{path}:{number}: expected 'PATH NAME LINES', got '{line}'")
            allowed[(fields[0], fields[1])] = int(fields[2])
    return allowed


if __name__ == "__main__":
    sys.exit(main())
