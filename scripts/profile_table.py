#!/usr/bin/env python3
"""The phase table of scripts/profile.sh: reads OUTDIR/*.tree (callgrind_annotate --tree=calling
--inclusive=yes) and OUTDIR/totals.tsv, prints instructions per update of each phase of
Controller::update, summed over the scripts."""
import collections
import pathlib
import re
import sys

# Phase of each direct callee of update / refresh_outputs / search (function name without
# arguments). Anything not listed is reported under its own name in "other".
PHASES = [
    ("simulation and prediction", ["mm::Controller::desired_motion", "mm::Controller::simulate",
                                   "mm::Controller::predict", "mm::Controller::should_search",
                                   "mm::Controller::follow_character", "mm::Controller::stand_turn",
                                   "mm::Controller::limit_turn_rate"]),
    ("query", ["mm::Controller::build_query"]),
    ("search", ["mm::Controller::search_candidates", "mm::Controller::record_search",
                "search (self)"]),
    ("playback sampling", ["mm::Controller::sample_playback", "mm::Controller::playback_point"]),
    ("transitions", ["mm::Controller::transition_to", "mm::Controller::show_transitions"]),
    ("root adjustment", ["mm::Controller::synchronize", "mm::Controller::move_root",
                         "mm::rotation_vector_rate_to_angular_velocity"]),
    # body_yaw, when inlined into update with limit_body_turn, shows as its callees (the only
    # calls update makes to them directly).
    ("turn limits and chest twist", ["mm::Controller::body_yaw", "mm::Controller::limit_body_turn",
                                     "mm::Controller::turn_chest_to_facing", "mm::wrap_angle",
                                     "mm::forward_kinematics_position", "mm::forward_kinematics_joint",
                                     "mm::pair_yaw", "mm::quat_yaw"]),
    ("foot locking and IK", ["mm::Controller::foot_lock"]),
    ("forward kinematics", ["mm::Controller::finish_pose"]),
    ("outputs", ["mm::Controller::publish_world_transforms", "mm::skinning_matrices",
                 "refresh_outputs (self)"]),
]
NESTED = {"mm::Controller::refresh_outputs", "mm::Controller::search"}
LINE = re.compile(r"^\s*([\d,]+) \([\s\d.]+%\)\s+([*>])\s+\S*?:(.*?)(?: \(([\d,]+)x\))? \[")


def name_of(signature):
    depth = 0
    for i, ch in enumerate(signature):
        if ch == "(" and depth == 0 and i > 0 and signature[i - 1] not in " ,<":
            return signature[:i]
        if ch == "<":
            depth += 1
        elif ch == ">":
            depth -= 1
    return signature


def callees(tree_text):
    """{caller: {callee: inclusive}} and {function: inclusive as a caller block head}."""
    calls, heads, current = collections.defaultdict(dict), {}, None
    for line in tree_text.splitlines():
        m = LINE.match(line)
        if not m:
            continue
        cost, kind, fn = int(m.group(1).replace(",", "")), m.group(2), name_of(m.group(3))
        if kind == "*":
            current = fn
            heads[fn] = cost
        elif current is not None:
            calls[current][fn] = calls[current].get(fn, 0) + cost
    return calls, heads


def main():
    out = pathlib.Path(sys.argv[1])
    rows = [line.split("\t") for line in (out / "totals.tsv").read_text().splitlines() if line]
    frames = sum(int(r[1]) for r in rows)
    total = sum(int(r[2]) for r in rows)
    cost = collections.Counter()
    us = sum(float(r[3]) * int(r[1]) for r in rows) / frames
    for name, _, _, _ in rows:
        calls, heads = callees((out / f"{name}.tree").read_text())
        update = "mm::Controller::update"
        for fn, c in calls[update].items():
            if fn not in NESTED:
                cost[fn] += c
        cost["update (self)"] += heads[update] - sum(calls[update].values())
        for nested in NESTED:
            if nested not in calls[update]:
                continue
            own = calls[update][nested]
            inner = calls.get(nested, {})
            # The nested function's block sums every caller's calls; scale to update's share.
            share = own / heads[nested] if heads.get(nested) else 0.0
            for fn, c in inner.items():
                cost[fn] += c * share
            label = nested.split("::")[-1] + " (self)"
            cost[label] += own - sum(inner.values()) * share
    print(f"scripts: {len(rows)}, updates: {frames}, instructions per update: {total / frames:,.0f}, "
          f"wall clock per update (native, mean): {us:.2f} us")
    print(f"{'phase':30s} {'instr/update':>13s} {'share':>7s} {'~us':>6s}  functions")
    seen = set()
    for phase, fns in PHASES:
        c = sum(cost[f] for f in fns)
        seen.update(fns)
        print(f"{phase:30s} {c / frames:13,.0f} {100 * c / total:6.1f}% {us * c / total:6.2f}  "
              + ", ".join(f.split("::")[-1] for f in fns if cost[f] > 0))
    rest = {f: c for f, c in cost.items() if f not in seen and c > 0}
    c = sum(rest.values())
    print(f"{'other':30s} {c / frames:13,.0f} {100 * c / total:6.1f}% {us * c / total:6.2f}  "
          + ", ".join(f.split("::")[-1] for f in sorted(rest, key=rest.get, reverse=True)))
    print(f"{'total':30s} {total / frames:13,.0f} {100.0:6.1f}% {us:6.2f}")
    for name, f, t, u in rows:
        print(f"  {name:14s} {int(t) / int(f):9,.0f} instructions/update over {f} updates, "
              f"{float(u):.2f} us/update")


if __name__ == "__main__":
    main()
