"""``benchmarks/oracle_crowdnav.py``: the humans ignore the invisible robot, the pre-rolled crowd
is the world's, and the oracle's search finds the obvious success of an empty scene."""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

BENCH = Path(__file__).resolve().parents[2] / "benchmarks"
if str(BENCH) not in sys.path:
    sys.path.insert(0, str(BENCH))

import oracle_crowdnav as oracle  # noqa: E402

from uvnav.controllers.base import make_law  # noqa: E402
from uvnav.core import BaseProbe  # noqa: E402
from uvnav.scenarios.build import build_episode  # noqa: E402
from uvnav.scenarios.catalog import kinds  # noqa: E402
from uvnav.sim.run import run_episode  # noqa: E402


class Crowd(BaseProbe):
    """The humans' centres and the robot's pose at every step of an episode."""

    def __init__(self) -> None:
        self.humans: list[np.ndarray] = []
        self.robot: list[np.ndarray] = []

    def on_step(self, world: Any, laws: Any) -> None:
        self.humans.append(world.bodies.centres()[0].copy())
        self.robot.append(world.pose)


def _episode(scn: Any, case: int, law: Any) -> Crowd:
    probe = Crowd()
    run_episode(build_episode(scn, case), law, kinds()["nav2d"].episode_rng(case), record=False,
                probes=[probe])  # fmt: skip
    return probe


def test_the_humans_move_alike_under_two_laws_and_as_pre_rolled() -> None:
    case = 100
    scn = oracle.scene(case, 5, 1.0, 2.0, 5)
    v2 = _episode(scn, case, make_law("zhang2019-v2"))
    turning = _episode(scn, case, oracle.Replay(np.array([[0.6, 1.5]])))
    n = min(len(v2.humans), len(turning.humans))
    assert n >= 20
    # the robots went different ways, the humans the same
    assert not np.allclose(v2.robot[n - 1], turning.robot[n - 1])
    np.testing.assert_array_equal(np.array(v2.humans[:n]), np.array(turning.humans[:n]))
    track = oracle.human_track(build_episode(scn, case))
    np.testing.assert_array_equal(track[: len(v2.humans)], np.array(v2.humans))


def test_the_search_finds_the_straight_run_of_an_empty_scene() -> None:
    case = 100
    scn = oracle.scene(case, 0, 1.0, 2.0, 5)
    c = oracle.oracle_case(scn, case)
    t, cmds = oracle.search(c)
    assert t is not None and cmds is not None
    # 7.7 m to the goal's edge at 1 m/s after a 1 s ramp from rest: 8.2 s at best
    assert t == pytest.approx(8.2, abs=0.11)
    status, arrival = oracle.replay(scn, case, cmds)
    assert status == "success" and arrival == pytest.approx(t)


def test_a_contact_between_the_samples_is_a_collision() -> None:
    human = np.array([[0.0, 0.5]])
    reach2 = np.array([0.6**2])
    passing = oracle._swept_hit(np.array([[-1.0, 0.0]]), np.array([[1.0, 0.0]]), human, human,
                                reach2)  # fmt: skip
    clear = oracle._swept_hit(np.array([[-1.0, -0.2]]), np.array([[1.0, -0.2]]), human, human,
                              reach2)  # fmt: skip
    assert passing.tolist() == [True] and clear.tolist() == [False]


def test_a_case_with_no_way_out_survives_no_time() -> None:
    c = oracle.oracle_case(oracle.scene(100, 0, 1.0, 2.0, 5), 100)
    # a wall of humans standing on the robot's start
    x, y, _ = c.start
    centres = np.tile(np.array([[x, y + 0.1]]), (c.steps + 1, 1, 1))
    boxed = oracle.Case(centres, np.array([0.3]), c.spec, c.start, c.goal, c.tolerance, c.dt,
                        c.ratio)  # fmt: skip
    assert oracle.search(boxed) == (None, None)
    assert oracle.survives(boxed, 2.0) == 0.0


def test_the_clearance_keeps_the_oracle_off_a_human_it_could_pass_close_to() -> None:
    c = oracle.oracle_case(oracle.scene(100, 0, 1.0, 2.0, 5), 100)
    # one human standing 0.7 m beside the straight run: 0.1 m of room at the closest
    centres = np.tile(np.array([[0.7, 0.0]]), (c.steps + 1, 1, 1))
    beside = oracle.Case(centres, np.array([0.3]), c.spec, c.start, c.goal, c.tolerance, c.dt,
                         c.ratio)  # fmt: skip
    close, _ = oracle.search(beside)
    wide, _ = oracle.search(dataclasses.replace(beside, clearance=0.5))  # 0.4 m out of its way
    assert close is not None and close == pytest.approx(8.2, abs=0.11)
    assert wide is not None and wide > close
