#!/usr/bin/env python3
"""Sweeps one feature channel's weight and plots metrics of a scripted run against it: how the
matching trades responsiveness for smoothness.

    python3 sweep_weight.py DATABASE.mmdb SCRIPT.txt OUT.png [--channel trajectory_position]
        [--weights 0.25,0.5,1,2,4] [--metrics heading_response_s,transitions_per_s]
"""

import argparse

import mm
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("database")
    parser.add_argument("script")
    parser.add_argument("out")
    parser.add_argument("--channel", default="trajectory_position")
    parser.add_argument("--weights", default="0.25,0.5,1,2,4",
                        help="multiples of the channel's weight in the database")
    parser.add_argument("--metrics", default="heading_response_s,transitions_per_s,"
                                             "foot_skate_cm_s_mean")
    args = parser.parse_args()

    db = mm.load_database(args.database)
    channel = next((c for c in db.channels if c["name"] == args.channel), None)
    if channel is None:
        parser.error(f"no channel {args.channel!r}; one of "
                     f"{', '.join(c['name'] for c in db.channels)}")
    factors = [float(w) for w in args.weights.split(",")]
    names = args.metrics.split(",")
    results = {name: [] for name in names}
    for factor in factors:
        weighted = db.with_weights(**{args.channel: channel["weight"] * factor})
        metrics = mm.evaluate(weighted, args.script)
        for name in names:
            results[name].append(metrics[name])
        print(f"weight x{factor:g}: " + ", ".join(f"{n} {metrics[n]:.3f}" for n in names))

    fig, axes = plt.subplots(len(names), 1, figsize=(7, 2.6 * len(names)), dpi=100, sharex=True)
    for ax, name in zip(axes if len(names) > 1 else [axes], names):
        ax.plot(factors, results[name], marker="o")
        ax.set_xscale("log", base=2)
        ax.set_ylabel(name)
        ax.grid(True, alpha=0.3)
    axes_list = axes if len(names) > 1 else [axes]
    axes_list[-1].set_xlabel(f"{args.channel} weight (x the database's {channel['weight']:g})")
    axes_list[0].set_title(f"{args.script.split('/')[-1]}: sweeping {args.channel}")
    fig.tight_layout()
    fig.savefig(args.out)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
