"""3D obstacle motion: exact rigid motion, AR and periodic motion within (3.9)-(3.10),
determinism."""

from __future__ import annotations

import numpy as np
import pytest

from uvnav.geometry.frames3d import rotation_from_vector
from uvnav.obstacles.bodies3d import SphereBody
from uvnav.obstacles.motion3d import (
    ARMotion3D,
    ConstantMotion3D,
    Obstacle3D,
    ObstacleState3D,
    PeriodicMotion3D,
    Waypoints3D,
)


def test_constant_motion_is_exact_rigid_motion() -> None:
    u = np.array([0.0, 0.1, 0.2])
    ob = Obstacle3D(SphereBody(1.0), ConstantMotion3D(np.array([0.1, 0.2, -0.3]), u),
                    ObstacleState3D(np.zeros(3)))  # fmt: skip
    for k in range(200):
        ob.step(k * 0.05, 0.05)
    assert np.allclose(ob.state.centre, np.array([0.1, 0.2, -0.3]) * 10.0)
    assert np.allclose(ob.state.rotation, rotation_from_vector(u * 10.0), atol=1e-12)
    assert np.allclose(ob.state.rotation @ ob.state.rotation.T, np.eye(3), atol=1e-12)


def test_ar_motion_obeys_its_bounds_is_slowly_varying_and_deterministic() -> None:
    def run(seed: int) -> np.ndarray:
        m = ARMotion3D(rng=np.random.default_rng(seed), v_mean=np.array([0.3, 0.0, 0.0]),
                       v_sigma=0.2, v_min=0.05, v_max=0.45, u_mean=np.array([0, 0, 0.1]),
                       u_sigma=0.2, u_max=0.25)  # fmt: skip
        st = ObstacleState3D(np.zeros(3))
        out = []
        for k in range(400):
            v, u = m.rates(k * 0.25, st)
            out.append(np.r_[v, u])
        return np.array(out)

    a = run(1)
    speeds = np.linalg.norm(a[:, :3], axis=1)
    assert speeds.max() <= 0.45 + 1e-12 and speeds.min() >= 0.05 - 1e-12  # (3.9)
    assert np.linalg.norm(a[:, 3:], axis=1).max() <= 0.25 + 1e-12  # (3.10)
    # held constant within each 1 s period (4 samples of 0.25 s)
    assert np.allclose(a[0:4], a[0])
    assert np.array_equal(a, run(1)) and not np.array_equal(a, run(2))


def test_waypoints_go_back_and_forth() -> None:
    ob = Obstacle3D(SphereBody(0.5), Waypoints3D(np.array([[0.0, 0, 0], [2.0, 0, 0]]), 0.5),
                    ObstacleState3D(np.zeros(3)))  # fmt: skip
    xs = []
    for k in range(200):
        ob.step(k * 0.05, 0.05)
        xs.append(ob.state.centre[0])
    assert max(xs) == pytest.approx(2.0, abs=0.03) and min(xs[100:]) < 0.05


def test_periodic_motion_without_noise_is_the_sampled_sinusoid_held_per_period() -> None:
    mean, ac, as_ = np.array([0.2, 0, 0]), np.array([0, 0.1, 0]), np.array([0, 0, 0.1])
    m = PeriodicMotion3D(mean, ac, as_, osc_period=8.0, phase=0.3)
    st = ObstacleState3D(np.zeros(3))
    for k in range(40):
        a = 2 * np.pi / 8.0 * k + 0.3
        want = mean + np.cos(a) * ac + np.sin(a) * as_
        for frac in (0.0, 0.45, 0.95):  # held within the 1 s period
            v, u = m.rates(k + frac, st)
            assert np.allclose(v, want, atol=1e-12) and np.array_equal(u, np.zeros(3))
    # a circle (equal orthogonal amplitudes perpendicular to the mean): constant speed
    assert np.linalg.norm(m.rates(40.0, st)[0]) == pytest.approx(np.hypot(0.2, 0.1))


def test_periodic_motion_with_noise_is_bounded_and_deterministic() -> None:
    def run(seed: int) -> np.ndarray:
        m = PeriodicMotion3D(np.array([0.35, 0, 0]), np.array([0, 0.3, 0]), np.zeros(3),
                             osc_period=6.0, v_max=0.45, damping=0.98, v_sigma=0.1,
                             rng=np.random.default_rng(seed))  # fmt: skip
        st = ObstacleState3D(np.zeros(3))
        return np.array([m.rates(k * 0.25, st)[0] for k in range(400)])

    a = run(1)
    assert np.linalg.norm(a, axis=1).max() <= 0.45 + 1e-12  # (3.9)
    assert np.allclose(a[0:4], a[0]) and not np.allclose(a[4], a[0])
    assert np.array_equal(a, run(1)) and not np.array_equal(a, run(2))
    with pytest.raises(ValueError, match="rng"):
        PeriodicMotion3D(np.zeros(3), np.zeros(3), np.zeros(3), 6.0, v_sigma=0.1)
    with pytest.raises(ValueError, match="damping"):
        PeriodicMotion3D(np.zeros(3), np.zeros(3), np.zeros(3), 6.0, damping=1.5)
