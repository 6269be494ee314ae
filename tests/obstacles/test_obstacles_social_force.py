"""Social-force pedestrians (Helbing and Molnár 1995): deterministic, the per-model and batched
paths bit for bit, pedestrians reach their goals without overlapping, and a visible robot repels
them while an invisible one does not."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from uvnav.obstacles import DiscBody, Obstacle, ObstacleBatch, ObstacleState, join_crowds
from uvnav.obstacles.social_force import (
    SocialForcePedestrian,
    social_acceleration,
)
from uvnav.scenarios import build_episode
from uvnav.scenarios.crowdnav import crowdnav_scenario


def _swap(radius: float = 2.0) -> list[Obstacle]:
    """Four pedestrians on a circle, each walking to the opposite point (not quite symmetric:
    a perfectly symmetric swap is a standstill of the social force model)."""
    out = []
    for a in (0.1, 1.9, 3.3, 4.6):
        p = radius * np.array([np.cos(a), np.sin(a)])
        out.append(
            Obstacle(DiscBody(0.3), ObstacleState(position=p), SocialForcePedestrian(goal=-p))
        )
    return out


def _run(obstacles: list[Obstacle], steps: int, batched: bool) -> np.ndarray:
    rows = []
    if batched:
        batch = ObstacleBatch(obstacles)
        for i in range(steps):
            batch.step(i * 0.1, 0.1)
            rows.append(batch.positions.copy())
        return np.array(rows)
    join_crowds(obstacles)
    for i in range(steps):
        for ob in obstacles:
            ob.state = ob.motion.step(ob.state, i * 0.1, 0.1)
        rows.append(np.array([ob.state.position for ob in obstacles]))
    return np.array(rows)


def test_batched_and_per_model_paths_agree_and_repeat() -> None:
    a = _run(_swap(), 120, batched=True)
    b = _run(_swap(), 120, batched=False)
    c = _run(_swap(), 120, batched=True)
    assert np.array_equal(a, b) and np.array_equal(a, c)


def test_pedestrians_swap_without_overlapping() -> None:
    obs = _swap()
    rows = _run(obs, 200, batched=True)
    goals = np.array([ob.motion.goal for ob in obs])  # type: ignore[attr-defined]
    assert np.all(np.hypot(*(rows[-1] - goals).T) < 0.5)  # they arrived (within 0.3 m + slack)
    for t in range(len(rows)):
        d = np.hypot(*(rows[t][:, None, :] - rows[t][None, :, :]).transpose(2, 0, 1))
        np.fill_diagonal(d, np.inf)
        assert d.min() > 0.45  # discs of 0.3 m barely touch at the worst moment


def test_the_driving_term_relaxes_to_the_preferred_velocity() -> None:
    acc = social_acceleration(
        np.zeros((1, 2)), np.array([[1.0, 0.0]]), np.array([[10.0, 0.0]]), np.ones(1),
        np.full(1, 0.3), np.array([[0.5, 7.0, 0.3, 0.3]]),
    )  # fmt: skip
    assert acc.tolist() == [[0.0, 0.0]]  # already at v0 toward the goal, nobody around


class _Standing:
    name = "standing"
    oracle = False
    mode = "M1"

    def reset(self, spec: Any, goal: np.ndarray, rng: np.random.Generator) -> None:
        pass

    def act(self, obs: Any) -> Any:
        from uvnav.dynamics.omni import VelocityCommand

        return VelocityCommand(0.0, 0.0)


@pytest.mark.parametrize("visible", [False, True])
def test_a_visible_robot_repels_an_invisible_one_does_not(visible: bool) -> None:
    from uvnav.scenarios.catalog import kinds
    from uvnav.sim.run import run_episode

    statuses = []
    for case in range(4):
        scn = crowdnav_scenario(case, human_policy="social_force", robot_visible=visible)
        setup = build_episode(scn, case)
        first = setup.obstacles[0]
        spot = first.state.position + 0.25 * (first.motion.goal - first.state.position)  # type: ignore[attr-defined]
        setup.start = np.array([spot[0], spot[1], 0.0])
        res = run_episode(
            setup, _Standing(), kinds()["nav2d"].episode_rng(case), record=False,
            vehicle="holonomic",
        )  # fmt: skip
        statuses.append(res.status)
    # invisible: the first pedestrian walks into the robot standing on its way; visible: no one
    assert statuses == (["timeout"] * 4 if visible else ["collision"] * 4)
