"""The unicycle's decision of ``zhang2019-v2`` on rolled-out paths, from the observation to the
compiled loop and back, on floats (:mod:`uvnav.controllers.zhang2019_v2`, "Acceleration
limits").

What a decision costs outside the compiled loop
(:func:`uvnav.controllers.zhang2019_v2_paths.plan_paths`) is a few dozen small numpy operations
of about a microsecond each; here the same values are computed on Python floats, with the same
operations in the same order (IEEE arithmetic rounds a float the same in numpy and in Python;
``math.hypot`` is the one the numpy building blocks call too), so the loop receives the same
numbers and the choice is the same to the bit (tests).  Units: metres, seconds, radians.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from uvnav.controllers.zhang2019_limits import RampModel
from uvnav.controllers.zhang2019_v2_bodies import body_table
from uvnav.controllers.zhang2019_v2_loop import outline_rings
from uvnav.controllers.zhang2019_v2_paths import plan_paths
from uvnav.dynamics.unicycle import UnicycleSpec
from uvnav.geometry.angles import FloatArray
from uvnav.sensors.observation import Observation


def preferred_floats(
    px: float, py: float, gx: float, gy: float, model: RampModel
) -> tuple[float, float]:
    """:func:`uvnav.controllers.zhang2019_limits.preferred_under_limits` of the position
    ``(px, py)`` and goal ``(gx, gy)`` [m], as two floats [m/s].

    >>> m = RampModel(1.0, 1.0, 0.5, math.inf, 0.25)
    >>> preferred_floats(0.0, 0.0, 8.0, 6.0, m)  # V_max toward the goal
    (0.8, 0.6)
    >>> preferred_floats(0.0, 0.0, 0.08, 0.06, m)  # 0.1 m away: sqrt(2 a d) = 0.316 m/s
    (0.25298221281347033, 0.18973665961010275)
    """
    dx, dy = gx - px, gy - py
    dist = math.hypot(dx, dy)
    if not math.isfinite(dist) or dist < 1e-12:  # toward_goal's zeros
        fx, fy = 0.0, 0.0
    else:
        scale = min(model.v_max, dist / model.period)
        fx, fy = dx / dist * scale, dy / dist * scale
    speed = math.hypot(fx, fy)
    cap = math.sqrt(2.0 * model.accel * dist)
    if speed > cap:
        ratio = cap / speed
        return fx * ratio, fy * ratio
    return fx, fy


def path_constants(model: RampModel, params: Any, robot_radius: float) -> FloatArray:
    """The ``prm`` vector of :func:`uvnav.controllers.zhang2019_v2_paths.plan_readings_py` of a
    law's parameters (:class:`~uvnav.controllers.zhang2019_v2.Zhang2019V2Params`); a
    standing body's spread is capped at ``still_cap`` on a vehicle with acceleration limits
    only."""
    p = params
    still_cap = p.still_cap if p.still_cap > 0.0 and not model.ideal else math.inf
    return np.array((model.v_max, model.u_max, model.accel, model.turn_accel, model.period,
                     p.horizon, p.rollout_step, p.comfort, p.comfort_horizon, p.safety_margin,
                     p.limited_spread, p.min_ttc, p.w_ttc, p.w_comfort, p.w_change,
                     p.forecast_horizon, p.max_tangent_bodies, p.n_headings, robot_radius,
                     p.spacing, p.comfort_min_speed, still_cap, float(model.turn_first)),
                    dtype=float)  # fmt: skip


def ramp_model(spec: UnicycleSpec, period: float) -> RampModel:
    """What the law knows of its vehicle ``spec`` at the decision period ``period`` [s]: its
    limits and whether it turns first (``turn-then-move``) or along arcs."""
    return RampModel(spec.v_max, spec.u_max, spec.accel_max, spec.turn_accel_max, period,
                     turn_first=spec.kinematics == "turn-then-move")  # fmt: skip


class PathConstants:
    """:func:`uvnav.controllers.zhang2019_v2.plan_limited`'s ``constants`` and the vehicle
    model they were made for, kept while the law's parameters are the same object and its
    vehicle spec, radius and decision period are the same."""

    def __init__(self) -> None:
        self._of: tuple[object, UnicycleSpec, float] | None = None
        self._value: tuple[RampModel, FloatArray, FloatArray] | None = None

    def get(
        self, params: Any, spec: UnicycleSpec, period: float
    ) -> tuple[RampModel, FloatArray, FloatArray]:
        """The :class:`RampModel` of ``spec`` (a unicycle's) at ``period`` [s], then
        :func:`path_constants` of ``params``, that model and ``spec``'s radius, and the
        speeds of ``params``' levels [m/s]."""
        of, value = self._of, self._value
        if value is not None and of is not None and of[0] is params and of[1] is spec:
            if of[2] == period:
                return value
            model = ramp_model(spec, period)
            if model != value[0]:
                value = (model, path_constants(model, params, float(spec.radius)), value[2])
        else:
            model = ramp_model(spec, period)
            speeds = model.v_max * np.asarray(params.speed_levels, dtype=float)
            value = (model, path_constants(model, params, float(spec.radius)), speeds)
        self._of, self._value = (params, spec, period), value
        return value


def plan_on_floats(
    obs: Observation,
    goal: FloatArray,
    model: RampModel,
    now: tuple[float, float],
    v_prev: FloatArray,
    noise_sigmas: float,
    constants: tuple[FloatArray, FloatArray],
) -> FloatArray:
    """:func:`uvnav.controllers.zhang2019_v2.plan_limited`'s loop path (no social term):
    ``(vx, vy, ttc, preferred)`` of :func:`~uvnav.controllers.zhang2019_v2_paths.plan_paths`,
    the preferred velocity and the state vector made on floats."""
    pose = obs.pose
    px, py = float(pose[0]), float(pose[1])
    fx, fy = preferred_floats(px, py, float(goal[0]), float(goal[1]), model)
    ox, oy = float(v_prev[0]), float(v_prev[1])
    moving = 1.0 if math.hypot(ox, oy) > 1e-9 else 0.0  # as extra_headings
    state = np.array((px, py, float(pose[2]), now[0], now[1], fx, fy, math.hypot(fx, fy),
                      ox, oy, moving), dtype=float)  # fmt: skip
    readings = obs.obstacles
    table = body_table(readings, noise_sigmas)
    prm, speeds = constants
    return plan_paths(state, table, outline_rings(readings, table[0]), speeds, prm)
