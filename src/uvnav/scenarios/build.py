"""From a validated :class:`~uvnav.scenarios.schema.Scenario` to a runnable episode, and the
thesis's obstacle constraints.

Randomness (DESIGN §2): ``build_episode(scenario, seed)`` makes
``rng = uvnav.sim.world_rng(seed)`` and hands obstacle ``i`` the child
``rng.spawn(n_obstacles)[i]``; only ``random_turn`` motions draw from it.  The same scenario and
seed therefore give bit-identical obstacle paths, and appending an obstacle to a scenario does not
change the draws of the ones before it.

Constraints, thesis Ch. 2 (2.6)-(2.8), checked per obstacle from its motion model's bounds:

* (2.6) ``||v_i|| < V_max`` with ``||v_i||`` bounded by ``speed_bound()``;
* (2.7) ``|u_i| < U_max`` with ``|u_i|`` bounded by ``turn_bound()``;
* (2.8) ``Delta distance < V_max - ||v_i||``, where ``Delta distance`` is the outward excursion of
  the boundary along a fixed ray while the body turns for one second at its largest rate,
  :func:`uvnav.obstacles.rotation_boundary_growth` ``(body, turn_bound() * 1 s)``.

The thesis writes (2.6) and (2.8) with the robot's current speed ``||v_R||``; its upper bound
``V_max`` is used here, which makes the check necessary rather than sufficient.  The strict lower
bound ``0 < ||v_i||`` of (2.6) is not enforced: a static obstacle is an easier case, not an
invalid one.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from uvnav.controllers.base import requires_slower_obstacles
from uvnav.obstacles import MotionModel, rotation_boundary_growth
from uvnav.scenarios.errors import ScenarioError
from uvnav.scenarios.pedestrians import crowd_speed_stats
from uvnav.scenarios.schema import ObstacleSpec, Scenario
from uvnav.sim import EpisodeSetup, world_rng

#: duration of rotation over which the thesis's Delta distance is measured [s]
DELTA_DISTANCE_HORIZON = 1.0


def build_episode(scenario: Scenario, seed: int) -> EpisodeSetup:
    """Instantiate ``scenario`` for one episode.

    Args:
        scenario: a validated scenario.
        seed: episode seed; obstacle ``i`` draws from ``world_rng(seed).spawn(n)[i]``.  The
            pedestrians of ``scenario.crowd`` (deterministic replays) come after the ``n``
            obstacles, in the order of :func:`uvnav.scenarios.pedestrians.episode_tracks`.

    Returns:
        A fresh :class:`~uvnav.sim.EpisodeSetup` (its obstacles are advanced in place by
        :func:`~uvnav.sim.run_episode`, so build one per run).

    Raises:
        ScenarioError: a 3D scene (``dim: 3``; built by ``Scenario3D.build``).
    """
    if getattr(scenario, "dim", 2) == 3:
        raise ScenarioError(
            getattr(scenario, "source", "<dict>"), "dim",
            "a 3D scene runs in the 3D simulator (Scenario3D.build + uvnav.sim.episode3d), "
            "not in the 2D one",
        )  # fmt: skip
    rng = world_rng(seed)
    children = rng.spawn(len(scenario.obstacles))
    obstacles = [
        spec.to_obstacle(child, scenario.dt, j)
        for j, (spec, child) in enumerate(zip(scenario.obstacles, children, strict=True))
    ]
    if scenario.crowd is not None:
        obstacles += scenario.crowd.to_obstacles(scenario.t_max)
    robot = scenario.robot
    start = np.array([robot.start[0], robot.start[1], robot.initial_heading()], dtype=float)
    return EpisodeSetup(
        spec=robot.to_spec(),
        start=start,
        goal=np.asarray(robot.goal, dtype=float),
        obstacles=obstacles,
        dt=float(scenario.dt),
        control_period=float(scenario.control_period),
        t_max=float(scenario.t_max),
        goal_tolerance=float(scenario.goal_tolerance),
        sensing=scenario.sensing.to_config(),
    )


def _motion(spec: ObstacleSpec) -> MotionModel:
    return spec.motion.to_model(np.random.default_rng(0))


def obstacle_bounds(spec: ObstacleSpec) -> tuple[float, float, float]:
    """``(speed bound [m/s], turn-rate bound [rad/s], Delta distance [m])`` of one obstacle.

    Delta distance is the boundary growth for ``turn bound * 1 s`` of rotation (a full turn when
    the turn rate is unbounded).
    """
    motion = _motion(spec)
    speed = float(motion.speed_bound())
    turn = float(motion.turn_bound())
    rotation = turn * DELTA_DISTANCE_HORIZON if math.isfinite(turn) else 2.0 * math.pi
    rotation = min(rotation, 2.0 * math.pi)
    growth = float(rotation_boundary_growth(spec.body.to_body(), rotation))
    return speed, turn, growth


def check_constraints(scenario: Scenario) -> list[str]:
    """Violations of the thesis's obstacle constraints (2.6)-(2.8), one human-readable line each.

    Returns:
        An empty list when every obstacle obeys (2.6)-(2.8) for the robot's V_max and U_max.
    """
    if getattr(scenario, "dim", 2) == 3:  # 3D: (3.9)-(3.10) are enforced by schema3d on loading
        return []
    v_max = scenario.robot.v_max
    u_max = scenario.robot.u_max
    lines: list[str] = []
    for j, spec in enumerate(scenario.obstacles):
        label = f"obstacles.{j}" + (f" ({spec.name})" if spec.name else "")
        speed, turn, growth = obstacle_bounds(spec)
        if not speed < v_max:
            lines.append(
                f"{label}: (2.6) speed bound {speed:.3g} m/s is not < V_max {v_max:.3g} m/s"
            )
        if not turn < u_max:
            lines.append(
                f"{label}: (2.7) turn-rate bound {turn:.3g} rad/s is not < U_max {u_max:.3g} rad/s"
            )
        if not growth < v_max - speed:
            lines.append(
                f"{label}: (2.8) Delta distance {growth:.3g} m "
                f"(1 s of rotation at {turn:.3g} rad/s) "
                f"is not < V_max - ||v_i|| = {v_max - speed:.3g} m/s"
            )
    if scenario.crowd is not None:
        lines.extend(crowd_warnings(scenario))
    return lines


def crowd_speeds(scenario: Scenario) -> tuple[int, float, float]:
    """``(pedestrians, typical speed, max speed)`` of the scene's crowd in its window [m/s].

    See :func:`uvnav.scenarios.pedestrians.crowd_speed_stats`; all zero without a crowd.
    """
    crowd = scenario.crowd
    if crowd is None:
        return 0, 0.0, 0.0
    pieces = crowd.pieces(scenario.t_max)
    typical, top = crowd_speed_stats(pieces, crowd.window(scenario.t_max))
    return len(pieces), typical, top


def crowd_warnings(scenario: Scenario) -> list[str]:
    """Warnings (never errors) about a crowd's pedestrians and the thesis's (2.6)-(2.8).

    Replayed pedestrians are not bound by (2.6)-(2.8): they walk at 1.0-1.4 m/s (often faster than
    a slow robot) and turn at will, and that is the point of these scenes.  One summary line for
    (2.6) when some pedestrian is not slower than V_max, and one for (2.7)-(2.8) (their turn rate is
    not bounded by the replay).
    """
    crowd = scenario.crowd
    if crowd is None:
        return []
    v_max = scenario.robot.v_max
    n, typical, top = crowd_speeds(scenario)
    if n == 0:
        return []
    pieces = crowd.pieces(scenario.t_max)
    faster = sum(bool(np.max(p.speeds()) >= v_max) for p in pieces)
    label = f"crowd ({crowd.dataset}, {n} pedestrians)"
    lines: list[str] = []
    if faster:
        lines.append(
            f"{label}: (2.6) {faster} pedestrian(s) reach >= V_max {v_max:.3g} m/s "
            f"(typical {typical:.3g}, max {top:.3g} m/s); real pedestrians, warning only"
        )
    lines.append(f"{label}: (2.7)-(2.8) replayed pedestrians turn at unbounded rate; warning only")
    return lines


def validate_for_controller(
    scenario: Scenario, controller_name: str, params: Mapping[str, Any] | None = None
) -> None:
    """Check that ``scenario`` satisfies the assumptions ``controller_name`` (with ``params``)
    declares, or the law it runs inside declares
    (:func:`uvnav.controllers.base.requires_slower_obstacles`).

    Raises:
        ScenarioError: the controller requires obstacles slower than the robot (thesis (2.6)) and an
            obstacle's speed bound is ``>= V_max``.
        uvnav.controllers.UnknownControllerError: no such controller.

    A crowd of real pedestrians is judged as a whole, not per pedestrian: it is rejected only when
    the robot is not faster than the crowd's *typical* walking speed (time-weighted mean speed of
    the pedestrians in the episode window, standing ones included), i.e. when the law's
    assumption fails for most of the obstacles it meets.  Individual pedestrians faster than
    V_max (some jog, most are faster for a moment) are a documented departure, reported by
    :func:`check_constraints` as warnings.
    """
    if not requires_slower_obstacles(controller_name, params):
        return
    v_max = scenario.robot.v_max
    for j, spec in enumerate(scenario.obstacles):
        speed = float(_motion(spec).speed_bound())
        if speed >= v_max:
            raise ScenarioError(
                scenario.source,
                f"obstacles.{j}.motion",
                f"speed bound {speed:.3g} m/s >= V_max {v_max:.3g} m/s, but {controller_name} "
                "requires obstacles slower than the robot (thesis (2.6))",
            )
    if scenario.crowd is not None:
        n, typical, _ = crowd_speeds(scenario)
        if n and typical >= v_max:
            raise ScenarioError(
                scenario.source,
                "crowd",
                f"typical pedestrian speed {typical:.3g} m/s >= V_max {v_max:.3g} m/s, but "
                f"{controller_name} requires obstacles slower than the robot (thesis (2.6)); "
                "raise robot.v_max",
            )
