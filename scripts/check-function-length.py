#!/usr/bin/env python3
"""Lists C++ function bodies longer than a limit in the given folders; exits 1 when there is one.

    check-function-length.py [--max LINES] FOLDER_OR_FILE...

A body's length counts the lines from its opening brace to its closing one. The parser is
deliberately small: comments, string and character literals are blanked first, then a '{' opens a
function body when the code before it ends with ')' (after qualifiers such as const, noexcept,
override or a trailing return type) and that parenthesis does not belong to if, for, while,
switch or catch. Bodies nested in a function (lambdas, local classes) count towards the function
that holds them. Braces are matched over the whole file.
"""
import argparse
import os
import re
import sys

SOURCE_SUFFIXES = (".cpp", ".cc", ".cxx", ".h", ".hpp")
CONTROL_WORDS = {"if", "for", "while", "switch", "catch", "return", "sizeof", "decltype", "alignof"}
QUALIFIERS = {"const", "noexcept", "override", "final", "mutable", "volatile", "constexpr"}


def blank_literals(text):
    """The text with comments, strings and character literals replaced by spaces (newlines kept)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            end = text.find("\n", i)
            end = n if end < 0 else end
            out.append(" " * (end - i))
            i = end
        elif text.startswith("/*", i):
            end = text.find("*/", i + 2)
            end = n if end < 0 else end + 2
            out.append(re.sub(r"[^\n]", " ", text[i:end]))
            i = end
        elif c == "R" and text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            open_paren = text.find("(", i + 2)
            delimiter = text[i + 2:open_paren] if open_paren >= 0 else ""
            end = text.find(")" + delimiter + '"', open_paren)
            end = n if open_paren < 0 or end < 0 else end + len(delimiter) + 2
            out.append(re.sub(r"[^\n]", " ", text[i:end]))
            i = end
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum():  # a digit separator: 1'000'000
                out.append(" ")
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            end = min(j + 1, n)
            out.append(re.sub(r"[^\n]", " ", text[i:end]))
            i = end
        else:
            out.append(c)
            i += 1
    return "".join(out)


def opens_function(code, brace):
    """True when the '{' at index brace starts a function body (or a lambda's)."""
    j = brace - 1
    while True:
        while j >= 0 and code[j].isspace():
            j -= 1
        word = re.search(r"[A-Za-z_]\w*$", code[:j + 1])
        if word and word.group(0) in QUALIFIERS:
            j = word.start() - 1
            continue
        break
    # A trailing return type: ") -> Type {" (on the same line as the brace).
    line_start = code.rfind("\n", 0, j + 1) + 1
    arrow = code.rfind("->", line_start, j + 1)
    if arrow >= 0 and code[arrow + 2:j + 1].strip() and ")" not in code[arrow:j + 1]:
        j = arrow - 1
        while j >= 0 and code[j].isspace():
            j -= 1
    if j < 0 or code[j] != ")":
        return False
    depth = 0
    k = j
    while k >= 0:
        if code[k] == ")":
            depth += 1
        elif code[k] == "(":
            depth -= 1
            if depth == 0:
                break
        k -= 1
    if k < 0:
        return False
    before = re.search(r"([A-Za-z_]\w*)\s*$", code[:k])
    return not (before and before.group(1) in CONTROL_WORDS)


def function_name(code, brace):
    """A readable name for the function whose body opens at brace: the words before its '('."""
    head = code[max(0, code.rfind(";", 0, brace), code.rfind("}", 0, brace)) + 1:brace]
    head = " ".join(head.split())
    paren = head.find("(")
    name = head[:paren].split()[-1] if paren > 0 and head[:paren].split() else head[:60]
    return name


def long_functions(path, limit):
    with open(path, encoding="utf-8", errors="replace") as f:
        code = blank_literals(f.read())
    found = []
    stack = []  # per open brace: (index, is a function body opened outside any function)
    inside_function = 0
    for i, c in enumerate(code):
        if c == "{":
            is_function = inside_function == 0 and opens_function(code, i)
            stack.append((i, is_function))
            if is_function or inside_function:
                inside_function += 1
        elif c == "}" and stack:
            start, is_function = stack.pop()
            if inside_function:
                inside_function -= 1
            if is_function:
                first = code.count("\n", 0, start) + 1
                last = code.count("\n", 0, i) + 1
                if last - first + 1 > limit:
                    found.append((first, last - first + 1, function_name(code, start)))
    return found


def source_files(paths):
    for p in paths:
        if os.path.isfile(p):
            yield p
            continue
        for folder, _, names in sorted(os.walk(p)):
            for name in sorted(names):
                if name.endswith(SOURCE_SUFFIXES):
                    yield os.path.join(folder, name)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--max", type=int, default=150, help="longest body allowed, in lines (default 150)")
    parser.add_argument("paths", nargs="+", help="folders (searched recursively) or files")
    args = parser.parse_args()
    failures = 0
    for path in source_files(args.paths):
        for line, length, name in long_functions(path, args.max):
            print(f"{path}:{line}: {name} is {length} lines long (at most {args.max})")
            failures += 1
    if failures:
        print(f"{failures} function(s) over {args.max} lines: split them into named steps")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
