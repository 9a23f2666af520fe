"""The examples in python/examples/ run on the shipped data and write their PNGs."""

import os
import subprocess
import sys

import numpy as np
import pytest
import matplotlib.image


# Each example's arguments, given the database, the scripts' folder and the PNG to write.
EXAMPLES = {
    "inspect_database.py": lambda db, scripts, out: [db, out],
    "plot_run.py": lambda db, scripts, out: [db, scripts / "showcase.txt", out],
    "sweep_weight.py": lambda db, scripts, out: [db, scripts / "stop-and-go.txt", out,
                                                 "--weights", "0.5,1,2"],
}


@pytest.mark.parametrize("example", sorted(EXAMPLES))
def test_the_example_writes_its_png(example, database_path, source_dir, scripts_dir, tmp_path):
    out = tmp_path / example.replace(".py", ".png")
    arguments = [str(a) for a in EXAMPLES[example](database_path, scripts_dir, out)]
    done = subprocess.run([sys.executable, str(source_dir / "python" / "examples" / example),
                           *arguments], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert f"wrote {out}" in done.stdout
    image = matplotlib.image.imread(out)
    assert image.shape[0] >= 400 and image.shape[1] >= 600
    # Not a blank canvas: a plot has many distinct colours.
    assert len(np.unique(image.reshape(-1, image.shape[2]), axis=0)) > 50
    # A copy kept beside the build for people to look at (MM_EXAMPLES_OUT, set by ctest).
    keep = os.environ.get("MM_EXAMPLES_OUT")
    if keep:
        os.makedirs(keep, exist_ok=True)
        os.replace(out, os.path.join(keep, out.name))
