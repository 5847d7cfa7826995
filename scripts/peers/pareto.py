#!/usr/bin/env python3
"""Issue 32 item 4: penumbra's methods against Embree at equal error.

    scripts/peers/.venv/bin/python scripts/peers/pareto.py SWEEP_DIR [--out DIR] [--runs N]
                                                         [--samples 1,4,16,64,256]

SWEEP_DIR is the output of `penumbra experiment accuracy-time` (its accuracy-time.json: every
method and knob setting with its error against `raycast` at 1024 samples and its median time,
the scene pass excluded). For every scene of the sweep, at the sweep's image size, the script

1. renders the sweep's reference (`raycast`, 1024 samples, the scene's own seed) once with
   penumbra;
2. has Mitsuba 3 (Embree, `llvm_ad_rgb`) cast the shadow rays of `raycast` at each sample
   count N of `--samples` (the same light samples and rules as `run.py`), N timed runs after
   one untimed one, interleaved over the sample counts; its error is the RMSE of its image
   against that reference over the whole image (background 1), the sweep's own error measure;
3. names, for each N, the fastest penumbra configuration of the sweep whose RMSE is at most
   the target: the smaller of Embree's RMSE and that of penumbra's `raycast` at N samples
   (the same estimator on penumbra's own receivers: Embree's receivers are primary-ray hits,
   which differ from penumbra's depth-buffer points at silhouettes, and at high N that
   difference, not the sampling, sets Embree's error), and the ratio of the two times;
4. for every method that does not sample the light (the wedge and map methods), its most
   accurate configuration and the fewest Embree samples that reach its RMSE: the time Embree
   needs for that error is at most its time there.

Times: penumbra's is the method's own (`experiment accuracy-time`: median of its timed runs;
the shared scene pass excluded). Embree's is its shadow rays' `ray_test` (warm, the kernel
compiled); the build of its BVH is reported beside it and not added, and its primary rays
(which stand for penumbra's scene pass) are left out, as penumbra's scene pass is. Both use
every core. The two are measured in different processes at different moments: run this right
after the sweep, on an idle machine.

It writes DIR/pareto.md and DIR/pareto.json (default DIR: SWEEP_DIR).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import numpy as np  # noqa: E402

import run as peers  # noqa: E402


# The methods that sample the light (their error falls with the sample count, like Embree's)
# and the hard shadow; the others are the wedge and map methods.
SAMPLING = ("raycast", "nsample", "hard-sv")


def rmse(a: np.ndarray, b: np.ndarray) -> float:
    """Root mean square of a − b over every pixel."""
    return float(np.sqrt(np.mean((np.asarray(a, np.float64) - np.asarray(b, np.float64)) ** 2)))


def reference(exe: Path, scene: str, size: list[str], tmp: Path) -> np.ndarray:
    """The sweep's reference image: raycast at 1024 samples with the scene's other options."""
    out = tmp / "reference"
    peers.run_penumbra(
        exe,
        ["render", scene, *size, "--methods", "raycast", "--opt", "raycast.samples=1024", "--out", str(out)],
    )
    return peers.gray(peers.read_pfm(out / "raycast" / "visibility.pfm"))


def label(row: dict) -> str:
    """`method knobs` of a sweep row."""
    return f"{row['method']} {row['knobs']}"


def fastest_within(rows: list[dict], error: float) -> dict | None:
    """The fastest row whose RMSE is at most `error` (a NaN error never qualifies)."""
    ok = [r for r in rows if r["error"]["rmse"] == r["error"]["rmse"] and r["error"]["rmse"] <= error]
    return min(ok, key=lambda r: (r["median_seconds"], r["error"]["rmse"]), default=None)


def scene_result(mi, dr, exe: Path, scene: str, rows: list[dict], counts: list[int], runs: int) -> dict:
    """Embree at every sample count against the sweep's rows of one scene."""
    w, h = rows[0]["width"], rows[0]["height"]
    size = ["--width", str(w), "--height", str(h)]
    with tempfile.TemporaryDirectory(prefix="penumbra-pareto-") as tmpdir:
        tmp = Path(tmpdir)
        ref = reference(exe, scene, size, tmp)
        embree = {n: peers.MitsubaPeer(mi, dr, peers.export(exe, scene, size, n, tmp)) for n in counts}
    for _ in range(runs):
        for n in counts:
            embree[n].run()
    own = {int(r["knobs"].split("=")[1]): r for r in rows if r["method"] == "raycast" and r["knobs"].startswith("samples=")}
    points = []
    for n in counts:
        e = embree[n]
        err = rmse(e.image(), ref)
        target = min(err, own[n]["error"]["rmse"]) if n in own else err
        best = fastest_within(rows, target)
        t = statistics.median(e.times)
        points.append(
            {
                "samples": n,
                "rays": e.rays,
                "embree": {**peers.summary(e.times), "build_median": statistics.median(e.build), "rmse": err},
                "target_rmse": target,
                "penumbra_raycast_rmse": own[n]["error"]["rmse"] if n in own else None,
                "fastest_penumbra_within": None
                if best is None
                else {
                    "configuration": label(best),
                    "median_seconds": best["median_seconds"],
                    "min_seconds": best["min_seconds"],
                    "max_seconds": best["max_seconds"],
                    "rmse": best["error"]["rmse"],
                    "ratio": best["median_seconds"] / t,
                },
            }
        )
    analytic = []
    for method in dict.fromkeys(r["method"] for r in rows if r["method"] not in SAMPLING):
        mine = [r for r in rows if r["method"] == method and r["error"]["rmse"] == r["error"]["rmse"]]
        if not mine:
            continue
        r = min(mine, key=lambda r: (r["error"]["rmse"], r["median_seconds"]))
        reach = next((p for p in points if p["embree"]["rmse"] <= r["error"]["rmse"]), None)
        analytic.append(
            {
                "configuration": label(r),
                "median_seconds": r["median_seconds"],
                "rmse": r["error"]["rmse"],
                "embree_samples": None if reach is None else reach["samples"],
                "embree_seconds": None if reach is None else reach["embree"]["seconds"]["median"],
            }
        )
    return {"scene": scene, "width": w, "height": h, "points": points, "analytic": analytic}


def fmt_ms(s: float) -> str:
    """Seconds as milliseconds with one decimal."""
    return f"{s * 1e3:.1f}"


def write(out: Path, doc: dict) -> None:
    """DIR/pareto.json (the document) and DIR/pareto.md (its tables)."""
    out.mkdir(parents=True, exist_ok=True)
    (out / "pareto.json").write_text(json.dumps(doc, indent=2) + "\n")
    lines = [
        "# penumbra against Embree at equal error",
        "",
        f"Sweep: `{doc['sweep']}` (reference {doc['reference']}). {doc['machine']}.",
        f"Embree: median of {doc['runs']} warm runs of its shadow rays (min–max); its BVH build beside it, "
        "not added. penumbra: the sweep's median time of the method (scene pass excluded).",
        "",
    ]
    for s in doc["scenes"]:
        lines += [
            f"## {s['scene']} ({s['width']}×{s['height']})",
            "",
            "| Embree samples | rays | Embree [ms] | BVH build [ms] | Embree RMSE | penumbra raycast RMSE | fastest penumbra configuration at ≤ the smaller | its time [ms] | its RMSE | time ratio |",
            "|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|",
        ]
        for p in s["points"]:
            e = p["embree"]
            sec = e["seconds"]
            own = p["penumbra_raycast_rmse"]
            b = p["fastest_penumbra_within"]
            best = (
                ["none", "–", "–", "–"]
                if b is None
                else [f"`{b['configuration']}`", fmt_ms(b["median_seconds"]), f"{b['rmse']:.5f}", f"{b['ratio']:.2f}×"]
            )
            lines.append(
                f"| {p['samples']} | {p['rays']} | {fmt_ms(sec['median'])} ({fmt_ms(sec['min'])}–{fmt_ms(sec['max'])}) "
                f"| {fmt_ms(e['build_median'])} | {e['rmse']:.5f} | {'–' if own is None else f'{own:.5f}'} | "
                + " | ".join(best)
                + " |"
            )
        lines += [
            "",
            "Each wedge or map method's most accurate configuration, and the fewest Embree samples that reach its RMSE:",
            "",
            "| configuration | time [ms] | RMSE | Embree samples | Embree [ms] | time ratio |",
            "|---|---:|---:|---:|---:|---:|",
        ]
        for a in s["analytic"]:
            if a["embree_samples"] is None:
                tail = "not reached | – | – |"
            else:
                ratio = a["median_seconds"] / a["embree_seconds"]
                tail = f"{a['embree_samples']} | {fmt_ms(a['embree_seconds'])} | {ratio:.2f}× |"
            lines.append(f"| `{a['configuration']}` | {fmt_ms(a['median_seconds'])} | {a['rmse']:.5f} | {tail}")
        lines.append("")
    (out / "pareto.md").write_text("\n".join(lines))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("sweep", type=Path, help="an `experiment accuracy-time` output directory")
    ap.add_argument("--out", type=Path, help="output directory (default: the sweep's)")
    ap.add_argument("--runs", type=int, default=5, help="timed Embree runs per sample count (default 5)")
    ap.add_argument("--samples", default="1,4,16,64,256", help="Embree's sample counts, perfect squares")
    ap.add_argument("--penumbra", help="the penumbra binary (default target/release/penumbra)")
    a = ap.parse_args()
    counts = [int(x) for x in a.samples.split(",")]
    if a.runs < 1 or any(n < 1 or int(n**0.5) ** 2 != n for n in counts):
        ap.error("--runs must be at least 1 and every sample count a perfect square ≥ 1")
    sweep_file = a.sweep / "accuracy-time.json"
    try:
        sweep = json.loads(sweep_file.read_text())
    except (OSError, ValueError) as e:
        print(f"pareto.py: {sweep_file}: {e}", file=sys.stderr)
        return 2
    exe = peers.penumbra_binary(a.penumbra)
    mi, dr = peers.mitsuba()
    import drjit

    load_before = os.getloadavg()[0]
    scenes = []
    for scene in dict.fromkeys(r["scene"] for r in sweep["rows"]):
        rows = [r for r in sweep["rows"] if r["scene"] == scene]
        scenes.append(scene_result(mi, dr, exe, scene, rows, counts, a.runs))
    load_after = os.getloadavg()[0]
    doc = {
        "sweep": str(sweep_file),
        "reference": sweep["reference"],
        "runs": a.runs,
        "machine": f"{os.cpu_count()} cores, mitsuba {mi.__version__} (drjit {drjit.__version__}, "
        f"{mi.variant()}); load average {load_before:.1f} before, {load_after:.1f} after",
        "scenes": scenes,
    }
    out = a.out or a.sweep
    write(out, doc)
    print((out / "pareto.md").read_text())
    return 0


if __name__ == "__main__":
    sys.exit(main())
