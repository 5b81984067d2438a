"""Helpers the page generators share (benchmarks_page.py, results_page.py): reading, number formats."""
import os


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def fmt(v, digits=3):
    """A number with `digits` significant digits, without exponent for everyday magnitudes."""
    if v is None:
        return "-"
    if v == 0:
        return "0"
    if abs(v) >= 10 ** digits:
        return f"{v:.0f}"
    if abs(v) < 1e-3:
        return f"{v:.{digits - 1}e}"
    return f"{v:.{digits}g}"


def fmt_time(ns):
    if ns is None:
        return "-"
    for unit, scale in (("s", 1e9), ("ms", 1e6), ("us", 1e3)):
        if ns >= scale:
            return f"{fmt(ns / scale)} {unit}"
    return f"{fmt(ns)} ns"


def fmt_ratio(r):
    return "-" if r is None else f"{r:.3g}x"



def met_text(ok):
    return "not measured" if ok is None else ("**yes**" if ok else "**no**")


def run_info(directory, script="scripts/results.sh"):
    """run_info.txt (machine, compiler, libraries, commit, command) as a Markdown list."""
    path = os.path.join(directory, "run_info.txt")
    if not os.path.exists(path):
        return "- (run_info.txt not found: run %s to record machine, compiler and commit)" % script
    return "\n".join("- " + line for line in read(path).strip().splitlines())


def table_lines(markdown):
    """The first Markdown table of a file and the paragraph that follows it (its legend)."""
    lines, out, in_table = markdown.splitlines(), [], False
    for i, line in enumerate(lines):
        if line.startswith("|"):
            in_table = True
            out.append(line)
        elif in_table:
            rest = [l for l in lines[i:] if l.strip()]
            if rest and not rest[0].startswith("Command"):
                out += ["", rest[0]]
            break
    return "\n".join(out)
