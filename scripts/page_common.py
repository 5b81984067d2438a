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


def run_info(directory, script):
    """run_info.txt (machine, compiler, libraries, commit, command) as a Markdown list."""
    path = os.path.join(directory, "run_info.txt")
    if not os.path.exists(path):
        return "- (run_info.txt not found: run %s to record machine, compiler and commit)" % script
    return "\n".join("- " + line for line in read(path).strip().splitlines())
