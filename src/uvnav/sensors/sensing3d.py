"""What a 3D robot senses: nearest points (3.8) within range, and obstacle rates.

Thesis Chapter 3 §3.2 (Y. Zhang, ICCAR 2020): for each obstacle, d_min(t), the minimum distance
(3.8) from the robot to the obstacle set, and r_min(t), the surface point achieving it; the mass
centre is known ("We suppose that the mass center of the obstacle is known"); the velocity v_i and
rotation u_i are *not* given — the thesis predicts them from their past values (§3.3.1).  Here:

* :func:`sense_obstacles3d` — exact nearest point and distance of each obstacle within
  ``sensing_range`` [m] (bounding-sphere culling, then the exact body kernel), its mass centre and
  orientation, and its spanning points (vertices) in the world frame; rates are the true ones only
  when asked for (``known=True``, an oracle — the thesis's "known motion" case);
* :class:`FiniteDifference3D` — rates estimated from what is sensed: backward differences of the
  sensed centre, v ~ (c_k - c_{k-1}) / dt, and of the sensed orientation,
  u ~ log(R_k R_{k-1}^T) / dt (the rotation vector of the relative rotation), optionally with
  Gaussian noise on the sensed centre.  Obstacles seen for the first time get zero rates.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.geometry.frames3d import rotation_to_vector
from uvnav.obstacles.motion3d import Obstacle3D


@dataclass(frozen=True)
class ObstacleReading3D:
    """One obstacle as sensed from the robot.

    Attributes:
        obstacle_id: stable index of the obstacle in the world.
        distance: d_min (3.8) from the robot centre to the obstacle set [m] (0 when inside).
        nearest_point: r_min [m], (3,).
        centre: mass centre [m], (3,).
        rotation: orientation (body-to-world rotation matrix), (3, 3).
        velocity: v_i [m/s], (3,) (true or estimated: ``velocity_source``).
        rotation_rate: u_i [rad/s], (3,).
        outline: the body's spanning points (mesh vertices) in the world frame, (n, 3) [m].
        bounding_radius: radius of the centre-centred sphere containing the body [m].
        velocity_source: ``"known"`` (ground truth, oracle) or ``"estimated"``.
    """

    obstacle_id: int
    distance: float
    nearest_point: FloatArray
    centre: FloatArray
    rotation: FloatArray
    velocity: FloatArray
    rotation_rate: FloatArray
    outline: FloatArray
    bounding_radius: float
    velocity_source: str = "known"


@dataclass(frozen=True)
class Observation3D:
    """Everything a 3D controller may use at one decision time.

    Attributes:
        time: simulation time [s].
        position: c_R [m], (3,).
        heading: a_R (unit), (3,).
        speed: current V_R [m/s].
        goal: end point E [m], (3,).
        obstacles: readings within sensing range, nearest first.
    """

    time: float
    position: FloatArray
    heading: FloatArray
    speed: float
    goal: FloatArray
    obstacles: tuple[ObstacleReading3D, ...] = ()


def sense_obstacles3d(
    position: FloatArray,
    obstacles: Sequence[Obstacle3D],
    *,
    sensing_range: float,
    known: bool = True,
) -> tuple[ObstacleReading3D, ...]:
    """Readings of the obstacles whose surface is within ``sensing_range`` [m] of ``position``.

    With ``known=False`` the rates are zero (to be filled by an estimator)."""
    p = np.asarray(position, dtype=float)
    out = []
    for i, ob in enumerate(obstacles):
        st = ob.state
        gap = p - st.centre
        if math.sqrt(float(gap @ gap)) - ob.body.bounding_radius > sensing_range:
            continue
        q, d = ob.nearest(p)
        if d > sensing_range:
            continue
        out.append(
            ObstacleReading3D(
                obstacle_id=i,
                distance=max(d, 0.0),
                nearest_point=q,
                centre=st.centre.copy(),
                rotation=st.rotation.copy(),
                velocity=st.velocity.copy() if known else np.zeros(3),
                rotation_rate=st.rotation_rate.copy() if known else np.zeros(3),
                outline=ob.world_outline(),
                bounding_radius=float(ob.body.bounding_radius),
                velocity_source="known" if known else "estimated",
            )
        )
    out.sort(key=lambda r: r.distance)
    return tuple(out)


@dataclass
class FiniteDifference3D:
    """Backward-difference rate estimator over an episode; call :meth:`update` once per decision.

    Attributes:
        rng: generator of the sensing noise.
        position_noise: std [m] of Gaussian noise on the sensed centre.
    """

    rng: np.random.Generator
    position_noise: float = 0.0
    _last: dict[int, tuple[float, FloatArray, FloatArray]] = field(default_factory=dict)

    def update(
        self, time: float, readings: tuple[ObstacleReading3D, ...]
    ) -> tuple[ObstacleReading3D, ...]:
        out = []
        for rd in readings:
            centre = rd.centre
            if self.position_noise > 0:
                centre = centre + self.rng.normal(0.0, self.position_noise, 3)
            v = np.zeros(3)
            u = np.zeros(3)
            prev = self._last.get(rd.obstacle_id)
            if prev is not None and time > prev[0]:
                dt = time - prev[0]
                v = (centre - prev[1]) / dt
                u = rotation_to_vector(rd.rotation @ prev[2].T) / dt
            self._last[rd.obstacle_id] = (time, centre, rd.rotation)
            out.append(
                ObstacleReading3D(
                    rd.obstacle_id,
                    rd.distance,
                    rd.nearest_point,
                    centre,
                    rd.rotation,
                    v,
                    u,
                    rd.outline,
                    rd.bounding_radius,
                    "estimated",
                )
            )  # fmt: skip (all fields: faster than dataclasses.replace, run per obstacle)
        return tuple(out)
