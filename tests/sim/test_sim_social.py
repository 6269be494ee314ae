"""Social metrics of the 2D worlds (:mod:`uvnav.sim.social`) on hand-built scenes whose values are
known exactly: a pedestrian passing a standing robot at a known distance, a pedestrian walking
into a standing robot, a robot driving into a standing or slower body, turning robots."""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np
import pytest

from uvnav.controllers import make_controller
from uvnav.dynamics import UnicycleCommand, UnicycleSpec
from uvnav.dynamics.omni import VelocityCommand
from uvnav.obstacles import ConstantVelocity, DiscBody, Obstacle, ObstacleState, PolygonBody
from uvnav.scenarios.pedestrians import PedestrianReplay
from uvnav.sensors import Observation
from uvnav.sim import EpisodeSetup, run_episode
from uvnav.sim.metrics import SOCIAL_METRIC_NAMES, EpisodeMetrics, episode_metrics
from uvnav.sim.social import DISCOMFORT_DISTANCE, INTIMATE_DISTANCE, GapHistory, pedestrian_ids

ROBOT_R = 0.2
PED_R = 0.3
SPEC = UnicycleSpec(v_max=1.0, u_max=1.0, radius=ROBOT_R)


class Scripted:
    """A law that returns ``commands(t)`` whatever it sees."""

    name: ClassVar[str] = "scripted"
    oracle = False

    def __init__(self, command: Any) -> None:
        self._command = command

    def reset(self, spec: Any, goal: np.ndarray, rng: np.random.Generator) -> None:
        pass

    def act(self, obs: Observation) -> Any:
        return self._command(obs.time)

    @property
    def mode(self) -> str:
        return ""


def _stand(t: float) -> UnicycleCommand:
    return UnicycleCommand(0.0, 0.0)


def _setup(obstacles: list[Obstacle], **kw: Any) -> EpisodeSetup:
    args: dict[str, Any] = {
        "spec": SPEC,
        "start": np.array([0.0, 0.0, 0.0]),
        "goal": np.array([20.0, 0.0]),
        "obstacles": obstacles,
        "dt": 0.25,
        "control_period": 0.25,
        "t_max": 10.0,
        "goal_tolerance": 0.1,
    }
    args.update(kw)
    return EpisodeSetup(**args)


def _run(setup: EpisodeSetup, law: Any, *, record: bool = False, vehicle: str = "unicycle") -> Any:
    return run_episode(setup, law, np.random.default_rng(0), record=record, vehicle=vehicle)


def _passer(offset: float) -> Obstacle:
    """A pedestrian walking at 1 m/s along y = ``offset``, from x = -5 (at x = 0 at t = 5 s);
    with dt = 0.25 s its x is exactly -5 + 0.25 k."""
    return Obstacle.moving_disc((-5.0, offset), PED_R, (1.0, 0.0), name="ped")


def test_pedestrian_rule() -> None:
    square = np.array([[-0.3, -0.3], [0.3, -0.3], [0.3, 0.3], [-0.3, 0.3]])
    obstacles = [
        Obstacle.moving_disc((0.0, 5.0), 0.3),  # a standing disc: not a pedestrian
        _passer(1.0),
        Obstacle(  # a moving polygon: not a pedestrian
            PolygonBody(square),
            ObstacleState(np.array([3.0, 3.0]), velocity=np.array([0.5, 0.0])),
            ConstantVelocity(np.array([0.5, 0.0])),
        ),
        Obstacle.moving_disc((4.0, 4.0), 0.25, (0.0, -0.4)),
    ]
    assert pedestrian_ids(obstacles).tolist() == [1, 3]
    assert pedestrian_ids([]).tolist() == []


def test_pedestrian_passing_at_a_known_distance() -> None:
    # centres 0.8 m apart at closest: gap 0.8 - 0.3 - 0.2 = 0.3 m, never too close; the gap is
    # below 0.45 m while |x| < sqrt(0.95^2 - 0.8^2) = 0.512 m: x = -0.5 ... 0.5, 5 steps
    res = _run(_setup([_passer(0.8)]), Scripted(_stand))
    m = res.metrics
    assert res.status == "timeout"
    assert m.min_separation == pytest.approx(0.3, abs=1e-12)
    assert m.min_separation == m.min_clearance  # the only body is the pedestrian
    assert m.too_close_time == 0.0 and m.too_close_frequency == 0.0
    assert m.intrusion_time == pytest.approx(5 * 0.25)
    assert m.path_irregularity is None  # the robot never moved
    assert m.collision_by is None


@pytest.mark.parametrize(("period", "frequency"), [(0.25, 3 / 40), (0.5, 2 / 20)])
def test_pedestrian_too_close(period: float, frequency: float) -> None:
    # centres 0.6 m apart at closest: gap 0.1 m; too close (< 0.2 m: centres < 0.7 m) at
    # x = -0.25, 0, 0.25 (steps 19, 20, 21); intrusion (centres < 0.95 m) at |x| <= 0.5
    res = _run(_setup([_passer(0.6)], control_period=period), Scripted(_stand))
    m = res.metrics
    assert m.min_separation == pytest.approx(0.1, abs=1e-12)
    assert m.too_close_time == pytest.approx(3 * 0.25)
    assert m.intrusion_time == pytest.approx(5 * 0.25)
    # 40 decisions every 0.25 s: 3 of them too close; every 0.5 s: steps 19 | 20, 21 fall in
    # the periods of decisions 9 and 10, 2 of 20
    assert m.too_close_frequency == pytest.approx(frequency)
    assert DISCOMFORT_DISTANCE == 0.2 and INTIMATE_DISTANCE == 0.45


def test_pedestrian_walking_into_a_standing_robot() -> None:
    res = _run(_setup([Obstacle.moving_disc((-3.0, 0.0), PED_R, (1.0, 0.0))]), Scripted(_stand))
    m = res.metrics
    assert res.status == "collision"
    assert m.collision_by == "pedestrian"
    assert m.min_separation is not None and m.min_separation < 0
    assert m.min_separation == m.min_clearance


@pytest.mark.parametrize("record", [False, True])
def test_robot_driving_into_a_standing_body(record: bool) -> None:
    standing = Obstacle.moving_disc((3.0, 0.0), PED_R)  # a standing disc (not a pedestrian)
    res = _run(_setup([standing]), make_controller("straight-v1"), record=record)
    m = res.metrics
    assert res.status == "collision"
    assert m.collision_by == "robot"
    assert m.min_separation is None  # no pedestrian in the scene
    assert m.path_irregularity == 0.0  # straight at the goal


def test_robot_catching_up_with_a_slower_pedestrian() -> None:
    slow = Obstacle.moving_disc((3.0, 0.0), PED_R, (0.3, 0.0))  # walking away at 0.3 m/s
    res = _run(_setup([slow]), make_controller("straight-v1"))
    assert res.status == "collision" and res.metrics.collision_by == "robot"


def _appearing(t0: float) -> Obstacle:
    """A replayed pedestrian whose track starts at ``t0`` [s] at (1.3, 0), walking +y at 1 m/s
    (across the robot's path, not toward it)."""
    track = np.array([[1.3, 0.0], [1.3, 4.0]])
    motion = PedestrianReplay(np.array([t0, t0 + 4.0]), track)
    return Obstacle(DiscBody(PED_R), motion.initial_state(0.0), motion)


def test_pedestrian_appearing_in_contact_is_not_the_robots_doing() -> None:
    """straight-v1 drives along y = 0 at 1 m/s, at x = 1.0 at t = 1 s: a track starting then at
    (1.3, 0) overlaps it on the step it appears.  By velocities alone the robot closed the gap
    (it drives at the body, which walks across); but the body did not exist one step before:
    it appeared in contact, its own cause."""
    res = _run(_setup([_appearing(1.0)]), make_controller("straight-v1"))
    assert res.status == "collision" and res.metrics.collision_by == "appeared"
    # the same body on the scene from the start and met at the same place: the robot's doing
    present = Obstacle.moving_disc((1.3, -1.0), PED_R, (0.0, 1.0))
    res = _run(_setup([present]), make_controller("straight-v1"))
    assert res.status == "collision" and res.metrics.collision_by == "robot"


def test_who_closed_the_gap_is_judged_over_the_last_second() -> None:
    """A person walks at 0.8 m/s after a robot that draws away at 0.3 m/s; in the last step the
    robot turns back at 1 m/s and they touch.  At the contact instant the robot's approach
    (1 m/s) exceeds the person's (0.8 m/s), but over the last second the person closed 0.8 m of
    the gap and the robot 0.025 m: the person closed it."""

    def law(t: float) -> VelocityCommand:
        return VelocityCommand(0.3, 0.0) if t < 4.75 - 1e-9 else VelocityCommand(-1.0, 0.0)

    def chaser() -> Obstacle:  # fresh: an episode leaves its obstacles where it ended
        return Obstacle.moving_disc((-3.0, 0.0), PED_R, (0.8, 0.0))

    res = _run(_setup([chaser()], t_max=8.0), Scripted(law), vehicle="holonomic")
    assert res.status == "collision" and 4.75 < res.contact_time <= 5.0
    assert res.metrics.collision_by == "pedestrian"
    # the same contact met by a robot that drove at the person the whole last second
    res = _run(_setup([chaser()], t_max=8.0), Scripted(lambda t: VelocityCommand(-1.0, 0.0)),
               vehicle="holonomic")  # fmt: skip
    assert res.status == "collision" and res.metrics.collision_by == "robot"


def test_gap_history_shares_sum_the_closing_over_the_window() -> None:
    h = GapHistory(2, 0.25)  # 1 s: 4 steps, 5 samples kept
    for k in range(8):  # robot still; body 0 walks in at 1 m/s, body 1 stands
        h.push(0.0, 0.0, np.array([[5.0 - 0.25 * k, 0.0], [0.0, 3.0]]), None)
    assert h.shares(0) == pytest.approx((0.0, 1.0))  # only the last second counts
    assert h.shares(1) == (0.0, 0.0) and not h.robot_closed(1)  # a tie is not the robot's
    absent = GapHistory(1, 0.25)
    for k in range(3):  # the body exists from the last sample only: no step of the window
        absent.push(0.5 * k, 0.0, np.array([[2.0, 0.0]]), np.array([k == 2]))
    assert absent.shares(0) == (0.0, 0.0)


def test_moving_polygon_into_a_standing_robot() -> None:
    square = np.array([[-0.3, -0.3], [0.3, -0.3], [0.3, 0.3], [-0.3, 0.3]])
    box = Obstacle(
        PolygonBody(square),
        ObstacleState(np.array([-3.0, 0.0]), velocity=np.array([1.0, 0.0])),
        ConstantVelocity(np.array([1.0, 0.0])),
    )
    res = _run(_setup([box]), Scripted(_stand))
    m = res.metrics
    assert res.status == "collision" and m.collision_by == "obstacle"
    assert m.min_separation is None


def test_record_does_not_change_social_metrics() -> None:
    obstacles = [_passer(0.6), Obstacle.moving_disc((6.0, 0.5), PED_R, (-0.5, 0.0))]
    law = make_controller("straight-v1")
    a = _run(_setup([*obstacles]), law, record=False).metrics.to_dict()
    b = _run(_setup([_passer(0.6), Obstacle.moving_disc((6.0, 0.5), PED_R, (-0.5, 0.0))]), law,
             record=True).metrics.to_dict()  # fmt: skip
    for name in SOCIAL_METRIC_NAMES:
        assert a[name] == b[name], name


def test_unicycle_path_irregularity_is_curvature_on_an_arc() -> None:
    # v = 0.5 m/s, u = 0.25 rad/s: 0.5 rad per metre of arc (the path sums chords: 1e-4 relative)
    res = _run(
        _setup([], dt=0.05, control_period=0.05, t_max=8.0),
        Scripted(lambda t: UnicycleCommand(0.5, 0.25)),
    )
    m = res.metrics
    assert m.path_length == pytest.approx(4.0, rel=1e-3)
    assert m.path_irregularity == pytest.approx(0.25 * 8.0 / m.path_length, rel=1e-12)
    assert m.path_irregularity == pytest.approx(0.5, rel=1e-3)
    assert m.min_separation is None and m.too_close_time is None and m.collision_by is None


def test_holonomic_path_irregularity_counts_direction_changes() -> None:
    # east for 2 s then north for 2 s at 0.5 m/s: one quarter turn over 2 m
    def law(t: float) -> VelocityCommand:
        return VelocityCommand(0.5, 0.0) if t < 2.0 - 1e-9 else VelocityCommand(0.0, 0.5)

    res = _run(
        _setup([], dt=0.25, control_period=0.25, t_max=4.0), Scripted(law), vehicle="holonomic"
    )
    m = res.metrics
    assert m.path_length == pytest.approx(2.0)
    assert m.path_irregularity == pytest.approx((math.pi / 2) / 2.0)


def test_other_kinds_leave_social_metrics_none() -> None:
    m = episode_metrics(
        status="success", path_length=1.0, shortest=1.0, straight_time=1.0, reached_at=1.0,
        min_clearance=None, control_effort=0.0, limit_violations=0, mode_switches=0,
        decision_us=[1.0],
    )  # fmt: skip
    assert all(getattr(m, name) is None for name in SOCIAL_METRIC_NAMES)
    assert isinstance(m, EpisodeMetrics)
