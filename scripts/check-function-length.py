#!/usr/bin/env python3
"""Checks that no function in include/, src/ and apps/ (.hpp, .cpp, .h) is longer than 80 lines.

A function's length is counted from the line of its body's opening brace to the line of its closing
brace, both included, comments and blank lines too. Class, struct, union, enum and namespace bodies are
not functions (the member functions inside them are); a lambda or local class inside a function is part
of that function. Comments, string and character literals and preprocessor lines are blanked first, so
braces in them do not count.

  scripts/check-function-length.py [REPO_ROOT]     prints path:line: name is N lines (limit 80) for
                                                   each longer function, exits 1 when there is any
"""
import pathlib
import re
import sys

LIMIT = 80
TREES = ("include", "src", "apps")
SUFFIXES = (".hpp", ".cpp", ".h")

LITERAL = re.compile(r'(?P<raw>R"(?P<delim>[^(\s]*)\(.*?\)(?P=delim)")'  # raw string
                     r'|"(?:\\.|[^"\\\n])*"'                               # string
                     r"|(?<![\w'])'(?:\\.|[^'\\\n])+'"                     # char (not a digit separator)
                     r"|//[^\n]*|/\*.*?\*/"                                # comments
                     r"|^[ \t]*#(?:[^\n]*\\\n)*[^\n]*",                    # preprocessor line
                     re.DOTALL | re.MULTILINE)
# What stands before a function body's brace: a parameter list, then qualifiers or a trailing return type.
FUNCTION_TAIL = re.compile(r"\)\s*(?:(?:const|volatile|noexcept|override|final|mutable|constexpr|try|&&?)\s*)*"
                           r"(?:->[^;{}]*)?$")
# A constructor whose member initialiser list ends in braces: `) : a_(a), b_{b}`.
BRACED_INIT_LIST = re.compile(r"\)\s*(?:noexcept\s*)?:(?!:)[^;]*\}$")
SCOPE = re.compile(r"\b(?:namespace|class|struct|union|enum|extern)\b")
NOT_A_NAME = {"decltype", "alignas", "sizeof", "alignof", "noexcept", "__attribute__", "void", "bool", "char",
              "int", "long", "short", "float", "double", "unsigned", "signed", "auto"}
NAME_BEFORE_PAREN = re.compile(r"(operator\s*(?:\(\)|[^\s(]+)|~?[A-Za-z_]\w*(?:\s*::\s*~?[A-Za-z_]\w*)*|\])\s*(?:<[^()]*>)?\s*\(")


def blank(match):
    """The literal or comment with every character but newlines replaced by a space (lines keep their numbers)."""
    return re.sub(r"[^\n]", " ", match.group(0))


def without_template_headers(head):
    """The declaration head without its `template <...>` parameter lists (whose `class` opens no scope)."""
    out, depth, i = [], 0, 0
    for match in re.finditer(r"\btemplate\s*<|[<>]", head):
        if match.group(0) != "<" and match.group(0) != ">":  # template <
            if depth == 0:
                out.append(head[i:match.start()])
            depth += 1
        elif depth and match.group(0) == "<":
            depth += 1
        elif depth and match.group(0) == ">":
            depth -= 1
            if depth == 0:
                i = match.end()
    if depth == 0:
        out.append(head[i:])
    return "".join(out)


def function_name(head):
    """The name before the parameter list of a function header (`lambda` for a lambda)."""
    for match in NAME_BEFORE_PAREN.finditer(head):
        name = re.sub(r"\s+", "", match.group(1))
        if name == "]":
            return "lambda"
        if name.split("::")[-1] not in NOT_A_NAME:
            return name
    return "?"


def long_functions(text):
    """(line, name, lines) of every function body in the C++ source text longer than LIMIT lines."""
    code = LITERAL.sub(blank, text)
    found = []
    head_start = 0   # where the declaration before the next brace begins
    stack = []       # one entry per open brace: (kind, position, head start to restore, name)
    for i, ch in enumerate(code):
        inside_function = any(kind == "function" for kind, *_ in stack)
        if ch == ";" and not inside_function:
            head_start = i + 1
        elif ch == "{":
            head = code[head_start:i].strip()
            if inside_function:
                kind = "block"
            elif FUNCTION_TAIL.search(head) or BRACED_INIT_LIST.search(head):
                kind = "function"
            elif SCOPE.search(without_template_headers(head)):
                kind = "scope"
            else:
                kind = "initialiser"  # `= {...}`, `x_{...}`: the declaration goes on after it
            stack.append((kind, i, head_start, function_name(head) if kind == "function" else ""))
            head_start = i + 1
        elif ch == "}" and stack:
            kind, start, outer_head_start, name = stack.pop()
            head_start = outer_head_start if kind == "initialiser" else i + 1
            if kind == "function":
                first, last = code.count("\n", 0, start) + 1, code.count("\n", 0, i) + 1
                if last - first + 1 > LIMIT:
                    found.append((first, name, last - first + 1))
    return found


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent)
    count = 0
    for tree in TREES:
        for path in sorted((root / tree).rglob("*")):
            if path.suffix in SUFFIXES and path.is_file():
                for line, name, lines in long_functions(path.read_text(encoding="utf-8", errors="replace")):
                    print(f"{path.relative_to(root)}:{line}: {name} is {lines} lines (limit {LIMIT})")
                    count += 1
    if count:
        print(f"check-function-length: {count} functions over {LIMIT} lines; split them into steps", file=sys.stderr)
    return 1 if count else 0


if __name__ == "__main__":
    sys.exit(main())
