r"""Pedestrians that walk by the social force model (Helbing and Molnár).

Reference: D. Helbing, P. Molnár, "Social force model for pedestrian dynamics", *Physical Review
E* 51 (1995) 4282-4286: eq. (1) the driving term, eqs. (3)-(4) the repulsion of other
pedestrians; the circular form of the repulsion (a function of the gap between two discs) is that
of D. Helbing, I. Farkas, T. Vicsek, "Simulating dynamical features of escape panic", *Nature* 407
(2000) 487-490, eq. (1).  For pedestrian i with goal g_i, preferred speed v0_i and velocity v_i::

    a_i = (v0_i e_i - v_i) / tau                      driving term, e_i = (g_i - p_i) / |g_i - p_i|
        + sum_j  A exp(-b_ij / B) n_ij                  other pedestrians (and a visible robot)

with b_ij the gap between the two discs (centre distance minus both radii) and n_ij the unit vector
from j to i.  Defaults: tau = 0.5 s and the repulsion V0 / sigma = 2.1 / 0.3 = 7 m/s^2 with range
B = sigma = 0.3 m, Helbing and Molnár's values (their potential V0 exp(-b / sigma) has the force
(V0 / sigma) exp(-b / sigma)); the speed is capped at 1.3 v0_i (their v_max = 1.3 v0).  Within
``goal_radius`` of its goal a pedestrian's desired velocity is zero (it stops there).  The
anisotropy of the 1995 paper (less reaction to what is behind) and walls are left out.

Integration: semi-implicit Euler at every integration step ``dt`` (velocity first, then position
with the new velocity); forces come from the state at the start of the step, for every pedestrian
at once.  Nothing is random: the same start gives the same trajectory.

A crowd is one shared state (:class:`ForceCrowd`) that advances once per time step whichever
member is stepped first, so the per-model ``step`` and the batched group agree bit for bit: the
members are :class:`~uvnav.obstacles.crowd.CrowdMember`\ s, joined by
:func:`~uvnav.obstacles.crowd.join_crowds` like the ORCA pedestrians.  **A visible robot**
(``sees_robot``) repels the pedestrians like one more pedestrian, at the position and radius the
world reports before every step (:meth:`ForceCrowd.see_robot`).

Why not the ``pysocialforce`` package: its last release is from 2020, it steps a whole scene of
its own (state arrays, groups, wall lines, a TOML configuration) with no way to take one
externally moving robot per step, and its extended model (groups, fields of view) is not the
model the crowd-navigation papers cite; the model above is twenty lines of numpy.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.obstacles.crowd import CrowdMember

TAU = 0.5  # relaxation time [s] (Helbing and Molnár 1995)
STRENGTH = 7.0  # A = V0 / sigma = 2.1 / 0.3 [m/s^2]
RANGE = 0.3  # B = sigma [m]
SPEED_CAP = 1.3  # v_max / v0
CUTOFF = 5.0  # pedestrians farther apart than this [m] do not interact (exp(-5/0.3) ~ 6e-8)
GOAL_RADIUS = 0.3  # within this of its goal a pedestrian stops [m]
DEFAULT_CROWD = "social"


@dataclass
class SocialForcePedestrian(CrowdMember):
    """One pedestrian of a social-force crowd (module docstring).

    Attributes:
        goal: where it walks to [m], shape (2,).
        v_pref: preferred speed v0 [m/s].
        crowd_id: pedestrians with the same id form one crowd.
        tau: relaxation time [s].
        strength: repulsion A [m/s^2].
        range: repulsion range B [m].
        goal_radius: distance to the goal within which it stops [m].
        sees_robot: a visible robot repels it.
    """

    goal: FloatArray
    v_pref: float = 1.0
    crowd_id: str = DEFAULT_CROWD
    tau: float = TAU
    strength: float = STRENGTH
    range: float = RANGE
    goal_radius: float = GOAL_RADIUS
    sees_robot: bool = False
    crowd: ForceCrowd | None = field(default=None, init=False, repr=False)
    index: int = field(default=-1, init=False, repr=False)

    def __post_init__(self) -> None:
        self.goal = np.asarray(self.goal, dtype=float).reshape(2)
        for name in ("v_pref", "tau", "strength", "range"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be > 0 (got {value!r})")
        if not (math.isfinite(self.goal_radius) and self.goal_radius >= 0):
            raise ValueError(f"goal_radius must be >= 0 (got {self.goal_radius!r})")

    def speed_bound(self) -> float:
        """The speed cap 1.3 v0 [m/s]."""
        return SPEED_CAP * float(self.v_pref)

    @classmethod
    def make_crowd(
        cls,
        members: Sequence[Any],
        positions: FloatArray,
        velocities: FloatArray,
        radii: Sequence[float],
    ) -> ForceCrowd:
        return ForceCrowd(members, positions, velocities, radii)


def social_acceleration(
    position: FloatArray,
    velocity: FloatArray,
    goal: FloatArray,
    v_pref: FloatArray,
    radius: FloatArray,
    params: FloatArray,
    robot: tuple[FloatArray, float] | None = None,
) -> FloatArray:
    """Every pedestrian's acceleration [m/s^2], shape (n, 2) (module docstring).

    Args:
        position, velocity, goal: (n, 2) [m], [m/s], [m]; v_pref, radius: (n,) [m/s], [m];
        params: (n, 4) rows ``tau, A, B, goal_radius``; robot: its position (2,) and radius.

    >>> a = social_acceleration(np.zeros((1, 2)), np.zeros((1, 2)), np.array([[3.0, 4.0]]),
    ...     np.ones(1), np.full(1, 0.3), np.array([[0.5, 7.0, 0.3, 0.3]]))
    >>> a.round(3).tolist()
    [[1.2, 1.6]]
    """
    tau, strength, rng_b, goal_r = params.T
    gap = goal - position
    dist = np.hypot(gap[:, 0], gap[:, 1])
    safe = np.where(dist > 0, dist, 1.0)
    desired = np.where((dist > goal_r)[:, None], gap / safe[:, None] * v_pref[:, None], 0.0)
    acc = (desired - velocity) / tau[:, None]
    others = [(position, radius)]
    if robot is not None:
        others.append((np.asarray(robot[0], dtype=float).reshape(1, 2), np.array([robot[1]])))
    n = len(position)
    for pos_j, rad_j in others:
        diff = position[:, None, :] - pos_j[None, :, :]  # (n, m, 2), from j to i
        d = np.hypot(diff[..., 0], diff[..., 1])
        same = pos_j is position
        if same:
            d = d + np.where(np.eye(n, dtype=bool), np.inf, 0.0)
        near = d < CUTOFF
        b = d - radius[:, None] - rad_j[None, :]
        mag = np.where(near, strength[:, None] * np.exp(-b / rng_b[:, None]), 0.0)
        unit = diff / np.where(d > 0, d, 1.0)[..., None]
        acc = acc + np.sum(mag[..., None] * unit, axis=1)
    return acc


class ForceCrowd:
    """The shared state of one social-force crowd (module docstring)."""

    def __init__(
        self,
        members: Sequence[SocialForcePedestrian],
        positions: FloatArray,
        velocities: FloatArray,
        radii: Sequence[float],
    ) -> None:
        self.members = list(members)
        n = len(self.members)
        self.position = np.array(positions, dtype=float).reshape(n, 2)
        self.velocity = np.array(velocities, dtype=float).reshape(n, 2)
        self.radius = np.array(radii, dtype=float).reshape(n)
        self.goal = np.array([m.goal for m in self.members]).reshape(n, 2)
        self.v_pref = np.array([m.v_pref for m in self.members], dtype=float)
        self.params = np.array(
            [[m.tau, m.strength, m.range, m.goal_radius] for m in self.members], dtype=float
        ).reshape(n, 4)
        self.sees_robot = any(m.sees_robot for m in self.members)
        self.robot: tuple[FloatArray, float] | None = None
        self._from: float | None = None
        self._dt: float | None = None

    def see_robot(self, position: FloatArray, velocity: FloatArray, radius: float) -> None:
        """The robot's state now (it repels the crowd at the next step when visible)."""
        if self.sees_robot:
            self.robot = (np.array(position[:2], dtype=float), float(radius))

    def advance(self, t: float, dt: float) -> None:
        """Advance from ``t`` [s] by ``dt`` [s], once per step (semi-implicit Euler)."""
        if self._from == t and self._dt == dt:
            return
        acc = social_acceleration(
            self.position, self.velocity, self.goal, self.v_pref, self.radius, self.params,
            self.robot if self.sees_robot else None,
        )  # fmt: skip
        vel = self.velocity + acc * dt
        speed = np.hypot(vel[:, 0], vel[:, 1])
        cap = SPEED_CAP * self.v_pref
        vel = vel * np.where(speed > cap, cap / np.where(speed > 0, speed, 1.0), 1.0)[:, None]
        self.velocity = vel
        self.position = self.position + vel * dt
        self._from, self._dt = t, dt
