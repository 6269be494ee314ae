"""The bookkeeping every world shares (DESIGN §4): one clock, one ledger per agent, one rule each.

A world owns its vehicle, its bodies and its sensor; what it counts is here, so that every vehicle
kind gives the same metric for the same event:

* :func:`decision_ratio` — a decision every ``control_period`` [s], a positive whole multiple of
  ``dt`` (within 1e-9 relative);
* :func:`step_count` — an episode lasts ``n = t_max / dt`` integration steps, and ``t_max`` must be
  a whole multiple of ``dt`` (within 1e-9 relative): the last step ends exactly at ``t_max``;
* :class:`Clock` — the step index ``k``, the time ``t = k dt`` [s] (never a running sum), whether a
  decision is due (``k % ratio == 0``) and whether the time is up (``k >= n``);
* :class:`Ledger` — one agent's outcome and sums: status, arrival time, path length, control
  effort, limit violations, minimum clearance, and its :class:`~uvnav.sim.metrics.EpisodeMetrics`.

The status rules, the same in every world:

* at t = 0 (:meth:`Ledger.begin`): a clearance below 0 is a ``collision``; else a start within
  the goal tolerance is a ``success`` with ``time_to_goal = 0.0``; the episode has not started
  otherwise;
* after each step (:meth:`Ledger.judge`): collision first (a sampled gap below 0, or a contact
  the world found along the step), then arrival (``time_to_goal`` = the step's end time), then
  ``timeout`` once the clock is up;
* the detour and time ratios are measured against the straight distance from the start to the
  edge of the goal disc (``None`` when the start is inside it: there is no detour to measure).

>>> clock = Clock(dt=0.1, control_period=0.2, t_max=0.3)
>>> clock.n_steps, clock.due
(3, True)
>>> book = Ledger(goal_tolerance=0.5)
>>> book.begin(clearance=2.0, goal_dist=0.4)  # starts inside the goal tolerance
True
>>> book.status, book.reached_at
('success', 0.0)
>>> step_count(1.0, 0.3)
Traceback (most recent call last):
...
ValueError: t_max must be a whole multiple of dt=0.3 s (got 1 s: 3.33333 steps)
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, ClassVar

import numpy as np

from uvnav.core import AgentLog
from uvnav.geometry.angles import FloatArray
from uvnav.sim.metrics import EpisodeMetrics, episode_metrics
from uvnav.sim.setup import EpisodeResult, GroupMetrics, MultiSetup

#: relative tolerance of the whole-multiple rules (the scenario schema uses the same)
MULTIPLE_RTOL = 1e-9


def _whole(ratio: float) -> int:
    """``ratio`` as a whole number >= 1, or 0 when it is not one within :data:`MULTIPLE_RTOL`."""
    n = round(ratio) if math.isfinite(ratio) else 0
    return int(n) if n >= 1 and abs(ratio - n) <= MULTIPLE_RTOL * max(1.0, ratio) else 0


def _check_dt(dt: float) -> None:
    if not (dt > 0 and math.isfinite(dt)):
        raise ValueError(f"dt must be a positive number of seconds (got {dt!r})")


def decision_ratio(control_period: float, dt: float) -> int:
    """Integration steps per decision: ``control_period / dt`` as a whole number >= 1.

    Raises:
        ValueError: ``dt`` is not a positive number, or ``control_period`` is not a positive
            whole multiple of it.

    >>> decision_ratio(0.25, 0.05)
    5
    """
    _check_dt(dt)
    n = _whole(control_period / dt)
    if not n:
        raise ValueError(
            f"control_period must be a positive multiple of dt={dt:g} s (got {control_period:g})"
        )
    return n


def step_count(t_max: float, dt: float) -> int:
    """Integration steps of an episode: ``t_max / dt`` as a whole number >= 1.

    Raises:
        ValueError: ``dt`` is not a positive number, or ``t_max`` is not a positive whole
            multiple of it (the last step would not end at ``t_max``).

    >>> step_count(24.0, 0.25)
    96
    """
    _check_dt(dt)
    n = _whole(t_max / dt)
    if not n:
        raise ValueError(
            f"t_max must be a whole multiple of dt={dt:g} s "
            f"(got {t_max:g} s: {t_max / dt:.6g} steps)"
        )
    return n


class Clock:
    """A world's time: ``n_steps`` steps of ``dt`` [s], a decision every ``ratio`` steps.

    Attributes:
        dt: integration step [s].
        ratio: integration steps per decision.
        n_steps: steps of the episode (:func:`step_count`).
        step_index: steps done.
        t: time now [s], ``step_index * dt``.
    """

    __slots__ = ("dt", "n_steps", "ratio", "step_index", "t")

    def __init__(self, dt: float, control_period: float, t_max: float) -> None:
        self.dt = float(dt)
        self.ratio = decision_ratio(float(control_period), self.dt)
        self.n_steps = step_count(float(t_max), self.dt)
        self.step_index = 0
        self.t = 0.0

    def tick(self) -> float:
        """One step done; returns the new time [s]."""
        self.step_index = k = self.step_index + 1
        self.t = t = k * self.dt
        return t

    @property
    def due(self) -> bool:
        """A decision is due at this step."""
        return self.step_index % self.ratio == 0

    @property
    def up(self) -> bool:
        """Every step of the episode is done."""
        return self.step_index >= self.n_steps


class Ledger:
    """One agent's outcome and sums over an episode (module docstring: the rules).

    The world adds to ``path`` [m], ``effort`` (see :class:`~uvnav.sim.metrics.EpisodeMetrics`)
    and ``violations`` as it integrates and applies commands, and reports each step's clearance
    and distance to the goal through :meth:`begin` and :meth:`judge`.

    Attributes:
        goal_tolerance: arrival radius [m].
        status: ``success``, ``collision`` or ``timeout`` (also while running).
        ended: the agent arrived or collided (its episode is over, whatever the clock says).
        reached_at: arrival time [s], ``None`` before.
        contact_at: time of the first contact of a collision [s] (``None`` without one).
        start_dist: distance from the start to the goal [m].
        min_clear: smallest clearance reported [m] (``inf`` before any, or without bodies).
        path, effort, violations: the sums the world keeps.
    """

    __slots__ = (
        "contact_at",
        "effort",
        "ended",
        "goal_tolerance",
        "min_clear",
        "path",
        "reached_at",
        "start_dist",
        "status",
        "violations",
    )

    def __init__(self, goal_tolerance: float) -> None:
        self.goal_tolerance = float(goal_tolerance)
        self.status = "timeout"
        self.ended = False
        self.reached_at: float | None = None
        self.contact_at: float | None = None
        self.start_dist = math.nan
        self.min_clear = math.inf
        self.path = 0.0
        self.effort = 0.0
        self.violations = 0

    @classmethod
    def settled(
        cls,
        goal_tolerance: float,
        *,
        status: str,
        start_dist: float,
        reached_at: float | None,
        path: float,
        effort: float,
        violations: int,
        min_clear: float,
    ) -> Ledger:
        """The ledger of an episode counted elsewhere (a compiled world's arrays; the time of
        a contact is not known there)."""
        book = cls(goal_tolerance)
        book.status, book.ended = status, status != "timeout"
        book.start_dist, book.reached_at = float(start_dist), reached_at
        book.path, book.effort, book.violations = float(path), float(effort), int(violations)
        book.min_clear = float(min_clear)
        return book

    def begin(self, clearance: float, goal_dist: float) -> bool:
        """The state at t = 0: collision, then arrival (at 0.0 s); returns :attr:`ended`."""
        self.start_dist = float(goal_dist)
        self.min_clear = float(clearance)
        if clearance < 0:
            self.status, self.ended, self.contact_at = "collision", True, 0.0
        elif goal_dist <= self.goal_tolerance:
            self.status, self.reached_at, self.ended = "success", 0.0, True
        return self.ended

    def judge(
        self, t: float, clearance: float, goal_dist: float, contact_at: float | None = None
    ) -> bool:
        """The state at the end of a step at time ``t`` [s]: collision (a ``clearance`` below 0
        [m], or a contact the world found along the step at ``contact_at`` [s]), then arrival;
        returns :attr:`ended`.  ``clearance`` may be a lower bound >= 0 where the exact value
        cannot matter (the world then passes the exact minimum to :meth:`metrics`)."""
        if clearance < self.min_clear:
            self.min_clear = clearance
        if contact_at is not None or clearance < 0:
            self.status, self.ended = "collision", True
            self.contact_at = t if contact_at is None else contact_at
        elif goal_dist <= self.goal_tolerance:
            self.status, self.reached_at, self.ended = "success", t, True
        return self.ended

    @property
    def shortest(self) -> float:
        """Straight distance from the start to the edge of the goal disc [m]."""
        return max(self.start_dist - self.goal_tolerance, 0.0)

    def metrics(
        self,
        log: AgentLog,
        *,
        top_speed: float,
        min_clearance: float | None = None,
        **extra: Any,
    ) -> EpisodeMetrics:
        """The agent's :class:`~uvnav.sim.metrics.EpisodeMetrics`.

        Args:
            log: what the loop measured for the agent (mode switches, decision times).
            top_speed: the vehicle's fastest speed along the start-goal line [m/s] (the time
                ratio's reference).
            min_clearance: the exact minimum clearance [m] when the world tracked it itself
                (default :attr:`min_clear`); ``None`` or infinite without bodies.
            extra: the social metrics of :func:`~uvnav.sim.metrics.episode_metrics`.
        """
        mc = self.min_clear if min_clearance is None else min_clearance
        shortest = self.shortest
        return episode_metrics(
            status=self.status,
            path_length=self.path,
            shortest=shortest,
            straight_time=shortest / top_speed if top_speed > 0 else 0.0,
            reached_at=self.reached_at if self.status == "success" else None,
            min_clearance=float(mc) if math.isfinite(mc) else None,
            control_effort=self.effort,
            limit_violations=self.violations,
            mode_switches=log.mode_switches,
            decision_us=log.timed_us,
            **extra,
        )


def group_outcome(
    setup: MultiSetup, status: Sequence[str], reached: Sequence[float | None], xy: FloatArray,
    window_start: FloatArray | None, t: float, robot_collisions: int, obstacle_collisions: int,
) -> GroupMetrics:  # fmt: skip
    """The group's outcome (:class:`~uvnav.sim.setup.GroupMetrics`, :mod:`uvnav.sim.multi`) from
    every robot's status, arrival time and position now [m], the positions at the start of the
    deadlock window (None: no step yet), the time [s] and the collision counts; a robot is stuck
    when it moved less than ``deadlock_distance`` since the window's start."""
    n = len(status)
    arrived = sum(s == "success" for s in status)
    all_arrived = arrived == n
    arrival_times = [a for a in reached if a is not None]
    moved = np.hypot(*(xy - window_start).T) if window_start is not None else np.zeros(n)
    stuck = sum(
        1
        for i in range(n)
        if status[i] == "timeout"
        and t >= setup.deadlock_window
        and moved[i] < setup.deadlock_distance
    )
    return GroupMetrics(
        all_arrived=all_arrived,
        arrived=int(arrived),
        robot_collisions=robot_collisions,
        obstacle_collisions=obstacle_collisions,
        makespan=max(arrival_times) if all_arrived else None,
        sum_of_times=float(sum(arrival_times)) if all_arrived else None,
        deadlocks=int(stuck),
    )


class OneVehicle:
    """What every one-vehicle world shares: one agent whose :class:`Ledger` (``book``) holds
    the status, a decision whenever the :class:`Clock` (``clock``) says, and the episode's one
    :class:`~uvnav.sim.setup.EpisodeResult`.  A world adds its own :meth:`metrics` and, where it
    has events of its own, :meth:`flags`."""

    n_agents: ClassVar[int] = 1
    book: Ledger
    clock: Clock

    @property
    def status(self) -> str:
        """``success``, ``collision`` or ``timeout`` (also while running)."""
        return self.book.status

    def acting(self) -> tuple[int, ...]:
        """``(0,)`` at a decision time (every ``control_period``), else ``()``."""
        clock = self.clock  # (clock.due, inline)
        return (0,) if clock.step_index % clock.ratio == 0 else ()

    def metrics(self, log: AgentLog, agent: int = 0) -> EpisodeMetrics:
        """The episode's metrics (each world's own)."""
        raise NotImplementedError

    def flags(self) -> dict[str, bool]:
        """The world's own events (none here)."""
        return {}

    def result(self, logs: Sequence[AgentLog], recorder: Any) -> EpisodeResult[Any]:
        """The episode's result: the metrics, status and first contact, the loop's decision
        times, ``recorder.finish()`` when recorded (the world's trajectory), the flags."""
        (log,) = logs
        return EpisodeResult(
            metrics=self.metrics(log),
            status=self.status,
            trajectory=recorder.finish() if recorder is not None else None,
            decision_us=log.decision_array(),
            contact_time=self.book.contact_at,
            flags=self.flags(),
        )
