"""The harder crowd (``crowd-dynamic``, :mod:`uvnav.scenarios.crowd_dynamic`) and the ORCA
pedestrians' goal changes it relies on
(:meth:`uvnav.obstacles.crowd.OrcaPedestrian.current_goal`)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.bench.spec import load_campaign
from uvnav.cli.app import app
from uvnav.obstacles import DiscBody, Obstacle, ObstacleState, OrcaPedestrian, join_crowds
from uvnav.scenarios import GENERATORS, ScenarioError, build_episode
from uvnav.scenarios.crowd_dynamic import MIN_LEG, WALL_CLEARANCE, crowd_dynamic_scenario
from uvnav.sim import run_episode

pytest.importorskip("pyrvo")


def _humans(scn: Any) -> list[Any]:
    return [o for o in scn.obstacles if o.motion.type == "orca_crowd"]


def test_registered_and_the_same_seed_gives_the_same_scene() -> None:
    assert GENERATORS["crowd-dynamic"](3) == crowd_dynamic_scenario(3)
    assert crowd_dynamic_scenario(3) != crowd_dynamic_scenario(4)


@settings(max_examples=15, deadline=None)
@given(st.integers(0, 10_000), st.booleans())
def test_drawn_attributes_lie_in_their_ranges(seed: int, walls: bool) -> None:
    scn = crowd_dynamic_scenario(seed, walls=walls, wall_half_width=5.0)
    humans = _humans(scn)
    assert len(humans) == 20
    robot_path = (np.array([0.0, -6.0]), np.array([0.0, 6.0]))
    for h in humans:
        r, m = h.body.disc, h.motion
        assert 0.3 <= r <= 0.5 and 0.5 <= m.v_pref <= 1.5 and m.arrival == r
        assert m.change_times == sorted(m.change_times) and all(t < 50 for t in m.change_times)
        goals = np.array([m.goal, *m.next_goals])
        assert np.all(np.hypot(*np.diff(goals, axis=0).T) >= MIN_LEG - 1e-9)
        assert np.all(np.hypot(*goals.T) <= 6.0 + 1e-9)  # within the arena's disc
        start = np.asarray(h.start.position)
        assert min(np.hypot(*(start - p)) for p in robot_path) >= r + 0.3 + 1.0
        if walls:  # every start and goal between the walls
            xs = np.r_[goals[:, 0], start[0]]
            assert np.all(np.abs(xs) <= 5.0 - r - WALL_CLEARANCE + 1e-9)
    assert (len(scn.obstacles) - len(humans)) == (2 if walls else 0)


def test_bad_parameters_are_one_line_errors() -> None:
    with pytest.raises(ScenarioError, match=r"crowd-dynamic:1: params.radius_min: 0.6 > "):
        GENERATORS["crowd-dynamic"](1, radius_min=0.6)
    with pytest.raises(ScenarioError, match=r"params.n_humans"):
        GENERATORS["crowd-dynamic"](1, n_humans=200, arena_radius=2.0)
    with pytest.raises(ScenarioError, match=r"params.wall_half_width"):
        GENERATORS["crowd-dynamic"](1, walls=True, wall_half_width=0.4)


def _walker(**kw: Any) -> Obstacle:
    motion = OrcaPedestrian(np.array([10.0, 0.0]), v_pref=1.0, period=0.25, **kw)
    return Obstacle(DiscBody(0.3), ObstacleState(np.zeros(2)), motion, "p")


def _walk(ob: Obstacle, seconds: float) -> list[np.ndarray]:
    join_crowds([ob])
    out = []
    for i in range(round(seconds / 0.25)):
        ob.state = ob.motion.step(ob.state, i * 0.25, 0.25)
        out.append(ob.state.velocity.copy())
    return out


def test_a_walker_turns_to_its_next_goal_at_its_change_time() -> None:
    ob = _walker(next_goals=np.array([[0.0, -10.0]]), change_times=np.array([2.0]))
    v = _walk(ob, 4.0)
    assert np.allclose(v[7], [1.0, 0.0], atol=1e-4)  # the step from 1.75 s: still east
    assert v[8][1] < -0.5  # the decision at 2.0 s: south, toward the next goal


def test_an_arriving_walker_sets_off_to_its_next_goal_and_keeps_the_last() -> None:
    ob = _walker(next_goals=np.array([[2.0, 0.0], [2.0, 5.0]]), arrival=0.3)
    ob.motion.goal = np.array([1.0, 0.0])  # type: ignore[attr-defined]
    v = _walk(ob, 12.0)
    assert ob.motion.current_goal(ob.state.position, 12.0).tolist() == [2.0, 5.0]  # type: ignore[attr-defined]
    assert np.hypot(*(ob.state.position - [2.0, 5.0])) < 0.3  # walked to the last goal
    assert np.hypot(*v[-1]) < 0.3  # and stays there: no goal after it


def test_a_walker_without_further_goals_is_crowdnavs() -> None:
    plain, scheduled = _walker(), _walker(change_times=np.array([1.0]))  # no goal to change to
    assert np.allclose(_walk(plain, 3.0), _walk(scheduled, 3.0))


def test_an_episode_runs_with_the_comfort_metrics() -> None:
    res = run_episode(build_episode(crowd_dynamic_scenario(100), 100),
                      _law("zhang2019-holonomic-v2"), np.random.default_rng(100),
                      vehicle="holonomic", record=True)  # fmt: skip
    assert res.status in ("success", "collision", "timeout")
    assert res.metrics.intrusion_ratio is not None and res.metrics.jerk is not None


def _law(name: str) -> Any:
    from uvnav.controllers.base import make_law

    return make_law(name)


def test_cli_simulate_takes_gen_params(tmp_path: Any) -> None:
    from typer.testing import CliRunner

    ok = CliRunner().invoke(
        app, ["simulate", "crowd-dynamic:101", "--gen-param", "n_humans=5", "--json"]
    )
    assert ok.exit_code == 0, ok.output
    bad = CliRunner().invoke(app, ["simulate", "crowd-dynamic:101", "--gen-param", "walls=maybe"])
    assert bad.exit_code == 2 and "params.walls" in bad.output


def test_the_campaign_file_loads() -> None:
    from pathlib import Path

    spec = load_campaign(Path(__file__).parents[2] / "campaigns" / "crowd-dynamic.yaml")
    assert {s.generator for s in spec.scenarios} == {"crowd-dynamic"}
    assert math.isclose(spec.scenarios[1].params["sensing_range"], 100.0)
