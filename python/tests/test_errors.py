"""Bad input raises a Python exception carrying the library's message, as `mm` prints it;
nothing crashes the interpreter."""

import math
import subprocess

import numpy as np
import pytest

import mm


def _cli_message(mm_tool, *args):
    """What `mm` prints for the same failure, without its "mm <command>: " prefix."""
    done = subprocess.run([str(mm_tool), *args], capture_output=True, text=True)
    assert done.returncode == 1, done
    line = done.stderr.strip().splitlines()[-1]
    return line.split(": ", 1)[1]


def test_a_missing_database_raises_file_not_found_with_the_library_message(mm_tool, tmp_path):
    path = tmp_path / "missing.mmdb"
    with pytest.raises(FileNotFoundError) as raised:
        mm.load_database(path)
    assert str(raised.value) == _cli_message(mm_tool, "info", str(path))
    assert "No such file or directory" in str(raised.value)


@pytest.mark.parametrize("kind", ["garbage", "truncated"])
def test_a_corrupt_database_raises_mm_error_with_the_library_message(database_path, mm_tool,
                                                                     tmp_path, kind):
    path = tmp_path / f"{kind}.mmdb"
    if kind == "garbage":
        path.write_bytes(bytes(range(256)) * 4)
    else:
        path.write_bytes(database_path.read_bytes()[:100_000])
    with pytest.raises(mm.Error) as raised:
        mm.load_database(path)
    assert isinstance(raised.value, RuntimeError)
    message = str(raised.value)
    assert message == _cli_message(mm_tool, "info", str(path))
    assert str(path) in message
    assert ("not a motion database file" in message) if kind == "garbage" else ("truncated" in message or "bytes" in message)


def test_unknown_or_bad_settings_raise_value_error(database, scripts_dir):
    with pytest.raises(ValueError, match="unknown setting 'no_such_setting'"):
        mm.Controller(database, no_such_setting=1)
    with pytest.raises(ValueError, match="walk_speed_forward"):
        mm.Controller(database, walk_speed_forward="fast")
    with pytest.raises(ValueError, match="max_dt"):
        mm.Controller(database, max_dt=-1.0)
    with pytest.raises(ValueError, match="unknown setting 'no_such_setting'"):
        mm.evaluate(database, scripts_dir / "showcase.txt", no_such_setting=1)
    with pytest.raises(ValueError, match=r"dt must be in \[0.000100, 1.000000\] seconds"):
        mm.run_script(database, scripts_dir / "showcase.txt", dt=0.0)
    controller = mm.Controller(database)
    before = controller.positions
    with pytest.raises(ValueError, match="unknown setting"):
        controller.set_settings(ik_enabled=False, nonsense=3)
    controller.update(1.0 / 60.0)
    assert np.all(np.isfinite(controller.positions)) and before.shape == controller.positions.shape


def test_a_missing_or_malformed_script_raises(database, tmp_path, mm_tool, database_path):
    with pytest.raises(FileNotFoundError, match="missing.txt"):
        mm.run_script(database, tmp_path / "missing.txt")
    bad = tmp_path / "bad.txt"
    bad.write_text("0 0 0 0 0\n1 banana 0 0 0\n")
    with pytest.raises(mm.Error) as raised:
        mm.evaluate(database, bad)
    assert str(raised.value) == _cli_message(mm_tool, "eval", "--db", str(database_path),
                                             "--script", str(bad))
    assert "bad.txt:2" in str(raised.value)


def test_wrong_argument_types_raise_type_error(database):
    controller = mm.Controller(database)
    with pytest.raises(TypeError):
        controller.update(1.0 / 60.0, left_stick=(1.0, 2.0, 3.0))
    with pytest.raises(TypeError):
        controller.update("soon")
    with pytest.raises(TypeError):
        mm.load_database(42)
    with pytest.raises(TypeError):
        mm.Controller("not a database")


def test_absurd_input_never_poisons_the_controller(database):
    controller = mm.Controller(database)
    for dt, stick, yaw in [(math.nan, (1.0, 0.0), 0.0), (1.0 / 60.0, (math.nan, math.inf), 0.0),
                           (1e9, (1e30, -1e30), math.inf), (-1.0, (0.5, 0.5), math.nan),
                           (1.0 / 60.0, (0.0, 1.0), 1e20)]:
        controller.update(dt, left_stick=stick, camera_yaw=yaw, facing_yaw=yaw)
        assert np.all(np.isfinite(controller.positions))
        assert np.all(np.isfinite(controller.skinning_matrices))
    with pytest.raises(ValueError, match="finite"):
        controller.teleport(math.nan, 0.0)
    for _ in range(120):
        controller.update(1.0 / 60.0, left_stick=(0.0, 1.0))
    state = controller.state
    assert all(math.isfinite(v) for v in state["root_position"])
