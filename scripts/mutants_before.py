#!/usr/bin/env python3
"""A cargo-mutants run's counts before and after tests were added, from one run.

`cargo mutants ... --lib` runs one test binary per mutant, and libtest runs every test in it
even after one fails, so each mutant's log names every test that caught it. Given the run
made with the new tests and the baseline log of a run at the old commit (the list of the
tests that existed then), a mutant counts as caught *before* when a test of the old list
failed on it, and as missed before when only new tests did. The code under test must be the
same at both commits (only tests added); a test removed since is listed, since the run
cannot say what it would have caught.

    python3 scripts/mutants_before.py OUT_DIR OLD_BASELINE_LOG [--check OLD_OUT_DIR]

OUT_DIR is the `-o` of the run with the new tests (it holds mutants.out/); OLD_BASELINE_LOG
is mutants.out/log/baseline.log of a run at the old commit. `--check` compares the derived
"before" with an actual run at the old commit for the mutants both runs tested.
"""

import argparse
import json
import re
import sys
from collections import Counter
from pathlib import Path

PASSED = re.compile(r"^test (\S+) \.\.\. ok$", re.M)
FAILED = re.compile(r"^test (\S+) \.\.\. FAILED$", re.M)
SHORT = {
    "CaughtMutant": "caught",
    "MissedMutant": "missed",
    "Unviable": "unviable",
    "Timeout": "timeout",
}


def outcomes(out_dir):
    """(mutant name, summary, log text) of every mutant of a run, in the run's order."""
    root = Path(out_dir) / "mutants.out"
    data = json.loads((root / "outcomes.json").read_text())
    for o in data["outcomes"]:
        if o["scenario"] == "Baseline":
            continue
        text = (root / o["log_path"]).read_text(errors="replace")
        yield o["scenario"]["Mutant"]["name"], SHORT.get(o["summary"], o["summary"]), text


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out_dir")
    ap.add_argument("old_baseline_log")
    ap.add_argument("--check", metavar="OLD_OUT_DIR")
    a = ap.parse_args()
    old = set(PASSED.findall(Path(a.old_baseline_log).read_text()))
    new_baseline = (Path(a.out_dir) / "mutants.out/log/baseline.log").read_text()
    now = set(PASSED.findall(new_baseline))
    if not old or not now:
        sys.exit("no passing test found in a baseline log")
    added = sorted(now - old)
    removed = sorted(old - now)
    before, after = Counter(), Counter()
    derived = {}
    only_new = []
    for name, summary, text in outcomes(a.out_dir):
        after[summary] += 1
        b = summary
        if summary == "caught":
            failed = set(FAILED.findall(text))
            if not failed:
                sys.exit(f"{name}: caught, but its log names no failed test")
            if not failed & old:
                b = "missed"
                only_new.append((name, sorted(failed)))
        elif summary == "timeout":
            # Which test hung is not in the log; count it as a timeout in both.
            pass
        before[b] += 1
        derived[name] = b
    keys = ["caught", "missed", "unviable", "timeout"]
    print(f"tests added: {len(added)}; removed: {len(removed)} {removed}")
    print("before (derived): " + " / ".join(f"{before[k]} {k}" for k in keys))
    print("after:            " + " / ".join(f"{after[k]} {k}" for k in keys))
    print(f"caught only by added tests: {len(only_new)}")
    for name, failed in only_new:
        print(f"  {name}\n      by {', '.join(t.rsplit('::', 1)[-1] for t in failed)}")
    if a.check:
        actual = {n: s for n, s, _ in outcomes(a.check)}
        both = [n for n in actual if n in derived]
        wrong = [(n, actual[n], derived[n]) for n in both if actual[n] != derived[n]]
        print(f"check against {a.check}: {len(both)} mutants in both, {len(wrong)} differ")
        for n, s, d in wrong:
            print(f"  {n}: actual {s}, derived {d}")
        if wrong:
            sys.exit(1)


if __name__ == "__main__":
    main()
