#!/usr/bin/env python3
"""Checks that no function in src/ or apps/ is longer than 80 lines (STYLE.md: "no function over
~80"). A function is a brace block at namespace or class scope whose opening brace follows a
parameter list; its length counts the lines from its signature's last line to its closing brace,
lambdas and local classes inside it included. Comments, strings and character literals are blanked
before braces are matched. Prints each function over the limit; exits 1 if any.

  check-function-length.py [--limit N] [--list]   (--list prints every function over 40 lines)"""
import os
import re
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
FOLDERS = ("src", "apps", "python")


def blank(text):
    """Replaces comments and string/char literals by spaces, keeping line breaks."""
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
        elif text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            k = text.find("(", i)
            delim = ")" + text[i + 2:k] + '"'
            j = text.find(delim, k)
            j = n if j < 0 else j + len(delim)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum():  # digit separator: 1'000'000
                out.append(" ")
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(" " * (j + 1 - i))
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


SIGNATURE_END = re.compile(r"\)\s*(const|noexcept|override|final|mutable|->\s*[\w:<>,\s*&]+|\s)*$")


def functions(text):
    """Yields (name, first_line, line_count) of each function body at namespace or class scope."""
    clean = blank(text).replace("{}", "  ")  # empty initialisers and bodies
    stack = []  # one entry per open brace: True when it opens a scope that may hold functions
    line = 1
    for i, c in enumerate(clean):
        if c == "\n":
            line += 1
        elif c == "{":
            outer = all(s is True for s in stack)
            head = clean[max(0, i - 400):i]
            head = head[max(head.rfind(";"), head.rfind("{"), head.rfind("}")) + 1:]
            is_function = outer and SIGNATURE_END.search(head.rstrip()) is not None
            is_function = is_function and not re.search(r"\b(if|for|while|switch|catch)\s*\(", head)
            is_function = is_function and not re.search(r"=\s*\[", head)  # a lambda's initialiser
            if is_function:
                name = re.findall(r"([~\w:]+)\s*\(", head)
                stack.append(("fn", name[0] if name else "?", line))
            else:
                scope = re.search(r"\b(namespace|class|struct|union|extern)\b", head) is not None
                stack.append(scope and outer)
        elif c == "}" and stack:
            top = stack.pop()
            if isinstance(top, tuple):
                yield top[1], top[2], line - top[2] + 1


def main():
    limit = 80
    list_mode = "--list" in sys.argv
    if "--limit" in sys.argv:
        limit = int(sys.argv[sys.argv.index("--limit") + 1])
    report = 40 if list_mode else limit
    over = []
    for folder in FOLDERS:
        for base, _, files in os.walk(os.path.join(ROOT, folder)):
            for name in sorted(files):
                if not name.endswith((".h", ".cpp")):
                    continue
                path = os.path.join(base, name)
                rel = os.path.relpath(path, ROOT)
                text = open(path, encoding="utf-8").read()
                for fn, first, count in functions(text):
                    if count > report:
                        over.append((count, f"{rel}:{first}: {fn} is {count} lines"))
    for count, message in sorted(over, reverse=True):
        print(message)
    bad = [m for c, m in over if c > limit]
    if bad and not list_mode:
        print(f"check-function-length: {len(bad)} function(s) over {limit} lines", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
