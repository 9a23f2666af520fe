"""mm.Controller driven from Python: the pose arrays, determinism, and no leak over 10,000
updates."""

import gc
import math
import os

import numpy as np

import mm

DT = 1.0 / 60.0


def _drive(controller, frames, start=0):
    """Walks forward, turns right, runs, stops: the same input for the same frame numbers."""
    for f in range(start, start + frames):
        phase = (f // 240) % 4
        stick = [(0.0, 1.0), (1.0, 0.0), (0.0, 1.0), (0.0, 0.0)][phase]
        controller.update(DT, left_stick=stick, run=phase == 2)


def test_the_pose_comes_out_as_arrays_and_the_character_moves(database):
    controller = mm.Controller(database)
    joints = database.joint_count
    assert controller.joint_names == database.joint_names
    start = np.array(controller.state["root_position"])
    for _ in range(180):
        controller.update(DT, left_stick=(0.0, 1.0))
    positions = controller.positions
    rotations = controller.rotations
    skinning = controller.skinning_matrices
    assert positions.shape == (joints, 3) and positions.dtype == np.float32
    assert rotations.shape == (joints, 4)
    assert skinning.shape == (joints, 4, 4)
    np.testing.assert_allclose(np.linalg.norm(rotations, axis=1), 1.0, atol=1e-4)
    state = controller.state
    # Pushed forward (camera yaw 0 looks along +Z) for 3 s: it walked along +Z.
    moved = np.array(state["root_position"]) - start
    assert moved[2] > 2.0 and abs(moved[0]) < 1.0
    np.testing.assert_allclose(positions[0], state["root_position"], atol=1e-4)
    # Skinning matrices are row-major: their last row is (0, 0, 0, 1), and they carry each
    # joint's bind position to its current one.
    np.testing.assert_allclose(skinning[:, 3, :], np.tile([0, 0, 0, 1], (joints, 1)), atol=1e-6)
    assert math.isfinite(state["root_yaw"])


def test_two_controllers_on_the_same_input_agree(database):
    a = mm.Controller(database)
    b = mm.Controller(database)
    _drive(a, 600)
    _drive(b, 600)
    assert np.array_equal(a.positions, b.positions)
    c = mm.Controller(database, ik_enabled=False)
    _drive(c, 600)
    assert not np.array_equal(a.positions, c.positions)


def _resident_bytes():
    with open(f"/proc/{os.getpid()}/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def test_ten_thousand_updates_from_python_do_not_leak(database):
    controller = mm.Controller(database)
    _drive(controller, 1000)
    for _ in range(1000):
        controller.positions, controller.skinning_matrices, controller.state
    gc.collect()
    before = _resident_bytes()
    checksum = 0.0
    for f in range(10_000):
        _drive(controller, 1, start=1000 + f)
        checksum += float(controller.positions[0, 0])
        controller.rotations, controller.skinning_matrices, controller.state
    gc.collect()
    grown = _resident_bytes() - before
    assert math.isfinite(checksum)
    # A leak of one pose array per update would be 10,000 x (joints x 12 bytes), over 2 MB.
    assert grown < 1_000_000, f"resident memory grew by {grown} bytes over 10,000 updates"
