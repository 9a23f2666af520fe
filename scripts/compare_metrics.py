#!/usr/bin/env python3
"""compare_metrics.py BASE_DIR BRANCH_DIR: each motion metric's largest difference between two
binaries' runs of scripts/compare_metrics.sh (the same file names in both directories).

Prints one row per metric: the largest absolute difference, the largest relative difference
(|b - a| / max(|a|, |b|)) and the run each comes from, then the count of runs and values that
differ at all. Metrics equal in every run are listed by name only. Last, every run where a
metric lies on the other side of its target in the two directories (the targets below)."""
import json
import os
import sys


# The motion's targets: (name, test of one run's metrics). A run where base and branch disagree
# on one of these is listed whatever the size of the difference.
TARGETS = [
    ("geometric skate <= the data's own",
     lambda d: d["foot_skate_geom_cm_s_mean"] <= d["foot_skate_geom_data_cm_s_mean"]),
    ("transition_accel_ratio <= 0.9", lambda d: d["transition_accel_ratio"] <= 0.9),
    ("toe clearance >= 1 cm", lambda d: d["toe_clearance_cm_min"] >= 1.0),
    ("stand-turn error <= 5 deg",
     lambda d: d["stand_turns"] == 0 or d["stand_turn_final_error_deg_max"] <= 5.0),
    ("foot pivot <= 25 deg/s", lambda d: d["foot_pivot_deg_s_mean"] <= 25.0),
]


def numbers(d, prefix=""):
    for k, v in d.items():
        if isinstance(v, bool) or v is None:
            continue
        if isinstance(v, (int, float)):
            yield prefix + k, float(v)
        elif isinstance(v, list) and all(isinstance(x, (int, float)) for x in v):
            for i, x in enumerate(v):
                yield f"{prefix}{k}[{i}]", float(x)
        elif isinstance(v, dict):
            yield from numbers(v, prefix + k + ".")


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: compare_metrics.py BASE_DIR BRANCH_DIR")
    base_dir, branch_dir = sys.argv[1], sys.argv[2]
    names = sorted(f for f in os.listdir(base_dir) if f.endswith(".json"))
    missing = [f for f in names if not os.path.exists(os.path.join(branch_dir, f))]
    if missing:
        sys.exit(f"missing in {branch_dir}: {' '.join(missing)}")
    worst = {}  # metric -> [abs, abs run, rel, rel run, a, b at rel]
    values = differing = 0
    runs_differing = set()
    crossings = []
    held = {name: [0, 0] for name, _ in TARGETS}  # runs meeting the target: base, branch
    for f in names:
        ja = json.load(open(os.path.join(base_dir, f)))
        jb = json.load(open(os.path.join(branch_dir, f)))
        for name, test in TARGETS:
            ta, tb = test(ja), test(jb)
            held[name][0] += ta
            held[name][1] += tb
            if ta != tb:
                crossings.append(f"{f[:-5]}: {name}: base {'meets' if ta else 'misses'} it, "
                                 f"branch {'meets' if tb else 'misses'} it")
        a = dict(numbers(ja))
        b = dict(numbers(jb))
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                sys.exit(f"{f}: metric {k} only in one of the two runs")
            values += 1
            w = worst.setdefault(k, [0.0, "", 0.0, "", 0.0, 0.0])
            d = abs(b[k] - a[k])
            if d == 0.0:
                continue
            differing += 1
            runs_differing.add(f)
            rel = d / max(abs(a[k]), abs(b[k]))
            if d > w[0]:
                w[0], w[1] = d, f[:-5]
            if rel > w[2]:
                w[2], w[3], w[4], w[5] = rel, f[:-5], a[k], b[k]
    print(f"runs: {len(names)} ({len(runs_differing)} differ), values: {values} ({differing} differ)")
    print("| metric | largest abs diff | run | largest rel diff | run | base -> branch |")
    print("| --- | ---: | --- | ---: | --- | --- |")
    equal = []
    for k in sorted(worst):
        w = worst[k]
        if w[0] == 0.0:
            equal.append(k)
            continue
        print(f"| {k} | {w[0]:.4g} | {w[1]} | {w[2]:.3%} | {w[3]} | {w[4]:.6g} -> {w[5]:.6g} |")
    print("equal in every run:", ", ".join(equal))
    print(f"targets (runs meeting each, base / branch, of {len(names)}):")
    for name, _ in TARGETS:
        print(f"  {name}: {held[name][0]} / {held[name][1]}")
    print("runs on the other side of a target:", "none" if not crossings else "")
    for c in crossings:
        print("  " + c)


if __name__ == "__main__":
    main()
