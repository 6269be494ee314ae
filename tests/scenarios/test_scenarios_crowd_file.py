"""Any trajectory file as a crowd: formats, hidden positions, stitching, waiting at rest, the
crowd-file generator, and absent pedestrians (never sensed, never in the clearance)."""

from __future__ import annotations

import json
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from uvnav.bench.spec import load_campaign, run_campaign_spec
from uvnav.bench.store import ResultsStore
from uvnav.controllers import make_controller
from uvnav.scenarios import GENERATORS, ScenarioError, build_episode, scenario_from_dict
from uvnav.scenarios import pedestrians as P  # noqa: N812
from uvnav.scenarios.generators import crowd_file_scenario
from uvnav.sensors.exact import sense_obstacles
from uvnav.sim import run_episode, run_rng
from uvnav.sim.episode import World2D

ETH = Path(P.__file__).parent / "data" / "pedestrians" / "eth" / "obsmat.txt.gz"


def write(tmp_path: Path, name: str, text: str) -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


# -------------------------------------------------------------------------------- formats


def test_trajnet_ndjson_reads_like_xy4(tmp_path: Path) -> None:
    lines = [{"scene": {"id": 0, "p": 1, "s": 10, "e": 30, "fps": 2.5}}]
    lines += [
        {"track": {"f": f, "p": p, "x": x, "y": y}}
        for f, p, x, y in ((10, 1, 1.0, 2.0), (20, 1, 1.4, 2.3), (30, 1, 2.0, 2.3), (20, 2, -5, 0))
    ]
    lines.append({"track": {"f": 30, "p": 2, "x": -4.0, "y": 0.5, "prediction_number": 0}})
    path = write(tmp_path, "t.ndjson", "\n".join(json.dumps(d) for d in lines) + "\n")
    tracks = P.read_tracks(path, "trajnet", frame_rate=25.0)
    xy4 = "10 1 1.0 2.0\n20 1 1.4 2.3\n30 1 2.0 2.3\n20 2 -5 0\n30 2 -4 0.5\n"
    ref = P.read_tracks(write(tmp_path, "t.txt", xy4), "xy4", frame_rate=25.0)
    assert sorted(tracks) == sorted(ref)
    for k in ref:
        np.testing.assert_array_equal(tracks[k].times, ref[k].times)
        np.testing.assert_array_equal(tracks[k].positions, ref[k].positions)


def test_hidden_positions_are_skipped_with_one_warning(tmp_path: Path) -> None:
    text = "0 1 0.0 0.0\n10 1 0.4 0.0\n20 1 ? ?\n30 1 1.2 0.0\n10 2 ? ?\n20 2 5 5\n30 2 5 6\n"
    path = write(tmp_path, "hidden.txt", text)
    with pytest.warns(P.HiddenPositionsWarning, match=r"hidden\.txt: 2 line\(s\).*line 3") as rec:
        tracks = P.read_tracks(path, "xy4", frame_rate=25.0)
    assert len(rec) == 1
    np.testing.assert_allclose(tracks[1].times, [0.0, 0.4, 1.2])
    np.testing.assert_allclose(tracks[2].positions, [[5, 5], [5, 6]])
    ndjson = "".join(
        json.dumps({"track": {"f": f, "p": 1, "x": x, "y": 1}}) + "\n"
        for f, x in ((0, 0), (10, None), (20, 1))
    )
    with pytest.warns(P.HiddenPositionsWarning, match=r"t\.ndjson: 1 line"):
        P.read_tracks(write(tmp_path, "t.ndjson", ndjson), "trajnet", frame_rate=25.0)


@pytest.mark.parametrize(
    ("fmt", "text", "expect"),
    [
        ("xy4", "0 1 0 0\n10 ? 1 1\n", r"bad\.txt: line 2: not a number: '\?' \(person id\)"),
        ("xy4", "0 1 0 0\n10 1 zz 1\n", r"bad\.txt: line 2: not a number: 'zz'"),
        (
            "trajnet",
            '{"track": {"f": 0, "p": 1, "x": 0, "y": 0}}\n{"track": {"f": 1,',
            r"line 2: not JSON",
        ),
        (
            "trajnet",
            '\n\n{"track": {"f": 0, "p": 1, "x": 0}}\n',
            r"bad\.txt: line 3: track lacks y",
        ),
        ("trajnet", '{"other": 1}\n', r"line 1: expected \{\"scene\""),
        (
            "trajnet",
            '{"track": {"f": 0, "p": 1.5, "x": 0, "y": 0}}\n',
            r"line 1: person id must be",
        ),
    ],
)
def test_malformed_file_is_one_line_with_file_and_line(
    tmp_path: Path, fmt: str, text: str, expect: str
) -> None:
    path = write(tmp_path, "bad.txt", text)
    with pytest.raises(ScenarioError, match=expect) as info:
        P.read_tracks(path, fmt, frame_rate=25.0)
    assert "\n" not in str(info.value)
    with pytest.raises(
        ScenarioError, match=r"crowd-file:0: params: path: .*bad\.txt: line \d+: "
    ) as info:
        crowd_file_scenario(0, path=str(path), format=fmt, frame_rate=25.0)
    assert "\n" not in str(info.value)


# ------------------------------------------------------------------------------- stitching

BROKEN = (
    # person 1 walks along y = 0 at 1 m/s; the tracker calls it 7 from t = 1.2 s on
    "0 1 0.0 0.0\n10 1 0.4 0.0\n20 1 0.8 0.0\n"
    "30 7 1.2 0.0\n40 7 1.6 0.0\n50 7 2.0 0.0\n"
    # person 2 ends at (5, 5); person 3 starts one step later but 3 m away: someone else
    "0 2 5.0 4.2\n10 2 5.0 4.6\n20 2 5.0 5.0\n"
    "30 3 8.0 5.0\n40 3 8.0 5.4\n"
    # person 4 starts 2 steps after person 1's end, next to it: too late to be the same
    "40 4 0.9 0.1\n50 4 0.9 0.5\n"
)


def test_stitching_joins_continuing_pieces_only(tmp_path: Path) -> None:
    tracks = P.read_tracks(write(tmp_path, "b.txt", BROKEN), "xy4", frame_rate=25.0)
    assert P.annotation_step(tracks) == pytest.approx(0.4)
    joined = P.stitch_tracks(tracks)
    assert sorted(joined) == [1, 2, 3, 4]
    np.testing.assert_allclose(joined[1].times, [0.0, 0.4, 0.8, 1.2, 1.6, 2.0])
    np.testing.assert_allclose(joined[1].positions[:, 0], [0.0, 0.4, 0.8, 1.2, 1.6, 2.0])
    for k in (2, 3, 4):
        np.testing.assert_array_equal(joined[k].positions, tracks[k].positions)
    # the replay of the stitched person never vanishes between the pieces
    ped = P.PedestrianReplay(joined[1].times, joined[1].positions)
    assert all(ped.present(t) for t in np.arange(0.0, 2.0, 0.1))
    unstitched = P.PedestrianReplay(tracks[1].times, tracks[1].positions)
    assert not unstitched.present(1.0)
    # a chain of three pieces becomes one track
    chain = BROKEN + "60 8 2.4 0.0\n70 8 2.8 0.0\n"
    joined = P.stitch_tracks(P.read_tracks(write(tmp_path, "c.txt", chain), "xy4", frame_rate=25.0))
    assert joined[1].times[-1] == pytest.approx(2.8) and 7 not in joined and 8 not in joined


def test_crowd_spec_stitches_scales_and_shifts(tmp_path: Path) -> None:
    path = write(tmp_path, "b.txt", BROKEN)
    crowd = {"dataset": str(path), "format": "xy4", "frame_rate": 25.0}
    data: dict[str, Any] = {
        "name": "c",
        "t_max": 3.0,
        "robot": {"start": [20.0, 20.0], "goal": [25.0, 20.0], "v_max": 1.5, "u_max": 2.0},
        "crowd": crowd,
    }
    plain = build_episode(scenario_from_dict(data, "c.yaml"), 0).obstacles
    assert len(plain) == 5
    data["crowd"] = {**crowd, "stitch": True, "scale": 2.0, "offset": [1.0, -1.0]}
    sc = scenario_from_dict(data, "c.yaml")
    obs = build_episode(sc, 0).obstacles
    assert [o.name for o in obs] == ["ped-1", "ped-2", "ped-3", "ped-4"]
    np.testing.assert_allclose(obs[0].motion.position_at(2.0), [2.0 * 2.0 + 1.0, -1.0])


def test_at_rest_waits_at_the_first_position(tmp_path: Path) -> None:
    path = write(tmp_path, "b.txt", BROKEN)
    tracks = P.read_tracks(path, "xy4", frame_rate=25.0)
    pieces = P.episode_tracks(tracks, t_start=0.0, duration=3.0, at_rest=True)
    late = next(p for p in pieces if p.ped_id == 4)
    ped = P.PedestrianReplay(late.times, late.positions)
    assert ped.present(0.0) and ped.present(1.0)
    np.testing.assert_allclose(ped.position_at(0.5), [0.9, 0.1])
    np.testing.assert_allclose(ped.velocity_at(0.5), [0.0, 0.0])
    np.testing.assert_allclose(ped.position_at(1.8), [0.9, 0.3])
    # people already walking at t = 0 are unchanged
    first = next(p for p in pieces if p.ped_id == 1)
    np.testing.assert_array_equal(first.times, tracks[1].times)


# ------------------------------------------------------------------------------- generator


def test_crowd_file_on_the_shipped_eth_file_crosses_the_same_walkway() -> None:
    sc = GENERATORS["crowd-file"](3, path=str(ETH), format="obsmat")
    eth = GENERATORS["crowd-eth"](3)
    assert sc.crowd is not None and sc.crowd.stitch and sc.crowd.format == "obsmat"
    # the same walkway axis and draws: the same crossing line
    assert sc.robot.start == eth.robot.start and sc.robot.goal == eth.robot.goal
    assert GENERATORS["crowd-file"](3, path=str(ETH)) == sc  # deterministic
    fixed = crowd_file_scenario(3, path=str(ETH), start=[4.0, 0.0], goal=[4.0, 9.0], min_near=0)
    assert fixed.robot.start == (4.0, 0.0) and fixed.robot.goal == (4.0, 9.0)


def test_crowd_file_needs_a_path_and_sane_params(tmp_path: Path) -> None:
    with pytest.raises(ScenarioError, match=r"crowd-file:3: params: crowd-file needs params: path"):
        GENERATORS["crowd-file"](3)
    with pytest.raises(ScenarioError, match=r"params.format: must be 'obsmat', 'xy4' or 'trajnet'"):
        crowd_file_scenario(0, path=str(ETH), format="csv")
    with pytest.raises(ScenarioError, match=r"crowd-file:0: params.stitch: "):
        crowd_file_scenario(0, path=str(ETH), stitch="maybe")
    with pytest.raises(ScenarioError, match=r"crowd-file:0: params.t_max: .*finite"):
        crowd_file_scenario(0, path=str(ETH), t_max=float("nan"))
    with pytest.raises(ScenarioError, match="both start and goal"):
        crowd_file_scenario(0, path=str(ETH), start=[0, 0])
    with pytest.raises(ScenarioError, match="params: path: no such file"):
        crowd_file_scenario(0, path=str(tmp_path / "none.txt"))
    with pytest.raises(ScenarioError, match=r"crowd-file:0: params.scale: must be > 0"):
        crowd_file_scenario(0, path=str(ETH), scale=-1.0)


# ------------------------------------------------------------------------ absent pedestrians


def late_crowd(tmp_path: Path) -> Any:
    """A robot crossing 3 m in a scene whose only pedestrian walks over its path 30-40 s in."""
    rows = "".join(f"{75 + k} 1 5.0 {-5 + 0.4 * k:.1f}\n" for k in range(26))
    data = {
        "name": "late",
        "t_max": 40.0,
        "robot": {"start": [3.5, 0.0], "goal": [6.5, 0.0], "v_max": 1.0, "u_max": 1.0},
        "crowd": {"dataset": str(write(tmp_path, "late.txt", rows)), "format": "xy4",
                  "frame_rate": 2.5},
    }  # fmt: skip
    return scenario_from_dict(data, "late.yaml")


@pytest.mark.parametrize("record", [False, True])
def test_nobody_present_means_no_clearance(tmp_path: Path, record: bool) -> None:
    setup = build_episode(late_crowd(tmp_path), 0)
    assert len(setup.obstacles) == 1
    result = run_episode(setup, make_controller("straight-v1"), run_rng(0), record=record)
    assert result.status == "success"
    assert result.metrics.min_clearance is None  # not the 1 km parking distance


def test_absent_pedestrians_are_never_sensed_nor_in_the_clearance() -> None:
    """crowd-eth:1 stepped by hand: every reading and the clearance use present people only."""
    setup = build_episode(GENERATORS["crowd-eth"](1), 0)
    world = World2D(setup, run_rng(1), exact=True)
    world.start()
    models = [o.motion for o in setup.obstacles]
    absent_seen = 0
    for _ in range(150):
        present = np.array([m.present(world.t) for m in models])
        absent_seen += int((~present).sum())
        readings = sense_obstacles(world.pose[:2], world.field, sensing_range=1e6)
        assert {r.obstacle_id for r in readings} == set(np.flatnonzero(present).tolist())
        if present.any():
            centres = world.field.centres[present]
            gaps = np.hypot(*(centres - world.pose[:2]).T) - 0.3 - float(setup.spec.radius)
            assert world.clearance == pytest.approx(float(gaps.min()), abs=1e-9)
            assert world.clearance < 100.0
        else:
            assert world.clearance == np.inf
        world.apply(type(world.applied)(0.5, 0.0))
        world.advance()
        if world.done:
            break
    assert absent_seen > 0  # the check met absent people


# ------------------------------------------------------------------------------- campaign

CAMPAIGN = """\
name: crowd-file-eth
scenarios:
  - generator: crowd-file
    seeds: [0, 2]
    params: {{path: {path}, format: obsmat}}
  - generator: crowd-file
    seeds: [0, 1]
    params: {{path: {path}, start: [5.0, 2.0], goal: [5.0, 5.0], t_start: 185.0, t_max: 20,
              min_near: 0}}
controllers:
  - name: straight-v1
"""


def test_campaign_with_crowd_file_runs(tmp_path: Path) -> None:
    spec = load_campaign(write(tmp_path, "c.yaml", CAMPAIGN.format(path=ETH)))
    with warnings.catch_warnings():
        warnings.simplefilter("error", P.HiddenPositionsWarning)
        with ResultsStore(tmp_path / "r.sqlite") as store:
            run = run_campaign_spec(store, spec)
            assert (run.ran, run.errors) == (3, 0)
            df = store.episodes_frame("crowd-file-eth")
    clear = df["min_clearance"].tolist()
    # the empty-walkway crossing (nobody there while the robot crosses) has no clearance
    empty = df[df["scenario"].str.contains("t_start")]
    assert len(empty) == 1 and empty["min_clearance"].isna().all()
    assert empty["min_separation"].isna().all()  # nor a pedestrian separation (nobody is there)
    assert all(c is None or np.isnan(c) or c < 50.0 for c in clear)
