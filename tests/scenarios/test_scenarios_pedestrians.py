"""Real pedestrians (ETH recordings): parsers, replay, crowd scenes, crossing generators."""

from __future__ import annotations

import gzip
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from uvnav.controllers import make_controller
from uvnav.obstacles import DiscBody
from uvnav.scenarios import (
    GENERATORS,
    ScenarioError,
    build_episode,
    check_constraints,
    load_scenario,
    scenario_from_dict,
    validate_for_controller,
)
from uvnav.scenarios import pedestrians as P  # noqa: N812
from uvnav.scenarios.generators import crowd_crossing_scenario
from uvnav.sim import run_episode, run_rng

OBSMAT = """\
   1.0000000e+01   1.0000000e+00   1.0000000e+00   0.0000000e+00   2.0000000e+00   0 0 0
   2.0000000e+01   1.0000000e+00   1.4000000e+00   0.0000000e+00   2.3000000e+00   0 0 0
   3.0000000e+01   1.0000000e+00   2.0000000e+00   0.0000000e+00   2.3000000e+00   0 0 0
   2.0000000e+01   2.0000000e+00  -5.0000000e+00   0.0000000e+00   0.0000000e+00   0 0 0
   3.0000000e+01   2.0000000e+00  -4.0000000e+00   0.0000000e+00   0.5000000e+00   0 0 0
"""
XY4 = "10\t1\t1.0\t2.0\n20\t1\t1.4\t2.3\n30\t1\t2.0\t2.3\n20\t2\t-5.0\t0.0\n30\t2\t-4.0\t0.5\n"


def write(tmp_path: Path, name: str, text: str) -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


# -------------------------------------------------------------------------------------- parsers


@pytest.mark.parametrize(("fmt", "text"), [("obsmat", OBSMAT), ("xy4", XY4)])
def test_parsers_read_both_formats(tmp_path: Path, fmt: str, text: str) -> None:
    path = write(tmp_path, f"t.{fmt}", text)
    tracks = P.read_tracks(path, fmt, frame_rate=25.0)
    assert sorted(tracks) == [1, 2]
    np.testing.assert_allclose(tracks[1].times, [0.4, 0.8, 1.2])
    np.testing.assert_allclose(tracks[1].positions, [[1.0, 2.0], [1.4, 2.3], [2.0, 2.3]])
    np.testing.assert_allclose(tracks[2].positions, [[-5.0, 0.0], [-4.0, 0.5]])
    # frame rate inferred from the 0.4 s annotation period: 10 frames per 0.4 s = 25 frames/s
    inferred = P.read_tracks(path, fmt)
    np.testing.assert_allclose(inferred[1].times, tracks[1].times)
    # gzip is read transparently
    gz = tmp_path / f"t.{fmt}.gz"
    gz.write_bytes(gzip.compress(text.encode()))
    np.testing.assert_array_equal(P.read_tracks(gz, fmt)[2].positions, tracks[2].positions)


@pytest.mark.parametrize(
    ("fmt", "text", "expect"),
    [
        (
            "xy4",
            "10 1 1.0 2.0\n20 1 1.4\n",
            r"bad\.txt: line 2: expected 4 columns for xy4 \(got 3",
        ),
        ("xy4", "10 1 1.0 2.0\n\n20 1 x 2.0\n", r"bad\.txt: line 3: not a number: 'x'"),
        ("obsmat", "10 1 1 0 2 0 0 0\n10 1 1 0 2 0 0 0\n", r"line 2: person 1 annotated twice"),
        ("obsmat", XY4, r"line 1: expected 8 columns for obsmat \(got 4\)"),
        ("xy4", "10 1.5 1 2\n", r"line 1: person id must be an integer"),
        ("xy4", "# nothing\n", r"bad\.txt: no annotations"),
        ("xy4", "10 1 1 2\n20 1 1e300 2\n", r"line 2: x: 1e\+300 is outside .* <= 1e\+06 m$"),
        ("xy4", "1e300 1 1 2\n", r"line 1: frame 1e\+300 is above 1e\+09$"),
    ],
)
def test_bad_files_give_one_line_naming_file_line_and_problem(
    tmp_path: Path, fmt: str, text: str, expect: str
) -> None:
    path = write(tmp_path, "bad.txt", text)
    with pytest.raises(ScenarioError, match=expect) as info:
        P.read_tracks(path, fmt, frame_rate=25.0)
    assert "\n" not in str(info.value)
    with pytest.raises(ScenarioError, match="no such file"):
        P.read_tracks(tmp_path / "missing.txt")


def test_shipped_datasets_match_their_readme() -> None:
    for name, n_people, mean_speed in (("eth", 360, 1.38), ("hotel", 390, 1.04)):
        tracks = P.load_dataset(name)
        assert len(tracks) == n_people
        speeds = np.concatenate([t.speeds() for t in tracks.values()])
        assert speeds.mean() == pytest.approx(mean_speed, abs=0.01)
        steps = np.concatenate([np.diff(t.times) for t in tracks.values()])
        np.testing.assert_allclose(steps, P.ANNOTATION_PERIOD, atol=1e-9)


# --------------------------------------------------------------------------------------- replay


def crowd_scene(path: Path, **crowd: Any) -> Any:
    data = {
        "name": "c",
        "description": "Pedestrians do not react to the robot.",
        "t_max": 5.0,
        "robot": {"start": [0.0, -5.0], "goal": [0.0, 5.0], "v_max": 1.5, "u_max": 2.0},
        "crowd": {"dataset": str(path), "format": "xy4", **crowd},
        "controller": {"name": "straight-v1"},
    }
    return scenario_from_dict(data, "c.yaml")


def test_replay_hits_the_data_at_annotations_is_linear_between_and_absent_outside(
    tmp_path: Path,
) -> None:
    sc = crowd_scene(write(tmp_path, "t.txt", XY4), t_start=0.4)  # recording 0.4 s is t = 0
    obstacles = build_episode(sc, seed=0).obstacles
    assert [o.name for o in obstacles] == ["ped-1", "ped-2"]
    ped1, ped2 = (o.motion for o in obstacles)
    assert isinstance(ped1, P.PedestrianReplay) and isinstance(ped2, P.PedestrianReplay)
    for t, xy in ((0.0, [1.0, 2.0]), (0.4, [1.4, 2.3]), (0.8, [2.0, 2.3])):
        np.testing.assert_allclose(ped1.position_at(t), xy, atol=1e-9, rtol=0)
    for s in (0.1, 0.25, 0.7):
        np.testing.assert_allclose(
            ped1.position_at(0.4 * s), (1 - s) * np.array([1.0, 2.0]) + s * np.array([1.4, 2.3])
        )
    # ped 2 appears at its first annotation (t = 0.4) and ped 1 leaves after its last (t = 0.8)
    far = P.ABSENT_DISTANCE / 2
    assert np.hypot(*obstacles[1].state.position) > far and not ped2.present(0.3)
    assert np.hypot(*ped1.position_at(0.9)) > far and np.hypot(*ped2.position_at(0.9)) > far
    # stepping with the simulator's dt: appear with the track's velocity, then follow the data
    state, t, dt = obstacles[1].state, 0.0, 0.1
    for _ in range(4):
        state = ped2.step(state, t, dt)
        t += dt
    np.testing.assert_allclose(state.position, [-5.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(state.velocity, [2.5, 1.25])
    state = ped2.step(state, t, dt)
    np.testing.assert_allclose(state.position, [-4.75, 0.125], atol=1e-9)
    np.testing.assert_allclose(state.velocity, [2.5, 1.25])
    assert ped2.speed_bound() == pytest.approx(np.hypot(2.5, 1.25))


def test_region_crop_and_window(tmp_path: Path) -> None:
    path = write(tmp_path, "t.txt", XY4)
    sc = crowd_scene(path, region=[0.0, 0.0, 10.0, 10.0], t_start=0.0)
    assert [o.name for o in build_episode(sc, 0).obstacles] == ["ped-1"]
    late = crowd_scene(path, t_start=100.0)  # nobody walks then
    assert build_episode(late, 0).obstacles == []


def test_bad_crowd_file_is_a_one_line_scenario_error(tmp_path: Path) -> None:
    path = write(tmp_path, "bad.txt", "10 1 1.0\n")
    with pytest.raises(ScenarioError, match=r"c\.yaml: crowd\.dataset: .*bad\.txt: line 1: "):
        crowd_scene(path)


def test_pedestrian_on_the_start_is_rejected(tmp_path: Path) -> None:
    data = {
        "name": "c",
        "robot": {"start": [1.0, 2.0], "goal": [0.0, 5.0], "v_max": 1.5, "u_max": 2.0},
        "crowd": {"dataset": str(write(tmp_path, "t.txt", XY4)), "format": "xy4", "t_start": 0.4},
    }
    with pytest.raises(ScenarioError, match=r"robot\.start: .*overlaps obstacle 0 \(ped-1\)"):
        scenario_from_dict(data, "c.yaml")


# ------------------------------------------------------------------------------ crowd scenes


CROWD_BUILTINS = ["crowd-eth-1", "crowd-eth-2", "crowd-hotel-1", "crowd-hotel-2"]


@pytest.mark.parametrize("name", CROWD_BUILTINS)
def test_crowd_scene_is_busy_and_clear_at_the_start(name: str) -> None:
    sc = load_scenario(name)
    assert "do not react to the robot" in sc.description
    setup = build_episode(sc, seed=0)
    start, goal = np.asarray(sc.robot.start), np.asarray(sc.robot.goal)
    assert 8.0 <= np.hypot(*(goal - start)) <= 12.0
    assert (sc.robot.v_max, sc.robot.u_max, sc.robot.radius, sc.t_max) == (
        sc.robot.v_max,
        2.0,
        0.3,
        40.0,
    )
    near = 0
    for ob in setup.obstacles:
        assert isinstance(ob.body, DiscBody) and ob.body.radius == 0.3
        gap = np.hypot(*(ob.state.position - start)) - 0.3 - sc.robot.radius
        assert gap > 0.0  # nobody on the robot at t = 0
        motion = ob.motion
        assert isinstance(motion, P.PedestrianReplay)
        ts = np.arange(0.0, 20.0, 0.4)
        pts = np.array([motion.position_at(t) for t in ts])
        ab = goal - start
        s = np.clip((pts - start) @ ab / (ab @ ab), 0, 1)
        near += bool(np.min(np.hypot(*(pts - start - s[:, None] * ab).T)) < 1.5)
    assert near > 3
    # (2.6)-(2.8) are warnings, and the default law accepts the scene
    assert check_constraints(sc) and all("warning only" in w for w in check_constraints(sc))
    validate_for_controller(sc, "zhang2019-v1")


def test_validate_rejects_a_robot_slower_than_the_crowd() -> None:
    sc = crowd_crossing_scenario(28, dataset="eth", v_max=0.5)
    validate_for_controller(sc, "straight-v1")  # no assumption, no check
    with pytest.raises(ScenarioError, match=r"crowd: typical pedestrian speed .* >= V_max 0\.5"):
        validate_for_controller(sc, "zhang2019-v1")


@pytest.mark.parametrize("generator", ["crowd-eth", "crowd-hotel"])
def test_crossing_generator_is_deterministic(generator: str) -> None:
    a, b, c = (load_scenario(f"{generator}:{s}") for s in (3, 3, 4))
    assert a == b and a != c
    assert GENERATORS[generator](3) == a
    assert a.crowd is not None and a.crowd.dataset == generator.split("-")[1]
    assert (a.robot.v_max, a.robot.u_max, a.robot.radius, a.dt, a.t_max) == (
        1.2,
        2.0,
        0.3,
        0.1,
        40.0,
    )
    assert crowd_crossing_scenario(3, dataset="eth", v_max=2.0).robot.v_max == 2.0


def test_crossing_is_across_the_walkway() -> None:
    for dataset in ("eth", "hotel"):
        _, along, across = P.walkway_axes(P.load_dataset(dataset))
        sc = crowd_crossing_scenario(0, dataset=dataset)
        d = np.asarray(sc.robot.goal) - np.asarray(sc.robot.start)
        assert abs(d @ along) < 1e-2 * np.hypot(*d) + 1e-2
        assert abs(d @ across) > 0.99 * np.hypot(*d)


def run(sc: Any, controller: str, seed: int) -> tuple[str, float | None]:
    res = run_episode(
        build_episode(sc, seed), make_controller(controller), run_rng(seed), record=False
    )
    return res.status, res.metrics.min_clearance


def test_straight_law_on_a_crowd_scene_is_deterministic() -> None:
    sc = load_scenario("crowd-hotel-1")
    first = run(sc, "straight-v1", 0)
    assert first == run(sc, "straight-v1", 0)
    assert first[0] in ("success", "collision")


def test_zhang2019_runs_on_crowd_eth_1() -> None:
    status, clearance = run(load_scenario("crowd-eth-1"), "zhang2019-v1", 0)
    assert status in ("success", "collision", "timeout")
    assert clearance is not None and np.isfinite(clearance)


@pytest.mark.parametrize("name", ["crowd-eth-1", "crowd-hotel-2"])
def test_vectorised_crowd_replay_equals_per_pedestrian_step_bit_for_bit(name: str) -> None:
    """ObstacleBatch advances every PedestrianReplay in one array step; over a whole scene
    (appearances, departures, parking) it must give exactly what each ``step`` gives."""
    import copy

    from uvnav.obstacles import ObstacleBatch

    setup = build_episode(load_scenario(name), 0)
    obstacles = setup.obstacles
    reference = copy.deepcopy(obstacles)
    states = [o.state for o in reference]
    batch = ObstacleBatch(obstacles)
    assert batch._groups and not batch._other  # the vectorised path is the one under test
    dt = setup.dt
    appeared = departed = 0
    for i in range(round(setup.t_max / dt)):
        t = i * dt
        before = [o.motion.present(t) for o in reference]  # type: ignore[attr-defined]
        states = [o.motion.step(s, t, dt) for o, s in zip(reference, states, strict=True)]
        after = [o.motion.present(t + dt) for o in reference]  # type: ignore[attr-defined]
        appeared += sum(a and not b for a, b in zip(after, before, strict=True))
        departed += sum(b and not a for a, b in zip(after, before, strict=True))
        batch.step(t, dt)
        for j, s in enumerate(states):
            got = batch.state(j)
            assert np.array_equal(got.position, s.position), (i, j)
            assert got.heading == s.heading, (i, j)
            assert np.array_equal(got.velocity, s.velocity), (i, j)
            assert got.angular_velocity == s.angular_velocity, (i, j)
    assert appeared > 0 and departed > 0  # the scene exercises both transitions


def test_a_corrupt_gz_or_a_file_that_never_ends_is_one_line(tmp_path: Path) -> None:
    import gzip
    import os

    good = gzip.compress(XY4.encode())
    corrupt = tmp_path / "tracks.txt.gz"
    corrupt.write_bytes(good[:12] + bytes(b ^ 0x5A for b in good[12:]))
    with pytest.raises(ScenarioError, match=r"tracks\.txt\.gz: cannot decode") as info:
        P.read_tracks(corrupt, "xy4", frame_rate=25.0)
    assert "\n" not in str(info.value)
    fifo = tmp_path / "fifo.txt"
    os.mkfifo(fifo)  # reading it would block for ever
    with pytest.raises(ScenarioError, match=r"fifo\.txt: is not a regular file"):
        P.read_tracks(fifo, "xy4", frame_rate=25.0)
    with pytest.raises(ScenarioError, match="is not a regular file"):
        P.read_tracks(tmp_path, "xy4", frame_rate=25.0)


def test_a_scale_that_puts_people_beyond_the_modelled_range_is_refused(tmp_path: Path) -> None:
    tracks = P.read_tracks(write(tmp_path, "t.txt", XY4), "xy4", frame_rate=25.0)
    with pytest.raises(
        ScenarioError, match=r"scale: a position scale \* p \+ offset of .* 1e\+06 m"
    ):
        P.shape_tracks(tracks, scale=1e300)
    assert P.shape_tracks(tracks, scale=2.0)[1].positions.shape[1] == 2
