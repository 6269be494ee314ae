"""Bodies from a lidar scan (:mod:`uvnav.sensors.scan_bodies`): discs where the bodies are, one
track id per body over time, and a 2D world whose law sees only them."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.controllers import make_controller
from uvnav.dynamics import UnicycleSpec
from uvnav.obstacles import ConstantVelocity, DiscBody, Obstacle, ObstacleField, ObstacleState
from uvnav.scenarios import ScenarioError, scenario_from_dict
from uvnav.sensors import lidar_scan
from uvnav.sensors.scan_bodies import ScanBodies
from uvnav.sim import EpisodeSetup, LidarConfig, SensingConfig, run_episode

POSE = np.array([0.0, 0.0, 0.0])


def _field(*discs: tuple[float, float, float]) -> ObstacleField:
    return ObstacleField.from_obstacles([Obstacle.moving_disc((x, y), r) for x, y, r in discs])


@settings(max_examples=40, deadline=None)
@given(
    st.floats(1.0, 4.0), st.floats(-math.pi, math.pi), st.floats(0.2, 0.45),
)  # fmt: skip
def test_a_disc_in_view_is_read_where_it_is(dist: float, bearing: float, radius: float) -> None:
    cx, cy = dist * math.cos(bearing), dist * math.sin(bearing)
    scan = lidar_scan(POSE, _field((cx, cy, radius)), n_rays=360, max_range=5.0)
    (rd,) = ScanBodies().readings(0.0, POSE, scan, 5.0)
    # short, never long (module docstring: the visible chord and the beams' spacing), by less
    # than 30 % of the radius plus a beam spacing at that distance (1-degree beams)
    spacing = dist * math.radians(1.0)
    assert 0.7 * radius - spacing <= rd.radius <= radius + 1e-9
    assert math.dist(rd.centre, (cx, cy)) <= 0.3 * radius + spacing
    assert rd.distance == pytest.approx(dist - radius, abs=0.03)
    assert rd.velocity_source == "estimated" and rd.radius == rd.bounding_radius


def test_bodies_keep_their_track_ids_as_they_move() -> None:
    bodies = ScanBodies()
    ids = []
    for k in range(10):  # two discs walking past each other's line of sight, 5 cm a scan
        scan = lidar_scan(
            POSE, _field((2.0, -1.0 + 0.05 * k, 0.3), (3.0, 1.0 - 0.05 * k, 0.3)), n_rays=360,
            max_range=5.0,
        )  # fmt: skip
        readings = bodies.readings(0.1 * k, POSE, scan, 5.0)
        ids.append(sorted((round(float(rd.centre[0])), rd.obstacle_id) for rd in readings))
    assert all(i == ids[0] for i in ids) and len(ids[0]) == 2
    assert bodies.readings(5.0, POSE, lidar_scan(POSE, _field(), n_rays=360), 5.0) == ()
    fresh = bodies.readings(5.1, POSE, lidar_scan(POSE, _field((2.0, 0.0, 0.3)), n_rays=360), 5.0)
    assert fresh[0].obstacle_id == 2  # the old tracks were forgotten; a new id


def test_people_side_by_side_are_two_bodies() -> None:
    scan = lidar_scan(POSE, _field((3.0, -0.31, 0.3), (3.0, 0.31, 0.3)), n_rays=360)
    assert len(ScanBodies().readings(0.0, POSE, scan, 5.0)) == 2


def test_a_law_driven_by_scan_bodies_sees_only_what_the_scan_shows() -> None:
    hidden = Obstacle(DiscBody(0.3), ObstacleState(position=np.array([6.0, 0.0])),
                      ConstantVelocity(np.zeros(2)))  # behind the first one  # fmt: skip
    front = Obstacle(DiscBody(0.5), ObstacleState(position=np.array([3.0, 0.0])),
                     ConstantVelocity(np.array([0.0, 0.2])))  # fmt: skip
    sensing = SensingConfig(sensing_range=8.0, velocities="estimated", bodies="lidar",
                            lidar=LidarConfig(n_rays=360, max_range=8.0))  # fmt: skip
    setup = EpisodeSetup(spec=UnicycleSpec(1.0, 1.0, 0.1), start=np.zeros(3),
                         goal=np.array([9.0, 0.0]), obstacles=[front, hidden], dt=0.1,
                         control_period=0.1, t_max=1.5, sensing=sensing)  # fmt: skip
    seen = []

    class Spy:
        oracle = False
        mode = "M1"
        name = "spy"

        def __init__(self) -> None:
            self.inner = make_controller("straight-v1")

        def reset(self, spec: object, goal: np.ndarray, rng: np.random.Generator) -> None:
            self.inner.reset(spec, goal, rng)

        def act(self, obs: object) -> object:
            seen.append(obs)
            return self.inner.act(obs)

    run_episode(setup, Spy(), np.random.default_rng(0), record=False)  # type: ignore[arg-type]
    first, last = seen[0].obstacles, seen[-1].obstacles
    assert len(first) == 1  # the disc behind the first one is occluded
    assert first[0].centre == pytest.approx([3.0, 0.0], abs=0.1)  # (1-degree beams: 4 cm apart)
    # the same body (one track), and its rate estimated from the scans: about (0, 0.2) m/s on
    # average (each estimate differences two fits a few cm apart)
    assert [rd.obstacle_id for rd in last] == [first[0].obstacle_id]
    rates = np.array([o.obstacles[0].velocity for o in seen[2:]])
    assert rates.mean(axis=0) == pytest.approx([0.0, 0.2], abs=0.1)


def test_a_scene_says_in_one_line_what_scan_bodies_need() -> None:
    base = {"name": "x", "robot": {"start": [0, 0], "goal": [5, 0], "v_max": 1, "u_max": 1}}
    with pytest.raises(ScenarioError, match=r"sensing\.bodies: 'lidar' needs a lidar block"):
        scenario_from_dict({**base, "sensing": {"bodies": "lidar", "velocities": "estimated"}})
    with pytest.raises(ScenarioError, match=r"sensing\.bodies: 'lidar' needs velocities: estim"):
        scenario_from_dict({**base, "sensing": {"bodies": "lidar", "lidar": {}}})
    with pytest.raises(ValueError, match="bodies sensed by lidar need a lidar"):
        SensingConfig(bodies="lidar")


def test_the_declared_centre_noise_is_what_the_fit_shows() -> None:
    """Discs of radius 0.3 m crossing a 360-beam scan with 1 cm range noise, sampled every
    0.25 s: each reading declares ``centre_std``, and the part of the fitted centre's error that
    changes from one scan to the next has about that spread per axis (what a tracker filters)."""
    rng = np.random.default_rng(3)
    changes = []
    for _ in range(80):
        start = rng.uniform(1.0, 4.0) * np.array([1.0, 0.0])
        heading = rng.uniform(-math.pi, math.pi)
        step = 0.25 * rng.uniform(0.5, 1.5) * np.array([math.cos(heading), math.sin(heading)])
        bodies, last = ScanBodies(), None
        for k in range(8):
            c = start + k * step
            if not 0.8 < math.hypot(*c) < 4.5:
                break
            scan = lidar_scan(POSE, _field((*c, 0.3)), rng, n_rays=360, noise_std=0.01)
            (rd,) = bodies.readings(0.25 * k, POSE, scan, 5.0)
            assert rd.position_std == bodies.centre_std > 0
            if last is not None:
                changes.append(rd.centre - c - last)
            last = rd.centre - c
    spread = math.sqrt(float(np.mean(np.square(changes))) / 2.0)
    assert len(changes) > 200
    assert 0.7 * ScanBodies.centre_std < spread < 1.3 * ScanBodies.centre_std
