"""``vo3d-v1``: 3D velocity obstacles by sampling (baseline, not in the thesis).

Reference: P. Fiorini and Z. Shiller, "Motion planning in dynamic environments using velocity
obstacles", IJRR 17(7), 1998; the sampling form follows the common practice of RVO2-3D
(J. van den Berg et al.) without its reciprocity (obstacles do not react).  Own numpy
implementation: no 3D VO library is in the project's dependency set (pyrvo is 2D).

Each sensed obstacle is a sphere of its bounding radius plus the robot's radius and ``margin``
around its mass centre, moving with its sensed velocity v_i.  Candidate velocities are
``n_dirs`` unit directions (a Fibonacci sphere, plus the current heading and the direction to E)
times ``n_speeds`` speeds in (0, V_max].  A candidate v collides within ``horizon`` tau if the ray
c_R + (v - v_i) t meets a sphere for t in [0, tau].  The chosen velocity minimises
``||v - v_pref|| + w_turn * angle(v, a_R) + penalty / t_collision`` (v_pref = V_max toward E), and
the vehicle turns toward it at the bounded rate with speed ||v||.  Conservative for non-convex
bodies (their bounding spheres are used).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar, cast

import numpy as np

from uvnav.controllers.base import ControllerInfo, check_params, register
from uvnav.controllers.base3d import Vehicle3DController
from uvnav.dynamics.vehicle3d import Vehicle3DCommand
from uvnav.geometry.angles import FloatArray
from uvnav.sensors.sensing3d import Observation3D


def fibonacci_sphere(n: int) -> FloatArray:
    """``n`` nearly uniform unit vectors (n, 3)."""
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    r = np.sqrt(np.maximum(1.0 - z * z, 0.0))
    phi = math.pi * (3.0 - math.sqrt(5.0)) * i
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def time_to_collision(rel_pos: FloatArray, rel_vel: FloatArray, radius: FloatArray) -> FloatArray:
    """Earliest t >= 0 at which ``rel_pos + rel_vel t`` enters the sphere of ``radius`` about 0.

    Args:
        rel_pos: (m, 3) robot position relative to each sphere centre [m].
        rel_vel: (k, m, 3) candidate relative velocities [m/s].
        radius: (m,) combined radii [m].

    Returns:
        (k, m) times [s] (0 when already inside, inf when never).
    """
    b = np.einsum("kmi,mi->km", rel_vel, rel_pos)
    a = np.einsum("kmi,kmi->km", rel_vel, rel_vel)
    c = np.einsum("mi,mi->m", rel_pos, rel_pos) - radius**2
    disc = b * b - a * c[None]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (-b - np.sqrt(np.maximum(disc, 0.0))) / a
    t = np.where((disc >= 0) & (a > 0) & (t >= 0), t, np.inf)
    return np.where(c[None] <= 0, 0.0, t)


@dataclass(frozen=True)
class VO3DParams:
    """Parameters of ``vo3d-v1``.

    Attributes:
        horizon: tau, the collision horizon [s].
        margin: added to the combined radii [m].
        n_dirs: sampled directions.
        n_speeds: sampled speeds.
        w_turn: weight of the heading change [m/s per rad].
        penalty: weight of 1 / time-to-collision [m].
    """

    horizon: float = 4.0
    margin: float = 0.25
    n_dirs: int = 96
    n_speeds: int = 3
    w_turn: float = 0.3
    penalty: float = 2.0

    def __post_init__(self) -> None:
        check_params(self, positive=("horizon", "n_dirs", "n_speeds"),
                     non_negative=("margin", "w_turn", "penalty"))  # fmt: skip


class VO3D(Vehicle3DController):
    """Sampled 3D velocity obstacles (see the module docstring)."""

    name: ClassVar[str] = "vo3d-v1"

    def __init__(self, params: VO3DParams | None = None) -> None:
        super().__init__()
        self.p = params or VO3DParams()
        self._dirs = fibonacci_sphere(int(self.p.n_dirs))

    def act(self, obs: Observation3D) -> Vehicle3DCommand:
        period = self.decision_period(obs.time)
        gap = self._goal - obs.position
        dist = float(np.linalg.norm(gap))
        if dist < 1e-9:
            return Vehicle3DCommand(0.0, np.zeros(3))
        to_goal = gap / dist
        if not obs.obstacles:
            self._mode = "M1"
            return self.approach(obs, period)
        vmax = self._spec.v_max
        v_pref = to_goal * min(vmax, dist / max(period, 1e-3))
        dirs = np.concatenate([self._dirs, obs.heading[None], to_goal[None]])
        speeds = vmax * np.arange(1, self.p.n_speeds + 1) / self.p.n_speeds
        cand = (dirs[None] * speeds[:, None, None]).reshape(-1, 3)
        centres = np.array([rd.centre for rd in obs.obstacles])
        vels = np.array([rd.velocity for rd in obs.obstacles])
        radii = np.array([rd.bounding_radius for rd in obs.obstacles]) + (
            self._spec.radius + self.p.margin
        )
        rel_pos = obs.position[None] - centres
        rel_vel = cand[:, None, :] - vels[None]
        ttc = time_to_collision(rel_pos, rel_vel, radii).min(axis=1)
        cost = np.linalg.norm(cand - v_pref, axis=1)
        cosang = np.clip(cand @ obs.heading / np.linalg.norm(cand, axis=1), -1.0, 1.0)
        cost += self.p.w_turn * np.arccos(cosang)
        with np.errstate(divide="ignore"):
            cost += np.where(ttc <= self.p.horizon, self.p.penalty / np.maximum(ttc, 1e-3), 0.0)
        best = int(np.argmin(cost))
        self._mode = "M2" if bool(np.any(ttc <= self.p.horizon)) else "M1"
        if self._mode == "M1" and best >= 0 and float(np.linalg.norm(cand[best] - v_pref)) < 1e-9:
            return self.approach(obs, period)
        v = cand[best]
        return self.steer(obs, v, float(np.linalg.norm(v)), period)


register(
    ControllerInfo(
        name=VO3D.name,
        factory=cast("Callable[..., Any]", VO3D),
        params_type=VO3DParams,
        summary="3D velocity obstacles by sampling, bounding spheres (baseline)",
        reference="Fiorini & Shiller, IJRR 1998",
        vehicle="vehicle3d",
    )
)
