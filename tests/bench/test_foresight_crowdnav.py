"""``benchmarks/foresight_crowdnav.py``: the receding-horizon planner sees only its horizon, keeps
a plan that stays clear, and drives the world as its plan says."""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np
import pytest

BENCH = Path(__file__).resolve().parents[2] / "benchmarks"
if str(BENCH) not in sys.path:
    sys.path.insert(0, str(BENCH))

import foresight_crowdnav as fs  # noqa: E402
import oracle_crowdnav as oracle  # noqa: E402


@pytest.fixture(scope="module")
def empty() -> oracle.Case:
    """Case 100 without humans: the robot 8 m below its goal, at rest."""
    return oracle.oracle_case(oracle.scene(100, 0, 1.0, 2.0, 5), 100)


def _standing(c: oracle.Case, at: tuple[float, float]) -> oracle.Case:
    """``c`` with one human standing at ``at`` for the whole episode."""
    centres = np.tile(np.array([at]), (c.steps + 1, 1, 1))
    return dataclasses.replace(c, centres=centres, radii=np.array([0.3]))


def test_a_plan_over_the_horizon_drives_toward_the_goal(empty: oracle.Case) -> None:
    plan = fs.search_plan(empty, 0.0, 0.0, periods=8)
    assert plan is not None and plan.clear == 8 and plan.cmds.shape == (8, 2)
    # from rest the speed may rise 0.25 m/s a period: the plan ramps up as fast as it may
    assert plan.cmds[:4, 0].tolist() == pytest.approx([0.25, 0.5, 0.75, 1.0])


def test_a_human_beyond_the_horizon_is_not_seen(empty: oracle.Case) -> None:
    x, y, _ = empty.start
    ahead = _standing(empty, (x, y + 3.0))  # 3 m up the straight line to the goal
    short = fs.search_plan(ahead, 0.0, 0.0, periods=4)  # 1 s: it cannot reach the human
    long = fs.search_plan(ahead, 0.0, 0.0, periods=24)  # 6 s: it must go round
    assert short is not None and long is not None
    assert not short.cmds[:, 1].any()  # straight at the goal, the human unseen
    assert long.cmds[:, 1].any()
    straight = np.vstack((short.cmds, np.tile([[1.0, 0.0]], (20, 1))))
    assert fs.stays_clear(ahead, 0.0, 0.0, straight, 24) < 24
    assert fs.stays_clear(ahead, 0.0, 0.0, long.cmds, 24) == 24


def test_a_blocked_start_has_no_plan_and_a_kept_plan_is_judged_anew(empty: oracle.Case) -> None:
    x, y, _ = empty.start
    boxed = _standing(empty, (x, y + 0.1))
    assert fs.search_plan(boxed, 0.0, 0.0, 4) is None
    straight = np.tile([[1.0, 0.0]], (4, 1))
    assert fs.stays_clear(empty, 0.0, 0.0, straight, 4) == 4
    assert fs.stays_clear(boxed, 0.0, 0.0, straight, 4) == 0


def test_the_window_reads_the_truth_from_now_on() -> None:
    track = np.arange(10.0).reshape(10, 1, 1)
    assert fs.window(track, 4, 2)[:, 0, 0].tolist() == [4.0, 5.0, 6.0]
    cv = fs.constant_velocity(np.array([[1.0, 2.0]]), np.array([[0.5, -1.0]]), 2, 0.5)
    assert cv[:, 0].tolist() == [[1.0, 2.0], [1.25, 1.5], [1.5, 1.0]]


def test_seeing_further_turns_a_collision_into_an_arrival() -> None:
    case = 101
    scn = oracle.scene(case, 5, 1.0, 2.0, 5)  # five humans
    short = fs.run_case(case, scn, "truth", horizon=1.0, clearance=0.0)
    far = fs.run_case(case, scn, "truth", horizon=4.0, clearance=0.0)
    assert short["status"] == "collision"
    assert far["status"] == "success" and far["time"] is not None
    assert fs.run_case(case, scn, "truth", horizon=4.0, clearance=0.0) == far  # deterministic


def test_the_causal_planner_reads_its_observation_and_crosses_an_empty_scene() -> None:
    r = fs.run([100], humans=0, see="cv", horizon=2.0)
    assert r["success"]["count"] == 1 and r["oracle"] is False
    assert r["time_to_goal_mean"] == pytest.approx(8.2, abs=0.11)  # the empty scene's best
