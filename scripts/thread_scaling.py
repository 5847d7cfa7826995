#!/usr/bin/env python3
"""Issue 32 item 2, the scaling row: every method's whole render on 1 and on 2 threads.

    python3 scripts/thread_scaling.py [--runs N] [--size W] [--out DIR] [--penumbra EXE]

Each method renders on the built-in scene of its light shape (`cube-of-spheres`, rectangle;
`cube-of-spheres-sphere`, sphere; `disk-block`, disk) with its defaults, at W×W (default
512), in its own `penumbra render` process, N times (default 3) on 1 thread and N times on
2, the two in turn (1, 2, 1, 2, …) so that a drift of the machine's speed moves both alike.
The time is `stats.json`'s `wall_seconds` of the method (its passes, the shared scene pass
not included); per pass too, so that the serial parts show. The output, DIR/scaling.md and
DIR/scaling.json (default out/thread-scaling), gives the medians and their ratio (1-thread
median / 2-thread median) per method and per pass. The renders are bit-identical on any
thread count (tested); only the time differs. Python 3 alone, no packages.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
# (method, scene): the built-in scene of the method's light shape.
CASES = [
    ("hard-sv", "cube-of-spheres"),
    ("ssv", "cube-of-spheres"),
    ("ssv-optimized", "cube-of-spheres"),
    ("wedge-blending", "cube-of-spheres"),
    ("nsample", "cube-of-spheres"),
    ("raycast", "cube-of-spheres"),
    ("pw2002", "cube-of-spheres-sphere"),
    ("pw-restructured", "cube-of-spheres-sphere"),
    ("penumbra-map", "cube-of-spheres-sphere"),
    ("dbuffer", "disk-block"),
]


def render(exe: Path, method: str, scene: str, size: int, threads: int, out: Path) -> dict:
    """One render's stats.json of `method`."""
    subprocess.run(
        [str(exe), "render", scene, "--methods", method, "--width", str(size), "--height", str(size),
         "--threads", str(threads), "--out", str(out)],
        check=True, stdout=subprocess.DEVNULL,
    )
    stats = json.loads((out / method / "stats.json").read_text())
    shutil.rmtree(out)
    return stats


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--out", type=Path, default=REPO / "out" / "thread-scaling")
    ap.add_argument("--penumbra", type=Path, default=REPO / "target" / "release" / "penumbra")
    a = ap.parse_args()
    if a.runs < 1 or a.size < 1:
        ap.error("--runs and --size must be at least 1")
    if not a.penumbra.exists():
        print(f"thread_scaling.py: {a.penumbra}: missing (cargo build --release)", file=sys.stderr)
        return 2
    load_before = os.getloadavg()[0]
    rows = []
    with tempfile.TemporaryDirectory(prefix="penumbra-scaling-") as tmp:
        for method, scene in CASES:
            times = {1: [], 2: []}
            passes: dict[str, dict[int, list[float]]] = {}
            for k in range(a.runs):
                for t in (1, 2):
                    s = render(a.penumbra, method, scene, a.size, t, Path(tmp) / f"{method}-{t}-{k}")
                    times[t].append(s["wall_seconds"])
                    for p in s["passes"]:
                        passes.setdefault(p["name"], {1: [], 2: []})[t].append(p["wall_seconds"])
            med = {t: statistics.median(v) for t, v in times.items()}
            rows.append({
                "method": method,
                "scene": scene,
                "seconds": {str(t): {"median": med[t], "min": min(v), "max": max(v)} for t, v in times.items()},
                "ratio": med[1] / med[2],
                "passes": [
                    {
                        "name": n,
                        "median_1": statistics.median(v[1]),
                        "median_2": statistics.median(v[2]),
                        "ratio": statistics.median(v[1]) / statistics.median(v[2])
                        if statistics.median(v[2]) > 0 else None,
                    }
                    for n, v in passes.items()
                ],
            })
            print(f"{method}: {med[1] * 1e3:.1f} ms / {med[2] * 1e3:.1f} ms = {med[1] / med[2]:.2f}×", file=sys.stderr)
    load_after = os.getloadavg()[0]
    doc = {"size": a.size, "runs": a.runs, "cores": os.cpu_count(),
           "load_average": [load_before, load_after], "rows": rows}
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "scaling.json").write_text(json.dumps(doc, indent=2) + "\n")
    lines = [
        f"# 1 thread against 2, {a.size}², median of {a.runs} (in turn); load {load_before:.1f} before, "
        f"{load_after:.1f} after",
        "",
        "| method | scene | 1 thread [ms] | 2 threads [ms] | ratio | passes: 1 → 2 threads [ms] (ratio), the longest first |",
        "|---|---|---:|---:|---:|---|",
    ]
    for r in rows:
        ps = sorted(r["passes"], key=lambda p: -p["median_1"])
        detail = "; ".join(
            f"{p['name']} {p['median_1'] * 1e3:.1f} → {p['median_2'] * 1e3:.1f}"
            + (f" ({p['ratio']:.2f}×)" if p["ratio"] else "")
            for p in ps if p["median_1"] >= 0.05 * r["seconds"]["1"]["median"]
        )
        lines.append(
            f"| {r['method']} | {r['scene']} | {r['seconds']['1']['median'] * 1e3:.1f} | "
            f"{r['seconds']['2']['median'] * 1e3:.1f} | {r['ratio']:.2f}× | {detail} |"
        )
    (a.out / "scaling.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
