"""ORCA pedestrians (:mod:`uvnav.obstacles.crowd`): one crowd per id, deterministic, the per-model
and batched paths bit for bit equal, pedestrians reaching their goals without overlapping."""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvnav.obstacles import (
    DiscBody,
    Obstacle,
    ObstacleBatch,
    ObstacleState,
    OrcaPedestrian,
    join_crowds,
)
from uvnav.obstacles.crowd import Crowd, preferred_velocity

pytest.importorskip("pyrvo")

DT = 0.25


def _circle(n: int = 5, radius: float = 4.0, seed: int = 0, **kw: object) -> list[Obstacle]:
    """n pedestrians on a circle (jittered, so that no symmetry deadlocks ORCA), goals opposite."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(n):
        a = 2.0 * math.pi * k / n + rng.uniform(-0.2, 0.2)
        p = radius * np.array([math.cos(a), math.sin(a)]) + rng.uniform(-0.3, 0.3, 2)
        out.append(Obstacle(DiscBody(0.3), ObstacleState(p), OrcaPedestrian(-p, **kw), f"p{k}"))  # type: ignore[arg-type]
    return out


def _per_model(obstacles: list[Obstacle], steps: int, dt: float = DT) -> np.ndarray:
    join_crowds(obstacles)
    traj = []
    for i in range(steps):
        for ob in obstacles:
            ob.state = ob.motion.step(ob.state, i * dt, dt)
        traj.append([np.r_[ob.state.position, ob.state.velocity] for ob in obstacles])
    return np.array(traj)


def _batched(obstacles: list[Obstacle], steps: int, dt: float = DT) -> np.ndarray:
    batch = ObstacleBatch(obstacles)
    traj = []
    for i in range(steps):
        batch.step(i * dt, dt)
        traj.append(np.c_[batch.positions, batch.velocities])
    batch.write_back()
    return np.array(traj)


def test_preferred_velocity_is_crowdnavs_rule() -> None:
    assert preferred_velocity(np.zeros(2), np.array([0.0, 3.0]), 1.0) == (0.0, 1.0)
    assert preferred_velocity(np.zeros(2), np.array([0.3, -0.4]), 1.0) == (0.3, -0.4)
    assert preferred_velocity(np.ones(2), np.ones(2), 1.0) == (0.0, 0.0)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_per_model_and_batched_paths_agree_bit_for_bit(seed: int) -> None:
    a = _per_model(_circle(seed=seed), 60)
    b_obs = _circle(seed=seed)
    b = _batched(b_obs, 60)
    assert np.array_equal(a, b)
    # write_back leaves the obstacles as the per-model loop would
    assert np.array_equal(np.array([o.state.position for o in b_obs]), a[-1, :, :2])


def test_batched_with_other_obstacles_in_between() -> None:
    peds = _circle(4, seed=5)
    mixed = [peds[0], Obstacle.moving_disc((9.0, 9.0), 0.5, (0.1, 0.0)), *peds[1:]]
    b = _batched(mixed, 40)
    a = _per_model(_circle(4, seed=5), 40)
    assert np.array_equal(b[:, [0, 2, 3, 4]], a)


def test_deterministic() -> None:
    assert np.array_equal(_batched(_circle(seed=3), 50), _batched(_circle(seed=3), 50))


def test_pedestrians_reach_their_goals_without_overlap() -> None:
    obs = _circle(6, seed=4)
    traj = _batched(obs, 120)
    pos = traj[:, :, :2]
    gaps = np.hypot(*(pos[:, :, None, :] - pos[:, None, :, :]).transpose(3, 0, 1, 2))
    n = len(obs)
    gaps[:, np.arange(n), np.arange(n)] = np.inf
    # RVO2's radius is 0.3 + 0.01 m, in float32: the discs (0.6 m apart) never overlap
    assert gaps.min() >= 0.6
    speeds = np.hypot(traj[:, :, 2], traj[:, :, 3])
    assert speeds.max() <= 1.0 + 1e-6  # v_pref is ORCA's max speed
    for j, ob in enumerate(obs):
        assert math.hypot(*(pos[-1, j] - ob.motion.goal)) < 0.05  # type: ignore[attr-defined]
        # progress toward the goal from the start
        start = pos[0, j] - traj[0, j, 2:] * DT
        goal = ob.motion.goal  # type: ignore[attr-defined]
        assert math.hypot(*(pos[10, j] - goal)) < math.hypot(*(start - goal)) - 1.0


def test_pedestrians_stop_at_goal() -> None:
    obs = [Obstacle(DiscBody(0.3), ObstacleState(np.zeros(2)), OrcaPedestrian(np.array([2.0, 0])))]
    traj = _batched(obs, 80)
    assert abs(traj[-1, 0, 0] - 2.0) < 1e-3 and abs(traj[-1, 0, 2]) < 1e-2


def test_crowd_ids_and_decision_period() -> None:
    obs = _circle(4, seed=1)
    obs += [
        Obstacle(DiscBody(0.3), ObstacleState(np.array([20.0, 0.0])),
                 OrcaPedestrian(np.array([25.0, 0.0]), crowd_id="other")),
    ]  # fmt: skip
    crowds = join_crowds(obs)
    assert [len(c) for c in crowds] == [4, 1]
    assert join_crowds(obs) == []  # already joined
    # a 0.25 s decision period integrated at 0.05 s: velocities held for 5 steps
    slow = _circle(3, seed=2, period=0.25)
    traj = _batched(slow, 20, dt=0.05)
    crowd = slow[0].motion.crowd  # type: ignore[attr-defined]
    assert isinstance(crowd, Crowd) and crowd.decisions == 4
    assert np.array_equal(traj[1:5, :, 2:], np.repeat(traj[:1, :, 2:], 4, axis=0))


def test_unjoined_model_refuses_to_step() -> None:
    m = OrcaPedestrian(np.array([1.0, 0.0]))
    with pytest.raises(RuntimeError, match="join_crowds"):
        m.step(ObstacleState(np.zeros(2)), 0.0, DT)
    with pytest.raises(ValueError, match="v_pref"):
        OrcaPedestrian(np.zeros(2), v_pref=0.0)
    with pytest.raises(ValueError, match="one decision period"):
        join_crowds(_circle(2, period=0.25) + _circle(1, period=0.5))
