#!/usr/bin/env python3
"""Checks the module dependency rules of docs/design.md against the include graph.

The rules are read from design.md's module diagram itself, so the document and the check cannot drift:
each module line ends in `-> what it may include`, a comma list of modules (`core`) or single headers
(`culling/culler.hpp`), then `+ Library` for the third-party libraries beyond the standard library
(compiler intrinsics count as standard). A line `src/<module>/ also -> ...` adds what the module's
compiled sources may include besides. Every module may include itself and Eigen (the library's base).
The umbrella header dyncull.hpp must include the library (core, geometry, culling, and culling/culler.hpp)
and nothing of the evaluation product or the adapters.

  scripts/check-modules.py [REPO_ROOT]     exit 0 when every include follows the rules
"""
import pathlib
import re
import sys

MODULES = ("core", "geometry", "culling", "eval", "sim", "opencv", "ceres", "host")
LIBRARY = ("core", "geometry", "culling")  # what the umbrella header holds
# Third-party include prefixes and the library name design.md gives them.
EXTERNAL = {"Eigen/": "Eigen", "unsupported/Eigen/": "Eigen", "opencv2/": "OpenCV", "ceres/": "Ceres"}
POSIX = re.compile(r"^(unistd\.h|fcntl\.h|sys/.*)$")
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^>"]+)[>"]', re.MULTILINE)


class Rule:
    def __init__(self):
        self.modules = set()   # whole modules it may include
        self.headers = set()   # single headers of other modules, "culling/culler.hpp"
        self.libraries = {"std", "Eigen"}

    def add(self, text):
        """Adds `core, culling/culler.hpp + OpenCV 4` (parenthesised remarks dropped)."""
        text = re.sub(r"\([^)]*\)", "", text)
        parts = text.split("+")
        for name in parts[0].split(","):
            name = name.strip()
            if not name:
                continue
            if name in ("std", "Eigen"):
                continue
            if "/" in name:
                self.headers.add(name)
            elif name in MODULES:
                self.modules.add(name)
            else:
                raise ValueError(f"design.md: unknown module '{name}'")
        for library in parts[1:]:
            self.libraries.add(library.split()[0])

    def allows(self, own, target):
        module = target.split("/")[0]
        return module == own or module in self.modules or target in self.headers


def read_rules(design):
    """Parses the ``` block under "## Modules and dependency rules" into header and source rules."""
    section = design.split("## Modules and dependency rules", 1)[1]
    block = section.split("```", 2)[1]
    headers, sources = {}, {}
    current = None
    for line in block.splitlines():
        start = re.match(r"^  ([a-z]+)/\s", line)
        if start and start.group(1) in MODULES:
            current = start.group(1)
        source = re.search(r"src/([a-z]+)/ also\s*->(.*)$", line)
        if source:
            sources.setdefault(source.group(1), Rule()).add(source.group(2))
        elif "->" in line and current:
            headers.setdefault(current, Rule()).add(line.split("->", 1)[1])
            current = None
    missing = [m for m in MODULES if m not in headers]
    if missing:
        raise ValueError(f"design.md: no '->' rule for {', '.join(missing)}")
    return headers, sources


def classify(include):
    """('dyncull', 'culling/culler.hpp'), ('library', 'OpenCV'), or ('library', 'std')."""
    if include.startswith("dyncull/"):
        return "dyncull", include[len("dyncull/"):]
    for prefix, name in EXTERNAL.items():
        if include.startswith(prefix):
            return "library", name
    if POSIX.match(include):
        return "library", "POSIX"
    if "/" in include or (include.endswith(".h") and not include.endswith("intrin.h")):
        return "library", include  # unknown: reported unless a rule names it
    return "library", "std"


def check_file(path, module, rule, extra, root):
    problems = []
    for include in INCLUDE.findall(path.read_text(encoding="utf-8")):
        kind, target = classify(include)
        if kind == "dyncull":
            if target == "version.hpp" or rule.allows(module, target) or (extra and extra.allows(module, target)):
                continue
        elif target in rule.libraries or (extra and target in extra.libraries):
            continue
        problems.append(f"{path.relative_to(root)}: includes <{include}>, which module '{module}' may not")
    return problems


def check_umbrella(root):
    path = root / "include/dyncull/dyncull.hpp"
    includes = INCLUDE.findall(path.read_text(encoding="utf-8"))
    problems = [f"include/dyncull/dyncull.hpp: includes <{i}>, outside the library ({', '.join(LIBRARY)})"
                for i in includes if i.split("/")[1] not in LIBRARY]
    if "dyncull/culling/culler.hpp" not in includes:
        problems.append("include/dyncull/dyncull.hpp: lacks dyncull/culling/culler.hpp")
    return problems


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent)
    headers, sources = read_rules((root / "docs/design.md").read_text(encoding="utf-8"))
    problems, files = [], 0
    for module in MODULES:
        for tree, extra in (("include/dyncull", None), ("src", sources.get(module))):
            for path in sorted((root / tree / module).rglob("*")):
                if path.suffix in (".hpp", ".cpp", ".h"):
                    files += 1
                    problems += check_file(path, module, headers[module], extra, root)
    problems += check_umbrella(root)
    for problem in problems:
        print(problem)
    print(f"check-modules: {files} files, {len(problems)} violations of the rules in docs/design.md")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
