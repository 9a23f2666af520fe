#!/usr/bin/env python3
"""Runs one controller on an input script and plots the run from above: the simulation
object's path, the character's root, and the toes, with their planted frames marked.

    python3 plot_run.py DATABASE.mmdb SCRIPT.txt OUT.png [--dt 0.0166667] [--ik on|off]
"""

import argparse

import mm
import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def toe_index(names, side):
    for candidate in (f"Toes_{side}", f"Foot_{side}"):
        if candidate in names:
            return names.index(candidate)
    raise SystemExit(f"no toe or foot joint for side {side} in {names}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("database")
    parser.add_argument("script")
    parser.add_argument("out")
    parser.add_argument("--dt", type=float, default=1.0 / 60.0)
    parser.add_argument("--ik", choices=["on", "off"], default="on")
    args = parser.parse_args()

    db = mm.load_database(args.database)
    run = mm.run_script(db, args.script, dt=args.dt, ik=args.ik == "on")
    metrics = mm.evaluate(db, args.script, dt=args.dt, ik=args.ik == "on")

    fig, ax = plt.subplots(figsize=(8, 8), dpi=100)
    sim, root = run["simulation"], run["root"]
    ax.plot(sim[:, 0], sim[:, 2], color="0.6", linewidth=3, label="simulation")
    ax.plot(root[:, 0], root[:, 2], color="k", linewidth=1, label="root")
    for side, colour in (("L", "tab:blue"), ("R", "tab:red")):
        toe = run["positions"][:, toe_index(db.joint_names, side)]
        contact = run["contacts"][:, 0 if side == "L" else 1]
        ax.plot(toe[:, 0], toe[:, 2], color=colour, linewidth=0.5, alpha=0.5)
        ax.scatter(toe[contact, 0], toe[contact, 2], s=2, color=colour,
                   label=f"toe {side}, planted ({contact.sum()} frames)")
    transitions = run["transition"]
    ax.scatter(root[transitions, 0], root[transitions, 2], marker="x", color="tab:green", s=18,
               label=f"transitions ({transitions.sum()})")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)")
    ax.set_title(f"{args.script.split('/')[-1]}: {len(run['t'])} frames, skate "
                 f"{metrics['foot_skate_cm_s_mean']:.2f} cm/s, root-sim "
                 f"{metrics['root_sim_distance_cm_mean']:.1f} cm")
    ax.legend(fontsize=8, loc="best")
    fig.tight_layout()
    fig.savefig(args.out)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
