#!/usr/bin/env python3
"""Counts the settable leaves of an options struct in include/dyncull: each data member is one leaf,
except a member or base that is itself an options struct of the library, whose leaves count instead.
A class with private data (MotionLevelTable) is one leaf. The stages' slots
(detail::OptionSlots<PipelineStages<T>>) count as the options of the stages listed in stages/list.hpp.

  scripts/count-option-leaves.py [--max N] [--list] STRUCT...   e.g. PipelineOptions CullerCoreOptions
Exit status 1 when a struct has more than N leaves (CI keeps the pipeline's settings readable)."""
import argparse
import os
import re
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "include", "dyncull")
HEAD = re.compile(r"(?<!enum )\b(struct|class)\s+(\w+)\s*(?:final\s*)?(?::\s*([^{;]*))?\{")
SKIP = re.compile(r"^\s*(static|constexpr|using|friend|typedef|template|public|private|protected|enum)\b")


def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def body_at(text, start):
    """The text inside the braces opened at text[start], with nested braces' contents dropped."""
    depth, out = 0, []
    for i in range(start, len(text)):
        c = text[i]
        if c == "{":
            depth += 1
            if depth > 1:
                out.append("{}")  # a nested body (a function, a default initialiser) is not a member
            continue
        if c == "}":
            depth -= 1
            if depth == 0:
                return "".join(out)
            continue
        if depth == 1:
            out.append(c)
    return "".join(out)


def bare(type_name):
    """The struct a type names: namespaces and template arguments dropped."""
    name = re.sub(r"<.*>", "", type_name.strip())
    return name.split("::")[-1].strip()


def read_structs():
    structs = {}
    for folder, _, files in os.walk(ROOT):
        for f in files:
            if not f.endswith(".hpp"):
                continue
            text = strip_comments(open(os.path.join(folder, f), encoding="utf-8").read())
            for m in HEAD.finditer(text):
                members, private = [], m.group(1) == "class"
                for stmt in body_at(text, m.end() - 1).split(";"):
                    if re.search(r"\b(public|private|protected)\s*:", stmt):
                        private = "public" not in stmt.split(":")[0] if "class" == m.group(1) else private
                        stmt = re.sub(r"\b(public|private|protected)\s*:", "", stmt)
                    stmt = stmt.strip()
                    if not stmt or SKIP.match(stmt) or "(" in stmt.split("=")[0].split("{")[0]:
                        continue
                    decl = re.match(r"([\w:<>, ]*?[\w>])\s+(\w+)\s*(\[[^\]]*\])?\s*(=.*|\{\}.*)?$", stmt, re.S)
                    if decl:
                        members.append((decl.group(1), decl.group(2), private))
                        # "int a = 1, b = 2": one leaf per declarator (commas outside brackets)
                        rest = re.sub(r"<[^<>]*>|\([^()]*\)|\{[^{}]*\}", "", stmt[decl.end(2):])
                        members += [(decl.group(1), n, private) for n in re.findall(r",\s*(\w+)", rest)]
                bases = [b.strip() for b in re.split(r",(?![^<]*>)", m.group(3) or "") if b.strip()]
                bases = [re.sub(r"^(public|private|protected)\s+", "", b) for b in bases]
                structs.setdefault(m.group(2), (bases, members))
    return structs


def listed_stage_options():
    """(member name, options struct) of each stage in stages/list.hpp, from the stage's OptionsSlot."""
    stages = os.path.join(ROOT, "culling", "stages")
    text = strip_comments(open(os.path.join(stages, "list.hpp"), encoding="utf-8").read())
    listed = [bare(s) for s in re.split(r",(?![^<]*>)", re.search(r"StageList<(.*)>;", text, re.S).group(1))]
    slots = {}
    for f in os.listdir(stages):
        header = strip_comments(open(os.path.join(stages, f), encoding="utf-8").read())
        for m in re.finditer(r"struct (\w+Stage)\s*\{.*?using Options = (\w+)\b.*?struct OptionsSlot\s*\{\s*Options (\w+)",
                             header, re.S):
            slots[m.group(1)] = (m.group(3), m.group(2))
    return [slots[s] for s in listed]


def leaves(name, structs, prefix, out):
    bases, members = structs[name]
    if any(private for _, _, private in members):
        out.append(prefix.rstrip("."))  # a class with private data: one setting (a table)
        return
    for b in bases:
        if bare(b) == "OptionSlots":
            for member, stage_options in listed_stage_options():
                leaves(stage_options, structs, prefix + member + ".", out)
        elif bare(b) in structs:
            leaves(bare(b), structs, prefix, out)
    for t, n, _ in members:
        if bare(t) in structs and bare(t) not in ("Status",):
            leaves(bare(t), structs, prefix + n + ".", out)
        else:
            out.append(prefix + n)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("structs", nargs="+")
    ap.add_argument("--max", type=int, default=0)
    ap.add_argument("--list", action="store_true")
    ap.add_argument("--doc", help="a Markdown page that must name every leaf in backticks")
    args = ap.parse_args()
    structs = read_structs()
    documented = set(re.findall(r"`([\w.]+)`", open(args.doc, encoding="utf-8").read())) if args.doc else None
    failed = False
    for s in args.structs:
        found = []
        leaves(s, structs, "", found)
        if args.list:
            print("\n".join(found))
        over = args.max and len(found) > args.max
        print(f"{s}: {len(found)} leaves" + (f" (limit {args.max})" if args.max else ""))
        # CullerCoreOptions' pipeline.* are PipelineOptions' leaves, listed without the prefix.
        missing = [f for f in found if documented is not None and re.sub(r"^pipeline\.", "", f) not in documented]
        for f in missing:
            print(f"{args.doc}: {s}'s setting {f} is not listed")
        failed = failed or over or bool(missing)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
