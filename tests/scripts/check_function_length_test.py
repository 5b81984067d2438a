#!/usr/bin/env python3
"""Tests of scripts/check-function-length.py (run by ctest): in a temporary tree, a function of 81 lines
(opening to closing brace) is reported and fails the check, one of 80 lines passes; a long class body, a
lambda inside a short function and braces in comments and strings are not counted as functions."""
import os
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts", "check-function-length.py")


def function(name, lines):
    """A C++ function whose body spans `lines` lines, braces included."""
    return f"int {name}(int x) {{\n" + "  x += 1;\n" * (lines - 3) + "  return x;\n}\n"


class CheckFunctionLength(unittest.TestCase):
    def check(self, files):
        """Runs the script on a tree of {relative path: text}; returns (exit code, stdout)."""
        with tempfile.TemporaryDirectory(prefix="dyncull_function_length_test_") as root:
            for path, text in files.items():
                os.makedirs(os.path.dirname(os.path.join(root, path)), exist_ok=True)
                with open(os.path.join(root, path), "w") as f:
                    f.write(text)
            run = subprocess.run([sys.executable, SCRIPT, root], capture_output=True, text=True)
            return run.returncode, run.stdout

    def test_81_lines_fail_and_80_pass(self):
        code, out = self.check({"include/a.hpp": "#pragma once\n\n" + function("too_long", 81),
                                "src/b.cpp": function("just_fits", 80) + "// a comment with { a brace\n"})
        self.assertEqual(code, 1)
        self.assertEqual(out.strip().splitlines(), ["include/a.hpp:3: too_long is 81 lines (limit 80)"])

    def test_classes_lambdas_and_literals_are_not_functions(self):
        members = "".join(f"  int f{i}() const {{ return {i}; }}\n" for i in range(90))
        lambda_inside = ("void outer() {\n  auto step = [](int v) {\n" + "    v += 1;\n" * 50
                         + "    return v;\n  };\n  step(1);\n}\n")
        strings = 'const char* open = "{{{";\nconst char brace = \'{\';\n' + function("short_one", 10)
        code, out = self.check({"apps/c.cpp": "namespace n {\nstruct Big {\n" + members + "};\n}\n",
                                "include/d.h": lambda_inside + strings})
        self.assertEqual((code, out), (0, ""))


if __name__ == "__main__":
    unittest.main()
