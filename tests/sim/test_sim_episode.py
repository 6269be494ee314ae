"""Behaviour of the 2D step loop: goal reaching, collisions, determinism, decision rate, metrics.

Every episode is built by hand from :mod:`uvnav.obstacles` and :mod:`uvnav.sim` and run with the
registered ``straight-v1`` law (or a probe that wraps it).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import fields
from typing import Any, ClassVar

import numpy as np
import pytest

from uvnav.controllers import make_controller
from uvnav.dynamics import UnicycleCommand, UnicycleSpec
from uvnav.obstacles import (
    ConstantVelocity,
    DiscBody,
    Obstacle,
    ObstacleField,
    ObstacleState,
    PolygonBody,
    RandomTurn,
    Waypoints,
)
from uvnav.sensors import Observation, sense_obstacles
from uvnav.sim import (
    METRIC_NAMES,
    EpisodeResult,
    EpisodeSetup,
    LidarConfig,
    SensingConfig,
    Trajectory,
    run_episode,
)

SPEC = UnicycleSpec(v_max=0.707, u_max=1.414, radius=0.1)
START = np.array([0.0, 0.0, math.pi / 4])
GOAL = np.array([10.0, 10.0])
ARROW = np.array([[-0.6, -0.4], [0.7, -0.5], [0.2, 0.1], [0.6, 0.6], [-0.5, 0.5]])


def _static(body: DiscBody | PolygonBody, x: float, y: float, heading: float = 0.0) -> Obstacle:
    return Obstacle(
        body,
        ObstacleState(position=np.array([x, y]), heading=heading),
        ConstantVelocity(np.zeros(2)),
    )


def _setup(obstacles: list[Obstacle], **kw: Any) -> EpisodeSetup:
    args: dict[str, Any] = {
        "spec": SPEC,
        "start": START.copy(),
        "goal": GOAL.copy(),
        "obstacles": obstacles,
    }
    args.update(kw)
    return EpisodeSetup(**args)


RESPONSIBLE = ("robot", "pedestrian", "obstacle")


def _metrics_are_clean(res: EpisodeResult) -> None:
    d = res.metrics.to_dict()
    assert tuple(d) == METRIC_NAMES
    for name, value in d.items():
        if name == "collision_by":
            assert value in ((None,) if not res.metrics.collision else RESPONSIBLE), value
            continue
        assert value is None or isinstance(value, bool | int) or math.isfinite(value), (
            f"{name} = {value!r}"
        )
    assert res.status in {"success", "collision", "timeout"}
    assert res.metrics.success == (res.status == "success")
    assert res.metrics.collision == (res.status == "collision")


class Probe:
    """Wraps a controller: records every observation, optionally scales speed / cycles modes."""

    name: ClassVar[str] = "probe"

    def __init__(
        self, inner: Any, *, v_scale: float = 1.0, modes: tuple[str, ...] = ("M1",)
    ) -> None:
        self.inner = inner
        self.v_scale = v_scale
        self.modes = modes
        self.seen: list[Observation] = []

    @property
    def oracle(self) -> bool:
        return bool(self.inner.oracle)

    @oracle.setter
    def oracle(self, value: bool) -> None:
        self.inner.oracle = value

    @property
    def mode(self) -> str:
        return self.modes[(len(self.seen) - 1) % len(self.modes)]

    def reset(self, spec: UnicycleSpec, goal: np.ndarray, rng: np.random.Generator) -> None:
        self.seen.clear()
        self.inner.reset(spec, goal, rng)

    def act(self, obs: Observation) -> UnicycleCommand:
        self.seen.append(obs)
        cmd = self.inner.act(obs)
        return UnicycleCommand(cmd.v * self.v_scale, cmd.u)


class ConstantCommand:
    name: ClassVar[str] = "constant"
    oracle = False
    mode = "M1"

    def __init__(self, v: float, u: float) -> None:
        self.cmd = UnicycleCommand(v, u)

    def reset(self, spec: UnicycleSpec, goal: np.ndarray, rng: np.random.Generator) -> None:
        pass

    def act(self, obs: Observation) -> UnicycleCommand:
        return self.cmd


def test_empty_world_straight_line_reaches_goal() -> None:
    res = run_episode(_setup([]), make_controller("straight-v1"), np.random.default_rng(0))
    _metrics_are_clean(res)
    m = res.metrics
    dist = float(np.hypot(*GOAL))
    assert res.status == "success" and m.success and not m.collision
    # straight at V_max: it stops on entering the tolerance disc, within one step of its rim
    step = SPEC.v_max * 0.1
    assert dist - 0.2 - 1e-9 <= m.path_length <= dist - 0.2 + step
    assert m.time_to_goal == pytest.approx((dist - 0.2) / SPEC.v_max, abs=0.1 + 1e-9)
    assert m.detour_ratio is not None and m.detour_ratio > 0.98  # exact value: see next test
    assert m.limit_violations == 0 and m.mode_switches == 0
    assert m.min_clearance is None  # no obstacle: no clearance (None, never inf/NaN/sentinel)
    traj = res.trajectory
    assert traj is not None
    assert np.hypot(*(traj.robot[-1, :2] - GOAL)) <= 0.2
    # every sample lies on the start-goal diagonal
    assert np.allclose(traj.robot[:, 0], traj.robot[:, 1], atol=1e-9)


def test_detour_ratio_respects_physical_limit() -> None:
    """DESIGN §4: 'detour ratio ... 1.0 is the physical limit'; the straight law must not beat it.

    The robot stops within ``goal_tolerance`` of T, so the shortest possible path is
    ``|T - I| - goal_tolerance``; dividing by ``|T - I|`` reports 0.986 for a perfect straight run.
    """
    res = run_episode(
        _setup([], goal_tolerance=0.5), make_controller("straight-v1"), np.random.default_rng(0)
    )
    assert res.status == "success"
    assert res.metrics.detour_ratio is not None
    assert 1.0 - 1e-9 <= res.metrics.detour_ratio <= 1.0 + 0.1 / 14.0
    assert res.metrics.time_ratio is not None and res.metrics.time_ratio >= 1.0 - 1e-9


def test_static_disc_on_the_line_causes_collision() -> None:
    disc = _static(DiscBody(0.5), 5.0, 5.0)
    res = run_episode(_setup([disc]), make_controller("straight-v1"), np.random.default_rng(0))
    _metrics_are_clean(res)
    assert res.status == "collision" and res.metrics.collision and not res.metrics.success
    assert res.metrics.min_clearance < 0
    assert res.metrics.detour_ratio is None and res.metrics.time_to_goal is None
    traj = res.trajectory
    assert traj is not None
    # it stops at the first step whose disc overlaps: within one step of first contact
    hit_at = math.hypot(5, 5) - 0.5 - SPEC.radius
    assert hit_at <= res.metrics.path_length <= hit_at + SPEC.v_max * 0.1
    assert traj.clearance[-1] < 0 <= traj.clearance[-2]
    assert traj.nearest_id[-1] == 0


def test_static_polygon_on_the_line_causes_collision() -> None:
    poly = _static(PolygonBody.from_vertices(ARROW), 5.0, 5.0, heading=0.4)
    res = run_episode(_setup([poly]), make_controller("straight-v1"), np.random.default_rng(0))
    assert res.status == "collision" and res.metrics.min_clearance < 0


@pytest.mark.parametrize(
    "body", [DiscBody(0.5), PolygonBody.from_vertices(ARROW)], ids=["disc", "polygon"]
)
def test_point_robot_entering_an_obstacle_collides(body: DiscBody | PolygonBody) -> None:
    """A robot of radius 0 that drives through an obstacle must collide (-0.0 is not a gap)."""
    spec = UnicycleSpec(v_max=0.707, u_max=1.414, radius=0.0)
    res = run_episode(
        _setup([_static(body, 5.0, 5.0)], spec=spec),
        make_controller("straight-v1"),
        np.random.default_rng(0),
    )
    assert res.status == "collision"
    assert res.metrics.min_clearance < 0


def test_disc_beside_the_line_is_passed_with_analytic_clearance() -> None:
    # centre 1 m off the diagonal: clearance = 1 - 0.5 - 0.1 = 0.4 m
    c = np.array([5.0, 5.0]) + np.array([1.0, -1.0]) / math.sqrt(2.0)
    res = run_episode(
        _setup([_static(DiscBody(0.5), *c)]),
        make_controller("straight-v1"),
        np.random.default_rng(0),
    )
    _metrics_are_clean(res)
    assert res.status == "success"
    assert res.metrics.min_clearance == pytest.approx(0.4, abs=1e-3)


def test_starting_in_collision_and_at_goal() -> None:
    res = run_episode(
        _setup([_static(DiscBody(1.0), 0.5, 0.0)]),
        make_controller("straight-v1"),
        np.random.default_rng(0),
    )
    assert res.status == "collision" and res.metrics.path_length == 0.0
    res = run_episode(
        _setup([], goal=np.array([0.05, 0.05])),
        make_controller("straight-v1"),
        np.random.default_rng(0),
    )
    assert res.status == "success" and res.metrics.time_to_goal == 0.0
    _metrics_are_clean(res)


def _moving_world(seed: int) -> EpisodeSetup:
    """Chapter-2 like scene; the obstacles' generators derive from the episode seed."""
    rng = np.random.default_rng(seed)
    obstacles = []
    for j in range(4):
        body: DiscBody | PolygonBody = DiscBody(0.4) if j % 2 else PolygonBody.from_vertices(ARROW)
        pos = np.array([2.0 + 2.0 * j, 3.0 + 1.5 * j])
        motion = RandomTurn(speed=(0.1, 0.4), turn_rate=(-0.3, 0.3), rng=rng.spawn(1)[0], spin=0.1)
        obstacles.append(Obstacle(body, ObstacleState(position=pos, heading=0.3 * j), motion))
    sensing = SensingConfig(
        sensing_range=4.0,
        velocities="estimated",
        position_noise=0.01,
        lidar=LidarConfig(n_rays=36, noise_std=0.02, dropout=0.1),
    )
    return _setup(obstacles, t_max=25.0, sensing=sensing)


def test_same_seed_same_trajectory_bit_for_bit() -> None:
    def once(seed: int) -> tuple[EpisodeResult, list[Observation]]:
        probe = Probe(make_controller("straight-v1"))
        return run_episode(_moving_world(seed), probe, np.random.default_rng(seed)), probe.seen

    (a, seen_a), (b, seen_b), (c, _) = once(3), once(3), once(4)
    ta, tb, tc = a.trajectory, b.trajectory, c.trajectory
    assert ta is not None and tb is not None and tc is not None
    for f in fields(Trajectory):
        va, vb = getattr(ta, f.name), getattr(tb, f.name)
        if isinstance(va, np.ndarray):
            assert va.dtype == vb.dtype and np.array_equal(va, vb), f.name
        elif f.name == "obstacle_shapes":
            assert all(np.array_equal(x, y) for x, y in zip(va, vb, strict=True))
        else:
            assert va == vb, f.name
    da, db = a.metrics.to_dict(), b.metrics.to_dict()
    for name in METRIC_NAMES:
        if not name.startswith("decision_us"):
            assert da[name] == db[name], name
    # sensing noise and lidar dropout are part of what must replay
    assert len(seen_a) == len(seen_b)
    for oa, ob in zip(seen_a, seen_b, strict=True):
        assert oa.lidar is not None and ob.lidar is not None
        assert np.array_equal(oa.lidar.ranges, ob.lidar.ranges, equal_nan=True)
        assert [r.velocity.tolist() for r in oa.obstacles] == [
            r.velocity.tolist() for r in ob.obstacles
        ]
    assert any(np.isnan(o.lidar.ranges).any() for o in seen_a if o.lidar is not None)
    # a different seed gives a different world
    assert not np.array_equal(
        ta.obstacle_centres[: len(tc.times)], tc.obstacle_centres[: len(ta.times)]
    )


@pytest.mark.parametrize(("control_period", "expected_calls"), [(0.1, 100), (0.5, 20), (1.0, 10)])
def test_controller_called_every_control_period(control_period: float, expected_calls: int) -> None:
    setup = _setup(
        [], goal=np.array([1000.0, 1000.0]), t_max=10.0, dt=0.1, control_period=control_period
    )
    probe = Probe(make_controller("straight-v1"))
    res = run_episode(setup, probe, np.random.default_rng(0))
    assert res.status == "timeout"
    assert len(probe.seen) == expected_calls == len(res.decision_us)
    times = np.array([o.time for o in probe.seen])
    assert times == pytest.approx(np.arange(expected_calls) * control_period)
    # the integration still runs at dt
    assert res.trajectory is not None
    assert len(res.trajectory.times) == 101
    assert np.diff(res.trajectory.times) == pytest.approx(np.full(100, 0.1))
    _metrics_are_clean(res)


def test_limit_violations_are_counted_and_the_command_saturated() -> None:
    setup = _setup([], goal=np.array([1000.0, 1000.0]), t_max=5.0, control_period=0.5)
    res = run_episode(
        setup, Probe(make_controller("straight-v1"), v_scale=2.0), np.random.default_rng(0)
    )
    assert res.metrics.limit_violations == 10
    assert res.trajectory is not None
    assert np.all(res.trajectory.commands[:, 0] <= SPEC.v_max)
    assert res.metrics.path_length == pytest.approx(SPEC.v_max * 5.0)
    res_ok = run_episode(setup, Probe(make_controller("straight-v1")), np.random.default_rng(0))
    assert res_ok.metrics.limit_violations == 0


def test_control_effort_and_mode_switches() -> None:
    setup = _setup([], goal=np.array([1000.0, 0.0]), t_max=4.0, start=np.zeros(3))
    res = run_episode(setup, ConstantCommand(0.5, 0.2), np.random.default_rng(0))
    # integral of u^2 dt over 4 s; the speed is constant after the first decision
    assert res.metrics.control_effort == pytest.approx(0.2**2 * 4.0)
    probe = Probe(make_controller("straight-v1"), modes=("M1", "M1", "M2"))
    res = run_episode(setup, probe, np.random.default_rng(0))
    # modes M1 M1 M2 M1 M1 M2 ...: two switches per period of three decisions
    n = len(probe.seen)
    modes = [("M1", "M1", "M2")[i % 3] for i in range(n)]
    assert res.metrics.mode_switches == sum(a != b for a, b in itertools.pairwise(modes))


def test_velocities_known_estimated_and_oracle() -> None:
    def first_reading_sources(velocities: str, oracle: bool) -> set[str]:
        ob = Obstacle(
            DiscBody(0.3),
            ObstacleState(position=np.array([3.0, 0.0]), velocity=np.array([0.0, 0.2])),
            ConstantVelocity(np.array([0.0, 0.2])),
        )
        setup = _setup(
            [ob],
            start=np.array([0.0, -3.0, 0.0]),
            t_max=1.0,
            sensing=SensingConfig(velocities=velocities),
        )  # type: ignore[arg-type]
        probe = Probe(make_controller("straight-v1", oracle=oracle))
        run_episode(setup, probe, np.random.default_rng(0))
        return {r.velocity_source for o in probe.seen for r in o.obstacles}

    assert first_reading_sources("known", False) == {"known"}
    assert first_reading_sources("estimated", False) == {"estimated"}
    assert first_reading_sources("estimated", True) == {"known"}


def test_collision_checked_at_every_integration_step() -> None:
    """An obstacle sweeping across the robot between two decisions is still caught."""
    sweeper = Obstacle(
        DiscBody(0.3),
        ObstacleState(position=np.array([1.5, -3.0])),  # crosses y = 0 at t = 1 s
        Waypoints(points=np.array([[1.5, 3.0]]), speed=3.0),
    )
    setup = _setup(
        [sweeper],
        start=np.array([1.0, 0.0, 0.0]),
        goal=np.array([20.0, 0.0]),
        control_period=5.0,
        t_max=10.0,
    )
    res = run_episode(setup, ConstantCommand(0.3, 0.0), np.random.default_rng(0))
    assert res.status == "collision"
    assert res.trajectory is not None and res.trajectory.times[-1] < 5.0


def test_record_off_gives_same_metrics() -> None:
    a = run_episode(
        _moving_world(1), make_controller("straight-v1"), np.random.default_rng(1), record=True
    )
    b = run_episode(
        _moving_world(1), make_controller("straight-v1"), np.random.default_rng(1), record=False
    )
    assert b.trajectory is None
    for name in METRIC_NAMES:
        if not name.startswith("decision_us"):
            assert a.metrics.to_dict()[name] == b.metrics.to_dict()[name]
    _metrics_are_clean(a)


@pytest.mark.parametrize(
    ("dt", "control_period"), [(0.1, 0.15), (0.1, 0.05), (0.1, 0.0), (0.1, 0.1000001), (0.0, 0.1)]
)
def test_control_period_must_be_a_multiple_of_dt(dt: float, control_period: float) -> None:
    setup = _setup([], dt=dt, control_period=control_period)
    with pytest.raises(ValueError, match=r"multiple of dt|dt must be"):
        run_episode(setup, make_controller("straight-v1"), np.random.default_rng(0))


def test_control_period_multiple_within_rounding_is_accepted() -> None:
    setup = _setup([], dt=0.1, control_period=0.30000000000000004, t_max=3.0)
    probe = Probe(make_controller("straight-v1"))
    run_episode(setup, probe, np.random.default_rng(0))
    assert len(probe.seen) == 10


def _crowd(seed: int, k: int = 30) -> EpisodeSetup:
    """Many wandering polygons and discs across the robot's path (culling, sensing, collisions)."""
    rng = np.random.default_rng(seed)
    obstacles = []
    for j in range(k):
        body: DiscBody | PolygonBody = (
            DiscBody(0.25) if j % 4 == 0 else PolygonBody.from_vertices(0.5 * ARROW)
        )
        pos = rng.uniform(1.0, 11.0, 2)
        motion = RandomTurn(
            speed=(0.05, 0.3),
            turn_rate=(-0.4, 0.4),
            rng=rng.spawn(1)[0],
            spin=0.1,
            arena=(0.0, 0.0, 12.0, 12.0),
        )
        obstacles.append(Obstacle(body, ObstacleState(position=pos, heading=0.7 * j), motion))
    return _setup(obstacles, t_max=30.0, sensing=SensingConfig(sensing_range=3.0))


@pytest.mark.parametrize(("seed", "k"), [(s, k) for s in range(6) for k in (6, 30)])
def test_record_off_gives_same_metrics_and_observations_in_a_crowd(seed: int, k: int) -> None:
    """Unrecorded runs skip the clearance of steps that cannot lower its minimum: nothing a
    caller can see may change (collisions and successes both occur over these seeds)."""
    runs = []
    for record in (True, False):
        probe = Probe(make_controller("straight-v1"))
        res = run_episode(_crowd(seed, k), probe, np.random.default_rng(seed), record=record)
        runs.append((res, probe.seen))
    (a, seen_a), (b, seen_b) = runs
    assert a.status == b.status
    for name in METRIC_NAMES:
        if not name.startswith("decision_us"):
            assert a.metrics.to_dict()[name] == b.metrics.to_dict()[name], name
    assert a.trajectory is not None
    # the minimum along the steps, at most the least sampled one
    assert a.metrics.min_clearance <= float(np.min(a.trajectory.clearance))
    assert len(seen_a) == len(seen_b)
    for oa, ob in zip(seen_a, seen_b, strict=True):
        assert [r.obstacle_id for r in oa.obstacles] == [r.obstacle_id for r in ob.obstacles]
        for ra, rb in zip(oa.obstacles, ob.obstacles, strict=True):
            assert ra.distance == rb.distance
            assert np.array_equal(ra.nearest_point, rb.nearest_point)
            assert np.array_equal(ra.outline, rb.outline)


def test_crowd_observations_equal_fresh_unculled_sensing() -> None:
    """What the controller is given equals sensing a freshly built field from the recorded poses
    (no cull, no cache), reading for reading."""
    setup = _crowd(3)
    bodies = [o.body for o in setup.obstacles]
    probe = Probe(make_controller("straight-v1"))
    res = run_episode(setup, probe, np.random.default_rng(3))
    traj = res.trajectory
    assert traj is not None and len(probe.seen) > 10
    seen_any = False
    for i, obs in enumerate(probe.seen):
        assert traj.times[i] == obs.time
        world = [
            Obstacle(
                body,
                ObstacleState(
                    position=traj.obstacle_centres[i, j],
                    heading=float(traj.obstacle_headings[i, j]),
                    velocity=traj.obstacle_velocities[i, j],
                    angular_velocity=float(traj.obstacle_omegas[i, j]),
                ),
                ConstantVelocity(np.zeros(2)),
            )
            for j, body in enumerate(bodies)
        ]
        expect = sense_obstacles(
            obs.position, ObstacleField.from_obstacles(world), sensing_range=3.0
        )
        assert len(expect) == len(obs.obstacles)
        for r, e in zip(obs.obstacles, expect, strict=True):
            seen_any = True
            assert r.obstacle_id == e.obstacle_id and r.distance == e.distance
            for name in ("nearest_point", "centre", "velocity", "outline"):
                assert np.array_equal(getattr(r, name), getattr(e, name)), name
            assert r.angular_velocity == e.angular_velocity and r.radius == e.radius
    assert seen_any


def test_final_obstacle_states_are_left_on_the_setup() -> None:
    """run_episode advances the obstacles in place, as the per-obstacle loop did."""
    setup = _crowd(1)
    reference = _crowd(1)
    res = run_episode(setup, make_controller("straight-v1"), np.random.default_rng(1))
    assert res.trajectory is not None
    n_steps = len(res.trajectory.times) - 1
    for i in range(n_steps):
        for ob in reference.obstacles:
            ob.state = ob.motion.step(ob.state, i * setup.dt, setup.dt)
    for ob, ref in zip(setup.obstacles, reference.obstacles, strict=True):
        assert np.array_equal(ob.state.position, ref.state.position)
        assert ob.state.heading == ref.state.heading
        assert np.array_equal(ob.state.velocity, ref.state.velocity)
        assert ob.state.angular_velocity == ref.state.angular_velocity
        assert ob.motion.course == ref.motion.course  # type: ignore[attr-defined]
    j = int(res.trajectory.nearest_id[-1])
    assert np.array_equal(res.trajectory.obstacle_centres[-1, j], setup.obstacles[j].state.position)


def test_a_turn_then_move_unicycle_turns_at_the_decision_then_goes_straight() -> None:
    """CrowdNav's unicycle (``kinematics='turn-then-move'``): a held (v, u) turns the robot by
    u T when the decision is taken, then moves it straight for the rest of the period."""
    spec = UnicycleSpec(v_max=1.0, u_max=2.0, radius=0.1, kinematics="turn-then-move")
    setup = _setup(
        [], spec=spec, start=np.zeros(3), goal=np.array([50.0, 0.0]), dt=0.05,
        control_period=0.25, t_max=0.5,
    )  # fmt: skip

    class Turning(Probe):
        def act(self, obs: Observation) -> UnicycleCommand:
            self.seen.append(obs)
            return UnicycleCommand(1.0, 2.0)

    res = run_episode(setup, Turning(make_controller("straight-v1")), np.random.default_rng(0))
    tr = res.trajectory
    assert tr is not None
    heading = tr.robot[:, 2]
    # after the first step of each period the heading holds: u T = 0.5 rad per decision
    np.testing.assert_allclose(heading[1:6], 0.5, atol=1e-12)
    np.testing.assert_allclose(heading[6:11], 1.0, atol=1e-12)
    steps = np.diff(tr.robot[:, :2], axis=0)
    np.testing.assert_allclose(np.hypot(*steps.T), 0.05, atol=1e-12)  # v dt every step
    np.testing.assert_allclose(np.arctan2(steps[:, 1], steps[:, 0]), heading[1:], atol=1e-12)
    arc = run_episode(
        _setup([], spec=UnicycleSpec(1.0, 2.0, 0.1), start=np.zeros(3),
               goal=np.array([50.0, 0.0]), dt=0.05, control_period=0.25, t_max=0.5),
        Turning(make_controller("straight-v1")), np.random.default_rng(0),
    )  # fmt: skip
    assert arc.trajectory is not None
    assert arc.trajectory.robot[-1, 2] == pytest.approx(1.0)  # the same total turn, on arcs
    assert not np.allclose(arc.trajectory.robot[-1, :2], tr.robot[-1, :2])


def test_an_acceleration_limited_unicycle_ramps_up_and_the_sensor_says_so() -> None:
    """With ``accel_max`` the robot's speed climbs at most ``accel_max dt`` a step toward the
    held command, and the observation reports the speed it has, not the command."""
    spec = UnicycleSpec(v_max=1.0, u_max=1.0, radius=0.1, accel_max=0.5)
    setup = _setup([], spec=spec, start=np.zeros(3), goal=np.array([50.0, 0.0]), dt=0.1,
                   control_period=0.5, t_max=3.0)  # fmt: skip
    probe = Probe(make_controller("straight-v1"))
    res = run_episode(setup, probe, np.random.default_rng(0))
    speeds = [o.speed for o in probe.seen]
    assert speeds == pytest.approx([0.0, 0.25, 0.5, 0.75, 1.0, 1.0])  # 0.5 m/s^2, at 0.5 s
    tr = res.trajectory
    assert tr is not None
    steps = np.hypot(*np.diff(tr.robot[:, :2], axis=0).T)
    np.testing.assert_allclose(steps[:10], 0.05 * np.arange(1, 11) * 0.1, atol=1e-12)
    assert res.metrics.limit_violations == 0  # the law asked for V_max: inside (2.4)
