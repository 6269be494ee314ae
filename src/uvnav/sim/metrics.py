"""Episode metrics, identical for every controller (DESIGN §4).

Names are the snake_case column names used in JSON, the results database and the report.  Metrics
that do not exist for an episode (time to goal of a failed run, minimum clearance in a world
without obstacles) are ``None``, never NaN or infinite.

The social metrics (:data:`SOCIAL_METRIC_NAMES`, defined in :mod:`uvnav.sim.social` and
:mod:`uvnav.sim.comfort`) come last; only the 2D worlds compute them, every other vehicle kind
leaves them ``None``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

#: the social and comfort metrics (:mod:`uvnav.sim.social`, :mod:`uvnav.sim.comfort`), last in
#: :data:`METRIC_NAMES`: 2D worlds only
SOCIAL_METRIC_NAMES: tuple[str, ...] = (
    "min_separation",
    "too_close_time",
    "too_close_frequency",
    "intrusion_time",
    "intrusion_ratio",
    "personal_space_time",
    "min_time_to_collision",
    "path_irregularity",
    "heading_irregularity",
    "jerk",
    "collision_by",
)

METRIC_NAMES: tuple[str, ...] = (
    "success",
    "collision",
    "min_clearance",
    "path_length",
    "detour_ratio",
    "time_to_goal",
    "time_ratio",
    "control_effort",
    "limit_violations",
    "mode_switches",
    "decision_us_median",
    "decision_us_p99",
    *SOCIAL_METRIC_NAMES,
)


@dataclass(frozen=True)
class EpisodeMetrics:
    """Outcome of one episode.

    Attributes:
        success: reached the goal tolerance before ``t_max`` without collision.
        collision: the robot's disc overlapped an obstacle: anywhere along an integration step
            in the 2D worlds (:mod:`uvnav.sim.swept`), at the end of one in the others.
        min_clearance: smallest gap between the robot's disc and any obstacle [m] (negative on
            overlap), along every step in the 2D worlds, over the ends of the integration steps
            in the others; ``None`` when the world has no obstacle.
        path_length: distance travelled by the robot centre [m].
        detour_ratio: path length / straight distance from the start to the edge of the goal
            tolerance disc (1.0 is the physical limit); ``None`` for a failed episode.
        time_to_goal: time of arrival [s], ``None`` if the goal was not reached.
        time_ratio: ``time_to_goal / (that straight distance / V_max)``, ``None`` if not reached.
        control_effort: integral of u_R^2 dt [rad^2/s] plus integral of (dV_R/dt)^2 dt [m^2/s^3].
        limit_violations: number of decisions whose command was outside the vehicle limits.
        mode_switches: number of changes of the controller's reported mode.
        decision_us_median: median controller compute time per decision [µs]: thread CPU time
            (:func:`time.thread_time_ns`), the first decision (warm-up) left out when there are
            several (:attr:`uvnav.core.AgentLog.timed_us`).
        decision_us_p99: 99th percentile of the same [µs].
        min_separation: smallest gap between the robot's disc and a pedestrian's [m]; ``None``
            without pedestrians or outside the 2D worlds (this and the fields below:
            :mod:`uvnav.sim.social`).
        too_close_time: time with a pedestrian closer than 0.2 m (CrowdNav's discomfort
            distance) [s].
        too_close_frequency: share of the decisions whose period had a pedestrian closer than
            0.2 m (CrowdNav's discomfort frequency).
        intrusion_time: time with a pedestrian closer than 0.45 m (Hall's intimate zone) [s].
        intrusion_ratio: share of the integration steps in which the robot's disc lies on a
            visible pedestrian's disc as constant velocity forecasts it over the next 1.25 s
            (the intrusion ratio of crowd-navigation work, CrowdNav++).
        personal_space_time: time with a pedestrian's disc closer than 0.5 m to the robot's,
            disc to disc [s] (this and the next: :mod:`uvnav.sim.comfort`).
        min_time_to_collision: smallest constant-velocity time to collision with a pedestrian
            over the steps [s] (0 in contact); ``None`` when never on a collision course.
        path_irregularity: total absolute heading change per metre of path [rad/m] (every 2D
            episode that moved).
        heading_irregularity: mean absolute angle between the heading and the direction to the
            goal over the steps [rad] (SocNavBench's path irregularity; every 2D episode).
        jerk: mean norm of the robot's jerk over the integration steps [m/s^3] (every 2D
            episode of two steps or more).
        collision_by: who closed the gap at the collision: ``"robot"``, ``"pedestrian"`` or
            ``"obstacle"`` (a body that is not a pedestrian), or ``"appeared"`` (the body's
            track starts in contact); ``None`` without collision.
    """

    success: bool
    collision: bool
    min_clearance: float | None
    path_length: float
    detour_ratio: float | None
    time_to_goal: float | None
    time_ratio: float | None
    control_effort: float
    limit_violations: int
    mode_switches: int
    decision_us_median: float
    decision_us_p99: float
    min_separation: float | None = None
    too_close_time: float | None = None
    too_close_frequency: float | None = None
    intrusion_time: float | None = None
    intrusion_ratio: float | None = None
    personal_space_time: float | None = None
    min_time_to_collision: float | None = None
    path_irregularity: float | None = None
    heading_irregularity: float | None = None
    jerk: float | None = None
    collision_by: str | None = None

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def episode_metrics(
    *,
    status: str,
    path_length: float,
    shortest: float,
    straight_time: float,
    reached_at: float | None,
    min_clearance: float | None,
    control_effort: float,
    limit_violations: int,
    mode_switches: int,
    decision_us: Sequence[float] | np.ndarray,
    min_separation: float | None = None,
    too_close_time: float | None = None,
    too_close_frequency: float | None = None,
    intrusion_time: float | None = None,
    intrusion_ratio: float | None = None,
    personal_space_time: float | None = None,
    min_time_to_collision: float | None = None,
    path_irregularity: float | None = None,
    heading_irregularity: float | None = None,
    jerk: float | None = None,
    collision_by: str | None = None,
) -> EpisodeMetrics:
    """The DESIGN §4 metrics of one finished episode, the same way for every simulator.

    Args:
        status: ``"success"``, ``"collision"`` or ``"timeout"``.
        path_length: distance travelled [m].
        shortest: straight distance from the start to the edge of the goal disc [m] (the detour
            ratio's denominator).
        straight_time: time [s] of the fastest straight run over ``shortest`` at the vehicle's top
            speed (the time ratio's denominator; a vehicle model may have its own top speed along
            the line, e.g. a UUV whose velocity components are bounded separately).
        reached_at: arrival time [s], ``None`` when the goal was not reached.
        min_clearance: smallest robot–obstacle gap [m], ``None`` without obstacles.
        control_effort: see :class:`EpisodeMetrics`.
        limit_violations: decisions whose command was outside the limits.
        mode_switches: changes of the controller's reported mode.
        decision_us: controller compute time of every decision [µs] (empty: no decision).
        min_separation, too_close_time, too_close_frequency, intrusion_time, intrusion_ratio,
        personal_space_time, min_time_to_collision, path_irregularity, heading_irregularity,
        jerk, collision_by: the social and comfort metrics of a 2D world
            (:mod:`uvnav.sim.social`, :mod:`uvnav.sim.comfort`), ``None`` where they do not
            apply (an infinite time to collision is ``None``).
    """
    dec = np.asarray(decision_us, dtype=float) if len(decision_us) else np.zeros(1)
    success = status == "success"
    return EpisodeMetrics(
        success=success,
        collision=status == "collision",
        min_clearance=None if min_clearance is None else float(min_clearance),
        path_length=float(path_length),
        detour_ratio=(path_length / shortest) if success and shortest > 0 else None,
        time_to_goal=reached_at,
        time_ratio=(reached_at / straight_time)
        if reached_at is not None and straight_time > 0
        else None,
        control_effort=float(control_effort),
        limit_violations=int(limit_violations),
        mode_switches=int(mode_switches),
        decision_us_median=float(np.median(dec)),
        decision_us_p99=float(np.percentile(dec, 99)),
        min_separation=_opt(min_separation),
        too_close_time=_opt(too_close_time),
        too_close_frequency=_opt(too_close_frequency),
        intrusion_time=_opt(intrusion_time),
        intrusion_ratio=_opt(intrusion_ratio),
        personal_space_time=_opt(personal_space_time),
        min_time_to_collision=_opt(min_time_to_collision),
        path_irregularity=_opt(path_irregularity),
        heading_irregularity=_opt(heading_irregularity),
        jerk=_opt(jerk),
        collision_by=collision_by,
    )


def _opt(value: float | None) -> float | None:
    """``value`` as a float; ``None`` for missing or non-finite."""
    if value is None:
        return None
    v = float(value)
    return v if math.isfinite(v) else None
