#!/usr/bin/env python3
"""Inspects a motion database: per-column feature statistics (printed), and a histogram of one
feature per tag (the clips' motion, action and style tags), written as a PNG.

    python3 inspect_database.py DATABASE.mmdb OUT.png [--feature hips_velocity_z]
"""

import argparse

import mm
import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("database")
    parser.add_argument("out")
    parser.add_argument("--feature", default="hips_velocity_z",
                        help="the feature column to histogram (db.feature_names)")
    args = parser.parse_args()

    db = mm.load_database(args.database)
    print(db)
    features = db.features  # (frames, dims), a view of the database's memory
    searchable = db.searchable.astype(bool)
    raw = features * db.feature_scale + db.feature_offset  # back to metres and m/s
    print(f"{'column':34s} {'mean':>9s} {'std':>9s} {'min':>9s} {'max':>9s}  (raw units)")
    for i, name in enumerate(db.feature_names):
        column = raw[searchable, i]
        print(f"{name:34s} {column.mean():9.3f} {column.std():9.3f} {column.min():9.3f} "
              f"{column.max():9.3f}")

    if args.feature not in db.feature_names:
        parser.error(f"no feature {args.feature!r}; one of {', '.join(db.feature_names)}")
    column = raw[:, db.feature_names.index(args.feature)]
    # Each frame's tags, from its clip's.
    clip_tags = [set(clip["tags"]) for clip in db.clips]
    frame_clip = db.frame_clip
    tags = [t for t in db.tag_names if t != "mirrored"]
    fig, ax = plt.subplots(figsize=(9, 5.5), dpi=100)
    bins = np.linspace(np.percentile(column, 0.5), np.percentile(column, 99.5), 60)
    shown = 0
    for tag in tags:
        has = np.array([tag in clip_tags[c] for c in frame_clip]) & searchable
        if has.sum() < 30:
            continue
        ax.hist(column[has], bins=bins, histtype="step", linewidth=1.5, density=True,
                label=f"{tag} ({has.sum()} frames)")
        shown += 1
    ax.set_xlabel(f"{args.feature} (raw units)")
    ax.set_ylabel("density")
    ax.set_title(f"{args.feature} per tag: {db.frame_count} frames, {len(db.clips)} clips")
    if shown:
        ax.legend(fontsize=8, ncol=2)
    fig.tight_layout()
    fig.savefig(args.out)
    print(f"wrote {args.out} ({shown} tags)")


if __name__ == "__main__":
    main()
