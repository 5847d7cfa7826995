#!/usr/bin/env python3
"""The performance table of docs/experiments.md ("Performance"), measured again.

    scripts/perf-table.py [--bin target/release/penumbra] [--vs OTHER_BINARY] [--runs 5]
                          [--rows hard-sv,wedges,optimized,forest,culling,threads,default]

Every figure is the median over --runs cold processes (`penumbra render`, one method, one
scene, one size, a fixed thread count) of the pass times the render writes to its
stats.json (`wall_seconds` of each pass; the method's time is its passes without the shared
scene-depth pass). With --vs, the two binaries run in turn (A B A B ...), so that a drift of
the machine's speed moves both alike, and each row gives both and their ratio. Standard
library only; nothing is installed. Timings are informational: no test reads them.
"""

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROWS = ["hard-sv", "wedges", "optimized", "forest", "culling", "threads", "default"]


def render(binary, out, scene, method, size, threads, opts):
    """One cold process; returns ({pass: ms}, method ms without scene-depth)."""
    shutil.rmtree(out, ignore_errors=True)
    cmd = [binary, "render", scene, "--methods", method, "--width", str(size),
           "--height", str(size), "--threads", str(threads), "--out", out]
    for o in opts:
        cmd += ["--opt", o]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    with open(os.path.join(out, method, "stats.json")) as f:
        stats = json.load(f)
    passes = {p["name"]: p["wall_seconds"] * 1e3 for p in stats["passes"]}
    return passes, sum(v for k, v in passes.items() if k != "scene-depth")


def row(args, label, scene, method, size, thread_counts, opts=()):
    """Alternate the binaries (and the thread counts) --runs times; print the medians (and
    min/max of the method) of each; return them by (binary, threads)."""
    bins = [("A", args.bin)] + ([("B", args.vs)] if args.vs else [])
    runs = [(name, binary, threads) for threads in thread_counts for name, binary in bins]
    got = {(name, threads): [] for name, _, threads in runs}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.runs):
            for name, binary, threads in runs:
                got[name, threads].append(render(binary, os.path.join(tmp, name), scene,
                                                 method, size, threads, opts))
    medians = {}
    for name, binary, threads in runs:
        results = got[name, threads]
        passes = {p: statistics.median(r[0][p] for r in results) for p in results[0][0]}
        totals = [r[1] for r in results]
        medians[name, threads] = statistics.median(totals)
        print(f"{label} [{name}: {binary}] {scene} {size}² {threads}T {' '.join(opts)}: "
              + " ".join(f"{p} {v:.1f}" for p, v in passes.items())
              + f" | method median {medians[name, threads]:.1f} ms (min {min(totals):.1f}, "
              f"max {max(totals):.1f})", flush=True)
    if args.vs:
        for threads in thread_counts:
            ratio = medians["A", threads] / medians["B", threads]
            print(f"{label} {threads}T: A/B = {ratio:.3f}", flush=True)
    return medians


def default_run(args):
    """The default run (`penumbra` with no arguments) in a scratch directory, wall time."""
    for name, binary in [("A", args.bin)] + ([("B", args.vs)] if args.vs else []):
        times = []
        for _ in range(min(args.runs, 3)):
            with tempfile.TemporaryDirectory() as tmp:
                start = time.monotonic()
                subprocess.run([os.path.abspath(binary)], cwd=tmp, check=True,
                               stdout=subprocess.DEVNULL)
                times.append(time.monotonic() - start)
        print(f"default run [{name}: {binary}]: " + ", ".join(f"{t:.2f}" for t in times)
              + " s", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--bin", default="target/release/penumbra")
    parser.add_argument("--vs", help="a second binary, timed in turn with the first")
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--rows", default=",".join(ROWS))
    args = parser.parse_args()
    rows = args.rows.split(",")
    unknown = [r for r in rows if r not in ROWS]
    if unknown:
        sys.exit(f"unknown rows {unknown}: choose from {ROWS}")
    if "hard-sv" in rows:
        row(args, "hard-sv depth + z-fail", "forest-spheres", "hard-sv", 256, [2],
            ["hard-sv.mode=zfail"])
    if "wedges" in rows:
        row(args, "ssv wedge pass", "cube-of-spheres", "ssv", 512, [1])
    if "optimized" in rows:
        row(args, "ssv-optimized", "cube-of-spheres", "ssv-optimized", 512, [1])
    if "forest" in rows:
        row(args, "ssv on forest-spheres", "forest-spheres", "ssv", 256, [2])
        row(args, "raycast 16", "forest-spheres", "raycast", 256, [2], ["raycast.samples=16"])
        row(args, "raycast 1024", "forest-spheres", "raycast", 256, [2])
    if "culling" in rows:
        row(args, "pw-restructured culling on", "cube-of-spheres-sphere", "pw-restructured",
            256, [1])
        row(args, "pw-restructured culling off", "cube-of-spheres-sphere", "pw-restructured",
            256, [1], ["pw-restructured.culling=off"])
    if "threads" in rows:
        for method in ["ssv", "raycast", "nsample"]:
            got = row(args, method, "cube-of-spheres", method, 512, [1, 2])
            for name in ["A", "B"][: 1 + bool(args.vs)]:
                print(f"{method} [{name}] 2 threads vs 1: "
                      f"{got[name, 1] / got[name, 2]:.2f}×", flush=True)
    if "default" in rows:
        default_run(args)


if __name__ == "__main__":
    main()
