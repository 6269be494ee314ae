"""Collisions and clearance judged along each step of the 2D worlds (:mod:`uvnav.sim.swept`)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.controllers.base import make_law
from uvnav.dynamics import UnicycleSpec
from uvnav.obstacles import ConstantVelocity, DiscBody, Obstacle, ObstacleState, PolygonBody
from uvnav.sim import EpisodeResult, EpisodeSetup, run_episode

WALL = np.array([[-0.02, -2.0], [0.02, -2.0], [0.02, 2.0], [-0.02, 2.0]])  # 4 cm thick


def _episode(obstacles: list[Obstacle], *, swept: bool, v_max: float = 2.0, dt: float = 0.1,
             vehicle: str = "unicycle", record: bool = False,
             compiled: bool = False) -> EpisodeResult:  # fmt: skip
    """A robot driving straight along y = 0 from x = -1.1 at ``v_max`` [m/s]."""
    setup = EpisodeSetup(
        spec=UnicycleSpec(v_max=v_max, u_max=1.0, radius=0.05), start=np.array([-1.1, 0.0, 0.0]),
        goal=np.array([3.0, 0.0]), obstacles=obstacles, dt=dt, control_period=dt, t_max=4.0,
    )  # fmt: skip
    law = make_law(
        "straight-holonomic-v1" if vehicle == "holonomic" else "straight-v1", vehicle=vehicle
    )
    return run_episode(setup, law, np.random.default_rng(0), record=record, swept=swept,
                       vehicle=vehicle, compiled=compiled)  # fmt: skip


def _wall(x: float = 0.0, velocity: tuple[float, float] = (0.0, 0.0)) -> Obstacle:
    return Obstacle(PolygonBody.from_vertices(WALL), ObstacleState(position=np.array([x, 0.0])),
                    ConstantVelocity(np.array(velocity)))  # fmt: skip


@pytest.mark.parametrize("record", [False, True])
def test_a_robot_that_passes_through_a_thin_wall_between_samples_collides(record: bool) -> None:
    # 0.2 m a step: the samples fall at x = -0.1 and 0.1, 3 cm clear of the wall's faces, and
    # the wall is crossed in between
    sampled = _episode([_wall()], swept=False, record=record)
    assert sampled.status == "success" and sampled.contact_time is None
    got = _episode([_wall()], swept=True, record=record)
    assert got.status == "collision" and got.metrics.collision
    # first contact: the robot's front (x + 0.05) meets the face x = -0.02 at x = -0.07
    assert got.contact_time == pytest.approx((-0.07 + 1.1) / 2.0, abs=1e-9)
    assert got.metrics.min_clearance is not None and got.metrics.min_clearance < 0
    assert got.metrics.path_length == pytest.approx(1.2)  # the episode ends with that step
    # judged at the contact: the robot drove into a still wall (at the step's end it is past it)
    assert got.metrics.collision_by == "robot"


def test_a_fast_disc_that_crosses_the_path_between_samples_collides() -> None:
    # a disc at 20 m/s sweeps across the robot's line within one step
    def disc() -> Obstacle:  # (an episode leaves its bodies where they ended)
        return Obstacle(DiscBody(0.1), ObstacleState(position=np.array([-1.09, -1.5])),
                        ConstantVelocity(np.array([0.0, 20.0])))  # fmt: skip

    sampled = _episode([disc()], swept=False, v_max=0.1, dt=0.1)
    swept = _episode([disc()], swept=True, v_max=0.1, dt=0.1)
    assert sampled.status != "collision"
    assert swept.status == "collision" and swept.contact_time is not None
    # the discs touch when the disc's centre is 0.15 m below the robot's: y = -0.15
    assert swept.contact_time == pytest.approx((1.5 - 0.15) / 20.0, abs=1e-3)
    assert swept.metrics.collision_by == "pedestrian"  # (a moving disc is one) it ran into it


def test_the_holonomic_robot_is_judged_along_the_step_too() -> None:
    got = _episode([_wall()], swept=True, vehicle="holonomic")
    assert got.status == "collision" and got.contact_time is not None


@settings(max_examples=25, deadline=None)
@given(
    x=st.floats(-0.5, 2.0),
    vx=st.floats(-1.0, 1.0),
    vy=st.floats(-0.2, 0.2),
    spin=st.floats(-1.0, 1.0),
)
def test_the_minimum_along_the_steps_never_exceeds_a_sampled_one_and_paths_agree(
    x: float, vx: float, vy: float, spin: float
) -> None:
    """Recorded or not, compiled or not: one status and one minimum clearance, at most the
    least sampled clearance."""

    def bodies() -> list[Obstacle]:
        return [
            Obstacle(PolygonBody.from_vertices(0.3 * WALL + 0.0), ObstacleState(
                position=np.array([x, 0.3]), heading=0.3), ConstantVelocity(np.array([vx, vy]),
                spin)),
            _wall(x + 1.0, (vx, -vy)),
        ]  # fmt: skip

    runs = [
        _episode(bodies(), swept=True, record=rec, compiled=comp, v_max=1.0)
        for rec in (True, False)
        for comp in (False, True)
    ]
    assert len({r.status for r in runs}) == 1
    assert len({r.metrics.min_clearance for r in runs}) == 1
    assert len({r.contact_time for r in runs}) == 1
    rec = runs[0]
    assert rec.trajectory is not None and rec.metrics.min_clearance is not None
    assert rec.metrics.min_clearance <= float(np.min(rec.trajectory.clearance))
    if rec.status == "collision":
        assert rec.contact_time is not None
        assert rec.contact_time <= rec.trajectory.times[-1] + 1e-12
        assert math.isfinite(rec.contact_time)


# ------------------------------------------------- every world: a contact between two samples


class _Straight:
    """A test law holding one command (any vehicle's)."""

    oracle = False
    mode = "M1"

    def __init__(self, command: object) -> None:
        self.command = command

    def reset(self, spec: object, goal: np.ndarray, rng: np.random.Generator) -> None:
        pass

    def act(self, obs: object) -> object:
        return self.command


def _ch3() -> tuple[str, float | None]:
    from uvnav.dynamics.vehicle3d import Vehicle3DCommand, Vehicle3DSpec
    from uvnav.obstacles.bodies3d import SphereBody
    from uvnav.obstacles.motion3d import ConstantMotion3D, Obstacle3D, ObstacleState3D
    from uvnav.sim.episode3d import Episode3DSetup
    from uvnav.sim.run import run_episode

    ball = Obstacle3D(SphereBody(0.05), ConstantMotion3D(np.zeros(3)),
                      ObstacleState3D(centre=np.zeros(3)))  # fmt: skip
    setup = Episode3DSetup(
        spec=Vehicle3DSpec(v_max=3.0, u_max=1.0, radius=0.05), start=np.array([-1.35, 0, 0]),
        heading=np.array([1.0, 0, 0]), goal=np.array([5.0, 0, 0]), obstacles=[ball], dt=0.1,
        control_period=0.1, t_max=1.0,
    )  # fmt: skip
    law = _Straight(Vehicle3DCommand(3.0, np.zeros(3)))
    res = run_episode(setup, law, np.random.default_rng(0), record=False)  # type: ignore[arg-type]
    return res.status, res.contact_time


def _ch4(swept: bool = True) -> tuple[str, float | None]:
    from uvnav.dynamics.holonomic import HolonomicCommand, HolonomicSpec
    from uvnav.obstacles.deforming import RigidShape
    from uvnav.sim.episode_uuv2d import Uuv2dSetup
    from uvnav.sim.run import run_episode

    wall = RigidShape(local=WALL, centre=np.zeros(2))
    setup = Uuv2dSetup(
        spec=HolonomicSpec(v_max=2.0, u_max=1.0, radius=0.05), start=np.array([-1.1, 0.0, 0.0]),
        goal=np.array([3.0, 0.0]), shapes=[wall], dt=0.1, control_period=0.1, t_max=1.0,
    )  # fmt: skip
    law = _Straight(HolonomicCommand(2.0, 0.0))
    res = run_episode(setup, law, np.random.default_rng(0), record=False, swept=swept)
    return res.status, res.contact_time


def _ch5() -> tuple[str, float | None]:
    from uvnav.dynamics.vehicle3d import Vehicle3DCommand, Vehicle3DSpec
    from uvnav.obstacles.deforming3d import CompoundBody, DeformingStar
    from uvnav.sensors.sonar_array import SonarArray
    from uvnav.sim.episode_uuv3d import UUV3DSetup
    from uvnav.sim.run import run_episode

    ball = CompoundBody(parts=(DeformingStar(centre=np.zeros(3), base_radius=0.05),))
    setup = UUV3DSetup(
        start=np.array([-1.35, 0.0, 0.0]), heading=np.array([1.0, 0, 0]),
        goal=np.array([5.0, 0, 0]), spec=Vehicle3DSpec(v_max=3.0, u_max=1.0, radius=0.05),
        obstacles=(ball,), array=SonarArray(hull_radius=0.05), dt=0.1, control_period=0.1,
        t_max=1.0,
    )  # fmt: skip
    law = _Straight(Vehicle3DCommand(3.0, np.zeros(3)))
    res = run_episode(setup, law, np.random.default_rng(0), record=False)  # type: ignore[arg-type]
    return res.status, res.contact_time


@pytest.mark.parametrize(
    ("run", "contact"),
    [
        # a 10 cm ball crossed at 0.3 m a step: samples 5 cm clear at x = -0.15 and 0.15;
        # first contact at x = -0.1 (radius sum 0.1 m), t = 1.25 / 3 s
        (_ch3, 1.25 / 3.0),
        (_ch4, (-0.07 + 1.1) / 2.0),  # the thin wall of the 2D tests, at 2 m/s
        (_ch5, 1.25 / 3.0),  # the ball as a Ch. 5 body (its tessellation lies inside it)
    ],
    ids=["vehicle3d", "uuv2d", "uuv3d"],
)
def test_every_world_judges_a_contact_between_two_samples(run: object, contact: float) -> None:
    status, at = run()  # type: ignore[operator]
    assert status == "collision" and at is not None
    # conservative advancement: the first sample in contact, at most 0.1 mm of travel late (the
    # tessellated ball's surface lies up to 1 mm inside the sphere: later, not earlier)
    assert contact - 1e-9 <= at <= contact + 0.002 / 3.0


def test_the_ch4_world_judged_at_step_ends_passes_through() -> None:
    assert _ch4(False) == ("timeout", None)


def test_two_robots_that_cross_between_two_samples_collide() -> None:
    from uvnav.sim.run import run_episode
    from uvnav.sim.setup import MultiSetup, RobotSetup

    def robot(start: tuple[float, float, float], goal: tuple[float, float]) -> RobotSetup:
        spec = UnicycleSpec(v_max=2.0, u_max=1.0, radius=0.05)
        return RobotSetup(spec, np.array(start), np.array(goal), make_law("straight-v1"))

    # 0.2 m a step: at 0.5 s and 0.6 s the robots are 4 cm clear, at 0.55 s both at the origin
    setup = MultiSetup(
        robots=[robot((-1.1, 0.0, 0.0), (3.0, 0.0)), robot((0.0, -1.1, math.pi / 2), (0.0, 3.0))],
        dt=0.1, control_period=0.1, t_max=2.0,
    )  # fmt: skip
    res = run_episode(setup, None, np.random.default_rng(0), record=False, vectorised=True)
    assert res.statuses == ["collision", "collision"] and res.collided_pairs == [(0, 1)]
    assert all(m.min_clearance is not None and m.min_clearance < 0 for m in res.robots)


def test_kept_steps_made_later_give_the_minimum_of_steps_made_at_once() -> None:
    """A robot passing a square: every step fed to two sweeps, one with the poses made at once,
    one with functions making them (``later``): the same minimum, and the functions of kept
    steps that cannot matter are never called."""
    from uvnav.obstacles.obstacle import FieldTemplate
    from uvnav.sim.swept import StepPoses, SweptClearance

    template = FieldTemplate.from_bodies([PolygonBody.from_vertices(0.2 * WALL)])
    now, later = SweptClearance(template, 0.05), SweptClearance(template, 0.05)
    called: list[int] = []
    centre, heading = np.array([[0.0, 0.6]]), np.array([0.0])
    for k in range(40):  # the robot along y = 0, from x = -2 to x = 2 at 0.1 m a step
        p0, p1 = np.array([-2.0 + 0.1 * k, 0.0]), np.array([-1.9 + 0.1 * k, 0.0])
        poses = StepPoses(centre, heading, centre, heading, None, None, p0, p1, 0.0)
        # the gaps at the step's ends, lower bounds: the square's lower edge is at y = 0.2
        g0, g1 = (math.hypot(max(abs(p[0]) - 0.004, 0.0), 0.2) - 0.05 for p in (p0, p1))
        ceiling = min(now.best, g0, g1)
        assert math.isnan(now.step(poses, 0.1, g0, g1, ceiling, shift=0.0))

        def make(poses: StepPoses = poses, k: int = k) -> StepPoses:
            called.append(k)
            return poses

        assert math.isnan(later.step(make, 0.1, g0, g1, ceiling, shift=0.0, later=True))
    assert later.finish(math.inf) == now.finish(math.inf) == pytest.approx(0.15)
    assert 0 < len(called) < 10  # kept: the steps near x = 0; swept: the few below the best
