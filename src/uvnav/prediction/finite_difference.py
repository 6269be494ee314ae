"""Velocity and rotation-rate estimates from what was seen (finite differences).

The thesis (Ch. 2 §2.2) assumes v_i and u_i are available; on a real robot they are estimated from
successive sightings.  :class:`FiniteDifferenceEstimator` replaces the true rates in each
:class:`~uvnav.sensors.ObstacleReading` by backward differences of the (optionally noisy) observed
mass centre and outline orientation:

    v_i(t) ~ (c_i(t) - c_i(t - dt_s)) / dt_s,
    u_i(t) ~ angle of the best rotation mapping the centred outline at t - dt_s onto the one at t
             (2D Kabsch: atan2 of the summed cross / dot products) / dt_s.

An obstacle seen for the first time gets zero rates.  Gaussian noise of ``position_noise`` [m] is
added to the observed centre (and outline, rigidly) before differencing, and each reading declares
its centre's noise (``position_std``): the incoming reading's own (a lidar's fitted centre, say)
and the added noise, independent, combined as ``hypot(position_std, position_noise)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.sensors.observation import ObstacleReading


@dataclass
class FiniteDifferenceEstimator:
    """Stateful estimator over a whole episode; call :meth:`update` once per decision."""

    rng: np.random.Generator
    position_noise: float = 0.0
    _last: dict[int, tuple[float, FloatArray, FloatArray]] = field(default_factory=dict)

    def update(
        self, time: float, readings: tuple[ObstacleReading, ...]
    ) -> tuple[ObstacleReading, ...]:
        out = []
        for rd in readings:
            noise = (
                self.rng.normal(0.0, self.position_noise, 2)
                if self.position_noise > 0
                else np.zeros(2)
            )
            centre = rd.centre + noise
            shape = rd.outline - rd.centre if len(rd.outline) else np.zeros((0, 2))
            velocity = np.zeros(2)
            omega = 0.0
            prev = self._last.get(rd.obstacle_id)
            if prev is not None and time > prev[0]:
                dt = time - prev[0]
                velocity = (centre - prev[1]) / dt
                if len(shape) and len(prev[2]) == len(shape):
                    a, b = prev[2], shape
                    cross = float(np.sum(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]))
                    dot = float(np.sum(a * b))
                    omega = float(np.arctan2(cross, dot)) / dt
            self._last[rd.obstacle_id] = (time, centre, shape)
            out.append(
                replace(
                    rd,
                    centre=centre,
                    outline=shape + centre if len(shape) else rd.outline,
                    nearest_point=rd.nearest_point + noise,
                    velocity=velocity,
                    angular_velocity=omega,
                    velocity_source="estimated",
                    position_std=math.hypot(rd.position_std, self.position_noise),
                )
            )
        return tuple(out)
