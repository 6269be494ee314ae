"""The demonstration driver: an ORACLE pure-pursuit expert with a corner-speed profile.

Paper: R. C. Coulter, "Implementation of the Pure Pursuit Path Tracking Algorithm", CMU-RI-TR-92-01
(1992).  Thesis Chapter 6 learns from a human driving the Udacity car; here the demonstrations come
from this expert, which reads the ground truth (the car's pose and the track centreline, hence an
oracle) and is never seen by the network.

Steering: pure pursuit to the centreline point ``L = lookahead + lookahead_gain · v`` ahead,
front-wheel angle ``δ = atan(2 W sin α / L)`` (W: CarRacing's wheelbase 3.24 m, α: bearing of the
target in the car frame), normalised by the 0.4 rad wheel limit.
Speed: the corner-speed profile of :func:`uvnav.driving.track.corner_speed_profile` ahead of the
car; throttle = ``clip(k_v (v_target − v), −1, 1)`` (gas or brake).  The label is this smooth
function of the state (speed, track ahead), which is what makes a learned throttle possible.

Recording noise (DART, Laskey et al. 2017): while recording, correlated AR(1) noise is added to
the steering that is APPLIED, but the label is the clean expert command at the perturbed state, so
the data show how to recover from drifts the clean expert never makes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from uvnav.driving.sim import MAX_WHEEL_ANGLE, Telemetry
from uvnav.driving.track import TrackGeometry, corner_speed_profile, point_ahead, project

#: CarRacing's wheelbase: front axle at +80, rear at −82 body units × SIZE 0.02 [m]
WHEELBASE = 3.24


@dataclass(frozen=True)
class ExpertParams:
    """Pure-pursuit expert parameters.

    Attributes:
        lookahead: base lookahead distance [m].
        lookahead_gain: extra lookahead per unit speed [s].
        v_max: top speed on straights [m/s].
        a_lat: lateral acceleration in corners [m/s²].
        a_brake: braking deceleration assumed by the profile [m/s²].
        preview: the target speed is the minimum of the profile over this distance ahead [m].
        k_speed: throttle per unit speed error [1/(m/s)].
    """

    lookahead: float = 8.0
    lookahead_gain: float = 0.25
    v_max: float = 120.0
    a_lat: float = 90.0
    a_brake: float = 50.0
    preview: float = 10.0
    k_speed: float = 0.15


class PurePursuitExpert:
    """ORACLE expert driver (reads pose and track).  ``act(telemetry) -> (steer, throttle)``."""

    def __init__(self, geometry: TrackGeometry, params: ExpertParams | None = None) -> None:
        self.geometry = geometry
        self.params = params or ExpertParams()
        p = self.params
        self.profile = corner_speed_profile(
            geometry, v_max=p.v_max, a_lat=p.a_lat, a_brake=p.a_brake
        )

    def target_speed(self, i: int) -> float:
        """Minimum of the speed profile from segment ``i`` over the preview distance [m/s]."""
        g = self.geometry
        n = len(g.points)
        k = int(np.ceil(self.params.preview / max(float(np.mean(g.seg_len)), 1e-9))) + 1
        idx = (i + np.arange(k)) % n
        return float(self.profile[idx].min())

    def act(self, tel: Telemetry) -> tuple[float, float]:
        """Clean expert command at the car's state.

        Args:
            tel: telemetry (pose and speed: ground truth).

        Returns:
            ``(steer, throttle)`` in [-1, 1]: normalised steering (+ right) and throttle.
        """
        steer, throttle, _ = self.label(tel)
        return steer, throttle

    def label(self, tel: Telemetry) -> tuple[float, float, float]:
        """Clean expert command and the speed it is tracking (the recorded labels).

        Args:
            tel: telemetry (pose and speed: ground truth).

        Returns:
            ``(steer, throttle, target_speed)``: as :meth:`act`, and the target speed [m/s] of
            the corner-speed profile at the car's position (``throttle = clip(k_speed ·
            (target_speed − speed), −1, 1)``).  The target speed depends on the road ahead
            only, not on the car's speed.
        """
        p = self.params
        i, t, _ = project(self.geometry, tel.x, tel.y)
        steer = self._steer(tel.x, tel.y, tel.heading, tel.speed, i, t)
        v_target = self.target_speed(i)
        throttle = float(np.clip(p.k_speed * (v_target - tel.speed), -1.0, 1.0))
        return steer, throttle, v_target

    def steer_at(self, x: float, y: float, heading: float, speed: float) -> float:
        """Pure-pursuit steering at pose ``(x [m], y [m], heading [rad])`` and ``speed`` [m/s].

        Returns:
            Normalised steering in [-1, 1] (+ right).
        """
        i, t, _ = project(self.geometry, x, y)
        return self._steer(x, y, heading, speed, i, t)

    def _steer(self, x: float, y: float, heading: float, speed: float, i: int, t: float) -> float:
        """:meth:`steer_at` with the pose's projection on the centreline (segment ``i``,
        fraction ``t``) already known."""
        p = self.params
        L = p.lookahead + p.lookahead_gain * speed
        target = point_ahead(self.geometry, i, t, L)
        alpha = np.arctan2(target[1] - y, target[0] - x) - heading
        alpha = (alpha + np.pi) % (2 * np.pi) - np.pi
        delta = np.arctan2(2 * WHEELBASE * np.sin(alpha), L)  # + left
        return float(np.clip(-delta / MAX_WHEEL_ANGLE, -1.0, 1.0))

    def side_steering(self, tel: Telemetry, shift: float) -> tuple[float, float]:
        """Exact steering labels of the left and right camera images (beyond the thesis).

        The image a camera ``shift`` [m] to the car's left sees is the centre camera's image of
        a car ``shift`` to the left with the same heading
        (:func:`uvnav.driving.camera.render_view`), so its label is the expert's command at that
        pose, at the same speed.  Udacity recordings have no such label and use a fixed
        ``± correction`` (0.2) instead; the true correction shrinks with speed (the lookahead
        grows) and grows near the road's edge, which the fixed value cannot follow.

        Args:
            tel: telemetry of the car (ground truth).
            shift: lateral offset of the side cameras [m] (:attr:`DrivingSim.side_shift`).

        Returns:
            ``(left, right)`` normalised steering (+ right).
        """
        nx, ny = -np.sin(tel.heading), np.cos(tel.heading)  # the car's left
        return (
            self.steer_at(tel.x + shift * nx, tel.y + shift * ny, tel.heading, tel.speed),
            self.steer_at(tel.x - shift * nx, tel.y - shift * ny, tel.heading, tel.speed),
        )


def ar1_noise(rng: np.random.Generator, n: int, *, sigma: float, rho: float) -> NDArray[np.float64]:
    """Stationary AR(1) sequence ``e_t = ρ e_{t−1} + σ √(1−ρ²) w_t`` with std ``sigma``.

    Args:
        rng: random generator.
        n: length.
        sigma: stationary standard deviation.
        rho: correlation between consecutive steps, in [0, 1).

    Returns:
        ``(n,)`` noise.
    """
    w = rng.standard_normal(n)
    e = np.empty(n)
    prev = sigma * rng.standard_normal()
    k = sigma * np.sqrt(1.0 - rho**2)
    for j in range(n):
        prev = rho * prev + k * w[j]
        e[j] = prev
    return e
