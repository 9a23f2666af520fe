"""mm.Database: the zero-copy views, the names, and poses against forward kinematics done
here in numpy."""

import gc

import numpy as np
import pytest

import mm


def test_features_view_the_database_memory_without_a_copy(database):
    features = database.features
    assert features.shape == (database.frame_count, database.feature_dims)
    assert features.dtype == np.float32
    assert not features.flags.owndata
    assert not features.flags.writeable
    # The same memory every time: a view, not a fresh copy.
    again = database.features
    assert features.__array_interface__["data"][0] == again.__array_interface__["data"][0]
    with pytest.raises(ValueError, match="read-only"):
        features[0, 0] = 1.0


def test_a_view_keeps_its_database_alive(database_path):
    db = mm.load_database(database_path)
    features = db.features
    expected = np.array(features)  # a copy, to compare with after the database is dropped
    assert features.base is db
    del db
    gc.collect()
    assert isinstance(features.base, mm.Database)
    assert np.array_equal(features, expected)


def test_feature_names_name_every_column(database):
    names = database.feature_names
    assert len(names) == database.feature_dims
    assert len(set(names)) == len(names)
    for name in ("left_foot_position_x", "right_foot_velocity_z", "hips_velocity_y",
                 "trajectory_position_0.33s_x", "trajectory_direction_1s_z"):
        assert name in names, f"{name} not in {names}"
    # Normalized columns: mean near 0 over the searchable frames.
    searchable = database.searchable.astype(bool)
    means = database.features[searchable].mean(axis=0)
    assert np.all(np.abs(means) < 0.05), dict(zip(names, means))


def test_clips_tile_the_frames_and_name_them(database):
    clips = database.clips
    assert [c["name"] for c in clips] == database.clip_names
    assert clips[0]["start"] == 0
    assert clips[-1]["end"] == database.frame_count
    for before, after in zip(clips, clips[1:]):
        assert before["end"] == after["start"]
    assert any(name.startswith("dataset-1_walk_normal") for name in database.clip_names)
    frame_clip = database.frame_clip
    for index, clip in enumerate(clips):
        assert np.all(frame_clip[clip["start"]:clip["end"]] == index)
    assert all(set(c["tags"]) <= set(database.tag_names) for c in clips)


def _rotate(q, v):
    """Rotates v by the unit quaternion q = (x, y, z, w)."""
    u, w = q[:3], q[3]
    return 2.0 * np.dot(u, v) * u + (w * w - np.dot(u, u)) * v + 2.0 * w * np.cross(u, v)


def _multiply(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return np.array([aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw,
                     aw * bw - ax * bx - ay * by - az * bz])


@pytest.mark.parametrize("frame_fraction", [0.0, 0.37, 0.999])
def test_positions_are_forward_kinematics_of_the_local_arrays(database, frame_fraction):
    frame = int(frame_fraction * (database.frame_count - 1))
    local_p = database.local_positions[frame].astype(np.float64)
    local_q = database.local_rotations[frame].astype(np.float64)
    parents = database.parents
    global_p = np.zeros_like(local_p)
    global_q = np.zeros_like(local_q)
    for j, parent in enumerate(parents):
        if parent < 0:
            global_p[j], global_q[j] = local_p[j], local_q[j]
        else:
            global_p[j] = global_p[parent] + _rotate(global_q[parent], local_p[j])
            global_q[j] = _multiply(global_q[parent], local_q[j])
    positions = database.positions(frame)
    assert positions.shape == (database.joint_count, 3)
    np.testing.assert_allclose(positions, global_p, atol=1e-4)
    rotations = database.rotations(frame)
    # q and -q are the same rotation.
    same = np.minimum(np.abs(rotations - global_q).max(axis=1), np.abs(rotations + global_q).max(axis=1))
    assert same.max() < 1e-4
    # A person stands on the ground: the feet near y = 0, the head well above them.
    assert positions[:, 1].min() > -0.05
    assert positions[:, 1].max() > 1.2


def test_frames_outside_the_database_raise_index_error(database):
    for frame in (-1, database.frame_count):
        with pytest.raises(IndexError, match=f"frame {frame} is outside the database's "
                                              f"{database.frame_count} frames"):
            database.positions(frame)


def test_repr_and_joint_names(database, database_path):
    assert len(database.joint_names) == database.joint_count
    assert len(database.parents) == database.joint_count
    assert database.parents[0] == -1
    assert str(database_path) in repr(database)
    assert database.build_report is None
    assert database.frame_time == pytest.approx(1.0 / 30.0)


def test_with_weights_rescales_one_channel_in_a_copy(database):
    channel = next(c for c in database.channels if c["name"] == "hips_velocity")
    first, end = channel["columns"]
    assert database.feature_names[first] == "hips_velocity_x" and end - first == 3
    heavier = database.with_weights(hips_velocity=channel["weight"] * 2.0)
    assert next(c for c in heavier.channels if c["name"] == "hips_velocity")["weight"] == \
        pytest.approx(channel["weight"] * 2.0)
    np.testing.assert_allclose(heavier.features[:, first:end], database.features[:, first:end] * 2.0,
                               rtol=1e-6)
    assert np.array_equal(heavier.features[:, :first], database.features[:, :first])
    assert np.array_equal(heavier.features[:, end:], database.features[:, end:])
    np.testing.assert_allclose(heavier.feature_scale[first:end],
                               database.feature_scale[first:end] / 2.0, rtol=1e-6)
    with pytest.raises(ValueError, match="no channel named 'hips'"):
        database.with_weights(hips=1.0)
    with pytest.raises(ValueError, match="the weight of hips_velocity must be finite and > 0"):
        database.with_weights(hips_velocity=0.0)
