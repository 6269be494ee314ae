"""3D sensing: nearest points (3.8) within range, finite-difference rates."""

from __future__ import annotations

import numpy as np
import pytest

from uvnav.obstacles.bodies3d import SphereBody
from uvnav.obstacles.motion3d import ConstantMotion3D, Obstacle3D, ObstacleState3D
from uvnav.sensors.sensing3d import FiniteDifference3D, sense_obstacles3d


def _world() -> list[Obstacle3D]:
    return [
        Obstacle3D(SphereBody(1.0), ConstantMotion3D(np.array([0.2, 0, 0]), np.array([0, 0, 0.3])),
                   ObstacleState3D(np.array([5.0, 0, 0]))),
        Obstacle3D(SphereBody(0.5), ConstantMotion3D(np.zeros(3)),
                   ObstacleState3D(np.array([0.0, 3.0, 0]))),
        Obstacle3D(SphereBody(0.5), ConstantMotion3D(np.zeros(3)),
                   ObstacleState3D(np.array([0.0, 30.0, 0]))),
    ]  # fmt: skip


def test_readings_are_exact_sorted_and_range_limited() -> None:
    world = _world()
    rd = sense_obstacles3d(np.zeros(3), world, sensing_range=8.0, known=False)
    assert [r.obstacle_id for r in rd] == [1, 0]
    assert rd[0].distance == pytest.approx(2.5) and np.allclose(rd[0].nearest_point, [0, 2.5, 0])
    assert rd[1].distance == pytest.approx(4.0)
    assert np.all(rd[0].velocity == 0) and rd[0].velocity_source == "estimated"


def test_finite_differences_recover_velocity_and_rotation() -> None:
    world = _world()
    est = FiniteDifference3D(np.random.default_rng(0))
    for k in range(4):
        for ob in world:
            ob.state.velocity, ob.state.rotation_rate = ob.motion.rates(k * 0.1, ob.state)
        out = est.update(k * 0.1, sense_obstacles3d(np.zeros(3), world, sensing_range=8.0))
        for ob in world:
            ob.step(k * 0.1, 0.1)
    far = next(r for r in out if r.obstacle_id == 0)
    assert np.allclose(far.velocity, [0.2, 0, 0], atol=1e-9)
    assert np.allclose(far.rotation_rate, [0, 0, 0.3], atol=1e-9)
