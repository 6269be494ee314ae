"""Tracking sensed bodies: a constant-velocity Kalman filter on their observed centres.

Where the rates of a body are *estimated* (:mod:`uvnav.prediction.finite_difference`: backward
differences of noisy centres), the velocity a law reads carries the centre noise amplified by
1/dt_s: with 0.1 m of noise and a 0.25 s decision period its standard deviation is about
0.1 sqrt(2) / 0.25 = 0.57 m/s, as large as a walking person's speed.  A law that plans on those
velocities sees people rush about at random.  The textbook remedy (Kalman 1960; Bar-Shalom, Li and
Kirubarajan, *Estimation with Applications to Tracking and Navigation*, 2001, §6.3.2, the
discrete white-noise acceleration model) is a filter per body on its centre, per axis:

    x = [p, v],  x_k = F x_{k-1} + w,  F = [[1, dt], [0, 1]],
    Q = sigma_a^2 [[dt^4 / 4, dt^3 / 2], [dt^3 / 2, dt^2]],   z_k = p_k + e,  R = sigma_z^2,

with the standard predict / update.  Both axes share F, Q and R, so they share one covariance
P (2, 2) and the gain; the state is p (2,), v (2,).  A body seen for the first time starts at its
observed centre with velocity 0 and variances ``(sigma_z^2, sigma_v0^2)``.

:class:`CentreTracker` applies it to a law's readings: a reading whose ``velocity_source`` is
``"estimated"`` gets the filtered centre (its outline and nearest point moved with it) and the
filtered velocity; a reading with known rates is returned as it is (nothing to filter), so a law
that tracks is unchanged wherever sensing is exact.  sigma_z is the sensor's: a reading that
declares its centre's noise (``position_std`` > 0: the finite-difference estimator's added noise,
a lidar's fitted centre) is filtered with it, one that declares none with the tracker's
``position_std``.  The filter's responsiveness is set by the ratio sigma_a dt^2 / sigma_z (the
tracking index), so one sigma_a serves both a precise sensor (a responsive filter: centres to a
few cm) and a noisy one (a smooth filter).  A walker's accelerations grow with its speed (turning
at rate w at speed s is an acceleration s w), so sigma_a may grow with a track's filtered speed
(``turn_std``): slow walkers get a smooth filter, fast ones a responsive one.  Units: m, s, m/s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.sensors.observation import ObstacleReading


def cv_predict(
    p: FloatArray, v: FloatArray, cov: FloatArray, dt: float, accel_std: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Predict a constant-velocity state ``dt`` [s] ahead under white-noise acceleration.

    >>> p, v, c = cv_predict(np.zeros(2), np.ones(2), np.eye(2), 2.0, 0.0)
    >>> p.tolist(), v.tolist(), c.tolist()
    ([2.0, 2.0], [1.0, 1.0], [[5.0, 2.0], [2.0, 1.0]])
    """
    f = np.array([[1.0, dt], [0.0, 1.0]])
    q = accel_std**2 * np.array([[dt**4 / 4.0, dt**3 / 2.0], [dt**3 / 2.0, dt**2]])
    return p + dt * v, v.copy(), f @ cov @ f.T + q


def cv_update(
    p: FloatArray, v: FloatArray, cov: FloatArray, z: FloatArray, position_std: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Correct a constant-velocity state with an observed position ``z`` [m] of noise
    ``position_std`` [m].

    With a far larger prior variance than the measurement's, the position jumps to ``z``:

    >>> p, v, c = cv_update(np.zeros(2), np.zeros(2), np.diag([1e6, 1.0]), np.ones(2), 0.1)
    >>> np.round(p, 4).tolist()
    [1.0, 1.0]
    """
    s = cov[0, 0] + position_std**2
    gain = cov[:, 0] / s
    r = z - p
    new_cov = cov - np.outer(gain, cov[0, :])
    return p + gain[0] * r, v + gain[1] * r, 0.5 * (new_cov + new_cov.T)


@dataclass
class CentreTracker:
    """A constant-velocity Kalman filter per sensed body (module docstring); one per episode.

    Attributes:
        position_std: sigma_z of a reading that declares no centre noise [m].
        accel_std: sigma_a, the assumed white-noise acceleration of a body [m/s^2].
        initial_speed_std: sigma_v0, the velocity spread of a body seen for the first time [m/s].
        turn_std: the spread of a body's turn rate [rad/s]: a body moving at speed s turning at
            rate w accelerates by s w, so a track's sigma_a is ``max(accel_std, turn_std s)``,
            s its filtered speed before the prediction (0: sigma_a is ``accel_std`` alone).
    """

    position_std: float = 0.1
    accel_std: float = 1.0
    initial_speed_std: float = 1.0
    turn_std: float = 0.0
    _tracks: dict[int, tuple[float, FloatArray, FloatArray, FloatArray]] = field(
        default_factory=dict
    )

    def reset(self) -> None:
        """Forget every track (a new episode)."""
        self._tracks.clear()

    def update(
        self, time: float, readings: tuple[ObstacleReading, ...], robot: FloatArray
    ) -> tuple[ObstacleReading, ...]:
        """The readings with filtered centres and velocities where the rates were estimated
        (``time`` [s]; ``robot``: the robot's position [m], for the moved nearest point's
        distance)."""
        out = []
        for rd in readings:
            if rd.velocity_source != "estimated":
                out.append(rd)
                continue
            z = np.asarray(rd.centre, dtype=float)
            sigma_z = rd.position_std if rd.position_std > 0 else self.position_std
            prev = self._tracks.get(rd.obstacle_id)
            if prev is None or not time > prev[0]:
                p, v = z.copy(), np.zeros(2)
                cov = np.diag([sigma_z**2, self.initial_speed_std**2])
            else:
                t0, p, v, cov = prev
                sigma_a = max(self.accel_std, self.turn_std * math.hypot(v[0], v[1]))
                p, v, cov = cv_predict(p, v, cov, time - t0, sigma_a)
                p, v, cov = cv_update(p, v, cov, z, sigma_z)
            self._tracks[rd.obstacle_id] = (time, p, v, cov)
            shift = p - z
            nearest = rd.nearest_point + shift
            gap = float(np.hypot(*(nearest - robot))) if rd.distance > 0 else 0.0
            out.append(
                replace(
                    rd,
                    centre=p,
                    outline=rd.outline + shift if len(rd.outline) else rd.outline,
                    nearest_point=nearest,
                    distance=gap,
                    velocity=v,
                )
            )
        return tuple(out)
