"""The one bookkeeper (:mod:`uvnav.sim.ledger`) and the same counting rules in every world.

The contract test runs each world (2D unicycle and holonomic, 3D, Chapter 4, Chapter 5, N
robots) with an episode that starts in its goal and one whose time runs out, and refuses a
``t_max`` that is not a whole multiple of ``dt`` in each.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from uvnav.controllers.base import make_law
from uvnav.core import AgentLog, BaseProbe
from uvnav.scenarios.catalog import resolve
from uvnav.scenarios.episodes import default_law
from uvnav.sim.ledger import Clock, Ledger, decision_ratio, step_count
from uvnav.sim.run import run_episode

# ------------------------------------------------------------------------- the rules themselves


@given(st.integers(1, 100_000), st.sampled_from([0.01, 0.05, 0.1, 0.25, 0.3]))
def test_a_whole_multiple_gives_its_step_count(n: int, dt: float) -> None:
    assert step_count(n * dt, dt) == n


@pytest.mark.parametrize(("t_max", "dt"), [(1.0, 0.3), (0.0, 0.1), (0.05, 0.1), (-1.0, 0.1)])
def test_a_t_max_that_is_no_whole_multiple_is_refused(t_max: float, dt: float) -> None:
    with pytest.raises(ValueError, match="t_max must be a whole multiple of dt"):
        step_count(t_max, dt)


def test_the_clock_counts_steps_not_sums() -> None:
    clock = Clock(dt=0.1, control_period=0.3, t_max=0.9)
    due = []
    while not clock.up:
        due.append(clock.due)
        clock.tick()
    assert clock.step_index == 9 and clock.t == 9 * 0.1  # k dt, not 0.1 + 0.1 + ...
    assert due == [True, False, False] * 3
    assert decision_ratio(0.3, 0.1) == 3


def test_the_ledger_judges_collision_before_arrival() -> None:
    book = Ledger(goal_tolerance=0.5)
    assert not book.begin(clearance=1.0, goal_dist=3.0)
    assert book.judge(0.1, clearance=-0.01, goal_dist=0.1)  # both at once: a collision
    assert book.status == "collision" and book.reached_at is None
    m = book.metrics(AgentLog(), top_speed=1.0)
    assert m.collision and m.time_to_goal is None and m.min_clearance == -0.01


def test_a_start_inside_the_goal_is_a_success_at_zero() -> None:
    book = Ledger(goal_tolerance=0.5)
    assert book.begin(clearance=math.inf, goal_dist=0.2)
    m = book.metrics(AgentLog(), top_speed=1.0)
    assert m.success and m.time_to_goal == 0.0
    assert m.detour_ratio is None and m.time_ratio is None  # nothing to measure against
    assert m.min_clearance is None  # no bodies


# ------------------------------------------------------------------- every world, same rules

#: (world, a scene it runs)
WORLDS = [
    ("unicycle", "thesis-ch2-one-obstacle"),
    ("holonomic", "thesis-ch2-one-obstacle"),
    ("vehicle3d", "thesis-ch3-fig3-5-single-cycle"),
    ("uuv2d", "thesis-ch4-fig4-7-approach"),
    ("uuv3d", "thesis-ch5-scene1"),
    ("multi", "antipodal:2"),
]


class _End(BaseProbe):
    """The time [s] the episode ended at."""

    t = math.nan

    def on_end(self, world: Any, laws: Any) -> None:
        self.t = world.t


Run = Callable[[Any], tuple[str, Any, float]]


def _setup_and_runner(world: str, scene: str) -> tuple[Any, Run]:
    """The scene's setup and a function running it through the one
    :func:`~uvnav.sim.run.run_episode` with the scene's own law: ``(status, metrics of agent 0,
    end time [s])``."""
    from uvnav.scenarios.build import build_episode
    from uvnav.scenarios.ch5 import build_uuv3d
    from uvnav.scenarios.multi import build_multi

    r = resolve(scene)
    law, params = default_law(r)
    options: dict[str, Any] = {}
    if world in ("unicycle", "holonomic"):
        setup: Any = build_episode(r.scenario, 0)
        options["vehicle"] = world
        if world == "holonomic":
            law, params = "orca-holonomic-v1", {}
    else:
        setup = {
            "vehicle3d": lambda: r.scenario.build(0),
            "uuv2d": lambda: r.scenario.to_setup(),
            "uuv3d": lambda: build_uuv3d(r.scenario),
            "multi": lambda: build_multi(r.scenario, 0),
        }[world]()
    rng = r.kind.episode_rng(0)

    def run(s: Any) -> tuple[str, Any, float]:
        end = _End()
        multi = world == "multi"
        res = run_episode(s, None if multi else make_law(law, **params), rng, record=False,
                          probes=[end], **options)  # fmt: skip
        if multi:
            return res.statuses[0], res.robots[0], end.t
        return res.status, res.metrics, end.t

    return setup, run


def _with_goal_at_start(world: str, setup: Any) -> Any:
    if world == "multi":
        robot = setup.robots[0]
        robot.goal = np.asarray(robot.start, dtype=float)[:2].copy()
        return setup
    start = np.asarray(setup.start, dtype=float)
    goal = start[: len(np.asarray(setup.goal))].copy()
    return dataclasses.replace(setup, goal=goal)


@pytest.mark.parametrize(("world", "scene"), WORLDS)
def test_an_episode_that_starts_in_its_goal_is_a_success_at_zero(world: str, scene: str) -> None:
    setup, run = _setup_and_runner(world, scene)
    status, m, end = run(_with_goal_at_start(world, setup))
    assert status == "success" and m.success and not m.collision
    assert end == 0.0 or world == "multi"  # (the other robots go on)
    assert m.time_to_goal == 0.0
    assert m.path_length == 0.0 and m.detour_ratio is None and m.time_ratio is None


@pytest.mark.parametrize(("world", "scene"), WORLDS)
def test_an_episode_whose_time_runs_out_ends_exactly_at_t_max(world: str, scene: str) -> None:
    setup, run = _setup_and_runner(world, scene)
    dt = float(setup.dt)
    steps = 3 * decision_ratio(float(setup.control_period), dt)
    status, m, end = run(dataclasses.replace(setup, t_max=steps * dt))
    assert status == "timeout" and not m.success and m.time_to_goal is None
    assert end == steps * dt  # the last step ends at t_max (k dt, not a running sum)
    assert m.path_length > 0.0


@pytest.mark.parametrize(("world", "scene"), WORLDS)
def test_a_t_max_that_is_no_multiple_of_dt_is_refused_by_every_world(
    world: str, scene: str
) -> None:
    setup, run = _setup_and_runner(world, scene)
    with pytest.raises(ValueError, match="t_max must be a whole multiple of dt"):
        run(dataclasses.replace(setup, t_max=2.5 * float(setup.dt)))
