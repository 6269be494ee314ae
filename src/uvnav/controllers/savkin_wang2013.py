"""``savkin-wang2013-v1``: the biologically inspired reactive law the thesis compares with in Ch. 2.

Reference: A. V. Savkin and C. Wang, "A simple biologically inspired algorithm for collision-free
navigation of a unicycle-like robot in dynamic environments with moving obstacles", *Robotica*
31(6), 2013; A. V. Savkin, A. S. Matveev, M. Hoy, C. Wang, *Safe Robot Navigation Among Moving and
Steady Obstacles*, Elsevier 2015, ch. 8.  Thesis Ch. 2 §2.1 and §2.4 (Figs. 2.9-2.10) describe it.

What is known of the law (and implemented as stated):

* Obstacles are discs of radius R moving at constant velocity v_obs.  For the obstacle being
  avoided, the robot sees it inside the vision cone between the two boundary rays at angles
  alpha_1 (clockwise) and alpha_2 (counter-clockwise); the cone is widened by alpha_0:
  ``beta_1 = alpha_1 - alpha_0``, ``beta_2 = alpha_2 + alpha_0``, with
  ``alpha_0 >= arccos(R / (R + d_safe))``.
* The two candidate avoidance vectors are ``l_j = (V_max - V) [cos beta_j, sin beta_j]`` with
  ``||v_obs|| <= V < V_max``: the robot's velocity relative to the obstacle runs along a widened
  cone boundary, so its absolute velocity ``v_obs + l_j`` has norm at most V_max.
* The side ``h = argmin_j |angle(v_obs + l_j, v_R)|`` is chosen when avoidance starts and kept.
* Steering: ``u = U_max f(v_obs + l_h, v_R)`` (turn toward the desired velocity, with the same
  boundary-layer sign function as the thesis's law, see ``heading_rate_toward``),
  ``V_R = ||v_obs + l_h||``.
* Constants of its own simulations: switching distance C = 1.5 m, sampling 0.1 s, V_M = 0.7 m/s.

Reconstructed (the exact switching rules were not available to us; this is documented as a
reconstruction in docs/thesis-notes.md):

* *Enter* avoidance when the nearest obstacle is within C and the robot's velocity *toward the
  target* at V_max, relative to the obstacle, points into the widened cone (a collision course).
* *Leave* avoidance (back to pure pursuit of the target at V_max) when that relative velocity no
  longer points into the widened cone — heading to the target has become safe.
* *Pure pursuit slows near T* (:func:`~uvnav.controllers.base.approach_speed`): at V_max a
  unicycle whose target lies inside its minimum turning circle (radius V_max / U_max) circles it
  for ever (measured: whole episodes at V_max round T); the speed is lowered to the
  largest one whose turning circle passes through T — the same rule as the thesis law's M1
  (``zhang2019-v1``, note 10), so the comparison does not turn on it.
* ``V`` is set to ``||v_obs||`` (the smallest value allowed), which gives the largest relative
  speed ``V_max - ||v_obs||`` along the cone boundary.
* Non-disc obstacles are replaced by their bounding disc about the mass centre (the law assumes
  discs); v_obs is whatever the sensing gives (true or finite-difference estimate), re-read at every
  decision — the law itself assumes it constant.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from uvnav.controllers.base import (
    ControllerInfo,
    UnicycleController,
    approach_speed,
    check_params,
    heading_rate_toward,
    register,
)
from uvnav.dynamics.unicycle import UnicycleCommand
from uvnav.geometry.angles import FloatArray, wrap_scalar
from uvnav.sensors.observation import Observation, ObstacleReading


@dataclass(frozen=True)
class SavkinWang2013Params:
    """Parameters of ``savkin-wang2013-v1``.

    Attributes:
        switch_distance: C [m], the distance at which avoidance may start (their value: 1.5 m).
        safe_distance: d_safe [m] kept between the robot's disc and the obstacle's disc.
        alpha0_min: lower bound [rad] on the cone widening alpha_0; the widening actually used is
            ``max(alpha0_min, arccos(R / (R + r_robot + d_safe)))``.
    """

    switch_distance: float = 1.5
    safe_distance: float = 0.15
    alpha0_min: float = 0.0

    def __post_init__(self) -> None:
        check_params(
            self, positive=("switch_distance",), non_negative=("safe_distance", "alpha0_min")
        )
        if self.alpha0_min >= 0.5 * math.pi:
            raise ValueError(f"alpha0_min must be < pi/2 rad (got {self.alpha0_min})")


def disc_of(reading: ObstacleReading) -> tuple[FloatArray, float]:
    """The disc the law assumes: the body's own for a disc, the bounding disc otherwise."""
    return reading.centre, (reading.radius if reading.is_disc else reading.bounding_radius)


def widened_cone(
    position: FloatArray, centre: FloatArray, radius: float, alpha0: float
) -> tuple[float, float]:
    """Angles (beta_1, beta_2) [rad] of the widened vision cone of a disc seen from ``position``.

    ``beta_1 = alpha_1 - alpha_0`` (clockwise boundary), ``beta_2 = alpha_2 + alpha_0``.  From
    inside
    the disc the cone is the half-plane facing it (half-angle pi/2).
    """
    ox, oy = float(centre[0]) - float(position[0]), float(centre[1]) - float(position[1])
    dist = math.hypot(ox, oy)
    base = math.atan2(oy, ox)
    half = math.asin(min(radius / dist, 1.0)) if dist > 0 else 0.5 * math.pi
    half = min(half + alpha0, math.pi)
    return wrap_scalar(base - half), wrap_scalar(base + half)


def in_cone(direction: FloatArray | tuple[float, float], beta1: float, beta2: float) -> bool:
    """True when ``direction`` points strictly inside the cone from ``beta1`` CCW to ``beta2``."""
    if math.hypot(direction[0], direction[1]) < 1e-12:
        return False
    ang = math.atan2(direction[1], direction[0])
    width = (beta2 - beta1) % (2.0 * math.pi)
    return 0.0 < (ang - beta1) % (2.0 * math.pi) < width


class SavkinWang2013Controller(UnicycleController):
    """Savkin & Wang (2013), with the reconstruction described in the module docstring."""

    name: ClassVar[str] = "savkin-wang2013-v1"

    def __init__(self, params: SavkinWang2013Params | None = None) -> None:
        super().__init__()
        self.params = params or SavkinWang2013Params()
        self._target_id: int | None = None
        self._side = 0

    def _reset_law(self, rng: np.random.Generator) -> None:
        self._target_id = None
        self._side = 0

    def alpha0(self, radius: float) -> float:
        """Cone widening alpha_0 = max(alpha0_min, arccos(R / (R + r_robot + d_safe))) [rad]."""
        grown = radius + self._spec.radius + self.params.safe_distance
        return max(
            self.params.alpha0_min, math.acos(min(radius / grown, 1.0)) if grown > 0 else 0.0
        )

    def collision_course(
        self, position: FloatArray, reading: ObstacleReading
    ) -> tuple[bool, float, float]:
        """Whether heading to T at V_max points into the widened cone; also (beta_1, beta_2)."""
        centre, radius = disc_of(reading)
        b1, b2 = widened_cone(position, centre, radius, self.alpha0(radius))
        gx, gy = (
            float(self._goal[0]) - float(position[0]),
            float(self._goal[1]) - float(position[1]),
        )
        dist = math.hypot(gx, gy)
        if dist < 1e-9:
            return False, b1, b2
        v_max, vel = self._spec.v_max, reading.velocity
        rel = (v_max * gx / dist - float(vel[0]), v_max * gy / dist - float(vel[1]))
        return in_cone(rel, b1, b2), b1, b2

    def desired_velocity(self, reading: ObstacleReading, beta: float) -> tuple[float, float]:
        """v_obs + l_j with l_j = (V_max - V) [cos beta_j, sin beta_j] and V = ||v_obs||
        [m/s]."""
        speed_obs = min(reading.speed, self._spec.v_max)
        scale = self._spec.v_max - speed_obs
        vel = reading.velocity
        return float(vel[0]) + scale * math.cos(beta), float(vel[1]) + scale * math.sin(beta)

    def act(self, obs: Observation) -> UnicycleCommand:
        period = self.decision_period(obs.time)
        pos = obs.position
        heading = obs.heading
        reading = obs.obstacles[0] if obs.obstacles else None
        avoiding = None
        if reading is not None and reading.distance <= self.params.switch_distance:
            on_course, b1, b2 = self.collision_course(pos, reading)
            if on_course:
                avoiding = (reading, b1, b2)
        if avoiding is None:
            self._mode, self._target_id, self._side = "M1", None, 0
            gx, gy = float(self._goal[0]) - float(pos[0]), float(self._goal[1]) - float(pos[1])
            beta = wrap_scalar(math.atan2(gy, gx) - heading)
            dist = math.hypot(gx, gy)
            v = approach_speed(self._spec.v_max, self._spec.u_max, dist, beta)
            return UnicycleCommand(v, heading_rate_toward(beta, self._spec.u_max, period))
        reading, b1, b2 = avoiding
        candidates = (self.desired_velocity(reading, b1), self.desired_velocity(reading, b2))
        if self._mode != "M2" or reading.obstacle_id != self._target_id:
            # side h chosen when avoidance starts: the one closest to the current velocity direction
            errors = [abs(wrap_scalar(math.atan2(v[1], v[0]) - heading)) for v in candidates]
            self._side = 0 if errors[0] <= errors[1] else 1
            self._target_id = reading.obstacle_id
        self._mode = "M2"
        desired = candidates[self._side]
        beta = wrap_scalar(math.atan2(desired[1], desired[0]) - heading)
        speed = min(math.hypot(desired[0], desired[1]), self._spec.v_max)
        return UnicycleCommand(speed, heading_rate_toward(beta, self._spec.u_max, period))


register(
    ControllerInfo(
        name="savkin-wang2013-v1",
        factory=SavkinWang2013Controller,
        params_type=SavkinWang2013Params,
        summary="Savkin & Wang 2013 biologically inspired law (discs, constant velocity); "
        "switching rules reconstructed.",
        reference="A. V. Savkin, C. Wang, Robotica 31(6), 2013",
        requires_slower_obstacles=True,
    )
)
