"""mm.run_script and mm.evaluate against `mm eval --dump` and `mm eval --json` of the same
run, and mm.build_database against its options."""

import csv
import json
import subprocess

import numpy as np
import pytest

import mm

# Wall-clock figures: the only values that differ between two runs of the same script.
TIMINGS = {"search_us_mean", "update_us_mean"}


def _mm_eval(mm_tool, database_path, script, tmp_path, *extra):
    dump = tmp_path / "dump.csv"
    out = tmp_path / "eval.json"
    subprocess.run([str(mm_tool), "eval", "--db", str(database_path), "--script", str(script),
                    "--json", str(out), "--dump", str(dump), *extra],
                   check=True, capture_output=True, text=True)
    with open(dump, newline="") as f:
        rows = list(csv.reader(f))
    header, values = rows[0], np.array(rows[1:], dtype=np.float64)
    return {name: values[:, i] for i, name in enumerate(header)}, json.loads(out.read_text())


@pytest.mark.parametrize("script_name,dt,ik", [("showcase.txt", 1.0 / 60.0, True),
                                               ("stand-turns.txt", 1.0 / 30.0, False)])
def test_run_script_equals_the_command_line_dump(database, database_path, mm_tool, scripts_dir,
                                                 tmp_path, script_name, dt, ik):
    script = scripts_dir / script_name
    dump, _ = _mm_eval(mm_tool, database_path, script, tmp_path, "--dt", repr(dt),
                       "--ik", "on" if ik else "off")
    run = mm.run_script(database, script, dt=dt, ik=ik)
    frames = len(dump["t"])
    assert frames > 100
    # The dump prints 6 decimals for positions and times, 4 for degrees.
    close = dict(atol=6e-6, rtol=0)
    np.testing.assert_allclose(run["t"], dump["t"], **close)
    np.testing.assert_allclose(run["simulation"][:, 0], dump["sim_x"], **close)
    np.testing.assert_allclose(run["simulation"][:, 2], dump["sim_z"], **close)
    np.testing.assert_allclose(run["root"][:, 0], dump["root_x"], **close)
    np.testing.assert_allclose(run["root"][:, 2], dump["root_z"], **close)
    for key, column in (("simulation_yaw_deg", "sim_yaw_deg"), ("root_yaw_deg", "root_yaw_deg"),
                        ("desired_yaw_deg", "desired_yaw_deg")):
        np.testing.assert_allclose(run[key], dump[column], atol=6e-5, rtol=0)
    np.testing.assert_allclose(run["desired_velocity"][:, 0], dump["desired_vx"], **close)
    np.testing.assert_allclose(run["desired_velocity"][:, 2], dump["desired_vz"], **close)
    assert np.array_equal(run["transition"], dump["transition"] == 1)
    assert np.array_equal(run["contacts"][:, 0], dump["contact_l"] == 1)
    assert np.array_equal(run["contacts"][:, 1], dump["contact_r"] == 1)
    assert np.array_equal(run["clip"], dump["clip"].astype(np.int32))
    assert np.array_equal(run["frame"], dump["frame"].astype(np.int32))
    np.testing.assert_allclose(run["toe_ground"][:, 0], dump["toe_ground_l"], **close)
    np.testing.assert_allclose(run["toe_ground"][:, 1], dump["toe_ground_r"], **close)
    np.testing.assert_allclose(run["hips_ground"], dump["hips_ground"], **close)
    np.testing.assert_allclose(run["wall_depth"], dump["wall_depth"], **close)
    assert np.array_equal(run["stuck"], dump["stuck"] == 1)
    positions = run["positions"]
    assert positions.shape == (frames, database.joint_count, 3)
    for j, name in enumerate(database.joint_names):
        for k, axis in enumerate("xyz"):
            np.testing.assert_allclose(positions[:, j, k], dump[f"{name}_{axis}"], **close)
    # The run moved and searched: not a trivially equal pair of empty runs.
    assert np.ptp(run["root"][:, 0]) + np.ptp(run["root"][:, 2]) > 1.0
    assert run["transition"].sum() > 3


@pytest.mark.parametrize("extra,kwargs", [((), {}),
                                          (("--ik", "off", "--dt", "0.03125"),
                                           dict(ik=False, dt=0.03125)),
                                          (("--set", "inertialization_halflife=0.2"),
                                           dict(inertialization_halflife=0.2))])
def test_evaluate_equals_the_command_line_json(database, database_path, mm_tool, scripts_dir,
                                               tmp_path, extra, kwargs):
    script = scripts_dir / "stop-and-go.txt"
    _, cli = _mm_eval(mm_tool, database_path, script, tmp_path, *extra)
    metrics = mm.evaluate(database, script, **kwargs)
    assert set(metrics) == set(cli)
    for key, value in cli.items():
        if key not in TIMINGS:
            assert metrics[key] == value, key
    assert metrics["frames"] > 1000
    assert metrics["transitions_per_s"] > 0


def test_settings_change_the_run(database, scripts_dir):
    script = scripts_dir / "stop-and-go.txt"
    plain = mm.evaluate(database, script)
    slow = mm.evaluate(database, script, walk_speed_forward=0.5)
    assert slow["root_sim_distance_cm_mean"] != plain["root_sim_distance_cm_mean"]


def test_build_database_reports_progress_and_honours_its_options(shared_dir, tmp_path):
    clips = sorted((shared_dir / "mocap" / "bandai-normal").glob("dataset-1_walk*_normal_00*.bvh"))[:3]
    assert len(clips) == 3
    calls = []
    out = tmp_path / "small.mmdb"
    db = mm.build_database(clips, out, rate=30, idle=0, threads=2,
                           progress=lambda done, total: calls.append((done, total)))
    assert out.is_file()
    assert db.clip_names == [c.stem for c in clips]
    assert calls[-1] == (2 * len(clips), 2 * len(clips))
    assert [done for done, _ in calls] == sorted(done for done, _ in calls)
    report = db.build_report
    assert report["inputs"] == 3 and report["clips"] == 3
    assert report["frames"] == db.frame_count
    loaded = mm.load_database(out)
    assert np.array_equal(loaded.features, db.features)

    mirrored = mm.build_database(clips, tmp_path / "mirrored.mmdb", mirror=True, idle=0, rate=15)
    assert mirrored.clip_names == [name for c in clips for name in (c.stem, c.stem + "_mirror")]
    assert mirrored.frame_time == pytest.approx(1.0 / 15.0)
    # Twice the clips at half the rate.
    assert mirrored.frame_count == pytest.approx(db.frame_count, rel=0.05)


def test_build_database_passes_a_progress_exception_on(shared_dir, tmp_path):
    clip = next((shared_dir / "mocap" / "bandai-normal").glob("*.bvh"))

    def stop(done, total):
        raise KeyboardInterrupt("stopped by the progress callback")

    with pytest.raises(KeyboardInterrupt, match="stopped by the progress callback"):
        mm.build_database([clip], tmp_path / "x.mmdb", idle=0, progress=stop)


def test_build_database_tags_map_and_warnings(shared_dir, tmp_path):
    folder = shared_dir / "mocap" / "bandai-normal"
    # A 24-frame run clip, too short for the features: the builder warns about it.
    clips = [folder / "dataset-1_run_normal_001.bvh", folder / "dataset-1_walk_normal_001.bvh"]
    tags = tmp_path / "tags.txt"
    tags.write_text("*walk_normal* sprint\n")
    joint_map = tmp_path / "map.txt"
    joint_map.write_text("hips=Hips\n")
    with pytest.warns(UserWarning, match="clip 'dataset-1_run_normal_001' \\(24 frames\\) is shorter"):
        db = mm.build_database(clips, tmp_path / "t.mmdb", idle=0, tags=tags, map=joint_map)
    assert "sprint" not in db.clips[0]["tags"]
    assert "sprint" in db.clips[1]["tags"]
    assert any("shorter than the feature times" in w for w in db.build_report["warnings"])
    joint_map.write_text("hips=NoSuchJoint\n")
    with pytest.raises(mm.Error, match="NoSuchJoint"):
        mm.build_database(clips, tmp_path / "u.mmdb", idle=0, map=joint_map)
    with pytest.raises(FileNotFoundError, match="nothing.bvh"):
        mm.build_database([folder / "nothing.bvh"], tmp_path / "v.mmdb")


def test_a_run_in_a_level_equals_the_command_line_and_stops_at_its_wall(
        database, database_path, mm_tool, scripts_dir, source_dir, tmp_path):
    script = scripts_dir / "course-walk.txt"
    level = source_dir / "data" / "levels" / "course.glb"
    # The head-on wall's lane: its face across the lane at z = 8 (docs/world-levels.md).
    dump, cli = _mm_eval(mm_tool, database_path, script, tmp_path, "--world", str(level),
                         "--start", "17.5,0")
    metrics = mm.evaluate(database, script, world=level, start=(17.5, 0.0))
    assert set(metrics) == set(cli)
    for key, value in cli.items():
        if key not in TIMINGS:
            assert metrics[key] == value, key
    assert metrics["world"] == str(level)
    run = mm.run_script(database, script, world=level, start=(17.5, 0.0))
    close = dict(atol=6e-6, rtol=0)
    np.testing.assert_allclose(run["simulation"][:, 2], dump["sim_z"], **close)
    np.testing.assert_allclose(run["wall_depth"], dump["wall_depth"], **close)
    # The wall stopped the simulation a capsule's radius (0.3 m) before it; without the level
    # the same script walks on through z = 8.
    assert run["simulation"][:, 2].max() < 8.0 - 0.29
    flat = mm.run_script(database, script, start=(17.5, 0.0))
    assert flat["simulation"][:, 2].max() > 9.0


def test_a_bad_level_raises_with_its_message(database, scripts_dir, tmp_path):
    script = scripts_dir / "course-walk.txt"
    with pytest.raises(FileNotFoundError, match="missing.glb"):
        mm.evaluate(database, script, world=tmp_path / "missing.glb")
    not_gltf = tmp_path / "level.gltf"
    not_gltf.write_text("this is not glTF")
    with pytest.raises(mm.Error) as raised:
        mm.run_script(database, script, world=not_gltf)
    assert str(raised.value).startswith(str(not_gltf))
