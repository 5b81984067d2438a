#!/usr/bin/env python3
"""Writes docs/benchmarks.md from a run of scripts/benchmarks.sh.

    scripts/benchmarks_page.py RUN_DIR PAGE

RUN_DIR holds one Google Benchmark JSON file per bench binary (bench_<module>_<name>_bench.json, and
bench_<...>.<part>.json for a second invocation of the same binary), run_info.txt (machine, compiler,
libraries, commit, command, wall time) and, when the compile-cost scripts wrote them, compile_cost.csv and
compile_cost_host.csv (unit,user_s,wall_s,peak_rss_mb). Every figure on the page comes from these files:
rerunning the script regenerates it.
"""
import csv
import glob
import json
import os
import re
import sys

from benchmarks_targets import targets
from benchmarks_text import OTHER_PEERS, PROSE, STAGE_TEXT
from page_common import fmt, fmt_ratio, fmt_time, met_text, read, run_info

# ---------------------------------------------------------------------------------------------- reading


class Run:
    """The benchmarks of one run: per binary, the median aggregate of each case (or its single run)."""

    def __init__(self, directory):
        self.dir = directory
        self.cases = {}     # binary -> {run name -> record}
        self.order = {}     # binary -> [run name] in the order the binary ran them
        self.context = {}   # binary -> Google Benchmark's context (load average, cpus)
        for path in sorted(glob.glob(os.path.join(directory, "bench_*.json"))):
            binary = os.path.basename(path).split(".")[0]
            with open(path, encoding="utf-8") as f:
                data = json.load(f)
            self.context.setdefault(binary, data.get("context", {}))
            cases = self.cases.setdefault(binary, {})
            order = self.order.setdefault(binary, [])
            for b in data.get("benchmarks", []):
                name = b.get("run_name", b["name"])
                if b.get("run_type") == "aggregate" and b.get("aggregate_name") != "median":
                    continue
                if name not in cases:
                    order.append(name)
                cases[name] = b

    def get(self, binary, name):
        return self.cases.get(binary, {}).get(name)

    def cpu_ns(self, binary, name):
        b = self.get(binary, name)
        if b is None:
            return None
        return b["cpu_time"] * UNIT_NS[b.get("time_unit", "ns")]

    def counter(self, binary, name, key):
        b = self.get(binary, name)
        return None if b is None or key not in b else float(b[key])

    def ratio(self, binary, ours, peer):
        a, b = self.cpu_ns(binary, ours), self.cpu_ns(binary, peer)
        return None if a is None or not b else a / b


UNIT_NS = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}
STANDARD_KEYS = {"name", "family_index", "per_family_instance_index", "run_name", "run_type", "repetitions",
                 "repetition_index", "threads", "aggregate_name", "aggregate_unit", "iterations", "real_time",
                 "cpu_time", "time_unit", "label", "error_occurred", "error_message"}


def other_peers(run):
    out = ["| case | dyncull | peer | peer time | ratio |", "|---|---|---|---|---|"]
    for binary, what, ours, peer_text, peer in OTHER_PEERS:
        r = run.ratio(binary, ours, peer)
        if r is not None:
            out.append(f"| {what} | {fmt_time(run.cpu_ns(binary, ours))} | {peer_text} | "
                       f"{fmt_time(run.cpu_ns(binary, peer))} | {fmt_ratio(r)} |")
    return "\n".join(out) if len(out) > 2 else "(none of these binaries was in this run)"


def stages(run):
    b = "bench_culling_stages_bench"
    names = [n for n in run.order.get(b, []) if n.startswith("BM_Stage_")]
    if not names:
        return "(bench_culling_stages_bench was not in this run)"
    out = ["| stage | CPU per frame | counters |", "|---|---|---|"]
    for n in names:
        out.append(f"| {STAGE_TEXT.get(n, n)} | {fmt_time(run.cpu_ns(b, n))} | {counters_text(run.get(b, n))} |")
    total = sum(run.cpu_ns(b, n) for n in names)
    out.append(f"| **sum of the stages** | **{fmt_time(total)}** | |")
    return "\n".join(out)


def allocations(run):
    b = "bench_culling_allocations_bench"
    names = [n for n in run.order.get(b, []) if n.startswith("BM_Allocations")]
    if not names:
        return "(bench_culling_allocations_bench was not in this run)"
    out = ["| preset | allocations per frame after warm-up (most of any frame) | mean | CPU per 3 frames |",
           "|---|---|---|---|"]
    for n in names:
        rec = run.get(b, n)
        out.append(f"| {rec.get('label', n)} | {fmt(run.counter(b, n, 'allocs_per_frame'))} | "
                   f"{fmt(run.counter(b, n, 'allocs_mean'))} | {fmt_time(run.cpu_ns(b, n))} |")
    return "\n".join(out)


def compile_cost(directory, name, baseline, baseline_text):
    """The CSV's units as a table; with `baseline` (a unit name, or None for the first line) a column of
    user time and peak memory over that unit's."""
    path = os.path.join(directory, name)
    if not os.path.exists(path):
        return None
    with open(path, newline="", encoding="utf-8") as f:
        rows = [r for r in csv.DictReader(f) if r.get("unit")]
    if not rows:
        return None
    base = rows[0] if baseline is None else next((r for r in rows if r["unit"] == baseline), None)
    head = "| translation unit | user time | wall | peak RSS |"
    sep = "|---|---|---|---|"
    if base:
        head += f" x {baseline_text} (user time / peak RSS) |"
        sep += "---|"
    out = [head, sep]
    for r in rows:
        u, w, m = float(r["user_s"]), float(r["wall_s"]), float(r["peak_rss_mb"])
        line = f"| `{r['unit']}` | {fmt(u)} s | {fmt(w)} s | {fmt(m, 4)} MB |"
        if base:
            bu, bm = float(base["user_s"]), float(base["peak_rss_mb"])
            line += f" {fmt(u / bu) if bu else '-'} / {fmt(m / bm) if bm else '-'} |"
        out.append(line)
    return "\n".join(out)


# ---------------------------------------------------------------------------------------------- tables


def counters_text(b):
    if b is None:
        return ""
    out = []
    for k in b:
        if k in STANDARD_KEYS or not isinstance(b[k], (int, float)):
            continue
        if k == "bytes_per_second":
            out.append(f"{fmt(b[k] / 1e9)} GB/s")
        elif k == "items_per_second":
            out.append(f"{fmt(b[k] / 1e6)} M items/s")
        else:
            out.append(f"{k} {fmt(float(b[k]))}")
    return ", ".join(out)


def binary_table(run, binary):
    labels = any(run.cases[binary][n].get("label") or run.cases[binary][n].get("error_occurred")
                 for n in run.order[binary])
    out = ["| case |" + (" label |" if labels else "") + " CPU | wall | counters |",
           "|---|" + ("---|" if labels else "") + "---|---|---|"]
    for n in run.order[binary]:
        b = run.cases[binary][n]
        if b.get("error_occurred"):
            out.append(f"| `{n}` | {b.get('error_message', '')} | - | - | |")
            continue
        unit = UNIT_NS[b.get("time_unit", "ns")]
        label = f" {b.get('label', '')} |" if labels else ""
        out.append(f"| `{n}` |{label} {fmt_time(b['cpu_time'] * unit)} | "
                   f"{fmt_time(b['real_time'] * unit)} | {counters_text(b)} |")
    return "\n".join(out)


def source_comment(binary):
    """The leading comment of the binary's source: what it measures, as the bench says it."""
    m = re.match(r"bench_([a-z]+)_(.+)$", binary)
    if not m:
        return ""
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "bench", m.group(1), m.group(2) + ".cpp")
    if not os.path.exists(path):
        return ""
    lines = []
    for line in read(path).splitlines():
        if not line.startswith("//"):
            break
        lines.append(line[2:].strip())
    return " ".join(lines)


SECTIONS = [("Geometry", "bench_geometry_"), ("Culling", "bench_culling_"), ("Evaluation", "bench_eval_"),
            ("Synthetic scene", "bench_sim_")]


def load_text(run, binary):
    load = run.context.get(binary, {}).get("load_avg")
    return f"load average at its start {', '.join(f'{x:.1f}' for x in load)}" if load else ""


def main():
    directory, page = sys.argv[1], sys.argv[2]
    run = Run(directory)
    info = run_info(directory, "scripts/benchmarks.sh")
    rows = targets(run)
    target_table = ["| hot path | target | measured (ratios within one binary's run) | met? |", "|---|---|---|---|"]
    target_table += [f"| {p} | {t} | {m} | {met_text(ok)} |" for p, t, m, ok in rows]

    cc = compile_cost(directory, "compile_cost.csv", "instantiate", "`instantiate`")
    cch = compile_cost(directory, "compile_cost_host.csv", None, "the unit without dyncull")
    cc_text = []
    if cc:
        cc_text += ["The culling pipeline in one translation unit, `g++ -std=c++17 -O2`, measured with `/usr/bin/time -v`",
                    "by `scripts/compile-cost.sh --csv FILE`: `include_only` includes `culling/pipeline.hpp`,",
                    "`instantiate` also instantiates `cull_frame<float>` for a dynamic_vo-like frame, and",
                    "`instantiate_precompiled` is that file with `-DDYNCULL_PRECOMPILED`, as a target linking",
                    "`dyncull::pipeline` compiles it (`cull_frame` and the solvers come from the library). Target: the",
                    "precompiled unit at most half of `instantiate`'s time and peak memory.", "", cc, ""]
    if cch:
        cc_text += ["A host translation unit like an ORB-SLAM front end (`opencv2/core`, `features2d`, `Eigen/Core`; ORB",
                    "into vectors), `g++ -std=c++14 -O2`, without dyncull and with `dyncull/opencv/culler.hpp`",
                    "included and the culler called, `scripts/compile-cost-host.sh --csv FILE`. Target: at most 2x the",
                    "time and peak memory of the unit without it.", "", cch, ""]
    if not cc_text:
        cc_text = ["Not measured in this run: `scripts/compile-cost.sh` and `scripts/compile-cost-host.sh` write the",
                   "CSV the page reads only with `--csv` (run them by hand for a console table).", ""]

    parts = [f"""# Benchmarks

How fast dyncull is, against the library a user would otherwise call (OpenCV, Eigen, Ceres, Open3D) **in the same
binary**, so each ratio comes from one run, with accuracy beside time as counters. Every hot path has a Google
Benchmark case under `bench/` (mirroring `include/dyncull/`; one binary per file, `bench_<module>_<name>_bench`).

This page is generated: `scripts/benchmarks.sh` builds the benches in Release (build/bench), runs each with
`--benchmark_format=json`, measures the compile cost, and rewrites the page from that output with
`scripts/benchmarks_page.py`; `scripts/benchmarks.sh --page-only DIR` rewrites it from an earlier run. To run one
binary by hand:

```sh
cmake -S . -B build/bench -DCMAKE_BUILD_TYPE=Release && cmake --build build/bench --target bench_culling_culler_bench -j1
build/bench/bench/bench_culling_culler_bench --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
```

Times are **CPU-time medians of the repetitions**, one thread (OpenCV pinned to one thread: Google Benchmark's CPU
time does not see worker threads). On a shared machine absolute times move with the load by 1.5-3x and ratios by
about 10-30 %: compare ratios within one run, and read the load average below.

This run:

{info}

## Targets and where dyncull stands

{chr(10).join(target_table)}

## Where the culling time goes

Each stage of `cull_frame` (`culling/stages/`) alone on the pipeline bench's frame (float, the recommended preset
given 3-D points and track ids, the multi-view check verifying its candidates, the probability on for its own case
only), `bench_culling_stages_bench`:

{stages(run)}

## Heap allocations per frame

`bench_culling_allocations_bench`: `cull_frame` on three frames of the synthetic culling scene with 3-D points and
track ids, replayed after three warm-up rounds, a keyframe ring of two slots (full before the count); the counter is
the most allocations any frame made. `tests/culling/pipeline_allocations_test.cpp` fails above its per-preset bound
on the same sequence, and `docs/design.md` lists what still allocates.

{allocations(run)}

## Compile cost

{chr(10).join(cc_text)}
## Other peers (no numeric target)

{other_peers(run)}
"""]
    for title, prefix in SECTIONS:
        binaries = [b for b in sorted(run.cases) if b.startswith(prefix)]
        if not binaries:
            continue
        parts.append(f"## {title} benchmarks\n")
        for b in binaries:
            parts.append(f"### {b}\n")
            text = source_comment(b)
            if text:
                parts.append(text + "\n")
            if b in PROSE:
                parts.append(PROSE[b].replace("\n", " ") + "\n")
            lt = load_text(run, b)
            if lt:
                parts.append(f"({lt}.)\n")
            parts.append(binary_table(run, b) + "\n")
    with open(page, "w", encoding="utf-8") as f:
        f.write("\n".join(parts).rstrip() + "\n")


if __name__ == "__main__":
    main()
