"""``apf-v1``: artificial potential field, the classical reactive baseline for the thesis's Ch. 2.

Reference: O. Khatib, "Real-time obstacle avoidance for manipulators and mobile robots",
*The International Journal of Robotics Research* 5(1), 1986 — §2 "the artificial potential
field" (attractive potential of the goal, U_xd = 1/2 k_p (x - x_d)^2) and §3 "FIRAS function"
(repulsive potential U_O = 1/2 eta (1/rho - 1/rho_0)^2 for rho <= rho_0, 0 beyond, and its force
F = eta (1/rho - 1/rho_0) (1/rho^2) d rho/dx).  The equation numbers of the printed paper were not
available to us; the names above are the paper's.  The local-minimum escape follows the common
"vortex field" / wall-following remedy (A. De Luca, G. Oriolo, "Local incremental planning for
nonholonomic mobile robots", ICRA 1994; Borenstein & Koren's discussion of APF traps, ICRA 1991).

Choices for the thesis's unicycle (2.1)-(2.4) and sensing model (§2.2), which gives each
obstacle's distance d_i and nearest point r_min:

* **Forces are desired velocities** [m/s] (the unicycle is kinematic: there is no mass to push).
  Attraction: quadratic potential inside ``attract_switch`` d* (F = k (T - p), vanishing at T so
  the robot slows onto it) and conic beyond (F = k d* (T - p) / ||T - p||, constant magnitude
  k d*; the usual combination, since a purely quadratic potential pulls hardest far away).
  Repulsion: Khatib's FIRAS force for each sensed obstacle with rho = d_i - r_robot (the gap
  between the robot's disc and the body, floored at ``min_distance``) inside the influence
  distance rho_0, directed from r_min to the robot (grad rho); from inside a body, from its centre.
  Obstacle velocities are *not* used: Khatib's field is static (the DWA baseline predicts).
* **Tracking.** The unicycle turns toward the force with the thesis-style bounded heading law
  u = U_max sat(err / (U_max T)) (:func:`uvnav.controllers.base.heading_rate_toward`, T the decision
  period) and drives at V = min(||F||, V_max) max(cos err, 0): it slows while turning and stops
  to turn in place when the force points behind it.
* **Local minima** (``escape=True``).  A *stall* is declared when an obstacle is within rho_0 and
  either the net force is below ``stall_force`` or the distance to T has shrunk by less than
  ``stall_progress`` over the last ``stall_window`` seconds.  The law then wall-follows the
  nearest obstacle (mode ``"ESCAPE"``): V_max along the tangent on a side drawn from the
  generator given to ``reset`` (deterministic per seed), with a radial correction
  ``follow_gain (follow_distance - rho)`` that holds the gap near ``follow_distance``.  It leaves
  (back to ``"M1"``) once the distance to T is ``leave_margin`` below its value at the stall —
  Bug-2's leave rule, which guarantees the robot does not fall back into the same basin — or when
  no obstacle is within rho_0; after ``escape_timeout`` seconds without leaving it follows the
  other way.  With ``escape=False`` this is the plain APF, which stalls in such traps.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from uvnav.controllers.base import (
    ControllerInfo,
    UnicycleController,
    check_params,
    heading_rate_toward,
    register,
)
from uvnav.dynamics.unicycle import UnicycleCommand
from uvnav.geometry.angles import FloatArray
from uvnav.geometry.small import wrap
from uvnav.sensors.observation import Observation, ObstacleReading


@dataclass(frozen=True)
class ApfParams:
    """Parameters of ``apf-v1``.

    Attributes:
        attract_gain: k, attractive gain [1/s] (force per metre to T, as a velocity).
        attract_switch: d* [m]: quadratic attraction within, conic beyond.
        repulse_gain: eta, FIRAS gain [m^3/s].
        influence: rho_0, influence distance of an obstacle [m].
        min_distance: floor of rho [m] (keeps the repulsion finite on contact).
        escape: enable the local-minimum escape (False: plain APF).
        stall_window: time window [s] of the progress test.
        stall_progress: least decrease [m] of the distance to T over the window.
        stall_force: net force [m/s] below which the robot is stalled.
        follow_distance: gap [m] held to the obstacle while escaping.
        follow_gain: radial correction gain [1/m] while escaping.
        leave_margin: the escape ends this much [m] closer to T than at the stall.
        escape_timeout: time [s] after which an unfinished escape reverses its side.
    """

    attract_gain: float = 1.0
    attract_switch: float = 1.0
    repulse_gain: float = 0.05
    influence: float = 1.0
    min_distance: float = 0.02
    escape: bool = True
    stall_window: float = 3.0
    stall_progress: float = 0.1
    stall_force: float = 0.05
    follow_distance: float = 0.35
    follow_gain: float = 3.0
    leave_margin: float = 0.1
    escape_timeout: float = 40.0

    def __post_init__(self) -> None:
        check_params(
            self,
            positive=(
                "attract_gain",
                "attract_switch",
                "influence",
                "min_distance",
                "stall_window",
                "follow_distance",
                "escape_timeout",
            ),
            non_negative=(
                "repulse_gain",
                "stall_progress",
                "stall_force",
                "follow_gain",
                "leave_margin",
            ),
        )
        if self.min_distance >= self.influence:
            raise ValueError(
                f"min_distance must be < influence (got {self.min_distance} >= {self.influence})"
            )
        if not isinstance(self.escape, bool):
            raise ValueError(f"escape must be a bool (got {self.escape!r})")


def attractive_force(
    position: FloatArray, goal: FloatArray, gain: float, switch: float
) -> FloatArray:
    """Attractive force [m/s]: k (T - p) within ``switch`` d* [m] of T, k d* (T - p) / ||T - p||
    beyond."""
    diff = np.asarray(goal, dtype=float) - np.asarray(position, dtype=float)
    d = math.hypot(diff[0], diff[1])
    if d <= switch:
        return np.asarray(gain * diff, dtype=float)
    return np.asarray(gain * switch * diff / d, dtype=float)


def away_direction(position: FloatArray, reading: ObstacleReading, heading: float) -> FloatArray:
    """Unit grad rho: from the nearest point to the robot; from the centre when the robot is on
    (or in) the body; straight back when it sits on the centre too."""
    refs = (reading.nearest_point, reading.centre) if reading.distance > 1e-9 else (reading.centre,)
    for ref in refs:
        off = np.asarray(position, dtype=float) - np.asarray(ref, dtype=float)
        n = math.hypot(off[0], off[1])
        if n > 1e-9 and math.isfinite(n):
            return np.asarray(off / n, dtype=float)
    return np.array([-math.cos(heading), -math.sin(heading)])


def gap_of(reading: ObstacleReading, robot_radius: float, floor: float) -> float:
    """rho [m]: gap between the robot's disc and the body, floored at ``floor``."""
    d = reading.distance - robot_radius
    return max(d, floor) if math.isfinite(d) else floor


def firas_force(
    position: FloatArray,
    heading: float,
    readings: tuple[ObstacleReading, ...],
    *,
    robot_radius: float,
    eta: float,
    rho0: float,
    floor: float,
) -> FloatArray:
    """Sum of Khatib's FIRAS forces eta (1/rho - 1/rho0) / rho^2 grad rho [m/s] of the obstacles
    within rho0."""
    total = np.zeros(2)
    for r in readings:
        rho = gap_of(r, robot_radius, floor)
        if rho > rho0:
            continue
        mag = eta * (1.0 / rho - 1.0 / rho0) / (rho * rho)
        total += mag * away_direction(position, r, heading)
    return total


class ApfController(UnicycleController):
    """Khatib's artificial potential field with a wall-following escape (module docstring)."""

    name: ClassVar[str] = "apf-v1"

    def __init__(self, params: ApfParams | None = None) -> None:
        super().__init__()
        self.params = params or ApfParams()
        self._rng = np.random.default_rng(0)
        self._history: deque[tuple[float, float]] = deque()
        self._side = 1
        self._stall_distance = math.inf
        self._escape_start = 0.0
        #: number of stalls detected in the episode (for inspection and tests)
        self.stalls = 0

    def _reset_law(self, rng: np.random.Generator) -> None:
        self._rng = rng
        self._history.clear()
        self._side = 1
        self._stall_distance = math.inf
        self._escape_start = 0.0
        self.stalls = 0

    def force(self, obs: Observation) -> FloatArray:
        """Net APF force [m/s] (attraction plus FIRAS repulsion) at the observed pose."""
        p = self.params
        pos = np.asarray(obs.position, dtype=float)
        f = attractive_force(pos, self._goal, p.attract_gain, p.attract_switch)
        f = f + firas_force(
            pos,
            obs.heading,
            obs.obstacles,
            robot_radius=self._spec.radius,
            eta=p.repulse_gain,
            rho0=p.influence,
            floor=p.min_distance,
        )
        return f

    def _escape_force(self, obs: Observation, reading: ObstacleReading) -> FloatArray:
        p = self.params
        n = away_direction(obs.position, reading, obs.heading)
        tangent = self._side * np.array([-n[1], n[0]])
        rho = gap_of(reading, self._spec.radius, p.min_distance)
        corr = max(-1.0, min(1.0, p.follow_gain * (p.follow_distance - rho)))
        f = tangent + corr * n
        norm = math.hypot(f[0], f[1])
        return np.asarray(self._spec.v_max * f / max(norm, 1e-9), dtype=float)

    def _update_mode(self, obs: Observation, net: FloatArray, d_goal: float, t: float) -> None:
        p = self.params
        near = [
            r for r in obs.obstacles if gap_of(r, self._spec.radius, p.min_distance) <= p.influence
        ]
        if self._mode == "ESCAPE":
            if not near or d_goal < self._stall_distance - p.leave_margin:
                self._mode = "M1"
                self._history.clear()
            elif t - self._escape_start > p.escape_timeout:
                self._side = -self._side
                self._escape_start = t
            return
        self._history.append((t, d_goal))
        while len(self._history) > 1 and t - self._history[1][0] >= p.stall_window:
            self._history.popleft()
        t0, d0 = self._history[0]
        no_progress = t - t0 >= p.stall_window and d0 - d_goal < p.stall_progress
        weak = math.hypot(net[0], net[1]) < p.stall_force
        if near and (no_progress or weak):
            self._mode = "ESCAPE"
            self.stalls += 1
            self._side = 1 if self._rng.random() < 0.5 else -1
            self._stall_distance = d_goal
            self._escape_start = t
            self._history.clear()

    def act(self, obs: Observation) -> UnicycleCommand:
        spec = self._spec
        t = float(obs.time) if math.isfinite(obs.time) else 0.0
        period = self.decision_period(t)
        pos = np.asarray(obs.position, dtype=float)
        d_goal = float(np.hypot(*(self._goal - pos)))
        net = self.force(obs)
        if self.params.escape:
            self._update_mode(obs, net, d_goal, t)
        if self._mode == "ESCAPE" and obs.obstacles:
            net = self._escape_force(obs, obs.obstacles[0])
        if not np.all(np.isfinite(net)):
            return UnicycleCommand(0.0, 0.0)
        mag = math.hypot(net[0], net[1])
        if mag < 1e-12:
            return UnicycleCommand(0.0, 0.0)
        err = wrap(math.atan2(net[1], net[0]) - obs.heading)
        v = min(mag, spec.v_max) * max(math.cos(err), 0.0)
        u = heading_rate_toward(err, spec.u_max, period)
        return UnicycleCommand(float(min(max(v, 0.0), spec.v_max)), u)


register(
    ControllerInfo(
        name="apf-v1",
        factory=ApfController,
        params_type=ApfParams,
        summary="Khatib artificial potential field (conic/quadratic attraction, FIRAS repulsion) "
        "with a wall-following local-minimum escape.",
        reference="O. Khatib, Int. J. Robotics Research 5(1), 1986",
    )
)
