#!/usr/bin/env python3
"""The rows of docs/world.md's off-lane tables from scripts/offlane.sh's output.

Usage: scripts/offlane_summary.py OFFLANE_OUTPUT...

Per file and time step: the runs, those breaking a target (BAD), and per target the runs that
break it (a toe below 1 cm, a toe in the ground with the deepest, a joint 2 cm in a wall,
geometric skating over the data's own, planted toes floating more than 1.5 cm higher than on
flat ground), the stuck time summed (and the runs stuck more than 0.5 s), and the planted toes'
float averaged over the runs.
"""
import collections
import re
import sys

LINE = re.compile(
    r'(BAD|ok ) (\S+) x=(\S+) dt=(\S+) clearance=(\S+) penetration=(\S+) wall=(\S+) '
    r'stuck=(\S+) float=(\S+)/(\S+) skate=(\S+)/(\S+)')
RATES = {'0.0333333': '1/30', '0.0166667': '1/60', '0.00694444': '1/144'}


def summarize(path):
    counts = collections.defaultdict(collections.Counter)
    deepest = collections.defaultdict(float)
    stuck = collections.defaultdict(float)
    floats = collections.defaultdict(list)
    for line in open(path):
        m = LINE.match(line)
        if not m:
            continue
        bad, _, _, dt, clearance, depth, wall, stuck_s, flt, flat, skate, data = m.groups()
        rate = RATES.get(dt, dt)
        c = counts[rate]
        c['runs'] += 1
        c['bad'] += bad == 'BAD'
        c['below 1 cm'] += float(clearance) < 1
        c['in the ground'] += float(depth) > 0
        c['in a wall'] += float(wall) > 2
        c['skating'] += float(skate) > float(data)
        c['floating'] += float(flt) > float(flat) + 1.5
        c['stuck > 0.5 s'] += float(stuck_s) > 0.5
        deepest[rate] = max(deepest[rate], float(depth))
        stuck[rate] += float(stuck_s)
        floats[rate].append(float(flt))
    print(path)
    for rate, c in counts.items():
        print(f"  {rate:>6}: {c['runs']} runs, {c['bad']} BAD; below 1 cm {c['below 1 cm']}, "
              f"in the ground {c['in the ground']} (deepest {deepest[rate]:.2f} cm), "
              f"in a wall {c['in a wall']}, skating {c['skating']}, floating {c['floating']}, "
              f"stuck {stuck[rate]:.2f} s ({c['stuck > 0.5 s']} over 0.5 s), "
              f"float mean {sum(floats[rate]) / len(floats[rate]):.2f} cm")


if __name__ == '__main__':
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    for p in sys.argv[1:]:
        summarize(p)
